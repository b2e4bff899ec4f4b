// The merge (hand-written task folders -> the table, results.csv, results.sqlite read back),
// the Pareto front and the means summary.png draws, the emitted scripts, and the local runner's
// handling of a worker process that dies.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/pipeline_test_util.hpp"
#include "sweep/emit.hpp"
#include "sweep/local_runner.hpp"
#include "sweep/results.hpp"
#include "sweep/summary.hpp"
#include "sweep/task.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::scenario_path;
using testing_support::write_text;

// a sweep of thompson_fig7: planner x speed, 4 tasks
std::string write_sweep(const std::string& dir) {
  return write_text(dir, "s.yaml",
                    "name: merged\nbase: " + scenario_path("thompson_fig7.yaml") +
                        "\ngrid:\n  planner: [lspb_mtt, stop_and_go]\n"
                        "  toolpath.speed: [2, 2.5]\n");
}

// a task folder as a task leaves it: task.json and <run>/metrics.json
void write_task(const Sweep& sweep, std::uint64_t index, const std::string& status,
                const nlohmann::ordered_json& metrics) {
  const SweepTask task = sweep.task(index);
  TaskRecord record;
  record.index = index;
  for (const auto& [key, value] : task.parameters) record.parameters.emplace_back(key, value.text);
  record.input_hash = sweep.input_hash(task);
  record.status = status;
  record.error = status == "ok" ? "" : "internal error: a, \"quoted\" failure";
  record.wall_s = 0.5 + static_cast<double>(index);
  record.run = task.parameters[0].second.text;
  const std::string folder = sweep.task_folder(index);
  fs::create_directories(folder + "/" + record.run);
  write_text(folder, "task.json", task_record_json(record));
  if (status == "ok") write_text(folder + "/" + record.run, "metrics.json", metrics.dump(2));
}

// a PNG's size from its IHDR chunk
bool png_dimensions(const std::string& bytes, int& width, int& height) {
  if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return false;
  const auto big_endian = [&](size_t at) {
    return (static_cast<unsigned char>(bytes[at]) << 24) |
           (static_cast<unsigned char>(bytes[at + 1]) << 16) |
           (static_cast<unsigned char>(bytes[at + 2]) << 8) |
           static_cast<unsigned char>(bytes[at + 3]);
  };
  width = static_cast<int>(big_endian(16));
  height = static_cast<int>(big_endian(20));
  return true;
}

nlohmann::ordered_json metrics_of(double time_s, double line_cv, bool flag) {
  nlohmann::ordered_json m;
  m["scenario"] = "thompson_fig7";
  m["planner"] = "ignored: a parameter has this name";
  m["time_s"] = {{"total", time_s}, {"print", 11}};
  m["thickness"] = {{"line_cv", line_cv}};
  m["actuators"] = {{"peak_vel", {1.0, 2.0}}, {"limit_violations", 0}};
  m["order"] = {{"lower_bound_s", nullptr}, {"refined", flag}};
  m["warnings"] = {"one", "two"};
  m["units"] = {{"time_s", {{"total", "s"}, {"print", "s"}}},
                {"thickness", {{"line_cv", "ratio"}}}};
  return m;
}

// tasks started side by side in a new folder (GNU parallel's, a Slurm array's): one finds the
// marker another is writing still under its temporary name, and takes the folder as a sweep's
// (before, it refused it as "not a depotwin sweep folder", exit 2, and the task went missing);
// a stranger's file is still refused
TEST(SweepFolder, AMarkerBeingWrittenByAnotherTaskIsASweepFolder) {
  const std::string dir = fresh_directory("sweep_marker_race");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  fs::create_directories(dir + "/out/logs");
  write_text(dir + "/out", ".depotwin.tmp-12345", "depotwin sweep folder (s)\n");
  EXPECT_NO_THROW(sweep.prepare_out_directory());
  EXPECT_TRUE(fs::exists(dir + "/out/.depotwin"));
  const Sweep other(write_sweep(dir), dir + "/other");
  fs::create_directories(dir + "/other/logs");
  write_text(dir + "/other", "notes.txt", "mine\n");
  EXPECT_THROW(other.prepare_out_directory(), InputError);
}

