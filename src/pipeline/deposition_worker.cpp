#include "pipeline/deposition_worker.hpp"

namespace depotwin {

DepositionWorker::DepositionWorker(LayeredDeposit& deposit) : deposit_(deposit) {
  filling_.reserve(kChunk);
  thread_ = std::thread([this] { work(); });
}

DepositionWorker::~DepositionWorker() {
  // an exception on the simulating side (an interrupt, a failure): what is still queued is
  // dropped, and the worker stops without rethrowing
  if (thread_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queue_.clear();
      done_ = true;
    }
    ready_.notify_one();
    thread_.join();
  }
}

void DepositionWorker::push(const DepositionStep& step, int layer) {
  filling_.push_back(Item{step, layer});
  if (filling_.size() == kChunk) hand_over();
}

void DepositionWorker::hand_over() {
  std::vector<Item> chunk;
  chunk.reserve(kChunk);
  chunk.swap(filling_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(chunk));
  }
  ready_.notify_one();
}

void DepositionWorker::finish() {
  if (!filling_.empty()) hand_over();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  ready_.notify_one();
  if (thread_.joinable()) thread_.join();
  if (failure_) std::rethrow_exception(failure_);
}

void DepositionWorker::work() {
  // chunks in the order they came; after a failure, the rest is dropped
  while (true) {
    std::vector<Item> chunk;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      ready_.wait(lock, [this] { return done_ || !queue_.empty(); });
      if (queue_.empty()) return;  // done, and nothing left
      chunk = std::move(queue_.front());
      queue_.pop_front();
    }
    if (failure_) continue;
    try {
      for (const Item& item : chunk) deposit_.advance(item.step, item.layer);
    } catch (...) {
      failure_ = std::current_exception();
    }
  }
}

}  // namespace depotwin
