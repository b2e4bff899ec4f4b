// `depotwin sweep FILE -j N`: the tasks on N local worker processes.
//
// Why processes, and why long-lived ones: a task runs MuJoCo, whose fatal errors end the
// process (sim/mujoco_boundary.hpp), so a crash must cost one task, not the sweep; and a
// process per task would pay depotwin's start-up each time (about 0.1 s of CPU linking
// OSMesa's LLVM and MuJoCo, a third of a thompson_fig7 run). So each worker is the same binary
// (`depotwin sweep FILE --out DIR --worker`, started once by posix_spawn), fed task indices on
// its stdin, one at a time; it runs each task in process (sweep/task.hpp) with its stdout
// and stderr in DIR/logs/task-<i>.log and reports "<index> <status>" on fd 3. A worker that
// dies mid-task has that task recorded as failed (its signal or exit status and the end of
// its log) and is replaced.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sweep/sweep.hpp"

namespace depotwin {

struct LocalRunOptions {
  int workers = 1;
  bool progress = true;    // a progress line with an ETA on stderr
  std::string executable;  // the depotwin binary the workers run
  std::string sweep_file;  // the sweep file as the workers read it
};

struct LocalRunSummary {
  std::uint64_t ran = 0;     // tasks run (ok or failed)
  std::uint64_t failed = 0;  // of those, failed
  std::vector<std::uint64_t> failed_tasks;
  double wall_s = 0.0;
};

// Runs `tasks` (indices) on the workers; returns when every one has a record.
LocalRunSummary run_tasks_locally(const Sweep& sweep, const std::vector<std::uint64_t>& tasks,
                                  const LocalRunOptions& options);

// The worker's loop (`--worker`): task indices from stdin until it closes, a line per task
// done on fd 3. InputError when fd 3 is not open (the flag is for depotwin's own use).
int sweep_worker(const Sweep& sweep);

// the path of the running executable (/proc/self/exe)
std::string current_executable();

}  // namespace depotwin