// another sweep's folder is refused: the second sweep's task 0 overwrote the first's and
// the rest of the first's stayed, under the first's marker (exit 0); the same sweep resumes
TEST(SweepFolder, AnotherSweepsFolderIsRefusedItsOwnResumed) {
  const std::string dir = fresh_directory("sweep_other_folder");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  sweep.prepare_out_directory();
  EXPECT_NO_THROW(sweep.prepare_out_directory());
  const std::string other_file =
      write_text(dir, "other.yaml",
                 "name: other\nbase: " + scenario_path("thompson_fig7.yaml") +
                     "\ngrid:\n  planner: [lspb_mtt]\n");
  const Sweep other(other_file, dir + "/out");
  try {
    other.prepare_out_directory();
    ADD_FAILURE() << "another sweep's folder taken";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u);
    EXPECT_EQ(error.problems()[0].message,
              dir +
                  "/out: is the folder of sweep 'merged', not of 'other': their tasks would "
                  "mix; choose an empty or new folder");
  }
}

TEST(SweepMerge, TheTableHasARowPerTaskAndAColumnPerParameterAndScalarMetric) {
  const std::string dir = fresh_directory("sweep_merge");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  sweep.prepare_out_directory();
  write_task(sweep, 0, "ok", metrics_of(24.5, 0.05, true));
  write_task(sweep, 1, "failed", {});
  write_task(sweep, 3, "ok", metrics_of(19.25, 0.125, false));
  const ResultsTable table = collect_results(sweep, 2);
  EXPECT_EQ(table.ok, 2u);
  EXPECT_EQ(table.failed, 1u);
  EXPECT_EQ(table.missing, 1u);

  // the columns, in order, with their kinds, types and units
  std::vector<std::string> names, types, units;
  for (const ResultColumn& column : table.columns) {
    names.push_back(column.name);
    types.push_back(column.type);
    units.push_back(column.unit);
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{
                "task", "planner", "toolpath.speed", "status", "error", "wall_s", "input_hash",
                "folder", "scenario", "time_s.total", "time_s.print", "thickness.line_cv",
                "actuators.limit_violations", "order.lower_bound_s", "order.refined", "warnings"}));
  EXPECT_EQ(types, (std::vector<std::string>{"INTEGER", "TEXT", "REAL", "TEXT", "TEXT", "REAL",
                                             "TEXT", "TEXT", "TEXT", "REAL", "INTEGER", "REAL",
                                             "INTEGER", "INTEGER", "INTEGER", "INTEGER"}));
  EXPECT_EQ(units[9], "s");
  EXPECT_EQ(units[11], "ratio");
  EXPECT_EQ(units[15], "count");

  // the CSV, every value exact
  const std::string hash_0 = sweep.input_hash(sweep.task(0));
  const std::string hash_1 = sweep.input_hash(sweep.task(1));
  const std::string hash_2 = sweep.input_hash(sweep.task(2));
  const std::string hash_3 = sweep.input_hash(sweep.task(3));
  const std::string csv = results_csv(table);
  const std::string expected =
      "task,planner,toolpath.speed,status,error,wall_s,input_hash,folder,scenario,time_s.total,"
      "time_s.print,thickness.line_cv,actuators.limit_violations,order.lower_bound_s,"
      "order.refined,warnings\n"
      "0,lspb_mtt,2,ok,,0.5," +
      hash_0 +
      ",tasks/0000,thompson_fig7,24.5,11,0.05,0,,1,2\n"
      "1,lspb_mtt,2.5,failed,\"internal error: a, \"\"quoted\"\" failure\",1.5," +
      hash_1 +
      ",tasks/0001,,,,,,,,\n"
      "2,stop_and_go,2,missing,no result: not run yet,," +
      hash_2 +
      ",tasks/0002,,,,,,,,\n"
      "3,stop_and_go,2.5,ok,,3.5," +
      hash_3 + ",tasks/0003,thompson_fig7,19.25,11,0.125,0,,0,2\n";
  EXPECT_EQ(csv, expected);

  // results.sqlite holds the same rows, the columns' units and the sweep's facts
  const std::string path = dir + "/out/results.sqlite";
  write_results_sqlite(table, sweep, path);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  const auto one_text = [&](const std::string& sql) {
    sqlite3_stmt* statement = nullptr;
    std::string text = "(none)";
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr) == SQLITE_OK &&
        sqlite3_step(statement) == SQLITE_ROW && sqlite3_column_text(statement, 0) != nullptr)
      text = reinterpret_cast<const char*>(sqlite3_column_text(statement, 0));
    sqlite3_finalize(statement);
    return text;
  };
  EXPECT_EQ(one_text("SELECT count(*) FROM results"), "4");
  EXPECT_EQ(one_text("SELECT \"time_s.total\" FROM results WHERE planner = 'stop_and_go' AND "
                     "\"toolpath.speed\" = 2.5"),
            "19.25");
  EXPECT_EQ(one_text("SELECT typeof(\"time_s.print\") FROM results WHERE task = 0"), "integer");
  EXPECT_EQ(one_text("SELECT group_concat(status, ' ') FROM results"), "ok failed missing ok");
  EXPECT_EQ(one_text("SELECT unit FROM columns WHERE name = 'thickness.line_cv'"), "ratio");
  EXPECT_EQ(one_text("SELECT kind FROM columns WHERE name = 'toolpath.speed'"), "parameter");
  EXPECT_EQ(one_text("SELECT value FROM sweep WHERE key = 'missing'"), "1");
  sqlite3_close(db);
  EXPECT_TRUE(fs::is_regular_file(path));
  EXPECT_FALSE(fs::exists(path + ".partial-" + std::to_string(::getpid())));
}

