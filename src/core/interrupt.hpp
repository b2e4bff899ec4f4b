// Stopping on SIGINT, SIGTERM, SIGHUP and SIGPIPE. The handler only records the signal and ends the
// child processes registered with it (gnuplot, ffmpeg), both async-signal-safe; the long loops (the
// step loop, the posture search, the planners, the writers, the wait for an output lock) call
// throw_if_interrupted(), and the Interrupted exception unwinds through the owners of the
// staging folders and the child processes, which clean up. main() turns it into exit status
// 128 + the signal (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP, 141 for SIGPIPE).
#pragma once

#include <sys/types.h>

#include <exception>
#include <string>

namespace depotwin {

// a signal asked the run to stop; not an InputError or InternalError, so no handler of those
// swallows it
class Interrupted : public std::exception {
 public:
  explicit Interrupted(int signal_number);
  int signal_number() const { return signal_number_; }
  // 128 + the signal, as a shell reports a process a signal ended
  int exit_status() const { return 128 + signal_number_; }
  const char* what() const noexcept override { return message_.c_str(); }

 private:
  int signal_number_;
  std::string message_;  // "interrupted by SIGINT"
};

// Installs the handler for SIGINT, SIGTERM, SIGHUP and SIGPIPE (SA_RESTART, so no other call sees
// EINTR; a write to a closed pipe then fails with EPIPE, and the run stops at its next check). A
// signal ignored when the process started (a shell's background job, nohup) stays ignored.
// Call once, early in main, before any thread starts.
void install_interrupt_handlers();

// the first signal that asked to stop, 0 while none has
int interrupt_signal();
inline bool interrupt_requested() {
  return interrupt_signal() != 0;
}
// throws Interrupted when a signal has asked to stop
void throw_if_interrupted();

// what the handler does, for tests: record the signal and end the registered children
void request_interrupt(int signal_number);
// forget a recorded signal (tests only)
void clear_interrupt();

// The child processes the handler ends with SIGKILL: registered from their spawn until just
// before they are reaped (so a kill never reaches a reused pid). At most kMaxChildProcesses at
// once; register_child_process returns false when the table is full.
inline constexpr int kMaxChildProcesses = 64;
bool register_child_process(pid_t pid);
void unregister_child_process(pid_t pid);

}  // namespace depotwin
