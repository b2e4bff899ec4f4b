#include "sweep/local_runner.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "pipeline/progress_line.hpp"
#include "sweep/task.hpp"

extern char** environ;

namespace depotwin {

namespace fs = std::filesystem;

namespace {

// the worker reports on this descriptor
constexpr int kReportFd = 3;
// characters of the progress bar
constexpr std::size_t kBarWidth = 24;

// the signal (SIGINT, SIGTERM, SIGHUP) that asked the local run to stop, 0 while none has
volatile sig_atomic_t g_stop_signal = 0;
extern "C" void record_stop_signal(int signal_number) {
  if (g_stop_signal == 0) g_stop_signal = signal_number;
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// the last non-empty line of a file (at most its last 4 kB), or ""
std::string last_line_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  const std::streamoff from = size > 4096 ? size - 4096 : 0;
  in.seekg(from);
  std::string text(static_cast<std::size_t>(size - from), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
    text.pop_back();
  const std::size_t newline = text.find_last_of("\r\n");
  return newline == std::string::npos ? text : text.substr(newline + 1);
}

// "killed by signal 11 (Segmentation fault)", "exited with status 1"
std::string ending_text(int status) {
  if (WIFSIGNALED(status))
    return "killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  return "ended (wait status " + std::to_string(status) + ")";
}

// "1 min 05 s", "12 s"
std::string duration_text(double seconds) {
  if (!std::isfinite(seconds)) return "--";
  const long long whole = std::llround(seconds);
  char text[64];
  if (whole >= 3600)
    std::snprintf(text, sizeof text, "%lld h %02lld min", whole / 3600, whole % 3600 / 60);
  else if (whole >= 60)
    std::snprintf(text, sizeof text, "%lld min %02lld s", whole / 60, whole % 60);
  else
    std::snprintf(text, sizeof text, "%lld s", whole);
  return text;
}

// A worker that ended by a stop request was stopped, not failed: its task is not recorded.
// Either it stopped itself (exit 128 + SIGINT, SIGTERM or SIGHUP, its task's staging folder
// removed), or the signal came before it set its handlers (just started) and ended it.
int stop_signal_of(int status) {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP})
    if ((WIFEXITED(status) && WEXITSTATUS(status) == 128 + signal_number) ||
        (WIFSIGNALED(status) && WTERMSIG(status) == signal_number))
      return signal_number;
  return 0;
}

// how long stopped workers get to remove their staging folders before SIGKILL
constexpr double kWorkerStopGrace_s = 20.0;

struct Worker {
  pid_t pid = -1;
  int command_fd = -1;  // task indices to the worker's stdin
  int report_fd = -1;   // "<index> <status>" lines back
  std::string pending;  // a report line in the making
  std::optional<std::uint64_t> task;
  double task_started_s = 0.0;
};

Worker spawn_worker(const LocalRunOptions& options, const Sweep& sweep) {
  int command[2], report[2];
  if (::pipe2(command, O_CLOEXEC) != 0 || ::pipe2(report, O_CLOEXEC) != 0)
    throw InternalError(std::string("cannot create a pipe for a sweep worker: ") +
                        std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, command[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, report[1], kReportFd);
  const std::string out = fs::absolute(sweep.out_directory()).string();
  std::vector<std::string> arguments{options.executable, "sweep", options.sweep_file, "--out", out,
                                     "--worker"};
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  Worker worker;
  const int failed = ::posix_spawn(&worker.pid, options.executable.c_str(), &actions, nullptr,
                                   argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(command[0]);
  ::close(report[1]);
  if (failed != 0) {
    ::close(command[1]);
    ::close(report[0]);
    throw EnvironmentError("cannot start a sweep worker (" + options.executable +
                           "): " + std::strerror(failed));
  }
  worker.command_fd = command[1];
  worker.report_fd = report[0];
  return worker;
}

}  // namespace

std::string current_executable() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (error) throw InternalError("cannot find the running executable: " + error.message());
  return self.string();
}

LocalRunSummary run_tasks_locally(const Sweep& sweep, const std::vector<std::uint64_t>& tasks,
                                  const LocalRunOptions& options) {
  LocalRunSummary summary;
  const double start_s = now_s();
  if (tasks.empty()) return summary;
  // a worker that died must not take this process with it on the next write to its stdin
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &previous);
  // Ctrl-C or a kill: recorded here (the workers ignore SIGINT), the workers asked to stop,
  // then this process (SIGHUP too: a closed terminal or a dropped ssh session). A signal
  // ignored (nohup, a script's background job) stays ignored, here and in the workers,
  // which inherit it
  struct sigaction stop {
  }, previous_int{}, previous_term{}, previous_hup{};
  stop.sa_handler = record_stop_signal;
  sigemptyset(&stop.sa_mask);
  g_stop_signal = 0;
  const auto catch_unless_ignored = [&](int signal_number, struct sigaction& previous_action) {
    ::sigaction(signal_number, nullptr, &previous_action);
    if (previous_action.sa_handler != SIG_IGN) ::sigaction(signal_number, &stop, nullptr);
  };
  catch_unless_ignored(SIGINT, previous_int);
  catch_unless_ignored(SIGTERM, previous_term);
  catch_unless_ignored(SIGHUP, previous_hup);
  // a signal that came before (while the tasks were checked) stops the run before it starts
  if (const int earlier = interrupt_signal(); earlier != 0) g_stop_signal = earlier;