// a metrics.json cut short (a full disk, a copy interrupted): the task is not up to date, so
// the next sweep reruns it, and the merge takes none of the half-read file's values
TEST(SweepMerge, AMetricsFileCutShortIsMissingAndRunAgain) {
  const std::string dir = fresh_directory("sweep_cut_short");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  write_task(sweep, 0, "ok", metrics_of(22.5, 0.1, false));
  write_task(sweep, 1, "ok", metrics_of(23.5, 0.2, false));
  const std::string hash = sweep.input_hash(sweep.task(0));
  EXPECT_TRUE(task_up_to_date(sweep, 0, hash));
  const std::string metrics = sweep.task_folder(0) + "/lspb_mtt/metrics.json";
  const std::string whole = read_text(metrics);
  const size_t cut = whole.find("\"thickness\"");  // after time_s.total
  ASSERT_NE(cut, std::string::npos);
  write_text(sweep.task_folder(0) + "/lspb_mtt", "metrics.json", whole.substr(0, cut));
  EXPECT_FALSE(task_up_to_date(sweep, 0, hash));
  const ResultsTable table = collect_results(sweep, 1);
  EXPECT_EQ(std::get<std::string>(table.rows[0][3]), "missing");
  EXPECT_EQ(std::get<std::string>(table.rows[0][4]),
            "its metrics.json cannot be read (at byte 141: parse error at line 8, column 3: "
            "syntax error while parsing object key - unexpected end of input; expected string "
            "literal): run it again");
  const int total = table.column("time_s.total");
  ASSERT_GE(total, 0);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(table.rows[0][total]));
  EXPECT_EQ(std::get<double>(table.rows[1][total]), 23.5);
}

