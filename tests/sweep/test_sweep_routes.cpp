// `depotwin sweep` run for real through the built CLI: local workers (-j), GNU parallel's
// command line and a local Slurm (when scripts/slurm-local.sh can start one) give the same
// table apart from wall times; a task equals `depotwin run` on the same scenario; up-to-date
// tasks are skipped; a failing task is recorded and counted in the exit status; bad input
// writes nothing; two sweeps of one folder run each task once; a failed merge leaves the
// earlier one whole.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "pipeline/pipeline_test_util.hpp"
#include "sweep/results.hpp"

extern char** environ;

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::CliResult;
using testing_support::depotwin;
using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::scenario_path;
using testing_support::shell;
using testing_support::write_text;

// results.csv as rows of named cells, without the wall-time columns
using Table = std::vector<std::map<std::string, std::string>>;
Table table_without_wall_times(const std::string& csv_path) {
  std::istringstream in(read_text(csv_path));
  // split one CSV line (quoted fields may hold commas, quotes and line breaks)
  const auto read_row = [&](std::vector<std::string>& cells) {
    cells.clear();
    std::string cell;
    bool quoted = false, any = false;
    char c;
    while (in.get(c)) {
      any = true;
      if (quoted) {
        if (c == '"' && in.peek() == '"') {
          cell += '"';
          in.get(c);
        } else if (c == '"') {
          quoted = false;
        } else {
          cell += c;
        }
      } else if (c == '"') {
        quoted = true;
      } else if (c == ',') {
        cells.push_back(cell);
        cell.clear();
      } else if (c == '\n') {
        break;
      } else {
        cell += c;
      }
    }
    if (any) cells.push_back(cell);
    return any;
  };
  std::vector<std::string> header, cells;
  Table table;
  if (!read_row(header)) return table;
  const std::vector<std::string>& wall = wall_time_columns();
  while (read_row(cells)) {
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < header.size() && k < cells.size(); ++k)
      if (std::find(wall.begin(), wall.end(), header[k]) == wall.end()) row[header[k]] = cells[k];
    table.push_back(row);
  }
  return table;
}

// two tasks of stop_and_go on the base (thompson_fig7) at two speeds: a few seconds in all
constexpr const char* kTwoTasks = R"(base: base.yaml
grid:
  planner: [stop_and_go]
  toolpath.speed: [1.5, 2]
)";

// A sweep of thompson_fig7 over two machines (the XY stage, and the same kinematics on a model
// that does not load), two planners and two speeds: 8 tasks, 4 of which fail when they run.
class SweepRoutes : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_directory("sweep_routes");
    write_text(dir_, "base.yaml", read_text(scenario_path("thompson_fig7.yaml")));
    write_text(dir_, "broken.xml", "<mujoco>\n  <worldbody>\n");
    sweep_ = write_text(dir_, "fig7.yaml", R"(name: fig7_routes
base: base.yaml
grid:
  machine: [xy_stage, {model: broken.xml, kinematics: xy_stage}]
  planner: [lspb_mtt, stop_and_go]
  toolpath.speed: [2, 3]
)");
  }
  // the sweep on two local workers into DIR/local, run once for the tests that compare with it
  static const CliResult& local() {
    static const CliResult result =
        depotwin("sweep " + sweep_ + " -j 2 --out " + dir_ + "/local --no-render --quiet");
    return result;
  }
  static std::string dir_, sweep_;
};
std::string SweepRoutes::dir_, SweepRoutes::sweep_;

