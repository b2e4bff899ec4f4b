// A parameter study (`depotwin sweep`): a base scenario, the overrides that make each task,
// and the folder their results go to.
//
// Tasks are numbered from 0 in the order of the sweep file: the grid's keys are a mixed-radix
// number whose last key varies fastest, and the zip's lists advance together after them
// (task = grid index x zip length + zip position). Task i's folder is DIR/tasks/<i>, zero-padded
// to at least four digits; it holds task.json (the task's parameters, input hash, status,
// error and wall time) and, for a task that ran, DIR/tasks/<i>/<run>/metrics.json (with
// `keep: all`, everything `depotwin run --no-render` writes there).
//
// A task's input hash covers what its scenario is made of: the base scenario's text and the
// overrides (`set:` and the task's parameters), which determine the overridden scenario, the
// bytes of the files it reads (G-code, STL, MJCF), `keep:` and the depotwin version. A task
// whose folder holds an `ok` result with the same hash is up to date and is skipped unless
// forced; any edit of the base file (a comment too) makes every task new.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scenario/sweep_file.hpp"

namespace depotwin {

// the depotwin version, part of every input hash
const char* sweep_depotwin_version();

struct SweepTask {
  std::uint64_t index = 0;
  // (key, value) per parameter: the grid's keys, then the zip's
  std::vector<std::pair<std::string, SweepValue>> parameters;
  // `set:` then the parameters, as the scenario loader applies them
  std::vector<ScenarioOverride> overrides;

  // "planner=bezier, toolpath.speed=2", for messages
  std::string parameters_text() const;
};

class Sweep {
 public:
  // Reads the sweep file and its base scenario's text. `out` is the results folder (empty:
  // results/<sweep name>). InputError for a bad sweep file.
  Sweep(const std::string& sweep_file, const std::string& out);

  const SweepSpec& spec() const { return spec_; }
  std::uint64_t size() const { return spec_.task_count; }
  // the swept keys, in column order: the grid's, then the zip's
  const std::vector<std::string>& parameter_keys() const { return parameter_keys_; }
  const std::string& out_directory() const { return out_; }

  // task `index` (< size())
  SweepTask task(std::uint64_t index) const;
  // "tasks/0007": its folder relative to the results folder, and the full path
  std::string task_folder_name(std::uint64_t index) const;
  std::string task_folder(std::uint64_t index) const;
  // The folder holding task `index`'s result: task_folder(index), or, when that is absent, the
  // same index under another zero-padding (a sweep grown past 9,999 tasks, or shrunk below
  // 10,000, names its folders with more or fewer digits than the run that wrote them).
  std::string found_task_folder(std::uint64_t index) const;
  // Renames the task folders written under another zero-padding to task_folder(), where that
  // name is free; folders beyond the last task are left as they are. Called by a local run or
  // merge holding the folder's lock; errors leave a folder where it is (found_task_folder still
  // finds it).
  void rename_task_folders_to_current_width() const;
  // the log of a task run by -j or GNU parallel: DIR/logs/task-<i>.log
  std::string task_log(std::uint64_t index) const;

  // The task's scenario: the base with its overrides, loaded and validated as a file is.
  // InputError listing every problem (those of an override at the sweep file's line).
  Scenario load_task(const SweepTask& task) const;
  // the task's input hash: 16 hex digits. InputError when the overrides do not fit the tree.
  std::string input_hash(const SweepTask& task) const;

  // Loads every task's scenario (on `threads` threads) and checks that each runs one planner;
  // InputError listing every problem once, each with the tasks it concerns
  // (`(tasks 2, 5, 8: toolpath.speed=5)`, `(every task)`). `progress`: a progress line.
  void validate_all(int threads, bool progress) const;

  // Refuses (InputError, key --out) a results folder that is a file, lies under a file, or
  // exists with files but is neither a sweep's folder (its .depotwin marker, or only tasks/ and
  // logs/ in it) nor empty; otherwise creates it with its marker, tasks/ and logs/.
  void prepare_out_directory() const;

 private:
  SweepSpec spec_;
  std::string base_text_;
  std::string out_;
  std::vector<std::string> parameter_keys_;
  int folder_digits_ = 4;
  // the hashes of the files the scenario reads when every task reads the same ones
  std::optional<std::vector<std::string>> shared_input_files_;
  std::vector<std::string> input_file_hashes(const std::vector<ScenarioOverride>& overrides) const;
};

// a task index from `--task` text: a whole number, or `env` (SLURM_ARRAY_TASK_ID plus
// DEPOTWIN_SWEEP_TASK_OFFSET, else JOB_COMPLETION_INDEX); InputError (key --task) for anything
// else, a missing variable or an index outside [0, count)
std::uint64_t task_index_from(const std::string& text, std::uint64_t count);

}  // namespace depotwin
