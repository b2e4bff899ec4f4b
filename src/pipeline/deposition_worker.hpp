// A simulated run's deposition on a worker thread: the step loop hands each step over and
// goes on simulating while the worker lays the steps down, in the order given, so the deposit
// is the same, bit for bit, as depositing on the simulating thread. On two cores the physics
// and the deposit (each about half of a printing run's work) then take turns no more.
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "deposition/layered_deposit.hpp"

namespace depotwin {

class DepositionWorker {
 public:
  // the deposit is the worker's until finish() returns
  explicit DepositionWorker(LayeredDeposit& deposit);
  ~DepositionWorker();
  DepositionWorker(const DepositionWorker&) = delete;
  DepositionWorker& operator=(const DepositionWorker&) = delete;

  // from the simulating thread: deposit this step into layer `layer`, in turn
  void push(const DepositionStep& step, int layer);
  // wait until every step is down; rethrows what the worker threw
  void finish();

 private:
  struct Item {
    DepositionStep step;
    int layer = 0;
  };
  static constexpr size_t kChunk = 2048;  // steps handed over at once

  void hand_over();  // the filling chunk to the worker
  void work();

  LayeredDeposit& deposit_;
  std::vector<Item> filling_;
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<std::vector<Item>> queue_;
  bool done_ = false;
  std::exception_ptr failure_;
  std::thread thread_;
};

}  // namespace depotwin
