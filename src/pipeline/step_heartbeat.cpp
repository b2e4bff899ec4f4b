#include "pipeline/step_heartbeat.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace depotwin {

namespace {

// each thread's step under way; the heartbeat showing its thread's steps (if any), under
// steps_mutex (locked before a heartbeat's own mutex, never after)
thread_local std::string current_step;
std::mutex steps_mutex;
StepHeartbeat* listener = nullptr;

// a terminal line is rewritten this often
constexpr double kTerminalPeriod_s = 0.5;
// the thread looks at the clock at least this often, and at most (a period of 0: every look)
constexpr double kLongestTick_s = 0.25;
constexpr double kShortestTick_s = 0.05;

}  // namespace

StepHeartbeat::StepHeartbeat(std::string label, ProgressLine::Style style, std::FILE* out,
                             double terminal_delay_s, double period_s)
    : label_(std::move(label)),
      style_(style),
      out_(out),
      terminal_delay_s_(terminal_delay_s),
      period_s_(period_s >= 0.0                          ? period_s
                : style == ProgressLine::Style::terminal ? kTerminalPeriod_s
                                                         : ProgressLine::log_period_s()) {
  if (style_ == ProgressLine::Style::off) return;
  {
    std::lock_guard<std::mutex> steps(steps_mutex);
    if (listener != nullptr) return;  // one shows already
    listener = this;
    listening_ = true;
    owner_ = std::this_thread::get_id();
    step_ = current_step;
    step_start_s_ = ProgressLine::steady_seconds();
  }
  thread_ = std::thread([this] { beat(); });
}

StepHeartbeat::~StepHeartbeat() {
  if (!listening_) return;
  {
    std::lock_guard<std::mutex> steps(steps_mutex);
    listener = nullptr;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
  end_line_locked();  // (the thread is gone: nothing else writes)
}

void StepHeartbeat::enter(const std::string& step) {
  current_step = step;
  std::lock_guard<std::mutex> steps(steps_mutex);
  if (listener == nullptr || listener->owner_ != std::this_thread::get_id()) return;
  StepHeartbeat& heartbeat = *listener;
  std::lock_guard<std::mutex> lock(heartbeat.mutex_);
  if (heartbeat.step_ == step) return;
  // the last step's line stays, with its time; the next starts afresh
  heartbeat.end_line_locked();
  heartbeat.step_ = step;
  heartbeat.step_start_s_ = ProgressLine::steady_seconds();
  heartbeat.last_write_s_ = -1.0;
}

void StepHeartbeat::beat() {
  const bool terminal = style_ == ProgressLine::Style::terminal;
  // the first line after the terminal's delay or a log's first period, then one per period
  const double first_s = terminal ? terminal_delay_s_ : period_s_;
  const double tick_s = std::clamp(period_s_, kShortestTick_s, kLongestTick_s);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, std::chrono::duration<double>(tick_s));
    if (stopping_ || step_.empty()) continue;
    const double elapsed_s = ProgressLine::steady_seconds() - step_start_s_;
    if (elapsed_s < first_s) continue;
    if (last_write_s_ >= 0.0 && elapsed_s < last_write_s_ + period_s_) continue;
    write_locked(elapsed_s);
  }
}

void StepHeartbeat::write_locked(double elapsed_s) {
  if (style_ == ProgressLine::Style::terminal) {
    // spaces over what a longer line before left
    const int length =
        std::fprintf(out_, "\r%s: %s (%.1f s)", label_.c_str(), step_.c_str(), elapsed_s);
    if (length < last_length_) std::fprintf(out_, "%*s", last_length_ - length, "");
    last_length_ = std::max(length, last_length_);
  } else {
    std::fprintf(out_, "%s: %s (%.1f s)\n", label_.c_str(), step_.c_str(), elapsed_s);
  }
  std::fflush(out_);
  last_write_s_ = elapsed_s;
}

void StepHeartbeat::end_line_locked() {
  // a terminal's line ends with the step's whole time
  if (style_ == ProgressLine::Style::terminal && last_length_ > 0) {
    write_locked(ProgressLine::steady_seconds() - step_start_s_);
    std::fputc('\n', out_);
    std::fflush(out_);
  }
  last_length_ = 0;
}

StepHeartbeat job_heartbeat(const std::string& scenario_path, bool quiet) {
  return StepHeartbeat(std::filesystem::path(scenario_path).stem().string(),
                       ProgressLine::style_for_stderr(!quiet));
}

WorkingStep::WorkingStep(const std::string& step) : before_(current_step) {
  StepHeartbeat::enter(step);
}

WorkingStep::~WorkingStep() {
  StepHeartbeat::enter(before_);
}

}  // namespace depotwin
