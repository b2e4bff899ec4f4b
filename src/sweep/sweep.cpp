#include "sweep/sweep.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/number_text.hpp"
#include "kinematics/machine.hpp"
#include "pipeline/models_dir.hpp"
#include "pipeline/progress_line.hpp"
#include "report/output_dir.hpp"
#include "scenario/overrides.hpp"
#include "sweep/hash.hpp"

namespace depotwin {

namespace fs = std::filesystem;

const char* sweep_depotwin_version() {
  return DEPOTWIN_VERSION;
}

std::string SweepTask::parameters_text() const {
  std::string text;
  for (const auto& [key, value] : parameters)
    text += (text.empty() ? "" : ", ") + key + "=" + value.text;
  return text;
}

Sweep::Sweep(const std::string& sweep_file, const std::string& out)
    : spec_(read_sweep_file(sweep_file)) {
  if (const std::string too_large = settings_file_size_problem("scenario", spec_.base);
      !too_large.empty())
    throw InputError(spec_.base, 0, "", too_large);
  base_text_ = read_text_file(spec_.base);
  out_ = out.empty() ? (fs::path("results") / spec_.name).string() : out;
  for (const SweepParameter& parameter : spec_.grid) parameter_keys_.push_back(parameter.key);
  for (const SweepParameter& parameter : spec_.zip) parameter_keys_.push_back(parameter.key);
  // folder names sort in task order: at least four digits, more for larger sweeps
  folder_digits_ = std::max<int>(4, static_cast<int>(std::to_string(size() - 1).size()));
  // the files every task reads, hashed once, unless a parameter can name other ones (the
  // machine's model, a G-code file, a part's STL)
  const auto names_files = [](const std::string& key) {
    for (const char* prefix : {"machine", "toolpath.gcode", "toolpath.surface"})
      if (key.compare(0, std::string(prefix).size(), prefix) == 0) return true;
    return key == "toolpath";
  };
  if (std::none_of(parameter_keys_.begin(), parameter_keys_.end(), names_files)) {
    try {
      shared_input_files_ = input_file_hashes(spec_.fixed);
    } catch (const InputError&) {
      // a set: override that does not fit: every task says so when it is checked
    }
  }
}

SweepTask Sweep::task(std::uint64_t index) const {
  if (index >= size())
    throw InternalError("task " + std::to_string(index) + " of a sweep of " +
                        std::to_string(size()));
  SweepTask task;
  task.index = index;
  // the zip's position is the last digit, the grid's keys before it (last key fastest)
  std::uint64_t rest = index;
  std::size_t zip_position = 0;
  if (!spec_.zip.empty()) {
    const std::uint64_t length = spec_.zip.front().values.size();
    zip_position = static_cast<std::size_t>(rest % length);
    rest /= length;
  }
  std::vector<std::size_t> grid_position(spec_.grid.size());
  for (std::size_t k = spec_.grid.size(); k-- > 0;) {
    const std::uint64_t length = spec_.grid[k].values.size();
    grid_position[k] = static_cast<std::size_t>(rest % length);
    rest /= length;
  }
  for (std::size_t k = 0; k < spec_.grid.size(); ++k)
    task.parameters.emplace_back(spec_.grid[k].key, spec_.grid[k].values[grid_position[k]]);
  for (const SweepParameter& parameter : spec_.zip)
    task.parameters.emplace_back(parameter.key, parameter.values[zip_position]);

  // the overrides: set: first, then the parameters at their lines
  task.overrides = spec_.fixed;
  const auto line_of = [&](const std::string& key) {
    for (const SweepParameter& p : spec_.grid)
      if (p.key == key) return p.line;
    for (const SweepParameter& p : spec_.zip)
      if (p.key == key) return p.line;
    return 0;
  };
  for (const auto& [key, value] : task.parameters)
    task.overrides.push_back(ScenarioOverride{key, value.yaml, spec_.file, line_of(key)});
  return task;
}

namespace {

// a task folder's name under tasks/: its index zero-padded to `width` digits
std::string zero_padded(std::uint64_t index, std::size_t width) {
  std::string digits = std::to_string(index);
  if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
  return digits;
}

// the task index a folder name under tasks/ stands for: digits only, zero-padded to at least
// four (a staging folder, tasks/<i>.partial-<pid>, is not one)
std::optional<std::uint64_t> task_index_of_folder(const std::string& name) {
  if (name.size() < 4 || name.size() > 19) return std::nullopt;
  if (!std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  return std::stoull(name);
}

}  // namespace

std::string Sweep::task_folder_name(std::uint64_t index) const {
  return "tasks/" + zero_padded(index, static_cast<std::size_t>(folder_digits_));
}

std::string Sweep::task_folder(std::uint64_t index) const {
  return (fs::path(out_) / task_folder_name(index)).string();
}

std::string Sweep::found_task_folder(std::uint64_t index) const {
  const std::string current = task_folder(index);
  std::error_code error;
  if (fs::exists(current, error)) return current;
  for (std::size_t width = std::max<std::size_t>(4, std::to_string(index).size()); width <= 19;
       ++width) {
    if (static_cast<int>(width) == folder_digits_) continue;
    const fs::path other = fs::path(out_) / "tasks" / zero_padded(index, width);
    if (fs::is_directory(other, error)) return other.string();
  }
  return current;
}

void Sweep::rename_task_folders_to_current_width() const {
  std::error_code error;
  std::vector<std::pair<fs::path, fs::path>> renames;
  for (const fs::directory_entry& entry : fs::directory_iterator(fs::path(out_) / "tasks", error)) {
    const std::string name = entry.path().filename().string();
    const std::optional<std::uint64_t> index = task_index_of_folder(name);
    if (!index || *index >= size() || static_cast<int>(name.size()) == folder_digits_) continue;
    if (!entry.is_directory(error)) continue;
    renames.emplace_back(entry.path(), fs::path(task_folder(*index)));
  }
  for (const auto& [from, to] : renames) {
    std::error_code ignored;
    if (!fs::exists(to, ignored)) fs::rename(from, to, ignored);
  }
}

std::string Sweep::task_log(std::uint64_t index) const {
  return (fs::path(out_) / "logs" / ("task-" + std::to_string(index) + ".log")).string();
}

Scenario Sweep::load_task(const SweepTask& task) const {
  return load_scenario(spec_.base, base_text_, task.overrides);
}

namespace {

// the bytes of the files a scenario reads, hashed once per process and version of the file
std::string file_hash(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, std::string> known;  // path|mtime|size -> hash
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return "missing";
  const std::string version =
      path + "|" + std::to_string(fs::last_write_time(path, error).time_since_epoch().count()) +
      "|" + std::to_string(fs::file_size(path, error));
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto found = known.find(version); found != known.end()) return found->second;
  }
  const std::string hash = Fnv1a64().add(read_text_file(path)).hex();
  const std::lock_guard<std::mutex> lock(mutex);
  known[version] = hash;
  return hash;
}

}  // namespace

