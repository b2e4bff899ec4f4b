#include "cli/sweep_verb.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>
#include <utility>

#include "cli/cli_checks.hpp"
#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/interrupt.hpp"
#include "report/output_dir.hpp"
#include "sweep/emit.hpp"
#include "sweep/local_runner.hpp"
#include "sweep/results.hpp"
#include "sweep/summary.hpp"
#include "sweep/sweep.hpp"
#include "sweep/task.hpp"

namespace depotwin {

namespace fs = std::filesystem;

int failed_tasks_status(unsigned long long failed) {
  return failed == 0 ? kExitOk : static_cast<int>(std::min<unsigned long long>(100 + failed, 255));
}

CLI::App* add_sweep_verb(CLI::App& app, SweepOptions& options) {
  CLI::App* sweep = app.add_subcommand(
      "sweep",
      "a parameter study: a base scenario run over a grid of overrides, on local workers, a "
      "Slurm array or GNU parallel, merged into results.sqlite");
  sweep->add_option("file", options.file, "sweep YAML file (base:, grid:, zip:, set:, keep:)")
      ->required();
  sweep->add_option("--out", options.out, "results folder (default: results/<sweep name>)");
  CLI::Option* list = sweep->add_flag(
      "--list", options.list, "print the tasks (index, parameters, folder, state) and exit");
  CLI::Option* task = sweep->add_option(
      "--task", options.task,
      "run task I alone; `env`: the index in SLURM_ARRAY_TASK_ID (Slurm arrays) or "
      "JOB_COMPLETION_INDEX (Kubernetes Indexed Jobs)");
  sweep
      ->add_option("-j,--jobs", options.jobs,
                   "local worker processes (default: one per core); with --emit, the most tasks "
                   "running at once")
      ->check(positive_number());
  CLI::Option* merge = sweep->add_flag(
      "--merge", options.merge,
      "gather every task's metrics into results.sqlite, results.csv and summary.png");
  CLI::Option* emit = sweep
                          ->add_option("--emit", options.emit,
                                       "print the script that runs the sweep on Slurm (an sbatch "
                                       "array and its merge) or the GNU parallel command line")
                          ->check(CLI::IsMember({"slurm", "parallel"}));
  sweep->add_flag("--force", options.force, "rerun tasks whose results are up to date");
  sweep->add_flag("--no-render", options.no_render, "merge without summary.png");
  sweep->add_flag("--quiet", options.quiet, "no progress line");
  sweep->add_flag("--no-wait", options.no_wait,
                  "exit (status 2) instead of waiting while another sweep or merge writes the "
                  "results folder");
  CLI::Option* worker = sweep->add_flag("--worker", options.worker)->group("");
  for (CLI::Option* a : {list, task, merge, emit, worker})
    for (CLI::Option* b : {list, task, merge, emit, worker})
      if (a != b) a->excludes(b);
  sweep->footer(
      "Exit status: 0 when every task is ok; 100 + k when k tasks failed (--merge: failed or "
      "missing; 255: 155 or more); 2 bad input (every problem listed, nothing written); 1 the "
      "machine refused (a full disk: said why) or an internal failure.");
  return sweep;
}

namespace {

int default_jobs() {
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

std::string absolute(const std::string& path) {
  return fs::absolute(path).lexically_normal().string();
}

// "done" (up to date), "failed", "stale" (a result of other inputs), "missing" (its
// metrics.json gone or cut short: run again) or "-" (not run)
std::string task_state(const Sweep& sweep, std::uint64_t index) {
  const std::optional<TaskRecord> record = read_task_record(sweep.found_task_folder(index));
  if (!record) return "-";
  std::string hash;
  try {
    hash = sweep.input_hash(sweep.task(index));
  } catch (const InputError&) {
    return "-";
  }
  if (record->input_hash != hash) return "stale";
  if (record->status != "ok") return "failed";
  return task_up_to_date(sweep, index, hash) ? "done" : "missing";
}

int list_tasks(const Sweep& sweep, const SweepOptions& options) {
  sweep.validate_all(default_jobs(), !options.quiet);
  const std::vector<std::string>& keys = sweep.parameter_keys();
  // the table's cells, then the widths of its columns
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header{"task"};
  header.insert(header.end(), keys.begin(), keys.end());
  header.push_back("folder");
  header.push_back("state");
  rows.push_back(header);
  std::uint64_t done = 0;
  for (std::uint64_t i = 0; i < sweep.size(); ++i) {
    const SweepTask task = sweep.task(i);
    std::vector<std::string> row{std::to_string(i)};
    for (const auto& parameter : task.parameters) row.push_back(parameter.second.text);
    row.push_back(sweep.found_task_folder(i));
    row.push_back(task_state(sweep, i));
    done += row.back() == "done";
    rows.push_back(std::move(row));
  }
  std::vector<std::size_t> width(header.size(), 0);
  for (const auto& row : rows)
    for (std::size_t k = 0; k < row.size(); ++k) width[k] = std::max(width[k], row[k].size());
  std::string shape;
  for (const SweepParameter& parameter : sweep.spec().grid)
    shape += (shape.empty() ? "" : " x ") + std::to_string(parameter.values.size());
  if (!sweep.spec().zip.empty())
    shape += (shape.empty() ? "zip of " : " x zip of ") +
             std::to_string(sweep.spec().zip.front().values.size());
  std::string out = "sweep " + sweep.spec().name + " (" + sweep.spec().file +
                    "): " + std::to_string(sweep.size()) + " tasks (" + shape + ") on " +
                    sweep.spec().base + ", " + std::to_string(done) + " up to date, results in " +
                    sweep.out_directory() + "\n\n";
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t k = 0; k < row.size(); ++k) {
      line += row[k];
      if (k + 1 < row.size()) line += std::string(width[k] - row[k].size() + 2, ' ');
    }
    out += line + "\n";
  }
  std::cout << out;
  return kExitOk;
}

// Moves the staged merge into the sweep folder: results.sqlite, results.csv and summary.png
// (plotted false: an earlier merge's summary.png is removed, it no longer matches the table).
void move_merged_files(const std::string& staging, const std::string& out, bool plotted) {
  std::error_code error;
  const auto move = [&](const std::string& name) {
    const std::string from = staging + "/" + name, to = out + "/" + name;
    fs::rename(from, to, error);
    if (error) throw EnvironmentError("cannot move " + from + " to " + to + ": " + error.message());
  };
  move("results.sqlite");
  move("results.csv");
  if (plotted) {
    move("summary.png");
    return;
  }
  fs::remove(out + "/summary.png", error);
  if (error)
    throw EnvironmentError("cannot remove the earlier " + out + "/summary.png: " + error.message());
}

void check_merge_folder(const Sweep& sweep) {
  std::error_code error;
  if (!fs::is_directory(sweep.out_directory(), error))
    throw InputError("--out", sweep.out_directory() +
                                  ": no results folder to merge (run the sweep first, or give "
                                  "--out as it was run)");
}

// One local sweep or merge of a results folder at a time (report/output_dir.hpp): a second one
// waits (--no-wait: refuses), then finds the tasks the first ran up to date instead of running
// them again. The folder is checked and made first: the lock file sits beside it.
std::unique_ptr<OutputLock> lock_results_folder(const Sweep& sweep, const SweepOptions& options) {
  sweep.prepare_out_directory();
  auto lock = std::make_unique<OutputLock>(absolute(sweep.out_directory()), sweep.out_directory(),
                                           "sweep", !options.no_wait);
  // a sweep grown past 9,999 tasks (or shrunk below): its finished tasks' folders renamed to
  // the current width, so they are found up to date and the merge reads them
  sweep.rename_task_folders_to_current_width();
  return lock;
}

// called holding the folder's lock (lock_results_folder, which checked and prepared it)
int merge_results(const Sweep& sweep, const SweepOptions& options, int threads) {
  const ResultsTable table = collect_results(sweep, threads);
  const std::string out = sweep.out_directory();
  // the merge's files are written in a staging folder and moved in together once all are
  // whole: a signal (core/interrupt.hpp) or a failure on the way leaves the earlier merge's
  // results.sqlite, results.csv and summary.png as they were, never a mix of old and new
  const std::string staging_base = out + "/merge";
  remove_stale_staging(absolute(staging_base));
  StagedDirectory staged(staging_base);
  write_file_atomically(staged.file(kOutputMarker), "depotwin sweep merge, staged\n");
  throw_if_interrupted();
  write_results_sqlite(table, sweep, staged.file("results.sqlite"));
  throw_if_interrupted();
  write_file_atomically(staged.file("results.csv"), results_csv(table));
  bool plotted = false;
  if (!options.no_render) plotted = write_summary_plot(table, sweep, staged.file("summary.png"));
  throw_if_interrupted();
  move_merged_files(staged.path(), out, plotted);
  std::cout << "sweep " << sweep.spec().name << ": " << sweep.size() << " tasks, " << table.ok
            << " ok, " << table.failed << " failed, " << table.missing << " missing\n"
            << "merged into " << out << "/results.sqlite, results.csv"
            << (plotted ? ", summary.png" : "") << "\n";
  // the failures, one line each
  const int status = table.column("status"), error_column = table.column("error");
  std::size_t shown = 0;
  for (const auto& row : table.rows) {
    const std::string& state = std::get<std::string>(row[static_cast<std::size_t>(status)]);
    if (state == "ok" || shown >= 20) continue;
    const ResultCell& cell = row[static_cast<std::size_t>(error_column)];
    std::string why = std::holds_alternative<std::string>(cell) ? std::get<std::string>(cell) : "";
    why = why.substr(0, why.find('\n'));
    std::cout << "  task " << std::get<long long>(row[0]) << " " << state << ": " << why << "\n";
    ++shown;
  }
  if (table.failed + table.missing > shown)
    std::cout << "  ... and " << table.failed + table.missing - shown << " more\n";
  return failed_tasks_status(table.failed + table.missing);
}

int run_one_task(const Sweep& sweep, const SweepOptions& options) {
  const std::uint64_t index = task_index_from(options.task, sweep.size());
  const SweepTask task = sweep.task(index);
  // this task's problems before anything is written
  const Scenario checked = sweep.load_task(task);
  if (checked.planners.size() != 1)
    throw InputError(sweep.spec().file, sweep.spec().base_line, "base",
                     "the task's scenario lists " + std::to_string(checked.planners.size()) +
                         " planners and a task runs one: sweep planner: in grid:");
  sweep.prepare_out_directory();
  const std::string hash = sweep.input_hash(task);
  if (!options.force && task_up_to_date(sweep, index, hash)) {
    std::cout << "task " << index << " (" << task.parameters_text() << "): up to date in "
              << sweep.found_task_folder(index) << " (--force reruns it)\n";
    return kExitOk;
  }
  const TaskRecord record = run_task(sweep, task, hash);
  std::cout << "task " << index << " (" << task.parameters_text() << "): " << record.status
            << " in " << record.wall_s << " s, " << sweep.task_folder(index) << "\n";
  if (record.status != "ok") std::cerr << "error: " << record.error << "\n";
  return record.status == "ok" ? kExitOk : failed_tasks_status(1);
}

int emit_script(const Sweep& sweep, const SweepOptions& options) {
  sweep.validate_all(default_jobs(), !options.quiet);
  EmitOptions emit;
  emit.executable = current_executable();
  emit.sweep_file = absolute(options.file);
  emit.out = absolute(sweep.out_directory());
  // the scripts carry these in comments, heredocs and quoted words: a line break or another
  // control byte in them would end one early and run the rest as commands
  const std::pair<const char*, const std::string*> words[] = {
      {"name", &sweep.spec().name},
      {"--out", &emit.out},
      {"the sweep file's path", &emit.sweep_file}};
  for (const auto& [what, text] : words)
    if (std::any_of(text->begin(), text->end(),
                    [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
      throw InputError("--emit", std::string(what) +
                                     " holds a line break or a control byte, which a script "
                                     "cannot carry safely; rename it");
  emit.max_running =
      options.jobs > 0 ? options.jobs : (options.emit == "slurm" ? 100 : default_jobs());
  std::cout << (options.emit == "slurm" ? slurm_script(sweep, emit)
                                        : parallel_command(sweep, emit));
  return kExitOk;
}

int run_all(const Sweep& sweep, const SweepOptions& options) {
  const int jobs = options.jobs > 0 ? options.jobs : default_jobs();
  sweep.validate_all(jobs, !options.quiet);
  const auto lock = lock_results_folder(sweep, options);
  // what is not up to date (once the lock is held: a sweep that ran meanwhile is seen)
  std::vector<std::uint64_t> pending;
  for (std::uint64_t i = 0; i < sweep.size(); ++i)
    if (options.force || !task_up_to_date(sweep, i, sweep.input_hash(sweep.task(i))))
      pending.push_back(i);
  LocalRunOptions local;
  local.workers = jobs;
  local.progress = !options.quiet;
  local.executable = current_executable();
  local.sweep_file = absolute(options.file);
  const LocalRunSummary summary = run_tasks_locally(sweep, pending, local);
  const std::size_t workers = std::min<std::size_t>(static_cast<std::size_t>(jobs), pending.size());
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f", summary.wall_s);
  std::cout << "sweep " << sweep.spec().name << ": " << sweep.size() << " tasks, " << summary.ran
            << " run (" << summary.failed << " failed), " << sweep.size() - pending.size()
            << " up to date";
  if (workers > 0)
    std::cout << ", in " << seconds << " s on " << workers << " worker" << (workers > 1 ? "s" : "");
  std::cout << "\n";
  const int merged = merge_results(sweep, options, jobs);
  return summary.failed > 0 ? failed_tasks_status(summary.failed) : merged;
}

}  // namespace

int sweep_verb(const SweepOptions& options) {
  const Sweep sweep(options.file, options.out);
  if (options.worker) return sweep_worker(sweep);
  if (options.list) return list_tasks(sweep, options);
  if (!options.task.empty()) return run_one_task(sweep, options);
  if (!options.emit.empty()) return emit_script(sweep, options);
  if (options.merge) {
    check_merge_folder(sweep);
    const auto lock = lock_results_folder(sweep, options);
    return merge_results(sweep, options, options.jobs > 0 ? options.jobs : default_jobs());
  }
  return run_all(sweep, options);
}

}  // namespace depotwin
