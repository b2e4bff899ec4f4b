// A verb's output is the earlier result or the new one, whole, never a mix, whatever happens
// to the process: SIGINT or SIGTERM at any point of a run (exit 130 or 143, the earlier
// result byte for byte, no staging folder, no lock file, no gnuplot left), SIGKILL (gnuplot
// dies with it, the next run clears what it left), two writers at once (one waits; the last
// one's result whole), --no-wait while another writer holds the lock (exit 2), a planner
// named twice (refused every time, nothing written), and a full disk (said as the system says
// it, exit 1, nothing left).
#include <gtest/gtest.h>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/child_process.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "report/output_dir.hpp"

extern char** environ;

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using testing_support::depotwin;
using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::scenario_path;

// ---- the CLI as a process the test can signal

// `depotwin ARGUMENTS`, stdout and stderr to `log`, with SIGINT and SIGTERM at their defaults
// (whatever this test inherited)
pid_t start_depotwin(const std::vector<std::string>& arguments, const std::string& log) {
  std::vector<std::string> command{std::string(DEPOTWIN_BINARY_DIR) + "/depotwin"};
  command.insert(command.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : command) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  posix_spawnattr_setsigdefault(&attributes, &signals);
  pid_t pid = -1;
  if (::posix_spawn(&pid, argv.front(), &actions, &attributes, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  return pid;
}

// how a process ended: its exit code, or the signal that killed it
struct Ending {
  int exit_code = -1;
  int killed_by = 0;
};

Ending ending_of(int status) {
  Ending ending;
  if (WIFEXITED(status)) ending.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) ending.killed_by = WTERMSIG(status);
  return ending;
}

Ending wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return ending_of(status);
}

// the process has ended (reaped into `ending`)
bool has_ended(pid_t pid, Ending& ending) {
  int status = 0;
  if (::waitpid(pid, &status, WNOHANG) != pid) return false;
  ending = ending_of(status);
  return true;
}

// a /proc file's bytes; empty when the process is gone (read(2) says ESRCH)
std::string read_proc_file(const std::string& path) {
  std::string text;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return text;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
    text.append(buffer, static_cast<size_t>(n));
  ::close(fd);
  return text;
}

// the command lines of live processes (not this one) that mention `text`
std::vector<std::string> processes_mentioning(const std::string& text) {
  std::vector<std::string> found;
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return found;
  while (const dirent* entry = ::readdir(proc)) {
    const std::string name = entry->d_name;
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (name == std::to_string(::getpid())) continue;
    std::string line = read_proc_file("/proc/" + name + "/cmdline");  // empty for a zombie
    std::replace(line.begin(), line.end(), '\0', ' ');
    if (line.find(text) != std::string::npos) found.push_back(name + ": " + line);
  }
  ::closedir(proc);
  return found;
}

// ---- what a folder holds

// every file under `dir` by its relative path with a checksum of its bytes (FNV-1a), and
// every folder
std::map<std::string, uint64_t> checksum_listing(const std::string& dir) {
  std::map<std::string, uint64_t> listing;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(entry.path(), dir).string();
    if (entry.is_directory()) {
      listing[name + "/"] = 0;
      continue;
    }
    uint64_t hash = 1469598103934665603ull;
    for (const char byte : read_text(entry.path().string()))
      hash = (hash ^ static_cast<unsigned char>(byte)) * 1099511628211ull;
    listing[name] = hash;
  }
  return listing;
}

std::vector<std::string> names_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::set<std::string> relative_names(const std::map<std::string, uint64_t>& listing) {
  std::set<std::string> names;
  for (const auto& [name, hash] : listing) names.insert(name);
  return names;
}

void copy_folder(const std::string& from, const std::string& to) {
  fs::remove_all(to);
  fs::copy(from, to, fs::copy_options::recursive);
}

// ---- interrupts

// when a trial's signal is sent
enum class Moment { gnuplot_running, staging_made, after_delay };