std::vector<std::string> Sweep::input_file_hashes(
    const std::vector<ScenarioOverride>& overrides) const {
  std::vector<std::string> hashes;
  const ResolvedScenario resolved = resolve_scenario(spec_.base, base_text_, overrides);
  for (const std::string& file : resolved.input_files) hashes.push_back(file_hash(file));
  // a shipped machine's MJCF, from the models folder the task's run reads it from
  if (const std::unique_ptr<Machine> machine = make_machine(resolved.shipped_machine))
    hashes.push_back(file_hash((fs::path(models_directory()) / machine->model_file()).string()));
  return hashes;
}

std::string Sweep::input_hash(const SweepTask& task) const {
  // what the task's scenario is made of: the base's text and the overrides (which determine
  // its tree), the bytes of the files it reads, `keep:` and the depotwin version
  Fnv1a64 hash;
  hash.add(std::string("depotwin ") + sweep_depotwin_version()).add("keep " + spec_.keep);
  hash.add(base_text_);
  for (const ScenarioOverride& override_ : task.overrides)
    hash.add(override_.key + "=" + override_.value_yaml);
  // the files' bytes, not their paths: a task's hash is the same from any working directory
  for (const std::string& file :
       shared_input_files_ ? *shared_input_files_ : input_file_hashes(task.overrides))
    hash.add(file);
  return hash.hex();
}

