// One task of a sweep: run in this process like `depotwin run --no-render` with the task's
// one planner, its folder written whole (staged beside its place and swapped in), and its
// record, task.json, read back by the merge and by the next run (up to date or not).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sweep/sweep.hpp"

namespace depotwin {

// task.json
struct TaskRecord {
  std::uint64_t index = 0;
  std::vector<std::pair<std::string, std::string>> parameters;  // key, value as text
  std::string input_hash;
  std::string status;  // ok | failed
  std::string error;   // failed: what went wrong
  double wall_s = 0.0;
  std::string run;  // ok: the run's folder under the task's (the planner's run label)
  std::string depotwin_version;
};

std::string task_record_json(const TaskRecord& record);
// the record in `folder`/task.json; nothing when it is absent or unreadable
std::optional<TaskRecord> read_task_record(const std::string& folder);

// an `ok` record with this input hash is in the task's folder, and its metrics.json, whole
bool task_up_to_date(const Sweep& sweep, std::uint64_t index, const std::string& input_hash);

// Runs the task and writes its folder: task.json, and for a task that ran
// <run>/metrics.json (keep: all: everything `run --no-render` writes). The task's own failure
// (bad input found while preparing it, a planner or simulator failure) is recorded, not
// thrown. Throws InputError only when the folder itself cannot be written (--out).
TaskRecord run_task(const Sweep& sweep, const SweepTask& task, const std::string& input_hash);

// Records a failure the task could not record itself (its process died): a folder holding
// task.json with status failed and `error`.
void record_task_failure(const Sweep& sweep, const SweepTask& task, const std::string& input_hash,
                         const std::string& error, double wall_s);

}  // namespace depotwin