// `trials` runs of thompson_fig7's lspb_mtt (images on, so gnuplot runs) into a folder holding
// stop_and_go's result, each stopped by `signal_number` at a moment of its own: while a
// gnuplot child draws, as soon as the staging folder exists, or after a delay spread over the
// run's length. Every trial must end with 128 + the signal and the earlier result byte for
// byte, or, when the signal came too late, 0 and the new result whole; never a staging
// folder, a lock file or a process of the run left.
void interrupt_trials(int signal_number, const std::string& name, int trials) {
  const std::string dir = fresh_directory(name);
  const std::string out = dir + "/results";
  const std::string keep = fresh_directory(name + "_pristine");
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  const std::string signal_name = signal_number == SIGINT ? "SIGINT" : "SIGTERM";

  // the earlier result, and the new one's names and its length when nothing stops it
  const auto earlier_run = depotwin("run " + fig7 + " --planner stop_and_go --quiet --out " + out);
  ASSERT_EQ(earlier_run.status, 0) << earlier_run.output;
  const std::map<std::string, uint64_t> earlier = checksum_listing(out);
  copy_folder(out, keep + "/results");
  const Clock::time_point reference_start = Clock::now();
  const auto reference =
      depotwin("run " + fig7 + " --planner lspb_mtt --quiet --out " + keep + "/new");
  const double run_s = std::chrono::duration<double>(Clock::now() - reference_start).count();
  ASSERT_EQ(reference.status, 0) << reference.output;
  const std::set<std::string> new_names = relative_names(checksum_listing(keep + "/new"));
  ASSERT_NE(new_names, relative_names(earlier));

  int interrupted = 0, before_handler = 0, finished = 0;
  std::vector<double> stop_s;  // signal to exit
  for (int trial = 0; trial < trials; ++trial) {
    const std::string log = keep + "/trial.log";
    const pid_t pid =
        start_depotwin({"run", fig7, "--planner", "lspb_mtt", "--quiet", "--out", out}, log);
    ASSERT_GT(pid, 0);
    const std::string staging = out + ".partial-" + std::to_string(pid);
    const Moment moment = trial % 4 == 0   ? Moment::gnuplot_running
                          : trial % 4 == 1 ? Moment::staging_made
                                           : Moment::after_delay;
    // wait for the moment (or the run's end)
    Ending ending;
    bool ended = false;
    const Clock::time_point start = Clock::now();
    const double delay_s = run_s * (0.05 + 0.95 * ((trial * 7) % trials) / trials);
    while (!(ended = has_ended(pid, ending))) {
      if (moment == Moment::after_delay &&
          std::chrono::duration<double>(Clock::now() - start).count() >= delay_s)
        break;
      if (moment == Moment::staging_made && fs::exists(staging)) break;
      if (moment == Moment::gnuplot_running) {
        bool drawing = false;
        for (const std::string& process : processes_mentioning(staging))
          drawing = drawing || process.find("gnuplot") != std::string::npos;
        if (drawing) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const Clock::time_point signalled = Clock::now();
    if (!ended) {
      ASSERT_EQ(::kill(pid, signal_number), 0);
      ending = wait_for(pid);
      stop_s.push_back(std::chrono::duration<double>(Clock::now() - signalled).count());
    }
    const std::string said = read_text(log);

    // stopped: the earlier result, byte for byte; finished first: the new one, whole
    if (ending.exit_code == 128 + signal_number) {
      ++interrupted;
      EXPECT_NE(said.find("depotwin: interrupted by " + signal_name +
                          "; stopped, the output is as it was"),
                std::string::npos)
          << said;
      EXPECT_EQ(checksum_listing(out), earlier) << "trial " << trial;
    } else if (ending.killed_by == signal_number) {
      ++before_handler;  // still starting up: nothing staged yet
      EXPECT_EQ(checksum_listing(out), earlier) << "trial " << trial;
    } else if (ending.exit_code == 0) {
      ++finished;
      EXPECT_EQ(relative_names(checksum_listing(out)), new_names) << "trial " << trial;
      copy_folder(keep + "/results", out);
    } else {
      ADD_FAILURE() << "trial " << trial << ": exit " << ending.exit_code << ", signal "
                    << ending.killed_by << "\n"
                    << said;
      copy_folder(keep + "/results", out);
    }
    // nothing else beside it, and nothing of the run still running
    EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"}) << "trial " << trial;
    const std::vector<std::string> left = processes_mentioning(dir);
    EXPECT_TRUE(left.empty()) << "trial " << trial << ": " << left.front();
  }

  // the figures, for the record; most trials must have met a run in progress
  std::sort(stop_s.begin(), stop_s.end());
  std::printf(
      "%s: %d trials (run %.2f s): %d stopped with exit %d, %d before the handler was set, %d "
      "finished first; signal to exit: median %.3f s, max %.3f s\n",
      signal_name.c_str(), trials, run_s, interrupted, 128 + signal_number, before_handler,
      finished, stop_s.empty() ? 0.0 : stop_s[stop_s.size() / 2],
      stop_s.empty() ? 0.0 : stop_s.back());
  EXPECT_GE(interrupted, trials / 2);
}

// trials per signal: 20, or DEPOTWIN_INTERRUPT_TRIALS (fewer under a sanitizer, more on demand)
int interrupt_trial_count() {
  const char* text = std::getenv("DEPOTWIN_INTERRUPT_TRIALS");
  const int count = text != nullptr ? std::atoi(text) : 0;
  return count > 0 ? count : 20;
}

TEST(OutputSafety, SigintAtAnyMomentLeavesTheEarlierResultWhole) {
  interrupt_trials(SIGINT, "safety_sigint", interrupt_trial_count());
}

TEST(OutputSafety, SigtermAtAnyMomentLeavesTheEarlierResultWhole) {
  interrupt_trials(SIGTERM, "safety_sigterm", interrupt_trial_count());
}

// SIGKILL runs no handler: gnuplot dies with depotwin all the same (the kernel's parent-death
// signal), and the next run into the folder clears the staging folder the dead one left
TEST(OutputSafety, AKilledRunsGnuplotDiesWithItAndItsLeftoversGoNextTime) {
  if (find_program("setpriv").empty()) GTEST_SKIP() << "util-linux's setpriv is not installed";
  const std::string dir = fresh_directory("safety_sigkill");
  const std::string log = fresh_directory("safety_sigkill_log") + "/run.log";
  const std::string out = dir + "/results";
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  pid_t killed = -1;
  for (int attempt = 0; attempt < 3 && killed < 0; ++attempt) {
    const pid_t pid =
        start_depotwin({"run", fig7, "--planner", "lspb_mtt", "--quiet", "--out", out}, log);
    ASSERT_GT(pid, 0);
    const std::string staging = out + ".partial-" + std::to_string(pid);
    Ending ending;
    while (!has_ended(pid, ending)) {
      bool drawing = false;
      for (const std::string& process : processes_mentioning(staging))
        drawing = drawing || process.find("gnuplot") != std::string::npos;
      if (drawing) {
        ASSERT_EQ(::kill(pid, SIGKILL), 0);
        wait_for(pid);
        killed = pid;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  ASSERT_GT(killed, 0) << "no run was caught while gnuplot drew";
  std::vector<std::string> left = processes_mentioning(dir);
  for (int i = 0; i < 500 && !left.empty(); ++i) {  // a loaded machine: up to 5 s
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    left = processes_mentioning(dir);
  }
  EXPECT_TRUE(left.empty()) << left.front();
  // what SIGKILL leaves: the staging folder (and the lock file, whose lock died with it)
  const std::string staging_name = "results.partial-" + std::to_string(killed);
  EXPECT_TRUE(fs::exists(dir + "/" + staging_name));

  // the next writer takes the lock at once, removes the dead one's staging folder, and writes
  const auto next = depotwin("plan " + fig7 + " --planner stop_and_go --no-wait --out " + out);
  ASSERT_EQ(next.status, 0) << next.output;
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"});
  EXPECT_EQ(names_in(out), (std::vector<std::string>{".depotwin", "stop_and_go"}));
}

// ---- two writers

// thompson_fig7's stop_and_go and thompson_fig11's lspb_mtt started together into one folder:
// both succeed, one after the other; the folder holds one of them whole (its run folder only,
// its scenario in every metrics.json), and it is the one that waited, which wrote last
TEST(OutputSafety, TwoWritersOfDifferentScenariosLeaveOneWholeResult) {
  const std::string dir = fresh_directory("safety_two_writers");
  const std::string logs = fresh_directory("safety_two_writers_logs");
  const std::string out = dir + "/results";
  struct Writer {
    std::string scenario, planner;
  };
  const std::vector<Writer> writers{{"thompson_fig7", "stop_and_go"},
                                    {"thompson_fig11", "lspb_mtt"}};
  int waited = 0;
  for (int round = 0; round < 4; ++round) {
    std::vector<pid_t> pids;
    for (size_t w = 0; w < writers.size(); ++w) {
      // the second starts a little later each round (0, 30, 60, 90 ms), taking turns first
      const size_t which = (w + round) % writers.size();
      if (w == 1) std::this_thread::sleep_for(std::chrono::milliseconds(30 * round));
      pids.push_back(
          start_depotwin({"run", scenario_path(writers[which].scenario + ".yaml"), "--planner",
                          writers[which].planner, "--no-render", "--quiet", "--out", out},
                         logs + "/" + std::to_string(which) + ".log"));
    }
    for (const pid_t pid : pids) EXPECT_EQ(wait_for(pid).exit_code, 0);
    // the writer that waited wrote last
    int last = -1;
    for (size_t w = 0; w < writers.size(); ++w)
      if (read_text(logs + "/" + std::to_string(w) + ".log").find("waiting: " + out) !=
          std::string::npos)
        last = static_cast<int>(w);
    waited += last >= 0;
    const std::vector<std::string> folders = names_in(out);
    ASSERT_EQ(folders.size(), 2u) << round;  // .depotwin and one run folder
    const size_t found = folders[1] == writers[0].planner ? 0 : 1;
    EXPECT_EQ(folders, (std::vector<std::string>{".depotwin", writers[found].planner})) << round;
    const auto metrics =
        nlohmann::json::parse(read_text(out + "/" + writers[found].planner + "/metrics.json"));
    EXPECT_EQ(metrics["scenario"], writers[found].scenario) << round;
    if (last >= 0) {
      EXPECT_EQ(static_cast<int>(found), last) << round;
    }
    EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"}) << round;
  }
  std::printf("two writers: %d of 4 rounds had one wait for the other\n", waited);
}

// another writer (here this test, holding the lock as a compare would): --no-wait refuses with
// exit 2 and names it, for every writing verb; without it, a writer waits and then writes
TEST(OutputSafety, NoWaitExitsTwoWhileAnotherWriterHoldsTheLock) {
  const std::string dir = fresh_directory("safety_no_wait");
  const std::string out = dir + "/results";
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  ASSERT_EQ(depotwin("plan " + fig7 + " --planner stop_and_go --out " + out).status, 0);
  const std::map<std::string, uint64_t> earlier = checksum_listing(out);
  const std::string holder =
      "is being written by pid " + std::to_string(::getpid()) + " (`depotwin compare`)";
  {
    OutputLock held(fs::absolute(out).string(), out, "compare", true);
    for (const std::string verb : {"run", "compare", "plan"}) {
      const auto refused = depotwin(
          verb + " " + fig7 + (verb == "compare" ? " --planners" : " --planner") + " lspb_mtt" +
          (verb == "plan" ? "" : " --no-render --quiet") + " --no-wait --out " + out);
      EXPECT_EQ(refused.status, 2) << verb << ": " << refused.output;
      EXPECT_NE(refused.output.find("error: --out: " + out + ": " + holder), std::string::npos)
          << verb << ": " << refused.output;
    }
    EXPECT_EQ(checksum_listing(out), earlier);
  }
  {
    const std::string gcode = dir + "/job.gcode";
    OutputLock held(gcode, gcode, "compare", true);
    const auto refused =
        depotwin("export " + fig7 + " --planner lspb_mtt --no-wait --out " + gcode);
    EXPECT_EQ(refused.status, 2) << refused.output;
    EXPECT_NE(refused.output.find("error: --out: " + gcode + ": " + holder), std::string::npos)
        << refused.output;
    EXPECT_FALSE(fs::exists(gcode));
  }

  // without --no-wait: it says it waits, waits while the lock is held, then writes
  auto held = std::make_unique<OutputLock>(fs::absolute(out).string(), out, "compare", true);
  const std::string log = fresh_directory("safety_no_wait_log") + "/plan.log";
  const pid_t pid = start_depotwin({"plan", fig7, "--planner", "lspb_mtt", "--out", out}, log);
  ASSERT_GT(pid, 0);
  Ending ending;
  bool ended = false;
  // the whole waiting line (stderr may reach the file in more than one write)
  while (!(ended = has_ended(pid, ending)) &&
         read_text(log).find("(--no-wait: exit instead)\n") == std::string::npos)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_FALSE(ended) << read_text(log);
  EXPECT_EQ(read_text(log), "waiting: " + out + " " + holder +
                                "; this run goes on when it is done (--no-wait: exit instead)\n");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(has_ended(pid, ending));  // still waiting
  EXPECT_EQ(checksum_listing(out), earlier);
  held.reset();
  EXPECT_EQ(wait_for(pid).exit_code, 0) << read_text(log);
  EXPECT_EQ(names_in(out), (std::vector<std::string>{".depotwin", "lspb_mtt"}));
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"});
}

// ---- a reader of the output that goes away

// `depotwin run ... 2>&1 | head -n 1`: the first write after head is gone raises SIGPIPE,
// which stops the run as SIGINT does (exit 141, nothing left behind); it used to kill the run
// outright and leave DIR.partial-<pid> and DIR.lock behind
TEST(OutputSafety, AReaderThatGoesAwayStopsTheRunAndLeavesNothing) {
  const std::string dir = fresh_directory("safety_sigpipe");
  const std::string out = dir + "/results";
  // (the reader is gone before the run starts, as below: its first progress line, after the
  // simulation and before the results are written, meets the closed pipe. A reader of one
  // line, `head -n 1`, raced the run on a loaded machine: not scheduled in the 0.1 s the run
  // takes to write its results, it left a whole result, exit 141)
  const auto r = testing_support::shell("bash -c '{ sleep 1; DEPOTWIN_PROGRESS_PERIOD_S=0 exec " +
                                        std::string(DEPOTWIN_BINARY_DIR) + "/depotwin run " +
                                        scenario_path("thompson_fig7.yaml") +
                                        " --planner lspb_mtt --no-render --out " + out +
                                        "; } 2>&1 | true; echo \"status ${PIPESTATUS[0]}\"'");
  EXPECT_NE(r.output.find("status 141"), std::string::npos) << r.output;
  EXPECT_EQ(names_in(dir), std::vector<std::string>{}) << r.output;
  // gone before the last lines, printed after the result was swapped in: the result is whole,
  // the status 141 as a verb ended by the signal reports it, and no error is said (it was
  // exit 1, "the standard output could not be written whole")
  // (the plan starts a second after `true`, which has surely gone by then even on a loaded
  // machine: started together, a plan that printed before `true` ended exited 0)
  const auto after = testing_support::shell(
      "bash -c '{ sleep 1; exec " + std::string(DEPOTWIN_BINARY_DIR) + "/depotwin plan " +
      scenario_path("thompson_fig7.yaml") + " --planner lspb_mtt --quiet --out " + out + "; } 2> " +
      dir + "/stderr.txt | true; echo \"status ${PIPESTATUS[0]}\"'");
  EXPECT_NE(after.output.find("status 141"), std::string::npos) << after.output;
  EXPECT_EQ(read_text(dir + "/stderr.txt"), "");
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{"results", "stderr.txt"}));
  EXPECT_TRUE(fs::exists(out + "/lspb_mtt/metrics.json"));
}

// ---- a planner named twice

// refused before any work, every time (it once raced two writers of one folder)
TEST(OutputSafety, APlannerNamedTwiceIsRefusedEveryTime) {
  const std::string dir = fresh_directory("safety_planner_twice");
  const std::string fig7 = scenario_path("thompson_fig7.yaml");
  for (int trial = 0; trial < 20; ++trial) {
    const auto r =
        depotwin("run " + fig7 + " --planner lspb_mtt,lspb_mtt --quiet --out " + dir + "/results");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_EQ(r.output, "error: --planner: 'lspb_mtt' is named twice\n") << trial;
  }
  const auto plan = depotwin("plan " + fig7 + " --planner stop_and_go,lspb_mtt,stop_and_go --out " +
                             dir + "/results");
  EXPECT_EQ(plan.status, 2);
  EXPECT_EQ(plan.output, "error: --planner: 'stop_and_go' is named twice\n");
  const auto compare =
      depotwin("compare " + fig7 + " --planners lspb_mtt,lspb_mtt --out " + dir + "/results");
  EXPECT_EQ(compare.status, 2);
  EXPECT_EQ(compare.output, "error: --planners: 'lspb_mtt' is named twice\n");
  // an empty name (a stray comma) is refused as move refuses its lists' (it was skipped)
  const auto stray =
      depotwin("compare " + fig7 + " --planners lspb_mtt, --out " + dir + "/results");
  EXPECT_EQ(stray.status, 2);
  EXPECT_EQ(stray.output,
            "error: --planners: 'lspb_mtt,' has an empty name (a comma with no name beside it)\n");
  const auto doubled =
      depotwin("plan " + fig7 + " --planner lspb_mtt,,stop_and_go --out " + dir + "/results");
  EXPECT_EQ(doubled.status, 2) << doubled.output;
  EXPECT_TRUE(names_in(dir).empty());
  // spaces beside a name are not part of it
  const auto spaced =
      depotwin("plan " + fig7 + " --planner 'lspb_mtt, stop_and_go' --out " + dir + "/results");
  EXPECT_EQ(spaced.status, 0) << spaced.output;
  EXPECT_EQ(names_in(dir + "/results"),
            (std::vector<std::string>{".depotwin", "lspb_mtt", "stop_and_go"}));
}

// ---- a full disk

// the machine's refusal is an error that says why (exit 1), not an "internal error", and
// nothing is left on the volume (a 16 KiB tmpfs: mounting one needs root, elsewhere skipped)
TEST(OutputSafety, AFullDiskIsSaidAsTheSystemSaysItAndLeavesNothing) {
  const std::string dir = fresh_directory("safety_full_disk");
  const std::string volume = dir + "/volume";
  fs::create_directories(volume);
  if (::geteuid() != 0 ||
      std::system(("mount -t tmpfs -o size=16k tmpfs '" + volume + "' 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "mounting a tmpfs needs root";
  const auto r = depotwin("plan " + scenario_path("thompson_fig7.yaml") +
                          " --planner stop_and_go --out " + volume + "/results");
  const std::vector<std::string> left = names_in(volume);
  EXPECT_EQ(std::system(("umount '" + volume + "'").c_str()), 0);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_EQ(r.output.rfind("error: cannot write " + volume + "/results.partial-", 0), 0u)
      << r.output;
  EXPECT_NE(r.output.find(": No space left on device\n"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  EXPECT_TRUE(left.empty()) << left.front();
}

}  // namespace
}  // namespace depotwin