namespace {

// a problem met by several tasks, listed once
struct SharedProblem {
  Problem problem;
  std::vector<std::uint64_t> tasks;
};

// the most distinct problems listed, then a count of the rest
constexpr std::size_t kMaxListedProblems = 50;

std::string tasks_note(const SharedProblem& shared, const Sweep& sweep) {
  const std::vector<std::uint64_t>& tasks = shared.tasks;
  if (tasks.size() == sweep.size() && sweep.size() > 1) return " (every task)";
  const std::string first = sweep.task(tasks.front()).parameters_text();
  if (tasks.size() == 1) return " (task " + std::to_string(tasks.front()) + ": " + first + ")";
  std::string list;
  for (std::size_t i = 0; i < std::min<std::size_t>(tasks.size(), 5); ++i)
    list += (list.empty() ? "" : ", ") + std::to_string(tasks[i]);
  if (tasks.size() > 5) list += ", ...";
  return " (" + std::to_string(tasks.size()) + " tasks: " + list + "; task " +
         std::to_string(tasks.front()) + ": " + first + ")";
}

}  // namespace

void Sweep::validate_all(int threads, bool progress) const {
  // every task's problems, in task order
  const std::uint64_t count = size();
  std::vector<std::vector<Problem>> problems(static_cast<std::size_t>(count));
  std::atomic<std::uint64_t> next{0}, done{0};
  const auto check = [&] {
    for (std::uint64_t i = next++; i < count; i = next++) {
      const SweepTask one = task(i);
      std::vector<Problem>& found = problems[static_cast<std::size_t>(i)];
      // a task runs one planner: the base's only one, or the one `planner` chooses (when the
      // scenario has other problems, counted in the overridden tree, so it is still said)
      std::optional<std::vector<std::string>> planners;
      try {
        const Scenario scenario = load_task(one);
        planners.emplace();
        for (const PlannerSpec& planner : scenario.planners)
          planners->push_back(planner.run_label());
      } catch (const InputError& error) {
        found = error.problems();
        try {
          planners = resolve_scenario(spec_.base, base_text_, one.overrides).planners;
        } catch (const InputError&) {
          // the same problems as the load's
        }
      }
      if (planners && planners->size() != 1) {
        std::string names;
        for (const std::string& name : *planners) names += (names.empty() ? "" : ", ") + name;
        found.insert(found.begin(),
                     Problem{spec_.file, spec_.base_line, "base",
                             "the scenario lists " + std::to_string(planners->size()) +
                                 " planners (" + names +
                                 ") and a task runs one: sweep planner: in grid: (or choose one "
                                 "under set:)"});
      }
      ++done;
    }
  };
  // small sweeps on this thread; large ones on `threads` threads, with a progress line
  if (threads <= 1 || count < 64) {
    check();
  } else {
    ProgressLine line("sweep " + spec_.name + ": checking " + std::to_string(count) + " tasks",
                      ProgressLine::style_for_stderr(progress));
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k) workers.emplace_back(check);
    while (done.load() < count) {
      line.update(static_cast<double>(done.load()) / static_cast<double>(count));
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    for (std::thread& worker : workers) worker.join();
    line.finish();
  }

  // each distinct problem once, with the tasks it concerns, in order of first appearance
  std::vector<SharedProblem> shared;
  std::map<std::string, std::size_t> position;
  for (std::uint64_t i = 0; i < count; ++i)
    for (const Problem& problem : problems[static_cast<std::size_t>(i)]) {
      const std::string identity = problem.str();
      const auto [at, fresh] = position.emplace(identity, shared.size());
      if (fresh) shared.push_back(SharedProblem{problem, {}});
      shared[at->second].tasks.push_back(i);
    }
  if (shared.empty()) return;
  std::vector<Problem> listed;
  for (std::size_t k = 0; k < shared.size() && k < kMaxListedProblems; ++k) {
    Problem problem = shared[k].problem;
    problem.message += tasks_note(shared[k], *this);
    listed.push_back(problem);
  }
  if (shared.size() > kMaxListedProblems)
    listed.push_back(Problem{spec_.file, 0, "",
                             "... and " + std::to_string(shared.size() - kMaxListedProblems) +
                                 " more problems (the first " + std::to_string(kMaxListedProblems) +
                                 " are listed)"});
  throw InputError(listed);
}

namespace {

// a folder a sweep may write in: its marker, or nothing but tasks/ and logs/ (what an
// emitted script makes before its first task runs)
bool is_sweep_folder(const fs::path& folder) {
  std::error_code error;
  if (fs::exists(folder / kOutputMarker, error)) return true;
  // (the marker on its way: the temporary file another task writes it through, then renames,
  // when tasks start side by side in a new folder, GNU parallel's or a Slurm array's)
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if ((name == "tasks" || name == "logs") && entry.is_directory(error)) continue;
    if (is_marker_being_written(name)) continue;
    return false;
  }
  return !error;
}

}  // namespace