// a sweep grown past 9,999 tasks names its folders with five digits: the tasks the smaller
// sweep finished (tasks/0000) are still up to date and merged, and a local run or merge renames
// them to the new width (before, every one of them was run again under tasks/00000)
TEST(SweepMerge, ASweepGrownPastTenThousandTasksFindsItsFinishedTasks) {
  const std::string dir = fresh_directory("sweep_grown");
  const auto sweep_file = [&](const std::string& name, const std::string& speeds) {
    return write_text(dir, name,
                      "name: merged\nbase: " + scenario_path("thompson_fig7.yaml") +
                          "\ngrid:\n  toolpath.speed: " + speeds +
                          "\n  planner: [lspb_mtt, stop_and_go]\n");
  };
  // 4 tasks, then the speeds extended to 5001 values: the planner is the fastest key, so
  // tasks 0-3 keep their index and their inputs
  const Sweep small(sweep_file("small.yaml", "[2, 2.5]"), dir + "/out");
  const Sweep grown(sweep_file("grown.yaml", "{from: 2, to: 2502, step: 0.5}"), dir + "/out");
  ASSERT_EQ(grown.size(), 10002u);
  EXPECT_EQ(small.task_folder_name(3), "tasks/0003");
  EXPECT_EQ(grown.task_folder_name(3), "tasks/00003");
  for (std::uint64_t index = 0; index < 4; ++index) {
    ASSERT_EQ(grown.input_hash(grown.task(index)), small.input_hash(small.task(index)));
    write_task(small, index, "ok", metrics_of(20 + static_cast<double>(index), 0.1, false));
  }
  // the grown sweep finds them up to date where the small one left them
  for (std::uint64_t index = 0; index < 4; ++index) {
    EXPECT_TRUE(task_up_to_date(grown, index, grown.input_hash(grown.task(index)))) << index;
    EXPECT_EQ(grown.found_task_folder(index), small.task_folder(index));
  }
  EXPECT_FALSE(task_up_to_date(grown, 4, grown.input_hash(grown.task(4))));
  // renamed to five digits; a folder beyond the last task and a staging folder stay
  fs::create_directories(dir + "/out/tasks/99999");
  fs::create_directories(dir + "/out/tasks/0002.partial-7");
  grown.rename_task_folders_to_current_width();
  for (std::uint64_t index = 0; index < 4; ++index) {
    EXPECT_TRUE(fs::is_directory(grown.task_folder(index))) << index;
    EXPECT_FALSE(fs::exists(small.task_folder(index))) << index;
    EXPECT_TRUE(task_up_to_date(grown, index, grown.input_hash(grown.task(index)))) << index;
  }
  EXPECT_TRUE(fs::is_directory(dir + "/out/tasks/99999"));
  EXPECT_TRUE(fs::is_directory(dir + "/out/tasks/0002.partial-7"));
  // the small sweep again: found under five digits, merged with the folder it is read from,
  // then renamed back to four
  EXPECT_TRUE(task_up_to_date(small, 3, small.input_hash(small.task(3))));
  const ResultsTable table = collect_results(small, 1);
  const int folder = table.column("folder");
  ASSERT_GE(folder, 0);
  EXPECT_EQ(std::get<std::string>(table.rows[3][static_cast<std::size_t>(folder)]), "tasks/00003");
  EXPECT_EQ(table.ok, 4u);
  small.rename_task_folders_to_current_width();
  EXPECT_TRUE(fs::is_directory(dir + "/out/tasks/0003"));
  EXPECT_FALSE(fs::exists(dir + "/out/tasks/00003"));
}

TEST(SweepMerge, AResultOfOtherInputsIsMissing) {
  const std::string dir = fresh_directory("sweep_stale");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  write_task(sweep, 0, "ok", metrics_of(1, 0.1, false));
  // the same folder, its record from other inputs
  std::string record = read_text(sweep.task_folder(0) + "/task.json");
  const std::string hash = sweep.input_hash(sweep.task(0));
  record.replace(record.find(hash), hash.size(), "0000000000000000");
  write_text(sweep.task_folder(0), "task.json", record);
  const ResultsTable table = collect_results(sweep, 1);
  EXPECT_EQ(std::get<std::string>(table.rows[0][3]), "missing");
  EXPECT_EQ(std::get<std::string>(table.rows[0][4]),
            "its folder holds the result of other inputs (the sweep, its scenario or depotwin "
            "changed since): run the task again");
}

TEST(SweepPlot, TheParetoFrontKeepsThePointsNoOtherBeatsInBoth) {
  // time, line cv: (3, 0.1) and (1, 0.5) and (2, 0.2) are on the front; (2.5, 0.3) is beaten by
  // (2, 0.2), (4, 0.1) by (3, 0.1); a point equal to a front point stays; NaN takes no part
  const std::vector<double> time{3, 1, 2, 2.5, 4, NAN, 2};
  const std::vector<double> cv{0.1, 0.5, 0.2, 0.3, 0.1, 0.0, 0.2};
  EXPECT_EQ(plots::pareto_front(time, cv), (std::vector<std::size_t>{1, 2, 6, 0}));
}