TEST_F(SweepRoutes, LocalWorkersRecordEveryTaskAndCountTheFailuresInTheExitStatus) {
  // 4 tasks failed: exit status 100 + 4
  EXPECT_EQ(local().status, 104) << local().output;
  EXPECT_NE(local().output.find("8 tasks, 8 run (4 failed), 0 up to date"), std::string::npos)
      << local().output;
  const Table table = table_without_wall_times(dir_ + "/local/results.csv");
  ASSERT_EQ(table.size(), 8u);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(table[i].at("task"), std::to_string(i));
    const bool broken = i >= 4;
    EXPECT_EQ(table[i].at("status"), broken ? "failed" : "ok") << i;
    EXPECT_EQ(table[i].at("folder"), "tasks/000" + std::to_string(i));
    if (broken) {
      // the model's own message, at its file and line
      EXPECT_EQ(table[i].at("error").rfind(dir_ + "/broken.xml:2: model: XML parse error", 0), 0u)
          << table[i].at("error");
      EXPECT_EQ(table[i].at("time_s.total"), "");
    } else {
      EXPECT_EQ(table[i].at("error"), "");
      EXPECT_EQ(table[i].at("planner"), i < 2 ? "lspb_mtt" : "stop_and_go");
      EXPECT_EQ(table[i].at("toolpath.speed"), i % 2 == 0 ? "2" : "3");
    }
  }
  // the shipped scenario's figure: lspb_mtt at 3 mm/s takes 19.355 s (README)
  EXPECT_NEAR(std::stod(table[1].at("time_s.total")), 19.355, 5e-4);
  // keep: metrics (the default): the run's folder holds metrics.json alone
  std::vector<std::string> kept;
  for (const auto& entry : fs::directory_iterator(dir_ + "/local/tasks/0001/lspb_mtt"))
    kept.push_back(entry.path().filename().string());
  EXPECT_EQ(kept, (std::vector<std::string>{"metrics.json"}));
}

TEST_F(SweepRoutes, ATaskIsTheRunOfTheSameScenario) {
  // task 2: stop_and_go at 2 mm/s, against `depotwin run` on that scenario written out
  std::string text = read_text(scenario_path("thompson_fig7.yaml"));
  text.replace(text.find("speed: 3"), 8, "speed: 2");
  const std::string scenario = write_text(dir_, "fig7_speed2.yaml", text);
  const CliResult run = depotwin("run " + scenario +
                                 " --planner stop_and_go --no-render --quiet "
                                 "--out " +
                                 dir_ + "/run_speed2");
  ASSERT_EQ(run.status, 0) << run.output;
  nlohmann::json from_run =
      nlohmann::json::parse(read_text(dir_ + "/run_speed2/stop_and_go/metrics.json"));
  ASSERT_EQ(local().status, 104) << local().output;
  nlohmann::json from_sweep =
      nlohmann::json::parse(read_text(dir_ + "/local/tasks/0002/stop_and_go/metrics.json"));
  // everything but the wall clock
  for (nlohmann::json* json : {&from_run, &from_sweep}) {
    json->at("sim").erase("wall_s");
    json->at("sim").erase("realtime_factor");
  }
  EXPECT_EQ(from_sweep, from_run);
}

