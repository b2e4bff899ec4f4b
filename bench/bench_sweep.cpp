// `depotwin sweep` at scale (issue 17's targets):
//
//   BM_SweepOverheadPerTask  the sweep's own work per task against the run it wraps: a
//                            thompson_fig7 run of one planner (load, prepare, simulate, write
//                            metrics.json: what a task does with `keep: metrics`). The sweep's
//                            own steps are timed directly: the parent's check of the task (its
//                            scenario loaded, its input hash, the up-to-date test), the
//                            worker's hash, log, staged folder and task.json, and the task's
//                            share of the merge. overhead_share = overhead / run (target <= 2 %).
//                            A worker's start-up (exec of depotwin, once per worker, not per
//                            task) is reported beside it.
//   BM_LocalThroughput       `sweep -j 1` against `sweep -j 2` on 16 thompson_fig7 tasks
//                            (--force, alternately, medians): speedup = t(-j 1) / t(-j 2)
//                            (target >= 1.8 on 2 idle cores); the load average is reported.
//   BM_List10000             `depotwin sweep --list` of a 10,000-task sweep (every task's
//                            scenario loaded and checked), wall s (target <= 5 s)
//   BM_Merge10000            `depotwin sweep --merge` of 10,000 finished tasks (results.sqlite,
//                            results.csv, summary.png), and without summary.png (target <= 5 s)
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/file_io.hpp"
#include "pipeline/run.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "sweep/results.hpp"
#include "sweep/sweep.hpp"
#include "sweep/task.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using namespace depotwin;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("depotwin_bench_sweep_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// wall seconds of the CLI with these arguments (output to /dev/null); the exit status in `status`
double run_cli(std::vector<std::string> arguments, int& status) {
  arguments.insert(arguments.begin(), DEPOTWIN_CLI);
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  const auto start = Clock::now();
  pid_t child = 0;
  status = -1;
  if (posix_spawn(&child, DEPOTWIN_CLI, &actions, nullptr, argv.data(), environ) == 0) {
    int wait_status = 0;
    if (waitpid(child, &wait_status, 0) > 0 && WIFEXITED(wait_status))
      status = WEXITSTATUS(wait_status);
  }
  posix_spawn_file_actions_destroy(&actions);
  return seconds_since(start);
}

void report_load(benchmark::State& state, const char* name) {
  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) state.counters[name] = load[0];
}

// a sweep of thompson_fig7's two planners over `speeds` print speeds
std::string fig7_sweep(const fs::path& dir, const std::string& speeds) {
  const fs::path file = dir / "fig7.yaml";
  write(file, "name: fig7_bench\nbase: " + std::string(DEPOTWIN_SCENARIOS_DIR) +
                  "/thompson_fig7.yaml\ngrid:\n  planner: [lspb_mtt, stop_and_go]\n"
                  "  toolpath.speed: " +
                  speeds + "\n");
  return file.string();
}