TEST(SweepPlot, CurveMeansAverageEachValueOverTheOtherParameters) {
  const std::vector<double> x{1, 1, 2, 2, 1, 2};
  const std::vector<double> y{1.0, 3.0, 10.0, NAN, 100.0, 20.0};
  const std::vector<std::size_t> curve{0, 0, 0, 0, 1, 0};
  EXPECT_EQ(plots::curve_means(x, y, curve, 0),
            (std::vector<std::pair<double, double>>{{1.0, 2.0}, {2.0, 15.0}}));
  EXPECT_EQ(plots::curve_means(x, y, curve, 1),
            (std::vector<std::pair<double, double>>{{1.0, 100.0}}));
}

TEST(SweepPlot, SummaryHasACurvePerPlannerAndAPanelPerParameterAndMetric) {
  const std::string dir = fresh_directory("sweep_summary");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  write_task(sweep, 0, "ok", metrics_of(24.5, 0.05, true));
  write_task(sweep, 2, "ok", metrics_of(25.0, 0.1, true));
  write_task(sweep, 3, "ok", metrics_of(19.5, 0.2, true));
  const ResultsTable table = collect_results(sweep, 1);
  const plots::SweepPlotInput input = summary_plot_input(table, sweep);
  EXPECT_EQ(input.curves, (std::vector<std::string>{"lspb_mtt", "stop_and_go"}));
  EXPECT_EQ(input.curve, (std::vector<std::size_t>{0, 1, 1}));
  ASSERT_EQ(input.parameters.size(), 1u);  // the planner is the curves
  EXPECT_EQ(input.parameters[0].key, "toolpath.speed");
  EXPECT_EQ(input.x[0], (std::vector<double>{2.0, 2.0, 2.5}));
  // the headline metrics the tasks have: time and line cv, and the Pareto panel of both
  ASSERT_EQ(input.metrics.size(), 2u);
  EXPECT_EQ(input.metrics[0].label, "time (s)");
  EXPECT_EQ(input.pareto_x, 0);
  EXPECT_EQ(input.pareto_y, 1);
  // drawn: two panels side by side over the Pareto panel, 920 x (70 + 280 + 380) px
  ASSERT_TRUE(write_summary_plot(table, sweep, dir + "/summary.png"));
  int width = 0, height = 0;
  ASSERT_TRUE(png_dimensions(read_text(dir + "/summary.png"), width, height));
  EXPECT_EQ(width, 920);
  EXPECT_EQ(height, 730);
}

TEST(SweepEmit, SlurmArraysAreChunkedWithOffsetsAndTheMergeWaitsForAll) {
  const std::string dir = fresh_directory("sweep_emit");
  const std::string file = write_text(dir, "s.yaml",
                                      "base: " + scenario_path("ganganath_n20.yaml") +
                                          "\ngrid:\n  toolpath.random_segments.seed: {from: 1, "
                                          "to: 2500}\n");
  const Sweep sweep(file, dir + "/out dir");
  EmitOptions options{"/opt/depotwin", file, dir + "/out dir", 8, 1000};
  const std::string script = slurm_script(sweep, options);
  // 2500 tasks: arrays of 1000, 1000 and 500, offsets 0, 1000, 2000
  EXPECT_NE(script.find("#SBATCH --array=0-999%8\n"), std::string::npos);
  EXPECT_NE(script.find("#SBATCH --array=0-499%8\n"), std::string::npos);
  EXPECT_NE(script.find("export DEPOTWIN_SWEEP_TASK_OFFSET=2000\n"), std::string::npos);
  EXPECT_NE(script.find("task-$((SLURM_ARRAY_TASK_ID + 1000)).log"), std::string::npos);
  EXPECT_NE(script.find("--dependency=\"afterok$arrays\" --kill-on-invalid-dep=yes"),
            std::string::npos);
  EXPECT_NE(script.find("/opt/depotwin sweep " + file + " --out '" + dir +
                        "/out dir' --task env --quiet || status=$?\n"),
            std::string::npos)
      << script;
  size_t arrays = 0;
  for (size_t at = 0; (at = script.find("arrays=\"$arrays:", at)) != std::string::npos; ++at)
    ++arrays;
  EXPECT_EQ(arrays, 3u);
  // the parallel line: every index, M jobs, a log per task, then the merge
  EXPECT_EQ(parallel_command(sweep, options),
            "mkdir -p '" + dir +
                "/out dir/logs' && seq 0 2499 | parallel --jobs 8 --halt never "
                "--joblog '" +
                dir + "/out dir/logs/parallel.joblog' '/opt/depotwin sweep " + file +
                " --out '\\''" + dir + "/out dir'\\'' --task {} --quiet > '\\''" + dir +
                "/out dir/logs'\\''/task-{}.log 2>&1'; /opt/depotwin sweep " + file + " --out '" +
                dir + "/out dir' --merge\n");
  EXPECT_EQ(shell_quoted("it's"), "'it'\\''s'");
}

