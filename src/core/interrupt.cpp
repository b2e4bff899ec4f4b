#include "core/interrupt.hpp"

#include <signal.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>

namespace depotwin {

namespace {

// lock-free atomics are safe to touch from a signal handler
std::atomic<int> recorded_signal{0};
std::array<std::atomic<pid_t>, kMaxChildProcesses> child_slots{};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free,
              "the signal handler needs lock-free atomics");

// the flag first, then the children: a thread that sees its child killed finds the flag set
void record_and_end_children(int signal_number) {
  int none = 0;
  recorded_signal.compare_exchange_strong(none, signal_number);
  for (std::atomic<pid_t>& slot : child_slots) {
    const pid_t pid = slot.load();
    if (pid > 0) ::kill(pid, SIGKILL);
  }
}

// async-signal-safe: atomics and kill(2) only, errno preserved
extern "C" void on_stop_signal(int signal_number) {
  const int saved_errno = errno;
  record_and_end_children(signal_number);
  errno = saved_errno;
}

}  // namespace

Interrupted::Interrupted(int signal_number)
    : signal_number_(signal_number),
      message_(std::string("interrupted by ") +
               (signal_number == SIGINT    ? "SIGINT"
                : signal_number == SIGTERM ? "SIGTERM"
                : signal_number == SIGHUP  ? "SIGHUP"
                : signal_number == SIGPIPE ? "SIGPIPE (the standard output or error was closed)"
                                           : "signal " + std::to_string(signal_number))) {}

void install_interrupt_handlers() {
  // SIGHUP too: what a closed terminal or a dropped ssh session sends; SIGPIPE: a reader of
  // the output that went away (`depotwin run ... 2>&1 | head`), which killed the run with its
  // staging folder and lock left behind (SIGQUIT keeps its core dump, for a hang to be looked
  // into)
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
    struct sigaction previous {};
    ::sigaction(signal_number, nullptr, &previous);
    if (previous.sa_handler == SIG_IGN) continue;  // ignored by whoever started us: stays so
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(signal_number, &action, nullptr);
  }
}

int interrupt_signal() {
  return recorded_signal.load();
}

void throw_if_interrupted() {
  const int signal_number = recorded_signal.load();
  if (signal_number != 0) throw Interrupted(signal_number);
}

void request_interrupt(int signal_number) {
  record_and_end_children(signal_number);
}

void clear_interrupt() {
  recorded_signal.store(0);
}

bool register_child_process(pid_t pid) {
  for (std::atomic<pid_t>& slot : child_slots) {
    pid_t empty = 0;
    if (!slot.compare_exchange_strong(empty, pid)) continue;
    // a signal that came before the registration did not reach this child: end it now
    if (recorded_signal.load() != 0) ::kill(pid, SIGKILL);
    return true;
  }
  return false;
}

void unregister_child_process(pid_t pid) {
  for (std::atomic<pid_t>& slot : child_slots) {
    pid_t registered = pid;
    if (slot.compare_exchange_strong(registered, 0)) return;
  }
}

}  // namespace depotwin