TEST_F(SweepRoutes, UpToDateTasksAreSkippedAndForceRunsThemAgain) {
  const std::string out = dir_ + "/resume";
  const std::string common = "sweep " + sweep_ + " -j 2 --no-render --quiet --out " + out;
  ASSERT_EQ(depotwin(common).status, 104);
  const std::string record = read_text(out + "/tasks/0001/task.json");
  // the ok tasks are up to date; the failed ones run again
  const CliResult again = depotwin(common);
  EXPECT_EQ(again.status, 104);
  EXPECT_NE(again.output.find("8 tasks, 4 run (4 failed), 4 up to date"), std::string::npos)
      << again.output;
  EXPECT_EQ(read_text(out + "/tasks/0001/task.json"), record);  // not rewritten
  // --list says which
  const CliResult list = depotwin("sweep " + sweep_ + " --list --quiet --out " + out);
  EXPECT_EQ(list.status, 0);
  EXPECT_NE(list.output.find("4 up to date"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find(out + "/tasks/0001  done"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find(out + "/tasks/0005  failed"), std::string::npos) << list.output;
  // --force: all of them
  const CliResult forced = depotwin(common + " --force");
  EXPECT_NE(forced.output.find("8 tasks, 8 run (4 failed), 0 up to date"), std::string::npos)
      << forced.output;
  // another speed: only its tasks are new
  std::string text = read_text(sweep_);
  text.replace(text.find("[2, 3]"), 6, "[2, 2.5]");
  const std::string changed = write_text(dir_, "fig7_changed.yaml", text);
  const CliResult rerun = depotwin("sweep " + changed + " -j 2 --no-render --quiet --out " + out);
  EXPECT_NE(rerun.output.find("8 tasks, 6 run (4 failed), 2 up to date"), std::string::npos)
      << rerun.output;
}

TEST_F(SweepRoutes, OneTaskByIndexOrSchedulerAndTheMergeListsWhatIsMissing) {
  const std::string out = dir_ + "/by_index";
  const std::string common = "sweep " + sweep_ + " --quiet --out " + out;
  const CliResult first = depotwin(common + " --task 1");
  EXPECT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("task 1 (machine=xy_stage, planner=lspb_mtt, toolpath.speed=3): ok"),
            std::string::npos)
      << first.output;
  // a Kubernetes Indexed Job's index; a failing task exits 101
  const CliResult failing = depotwin("sweep " + sweep_ + " --quiet --out " + out +
                                     " --task env");  // no variable: refused
  EXPECT_EQ(failing.status, 2) << failing.output;
  const CliResult k8s = shell("JOB_COMPLETION_INDEX=5 " + std::string(DEPOTWIN_BINARY_DIR) +
                              "/depotwin " + common + " --task env");
  EXPECT_EQ(k8s.status, 101) << k8s.output;
  // up to date the second time
  EXPECT_NE(depotwin(common + " --task 1").output.find("up to date"), std::string::npos);
  // the merge: 1 ok, 1 failed, 6 never run: 100 + 7
  const CliResult merged = depotwin(common + " --merge --no-render");
  EXPECT_EQ(merged.status, 107) << merged.output;
  EXPECT_NE(merged.output.find("8 tasks, 1 ok, 1 failed, 6 missing"), std::string::npos)
      << merged.output;
  const Table table = table_without_wall_times(out + "/results.csv");
  ASSERT_EQ(table.size(), 8u);
  EXPECT_EQ(table[0].at("status"), "missing");
  EXPECT_EQ(table[0].at("error"), "no result: not run yet");
  EXPECT_EQ(table[1].at("status"), "ok");
  EXPECT_EQ(table[5].at("status"), "failed");
}

// the processes whose command line holds `text` (the workers of one sweep, by its folder)
int processes_with(const std::string& text) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = read_text(entry.path().string() + "/cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(text) != std::string::npos && cmdline.find("--worker") != std::string::npos)
      ++count;
  }
  return count;
}

// depotwin started with `arguments`, standard output to /dev/null; with `own_group`, in a
// process group of its own (as a shell starts a job), which kill(-pid, ...) signals whole
pid_t spawn_depotwin(std::vector<std::string> arguments, bool own_group = false) {
  arguments.insert(arguments.begin(), DEPOTWIN_BINARY_DIR "/depotwin");
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  if (own_group) {
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);
  }
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &actions, &attributes, argv.data(), environ) != 0) pid = 0;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  return pid;
}

// the names in `folder` and below that hold `text`
std::vector<std::string> names_holding(const std::string& folder, const std::string& text) {
  std::vector<std::string> found;
  std::error_code ignored;
  for (auto it = fs::recursive_directory_iterator(folder, ignored);
       it != fs::recursive_directory_iterator(); it.increment(ignored))
    if (it->path().filename().string().find(text) != std::string::npos)
      found.push_back(it->path().string());
  return found;
}

TEST_F(SweepRoutes, CtrlCStopsTheWorkersAndTheNextRunResumes) {
  const std::string sweep = write_text(dir_, "interrupted.yaml", R"(base: base.yaml
grid:
  planner: [lspb_mtt, stop_and_go]
  toolpath.speed: [1.5, 2, 2.5, 3]
)");
  const std::string out = dir_ + "/interrupted";
  const pid_t pid =
      spawn_depotwin({"sweep", sweep, "-j", "1", "--out", out, "--quiet", "--no-render"});
  ASSERT_GT(pid, 0);
  // once the first task has its record (at most a minute), Ctrl-C
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!fs::exists(out + "/tasks/0000/task.json") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  // stopped as every writing verb (130), its workers with it, the unfinished tasks not
  // recorded, nothing half-written left: no staging folder, no task's or DIR's lock
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << status;
  EXPECT_EQ(processes_with(out), 0);
  EXPECT_EQ(names_holding(out, ".partial"), std::vector<std::string>{});
  EXPECT_EQ(names_holding(out, ".lock"), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(out + ".lock"));
  int recorded = 0;
  for (int i = 0; i < 8; ++i)
    recorded += fs::exists(out + "/tasks/000" + std::to_string(i) + "/task.json");
  EXPECT_GE(recorded, 1);
  EXPECT_LT(recorded, 8);
  // the next run does the rest
  const CliResult resumed = depotwin("sweep " + sweep + " -j 2 --quiet --no-render --out " + out);
  EXPECT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("8 tasks, " + std::to_string(8 - recorded) + " run (0 failed), " +
                                std::to_string(recorded) + " up to date"),
            std::string::npos)
      << resumed.output;
}