  std::deque<std::uint64_t> queue(tasks.begin(), tasks.end());
  std::vector<Worker> workers;
  const std::uint64_t total = tasks.size();
  ProgressLine line("sweep " + sweep.spec().name, ProgressLine::style_for_stderr(options.progress));

  // hand the worker its next task, or close its stdin when there is none
  const auto give_next = [&](Worker& worker) {
    worker.task.reset();
    if (queue.empty()) {
      if (worker.command_fd >= 0) ::close(worker.command_fd);
      worker.command_fd = -1;
      return;
    }
    const std::uint64_t index = queue.front();
    queue.pop_front();
    const std::string text = std::to_string(index) + "\n";
    worker.task = index;
    worker.task_started_s = now_s();
    // a failed write means the worker died: its end of file comes next and records the task
    [[maybe_unused]] const ssize_t written = ::write(worker.command_fd, text.data(), text.size());
  };
  const auto task_done = [&](std::uint64_t index, bool ok) {
    ++summary.ran;
    if (!ok) {
      ++summary.failed;
      summary.failed_tasks.push_back(index);
    }
  };

  const std::size_t count =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(1, options.workers)), tasks.size());
  for (std::size_t k = 0; k < count && g_stop_signal == 0; ++k) {
    workers.push_back(spawn_worker(options, sweep));
    give_next(workers.back());
  }

  while (g_stop_signal == 0) {
    std::vector<pollfd> polled;
    std::vector<std::size_t> owner;
    for (std::size_t k = 0; k < workers.size(); ++k)
      if (workers[k].report_fd >= 0) {
        polled.push_back(pollfd{workers[k].report_fd, POLLIN, 0});
        owner.push_back(k);
      }
    if (polled.empty()) break;
    const int ready = ::poll(polled.data(), polled.size(), 200);
    if (ready < 0 && errno != EINTR)
      throw InternalError(std::string("poll: ") + std::strerror(errno));
    for (std::size_t p = 0; p < polled.size() && ready > 0; ++p) {
      if (polled[p].revents == 0) continue;
      Worker& worker = workers[owner[p]];
      char buffer[512];
      const ssize_t n = ::read(worker.report_fd, buffer, sizeof buffer);
      if (n > 0) {
        // "<index> <status>" per finished task
        worker.pending.append(buffer, static_cast<std::size_t>(n));
        for (std::size_t end; (end = worker.pending.find('\n')) != std::string::npos;) {
          const std::string report = worker.pending.substr(0, end);
          worker.pending.erase(0, end + 1);
          task_done(std::stoull(report), report.find(" ok") != std::string::npos);
          give_next(worker);
        }
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      // end of file: the worker ended; a task it was running is recorded as failed
      ::close(worker.report_fd);
      worker.report_fd = -1;
      if (worker.command_fd >= 0) ::close(worker.command_fd);
      worker.command_fd = -1;
      int status = 0;
      ::waitpid(worker.pid, &status, 0);
      if (const int stopped = stop_signal_of(status); stopped != 0 && worker.task) {
        // a signal to the process group reached the worker first: the run stops
        if (g_stop_signal == 0) g_stop_signal = stopped;
        worker.task.reset();
      }
      if (g_stop_signal != 0) worker.task.reset();  // stopping: what ended it is no failure
      if (worker.task) {
        const std::uint64_t index = *worker.task;
        const SweepTask task = sweep.task(index);
        std::string error = "the task's worker process " + ending_text(status) +
                            " before the task recorded a result";
        const std::string last = last_line_of(sweep.task_log(index));
        if (!last.empty()) error += "; its log (" + sweep.task_log(index) + ") ends: " + last;
        record_task_failure(sweep, task, sweep.input_hash(task), error,
                            now_s() - worker.task_started_s);
        task_done(index, false);
        // a replacement for the rest
        if (!queue.empty()) {
          workers.push_back(spawn_worker(options, sweep));
          give_next(workers.back());
        }
      }
    }
    // progress: tasks done, failures, the time left at the pace so far
    const double elapsed = now_s() - start_s;
    const std::uint64_t done = summary.ran;
    const double eta =
        done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(total - done) : NAN;
    const double fraction = static_cast<double>(done) / static_cast<double>(total);
    const std::size_t filled = static_cast<std::size_t>(fraction * kBarWidth);
    line.update(fraction,
                "[" + std::string(filled, '#') + std::string(kBarWidth - filled, '.') + "] " +
                    std::to_string(done) + "/" + std::to_string(total) + " tasks" +
                    (summary.failed > 0 ? ", " + std::to_string(summary.failed) + " failed" : "") +
                    ", ETA " + duration_text(eta));
  }
  if (g_stop_signal == 0) line.finish();
  ::sigaction(SIGPIPE, &previous, nullptr);
  ::sigaction(SIGINT, &previous_int, nullptr);
  ::sigaction(SIGTERM, &previous_term, nullptr);
  ::sigaction(SIGHUP, &previous_hup, nullptr);
  if (const int signal_number = g_stop_signal; signal_number != 0) {
    // stopped: each running worker is asked to stop (SIGTERM: its task's staging folder and
    // lock are removed as the exception unwinds; an unfinished task is not recorded and runs
    // again next time), ended outright if it has not within the grace; then this process
    // stops as every writing verb does, its lock on DIR released (Interrupted)
    // (a worker waiting for its next task ends at the end of its input)
    for (Worker& worker : workers) {
      if (worker.command_fd >= 0) ::close(worker.command_fd);
      worker.command_fd = -1;
      if (worker.report_fd >= 0) ::kill(worker.pid, SIGTERM);
    }
    const double deadline_s = now_s() + kWorkerStopGrace_s;
    for (Worker& worker : workers) {
      if (worker.report_fd < 0) continue;
      while (::waitpid(worker.pid, nullptr, WNOHANG) == 0) {
        if (now_s() > deadline_s) {
          ::kill(worker.pid, SIGKILL);
          ::waitpid(worker.pid, nullptr, 0);
          break;
        }
        ::usleep(10000);
      }
      ::close(worker.report_fd);
    }
    std::fprintf(stderr, "\nsweep %s: stopped by %s after %llu of %llu tasks\n",
                 sweep.spec().name.c_str(), strsignal(signal_number),
                 static_cast<unsigned long long>(summary.ran),
                 static_cast<unsigned long long>(total));
    throw Interrupted(signal_number);
  }
  summary.wall_s = now_s() - start_s;
  return summary;
}