// the worker's steps around a task's run: its hash and log, its folder staged with
// metrics.json (copied: the run writes it) and task.json, then swapped in
void worker_steps(const Sweep& sweep, const SweepTask& task, const fs::path& metrics) {
  const std::string hash = sweep.input_hash(task);
  const int log = ::open(sweep.task_log(task.index).c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (log >= 0) ::close(log);
  OutputFolder out(sweep.task_folder(task.index), "sweep", sweep.spec().base);
  const std::string run = task.parameters[0].second.text;
  fs::create_directories(out.path() + "/" + run);
  fs::copy_file(metrics, out.path() + "/" + run + "/metrics.json");
  TaskRecord record;
  record.index = task.index;
  record.input_hash = hash;
  record.status = "ok";
  record.run = run;
  write_file_atomically(out.path() + "/task.json", task_record_json(record));
  out.commit();
}

void BM_SweepOverheadPerTask(benchmark::State& state) {
  const fs::path dir = scratch("overhead");
  const std::string file = fig7_sweep(dir, "[2, 3]");
  std::vector<double> run_s, parent_s, worker_s, rerun_s, merge_s;
  int iteration = 0;
  for (auto _ : state) {
    // a sweep into a new folder each time: its tasks are new, as in a first run
    const Sweep sweep(file, (dir / ("out" + std::to_string(iteration++))).string());
    sweep.prepare_out_directory();
    for (std::uint64_t i = 0; i < sweep.size(); ++i) {
      const SweepTask task = sweep.task(i);
      // the run a task wraps: load, prepare, simulate, metrics.json
      auto start = Clock::now();
      {
        const Scenario scenario = sweep.load_task(task);
        const PreparedJob job = prepare_job(scenario);
        RunSettings settings;
        settings.render = false;
        settings.progress = false;
        const SimulatedRun run = simulate_job(job, scenario.planners.front(), settings);
        fs::create_directories(dir / "run");
        write_file_atomically((dir / "run" / "metrics.json").string(),
                              metrics_json_text(run.report));
      }
      run_s.push_back(seconds_since(start));
      // the parent: the task checked before anything runs, its hash, up to date or not
      start = Clock::now();
      {
        const Scenario checked = sweep.load_task(task);
        benchmark::DoNotOptimize(checked.planners.size());
        benchmark::DoNotOptimize(task_up_to_date(sweep, i, sweep.input_hash(task)));
      }
      parent_s.push_back(seconds_since(start));
      // the worker: a new task's folder, then the same task again (--force: the old folder
      // replaced and deleted)
      start = Clock::now();
      worker_steps(sweep, task, dir / "run" / "metrics.json");
      worker_s.push_back(seconds_since(start));
      start = Clock::now();
      worker_steps(sweep, task, dir / "run" / "metrics.json");
      rerun_s.push_back(seconds_since(start));
    }
    // the merge's share of each task
    const auto start = Clock::now();
    const ResultsTable table = collect_results(sweep, 1);
    write_results_sqlite(table, sweep, sweep.out_directory() + "/results.sqlite");
    write_file_atomically(sweep.out_directory() + "/results.csv", results_csv(table));
    merge_s.push_back(seconds_since(start) / static_cast<double>(sweep.size()));
  }
  // a worker's start-up: the binary exec'd and exiting, once per worker
  std::vector<double> startup_s;
  int status = 0;
  for (int k = 0; k < 5; ++k) startup_s.push_back(run_cli({"--version"}, status));
  const double run = median(run_s);
  const double own = median(parent_s) + median(merge_s);
  state.counters["run_ms"] = 1e3 * run;
  state.counters["parent_ms"] = 1e3 * median(parent_s);
  state.counters["worker_ms"] = 1e3 * median(worker_s);
  state.counters["worker_rerun_ms"] = 1e3 * median(rerun_s);
  state.counters["merge_ms"] = 1e3 * median(merge_s);
  state.counters["overhead_share"] = (own + median(worker_s)) / run;
  state.counters["overhead_share_rerun"] = (own + median(rerun_s)) / run;
  state.counters["worker_startup_ms"] = 1e3 * median(startup_s);
  report_load(state, "load_average");
  fs::remove_all(dir);
}
BENCHMARK(BM_SweepOverheadPerTask)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

void BM_LocalThroughput(benchmark::State& state) {
  const fs::path dir = scratch("throughput");
  const std::string file = fig7_sweep(dir, "[1.25, 1.5, 1.75, 2, 2.25, 2.5, 2.75, 3]");
  const std::string out = (dir / "out").string();
  report_load(state, "load_average_before");
  std::vector<double> one, two;
  int status = 0;
  for (auto _ : state) {
    one.push_back(
        run_cli({"sweep", file, "--out", out, "-j", "1", "--force", "--no-render"}, status));
    if (status != 0) state.SkipWithError("sweep -j 1 failed");
    two.push_back(
        run_cli({"sweep", file, "--out", out, "-j", "2", "--force", "--no-render"}, status));
    if (status != 0) state.SkipWithError("sweep -j 2 failed");
  }
  state.counters["j1_s"] = median(one);
  state.counters["j2_s"] = median(two);
  state.counters["speedup"] = median(one) / median(two);
  report_load(state, "load_average_after");
  fs::remove_all(dir);
}
BENCHMARK(BM_LocalThroughput)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// a 10,000-task sweep: 100 speeds x 100 acceleration limits of thompson_fig7 with lspb_mtt
std::string big_sweep(const fs::path& dir) {
  const fs::path file = dir / "big.yaml";
  write(file, "name: big\nbase: " + std::string(DEPOTWIN_SCENARIOS_DIR) +
                  "/thompson_fig7.yaml\nset: {planner: lspb_mtt}\ngrid:\n"
                  "  toolpath.speed: {from: 0.03, to: 3, count: 100}\n"
                  "  limits.a_max: {from: 10, to: 109}\n");
  return file.string();
}

void BM_List10000(benchmark::State& state) {
  const fs::path dir = scratch("list");
  const std::string file = big_sweep(dir);
  const std::string out = (dir / "out").string();
  int status = 0;
  for (auto _ : state) {
    const double wall_s = run_cli({"sweep", file, "--out", out, "--list", "--quiet"}, status);
    if (status != 0) state.SkipWithError("sweep --list failed");
    state.SetIterationTime(wall_s);
  }
  report_load(state, "load_average");
  fs::remove_all(dir);
}
BENCHMARK(BM_List10000)->Unit(benchmark::kMillisecond)->Iterations(3)->UseManualTime();

void BM_Merge10000(benchmark::State& state) {
  const fs::path dir = scratch("merge");
  const std::string file = big_sweep(dir);
  const Sweep sweep(file, (dir / "out").string());
  sweep.prepare_out_directory();
  // every task finished: task.json and a real metrics.json of thompson_fig7
  const SweepTask first = sweep.task(0);
  run_task(sweep, first, sweep.input_hash(first));
  const std::string metrics = read_text_file(sweep.task_folder(0) + "/lspb_mtt/metrics.json");
  for (std::uint64_t i = 1; i < sweep.size(); ++i) {
    const SweepTask task = sweep.task(i);
    TaskRecord record;
    record.index = i;
    for (const auto& [key, value] : task.parameters)
      record.parameters.emplace_back(key, value.text);
    record.input_hash = sweep.input_hash(task);
    record.status = "ok";
    record.wall_s = 0.2;
    record.run = "lspb_mtt";
    const fs::path folder = sweep.task_folder(i);
    fs::create_directories(folder / "lspb_mtt");
    write(folder / "task.json", task_record_json(record));
    write(folder / "lspb_mtt" / "metrics.json", metrics);
  }
  int status = 0;
  std::vector<double> with_plot, without_plot;
  for (auto _ : state) {
    with_plot.push_back(
        run_cli({"sweep", file, "--out", (dir / "out").string(), "--merge", "--quiet"}, status));
    if (status != 0) state.SkipWithError("sweep --merge failed");
    without_plot.push_back(run_cli(
        {"sweep", file, "--out", (dir / "out").string(), "--merge", "--quiet", "--no-render"},
        status));
    if (status != 0) state.SkipWithError("sweep --merge --no-render failed");
    state.SetIterationTime(with_plot.back());
  }
  state.counters["merge_s"] = median(with_plot);
  state.counters["merge_without_plot_s"] = median(without_plot);
  report_load(state, "load_average");
  // DEPOTWIN_BENCH_KEEP=1 keeps the 10,000 task folders for a closer look
  if (std::getenv("DEPOTWIN_BENCH_KEEP") == nullptr) fs::remove_all(dir);
}
BENCHMARK(BM_Merge10000)->Unit(benchmark::kMillisecond)->Iterations(3)->UseManualTime();

}  // namespace

BENCHMARK_MAIN();