// one task run by hand (`sweep --task`, as a cluster's job runs it) stopped by SIGTERM (a
// scheduler's cancel) or SIGHUP (a closed terminal): its staging folder removed, nothing
// recorded, the shell's exit status (128 + the signal); a local run's SIGHUP ends its workers
TEST_F(SweepRoutes, ATaskStoppedBySIGTERMOrSIGHUPLeavesNothingHalfWritten) {
  const std::string sweep = write_text(dir_, "stopped.yaml", kTwoTasks);
  for (const int signal_number : {SIGTERM, SIGHUP}) {
    const std::string out = dir_ + "/stopped_" + std::to_string(signal_number);
    const pid_t pid = spawn_depotwin({"sweep", sweep, "--task", "1", "--out", out, "--quiet"});
    ASSERT_GT(pid, 0);
    // once the task's staging folder is there (the task is running), the signal
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
    while (names_holding(out, ".partial").empty() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ::kill(pid, signal_number);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + signal_number)
        << signal_number << ": " << status;
    EXPECT_EQ(names_holding(out, ".partial"), std::vector<std::string>{}) << signal_number;
    EXPECT_FALSE(fs::exists(out + "/tasks/0001/task.json")) << signal_number;
  }
  // the local runner: SIGHUP ends it and its workers, as Ctrl-C does
  const std::string out = dir_ + "/stopped_local";
  const pid_t pid = spawn_depotwin({"sweep", sweep, "-j", "1", "--out", out, "--quiet"});
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (processes_with(out) == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ::kill(pid, SIGHUP);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGHUP) << status;
  EXPECT_EQ(processes_with(out), 0);
  EXPECT_EQ(names_holding(out, ".partial"), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(out + ".lock"));
}

// SIGTERM to the whole process group (`kill -TERM -<pgid>`, a terminal's or a job
// control's stop), so that the workers have it too, mid-task: each removes its staging
// folder and task lock, the unfinished tasks are not recorded as failed, DIR's lock goes
TEST_F(SweepRoutes, ALocalRunSignalledAsAGroupLeavesNothingHalfWritten) {
  const std::string sweep = write_text(dir_, "group.yaml", kTwoTasks);
  const std::string out = dir_ + "/group";
  const pid_t pid =
      spawn_depotwin({"sweep", sweep, "-j", "2", "--out", out, "--quiet"}, /*own_group=*/true);
  ASSERT_GT(pid, 0);
  // once a task's staging folder is there (the workers are mid-task), the signal
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (names_holding(out, ".partial").empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ::kill(-pid, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGTERM) << status;
  EXPECT_EQ(processes_with(out), 0);
  EXPECT_EQ(names_holding(out, ".partial"), std::vector<std::string>{});
  EXPECT_EQ(names_holding(out, ".lock"), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(out + ".lock"));
  // a task stopped mid-way has no record (not a failure): it runs again next time
  for (const char* task : {"/tasks/0000/task.json", "/tasks/0001/task.json"}) {
    if (fs::exists(out + task)) {
      EXPECT_EQ(read_text(out + task).find("\"failed\""), std::string::npos) << task;
    }
  }
  const CliResult resumed = depotwin("sweep " + sweep + " --quiet --no-render --out " + out);
  EXPECT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("(0 failed)"), std::string::npos) << resumed.output;

  // the signal as the workers start (before some have set their handlers, so that the
  // signal's default action ends them): stopped, no task recorded as failed
  for (int trial = 0; trial < 3; ++trial) {
    const std::string early = dir_ + "/group_early_" + std::to_string(trial);
    const pid_t started =
        spawn_depotwin({"sweep", sweep, "-j", "2", "--out", early, "--quiet"}, /*own_group=*/true);
    ASSERT_GT(started, 0);
    const auto until = std::chrono::steady_clock::now() + std::chrono::minutes(1);
    while (processes_with(early) == 0 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    ::kill(-started, SIGTERM);
    ASSERT_EQ(::waitpid(started, &status, 0), started);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGTERM) << status;
    EXPECT_EQ(names_holding(early, ".partial"), std::vector<std::string>{});
    EXPECT_EQ(names_holding(early, "task.json"), std::vector<std::string>{}) << trial;
    EXPECT_FALSE(fs::exists(early + ".lock"));
  }
}