// the sweep's name and --out are the user's words: the script prints them, never runs them
TEST(SweepEmit, TheSlurmScriptRunsNothingOfTheNameOrTheOutFolder) {
  const std::string dir = fresh_directory("sweep_emit_quoted");
  const std::string file =
      write_text(dir, "s.yaml",
                 "name: \"x$(touch made_by_name)`touch made_by_tick`\"\nbase: " +
                     scenario_path("ganganath_n20.yaml") +
                     "\ngrid:\n  toolpath.random_segments.seed: [1, 2]\n");
  const std::string out = dir + "/out $(touch made_by_out)";
  const Sweep sweep(file, out);
  const std::string script = write_text(
      dir, "submit.sh", slurm_script(sweep, EmitOptions{"/opt/depotwin", file, out, 8, 1000}));
  // sbatch stubbed: it swallows the job script and answers a job id
  fs::create_directories(dir + "/bin");
  const std::string stub = write_text(dir, "bin/sbatch", "#!/bin/sh\ncat > /dev/null\necho 7\n");
  fs::permissions(stub, fs::perms::owner_all);
  const std::string command =
      "cd '" + dir + "' && PATH='" + dir + "/bin':$PATH bash submit.sh > said.txt";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_text(script);
  for (const char* made : {"made_by_name", "made_by_tick", "made_by_out"})
    EXPECT_FALSE(fs::exists(dir + "/" + made)) << made;
  EXPECT_EQ(read_text(dir + "/said.txt"),
            "x$(touch made_by_name)`touch made_by_tick`: submitted array job(s) 7 (2 tasks) and "
            "merge job 7; results in " +
                out + "\n");
}

TEST(SweepLocalRunner, AWorkerThatDiesHasItsTaskRecordedAndIsReplaced) {
  const std::string dir = fresh_directory("sweep_crash");
  const Sweep sweep(write_sweep(dir), dir + "/out");
  sweep.prepare_out_directory();
  // a worker that reports even tasks done and dies on odd ones
  const std::string worker = write_text(dir, "worker.sh", R"(#!/bin/sh
while read -r index; do
  if [ $((index % 2)) -eq 1 ]; then echo "dying on task $index"; kill -SEGV $$; fi
  echo "$index ok" >&3
done
)");
  fs::permissions(worker, fs::perms::owner_all);
  LocalRunOptions options;
  options.workers = 2;
  options.progress = false;
  options.executable = worker;
  options.sweep_file = sweep.spec().file;
  const LocalRunSummary summary = run_tasks_locally(sweep, {0, 1, 2, 3}, options);
  EXPECT_EQ(summary.ran, 4u);
  EXPECT_EQ(summary.failed, 2u);
  std::vector<std::uint64_t> failed = summary.failed_tasks;
  std::sort(failed.begin(), failed.end());
  EXPECT_EQ(failed, (std::vector<std::uint64_t>{1, 3}));
  for (const std::uint64_t index : {1, 3}) {
    const std::optional<TaskRecord> record = read_task_record(sweep.task_folder(index));
    ASSERT_TRUE(record) << index;
    EXPECT_EQ(record->status, "failed");
    EXPECT_EQ(record->input_hash, sweep.input_hash(sweep.task(index)));
    EXPECT_EQ(record->error.rfind("the task's worker process killed by signal 11 (Segmentation "
                                  "fault) before the task recorded a result",
                                  0),
              0u)
        << record->error;
  }
}

}  // namespace
}  // namespace depotwin