void Sweep::prepare_out_directory() const {
  const auto refuse = [&](const std::string& why) { throw InputError("--out", out_ + ": " + why); };
  std::error_code error;
  const fs::path target = fs::absolute(out_, error).lexically_normal();
  const fs::file_status status = fs::status(target, error);
  if (fs::exists(status) && !fs::is_directory(status)) refuse("is a file, not a folder");
  if (fs::is_directory(status) && !is_sweep_folder(target))
    refuse("exists and is not a depotwin sweep folder (it has files but no " +
           std::string(kOutputMarker) + " marker); choose an empty or new folder");
  const std::string first_line = output_marker_line(target.string());
  // a run's, compare's or plan's folder (their marker) is not a sweep's: the two would mix
  {
    // ("depotwin output folder, written by `depotwin run`; ...": who wrote it)
    const std::string run_marker = "depotwin output folder";
    if (first_line.rfind(run_marker, 0) == 0) {
      const std::size_t by = first_line.find("written by");
      const std::string writer =
          by == std::string::npos ? "" : " " + first_line.substr(by, first_line.find(';', by) - by);
      refuse("is a depotwin output folder" + writer +
             ", not a sweep's; choose an empty or new folder");
    }
  }
  // another sweep's folder: its tasks and this one's would mix under one marker
  {
    const std::string sweep_marker = "depotwin sweep folder (";
    const std::size_t close = first_line.find("):");
    if (first_line.rfind(sweep_marker, 0) == 0 && close != std::string::npos) {
      const std::string owner = first_line.substr(sweep_marker.size(), close - sweep_marker.size());
      if (owner != spec_.name)
        refuse("is the folder of sweep '" + owner + "', not of '" + spec_.name +
               "': their tasks would mix; choose an empty or new folder");
    }
  }
  for (const char* folder : {"tasks", "logs"}) {
    fs::create_directories(target / folder, error);
    if (error) refuse("cannot create " + (target / folder).string() + ": " + error.message());
  }
  if (!fs::exists(target / kOutputMarker, error)) {
    try {
      write_file_atomically((target / kOutputMarker).string(),
                            "depotwin sweep folder (" + spec_.name +
                                "): tasks/<i> per task, results.sqlite, results.csv and "
                                "summary.png after `depotwin sweep --merge`\n");
    } catch (const InternalError& failure) {
      refuse(std::string("cannot write in it: ") + failure.what());
    }
  }
}

std::uint64_t task_index_from(const std::string& text, std::uint64_t count) {
  std::string given = text;
  std::uint64_t offset = 0;
  // a scheduler's array index: Slurm (plus the chunk's offset of a large sweep), then k8s
  if (text == "env") {
    const char* slurm = std::getenv("SLURM_ARRAY_TASK_ID");
    const char* k8s = std::getenv("JOB_COMPLETION_INDEX");
    if (slurm != nullptr && *slurm != '\0') {
      given = slurm;
      if (const char* chunk = std::getenv("DEPOTWIN_SWEEP_TASK_OFFSET"); chunk && *chunk) {
        // (digits only: strtoull would take "-1" as 2^64 - 1, and wrap beyond it)
        const std::string text = chunk;
        if (text.size() > 18 ||
            !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
          throw InputError("--task", "DEPOTWIN_SWEEP_TASK_OFFSET is '" + printable_text(text) +
                                         "', not a whole number from 0");
        offset = std::stoull(text);
      }
    } else if (k8s != nullptr && *k8s != '\0') {
      given = k8s;
    } else {
      throw InputError("--task",
                       "env: neither SLURM_ARRAY_TASK_ID (a Slurm array job) nor "
                       "JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set");
    }
  }
  const bool digits =
      !given.empty() && given.size() <= 18 &&
      std::all_of(given.begin(), given.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits)
    throw InputError("--task",
                     "'" + given + "' is not a task index (a whole number from 0, or env)");
  const std::uint64_t index = std::stoull(given) + offset;
  if (index >= count)
    throw InputError("--task", "task " + std::to_string(index) +
                                   " is out of range: the sweep has " + std::to_string(count) +
                                   " tasks (0.." + std::to_string(count - 1) + ")");
  return index;
}

}  // namespace depotwin