// started with SIGHUP ignored (nohup), a local run and its workers keep ignoring it: a hangup
// to the whole group mid-run changes nothing (it stopped the run once its workers ran)
TEST_F(SweepRoutes, ALocalRunStartedUnderNohupIgnoresAHangup) {
  const std::string sweep = write_text(dir_, "nohup.yaml", kTwoTasks);
  const std::string out = dir_ + "/nohup";
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGHUP, &ignore, &previous);
  const pid_t pid =
      spawn_depotwin({"sweep", sweep, "-j", "2", "--out", out, "--quiet", "--no-render"},
                     /*own_group=*/true);
  ::sigaction(SIGHUP, &previous, nullptr);
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (names_holding(out, ".partial").empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ::kill(-pid, SIGHUP);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  for (const char* task : {"/tasks/0000/task.json", "/tasks/0001/task.json"})
    EXPECT_NE(read_text(out + task).find("\"ok\""), std::string::npos) << task;
}

TEST_F(SweepRoutes, KeepAllKeepsWhatRunNoRenderWrites) {
  const std::string sweep = write_text(dir_, "keep_all.yaml", R"(base: base.yaml
keep: all
grid:
  planner: [stop_and_go]
)");
  const std::string out = dir_ + "/keep_all";
  const CliResult r = depotwin("sweep " + sweep + " --task 0 --quiet --out " + out);
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* file :
       {"metrics.json", "trajectory.csv", "thickness.csv", "thickness_field.png", "replay.json"})
    EXPECT_TRUE(fs::is_regular_file(out + "/tasks/0000/stop_and_go/" + file)) << file;
}