int sweep_worker(const Sweep& sweep) {
  if (::fcntl(kReportFd, F_GETFD) == -1)
    throw InputError("--worker", "is for depotwin's own worker processes (sweep -j)");
  // Ctrl-C reaches the whole process group: the parent decides, and ends its workers
  ::signal(SIGINT, SIG_IGN);
  std::string text;
  while (std::getline(std::cin, text)) {
    const std::uint64_t index = std::stoull(text);
    // the task's own output (its messages, a crash's last words) into its log
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    const std::string log = sweep.task_log(index);
    const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (log_fd >= 0) {
      ::dup2(log_fd, STDOUT_FILENO);
      ::dup2(log_fd, STDERR_FILENO);
      ::close(log_fd);
    }
    const SweepTask task = sweep.task(index);
    std::string status = "failed";
    try {
      const TaskRecord record = run_task(sweep, task, sweep.input_hash(task));
      status = record.status;
      std::cout << "task " << index << " (" << task.parameters_text() << "): " << record.status
                << " in " << record.wall_s << " s"
                << (record.error.empty() ? "" : "\n" + record.error) << std::endl;
    } catch (const InputError& error) {
      // the folder could not be written: nothing recorded (the merge lists the task as
      // missing), said in the log
      for (const Problem& problem : error.problems())
        std::cerr << "error: " << problem.str() << '\n';
    }
    std::fflush(nullptr);
    // an empty log says nothing
    std::error_code ignored;
    if (fs::file_size(log, ignored) == 0) fs::remove(log, ignored);
    const std::string report = std::to_string(index) + " " + status + "\n";
    if (::write(kReportFd, report.data(), report.size()) < 0) return kExitInternal;
  }
  return kExitOk;
}

}  // namespace depotwin
