// What a long job is doing while no fraction of it can be told: loading a part's hatch, the
// print order, an arm's posture, each planner's plan, the poses' check, the files written.
// The pipeline names its steps (WorkingStep, cheap whether anyone shows them or not); a verb
// that may run long holds a StepHeartbeat, whose thread shows the step on stderr once it has
// taken a while, as ProgressLine does for a fraction:
//   terminal  "<label>: planning conformal (12.3 s)", rewritten in place every half second
//             after the step's first second, and ended with a newline when the step ends, so
//             the steps that took long stay listed with their times;
//   log       the same line every few seconds (DEPOTWIN_PROGRESS_PERIOD_S, as ProgressLine);
//   off       nothing (--quiet).
// A step named "" shows nothing (a stretch with its own ProgressLine, the simulation). Each
// thread has its own steps, and a heartbeat shows those of the thread that made it; at most
// one heartbeat shows at a time (a second one, nested, shows nothing).
#pragma once

#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

#include "pipeline/progress_line.hpp"

namespace depotwin {

class StepHeartbeat {
 public:
  // (terminal_delay_s: a step shows after this long on a terminal; period_s: how often the
  // line is written, a terminal's every half second by default, a log's every
  // ProgressLine::log_period_s())
  StepHeartbeat(std::string label, ProgressLine::Style style, std::FILE* out = stderr,
                double terminal_delay_s = ProgressLine::kTerminalDelay_s, double period_s = -1.0);
  // the line closed, the thread joined
  ~StepHeartbeat();
  StepHeartbeat(const StepHeartbeat&) = delete;
  StepHeartbeat& operator=(const StepHeartbeat&) = delete;

  // (WorkingStep's: the step now under way, "" for none)
  static void enter(const std::string& step);

 private:
  void beat();
  void write_locked(double elapsed_s);
  void end_line_locked();

  std::string label_;
  ProgressLine::Style style_;
  std::FILE* out_;
  double terminal_delay_s_, period_s_;
  bool listening_ = false;  // this one shows the steps (the first heartbeat of its time)
  std::thread::id owner_;   // the thread whose steps it shows (the one that made it)
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::string step_;
  double step_start_s_ = 0.0;
  double last_write_s_ = -1.0;  // elapsed time of the step's last line (-1: none yet)
  int last_length_ = 0;         // characters of the terminal line now shown (0: none)
  std::thread thread_;
};

// A verb's heartbeat: named by the scenario file's name (its stem), on stderr; off when quiet.
StepHeartbeat job_heartbeat(const std::string& scenario_path, bool quiet);

// The step under way while it is in scope (then the one before again).
class WorkingStep {
 public:
  explicit WorkingStep(const std::string& step);
  ~WorkingStep();
  WorkingStep(const WorkingStep&) = delete;
  WorkingStep& operator=(const WorkingStep&) = delete;

 private:
  std::string before_;
};

}  // namespace depotwin