// two local sweeps of one folder started together: the second waits for the first's lock and
// finds its tasks up to date (each task runs once); with --no-wait it exits 2 instead
TEST_F(SweepRoutes, TwoSweepsOfOneFolderRunEachTaskOnce) {
  const std::string sweep = write_text(dir_, "together.yaml", kTwoTasks);
  const std::string out = dir_ + "/together";
  const std::string command = std::string(DEPOTWIN_BINARY_DIR) + "/depotwin sweep " + sweep +
                              " -j 1 --quiet --no-render --out " + out;
  shell("(" + command + " > " + dir_ + "/together_1.log 2>&1; echo $? >> " + dir_ +
        "/together_1.log) & " + command + " > " + dir_ + "/together_2.log 2>&1; echo $? >> " +
        dir_ + "/together_2.log; wait");
  const std::string logs =
      read_text(dir_ + "/together_1.log") + read_text(dir_ + "/together_2.log");
  EXPECT_NE(logs.find("2 tasks, 2 run (0 failed), 0 up to date"), std::string::npos) << logs;
  EXPECT_NE(logs.find("2 tasks, 0 run (0 failed), 2 up to date"), std::string::npos) << logs;
  EXPECT_NE(logs.find("waiting: " + out + " is being written by pid "), std::string::npos) << logs;
  // each log ends with its exit status
  for (const char* log : {"/together_1.log", "/together_2.log"}) {
    const std::string text = read_text(dir_ + log);
    EXPECT_EQ(text.substr(text.size() - 2), "0\n") << text;
  }
  EXPECT_FALSE(fs::exists(out + ".lock"));
  // --no-wait while a merge holds the folder: refused
  const pid_t pid = spawn_depotwin({"sweep", sweep, "--merge", "--quiet", "--out", out});
  ASSERT_GT(pid, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!fs::exists(out + ".lock") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const CliResult refused = depotwin("sweep " + sweep + " --merge --no-wait --quiet --out " + out);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  if (refused.status == 0) GTEST_SKIP() << "the merge ended before the second one started";
  EXPECT_EQ(refused.status, 2) << refused.output;
  EXPECT_NE(refused.output.find("error: --out: " + out + ": is being written by pid "),
            std::string::npos)
      << refused.output;
}

// the merge's three files move in together: one that fails on the way (gnuplot failing)
// leaves the earlier merge's results.sqlite, results.csv and summary.png byte for byte; one
// without a plot removes the earlier summary.png, which no longer matches
TEST_F(SweepRoutes, AMergeThatFailsLeavesTheEarlierMergeWhole) {
  const std::string sweep = write_text(dir_, "merged.yaml", kTwoTasks);
  const std::string out = dir_ + "/merged";
  const CliResult first = depotwin("sweep " + sweep + " -j 2 --quiet --out " + out);
  ASSERT_EQ(first.status, 0) << first.output;
  ASSERT_TRUE(fs::is_regular_file(out + "/summary.png")) << first.output;
  std::map<std::string, std::string> earlier;
  for (const char* name : {"results.sqlite", "results.csv", "summary.png"})
    earlier[name] = read_text(out + "/" + name);
  // a task's result gone: the next merge's table differs
  ASSERT_TRUE(fs::remove(out + "/tasks/0001/stop_and_go/metrics.json"));
  const std::string bin = dir_ + "/failing_gnuplot";
  fs::create_directories(bin);
  write_text(bin, "gnuplot", "#!/bin/sh\necho 'gnuplot broke' >&2\nexit 3\n");
  fs::permissions(bin + "/gnuplot", fs::perms::owner_all);
  const CliResult failed = shell("PATH=" + bin + ":$PATH " + std::string(DEPOTWIN_BINARY_DIR) +
                                 "/depotwin sweep " + sweep + " --merge --quiet --out " + out);
  EXPECT_EQ(failed.status, 1) << failed.output;
  EXPECT_NE(failed.output.find("gnuplot broke"), std::string::npos) << failed.output;
  for (const auto& [name, bytes] : earlier)
    EXPECT_TRUE(read_text(out + "/" + name) == bytes) << name << " changed";
  EXPECT_EQ(names_holding(out, "merge"), std::vector<std::string>{});
  // a merge without the plot: the new table, the earlier plot gone
  const CliResult unplotted = depotwin("sweep " + sweep + " --merge --no-render --out " + out);
  EXPECT_EQ(unplotted.status, 101) << unplotted.output;
  EXPECT_NE(unplotted.output.find("2 tasks, 1 ok, 0 failed, 1 missing"), std::string::npos)
      << unplotted.output;
  EXPECT_FALSE(fs::exists(out + "/summary.png"));
  EXPECT_NE(read_text(out + "/results.csv"), earlier["results.csv"]);
}

TEST_F(SweepRoutes, BadInputExitsTwoAndWritesNothing) {
  const std::string bad = write_text(dir_, "bad.yaml", R"(base: base.yaml
grid:
  planner: [lspb_mtt]
  limits.a_maxx: [10, 30]
)");
  for (const std::string mode : {"", " --list", " --emit slurm", " --emit parallel", " --task 0"}) {
    const std::string out = dir_ + "/bad_out";
    const CliResult r = depotwin("sweep " + bad + mode + " --out " + out);
    EXPECT_EQ(r.status, 2) << mode << ": " << r.output;
    EXPECT_NE(r.output.find("error: " + bad + ":4: limits.a_maxx: unknown key"), std::string::npos)
        << mode << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << mode;
  }
  // a task index out of range
  const CliResult range = depotwin("sweep " + sweep_ + " --task 8 --out " + dir_ + "/range_out");
  EXPECT_EQ(range.status, 2);
  EXPECT_NE(
      range.output.find("error: --task: task 8 is out of range: the sweep has 8 tasks (0..7)"),
      std::string::npos)
      << range.output;
  EXPECT_FALSE(fs::exists(dir_ + "/range_out"));
  // a results folder that is not ours
  fs::create_directories(dir_ + "/not_ours");
  write_text(dir_ + "/not_ours", "notes.txt", "mine");
  const CliResult theirs = depotwin("sweep " + sweep_ + " --quiet --out " + dir_ + "/not_ours");
  EXPECT_EQ(theirs.status, 2) << theirs.output;
  EXPECT_EQ(fs::directory_iterator(dir_ + "/not_ours")->path().filename(), "notes.txt");
}

TEST_F(SweepRoutes, GnuParallelsCommandLineGivesTheSameTable) {
  if (shell("command -v parallel").status != 0)
    GTEST_SKIP() << "GNU parallel is not installed (Debian package parallel)";
  ASSERT_EQ(local().status, 104) << local().output;
  const std::string out = dir_ + "/parallel";
  const CliResult emitted =
      depotwin("sweep " + sweep_ + " --emit parallel -j 2 --quiet --out " + out);
  ASSERT_EQ(emitted.status, 0) << emitted.output;
  EXPECT_NE(emitted.output.find("seq 0 7 | parallel --jobs 2"), std::string::npos);
  const std::string script = write_text(dir_, "parallel.sh", emitted.output);
  // the merge's exit status: 4 failed
  const CliResult ran = shell("bash " + script);
  EXPECT_EQ(ran.status, 104) << ran.output;
  EXPECT_EQ(table_without_wall_times(out + "/results.csv"),
            table_without_wall_times(dir_ + "/local/results.csv"));
}

// scripts/slurm-local.sh start|status|stop, bounded in time
CliResult slurm_local(const std::string& action) {
  return shell("DEPOTWIN_SLURM_TIMEOUT_S=20 timeout 60 bash " + std::string(DEPOTWIN_SOURCE_DIR) +
               "/scripts/slurm-local.sh " + action);
}

TEST_F(SweepRoutes, ASlurmArrayGivesTheSameTable) {
  // a local Slurm, started here when it is not running (and stopped again at the end)
  const bool was_running = slurm_local("status").status == 0;
  if (!was_running) {
    const CliResult started = slurm_local("start");
    if (started.status != 0)
      GTEST_SKIP() << "no local Slurm: scripts/slurm-local.sh start said:\n" << started.output;
  }
  // what this test started is stopped however it ends
  struct StopAtEnd {
    bool active;
    ~StopAtEnd() {
      if (active) slurm_local("stop");
    }
  } stop_at_end{!was_running};
  ASSERT_EQ(local().status, 104) << local().output;
  const std::string out = dir_ + "/slurm";
  const CliResult emitted = depotwin("sweep " + sweep_ + " --emit slurm -j 2 --quiet --out " + out);
  ASSERT_EQ(emitted.status, 0) << emitted.output;
  EXPECT_NE(emitted.output.find("#SBATCH --array=0-7%2"), std::string::npos) << emitted.output;
  const std::string script = write_text(dir_, "slurm.sh", emitted.output);
  const CliResult submitted = shell("timeout 60 bash " + script);
  ASSERT_EQ(submitted.status, 0) << submitted.output;
  // "... and merge job N; ...": wait (at most 3 minutes) until the merge has run
  ASSERT_NE(submitted.output.find("(8 tasks) and merge job "), std::string::npos)
      << submitted.output;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  std::string queue;
  do {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    queue = shell("timeout 10 squeue -h -n fig7_routes,fig7_routes-merge -o '%i %j %T %r'").output;
  } while (!queue.empty() && std::chrono::steady_clock::now() < deadline);
  if (!queue.empty())
    shell("timeout 10 scancel --name=fig7_routes; timeout 10 scancel --name=fig7_routes-merge");
  ASSERT_TRUE(queue.empty()) << "Slurm jobs still queued after 3 minutes:\n" << queue;
  ASSERT_TRUE(fs::exists(out + "/results.csv")) << read_text(out + "/logs/merge.log");
  EXPECT_EQ(table_without_wall_times(out + "/results.csv"),
            table_without_wall_times(dir_ + "/local/results.csv"));
}

}  // namespace
}  // namespace depotwin
