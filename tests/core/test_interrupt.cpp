// core/interrupt and core/child_process: the handler records the first stop signal and the
// exit status follows it; the children it knows of are ended by it, spawned in their own
// process group, and killed by the kernel when the process that spawned them dies.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "core/child_process.hpp"
#include "core/interrupt.hpp"

namespace depotwin {
namespace {

// the state letter of /proc/<pid>/stat ('Z': a zombie), 0 when the process is gone
char process_state(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const size_t name_end = text.rfind(')');
  return name_end == std::string::npos || name_end + 2 >= text.size() ? 0 : text[name_end + 2];
}

TEST(Interrupt, TheFirstSignalIsRecordedAndGivesTheShellsExitStatus) {
  clear_interrupt();
  install_interrupt_handlers();
  EXPECT_NO_THROW(throw_if_interrupted());
  ASSERT_EQ(::raise(SIGTERM), 0);  // handled: this process goes on
  EXPECT_EQ(interrupt_signal(), SIGTERM);
  ASSERT_EQ(::raise(SIGINT), 0);  // a second signal does not replace the first
  EXPECT_EQ(interrupt_signal(), SIGTERM);
  try {
    throw_if_interrupted();
    ADD_FAILURE() << "no Interrupted thrown";
  } catch (const Interrupted& stop) {
    EXPECT_EQ(stop.signal_number(), SIGTERM);
    EXPECT_EQ(stop.exit_status(), 143);
    EXPECT_STREQ(stop.what(), "interrupted by SIGTERM");
  }
  EXPECT_EQ(Interrupted(SIGINT).exit_status(), 130);
  clear_interrupt();
  EXPECT_NO_THROW(throw_if_interrupted());
  // a closed terminal's SIGHUP stops as cleanly
  ASSERT_EQ(::raise(SIGHUP), 0);
  EXPECT_EQ(interrupt_signal(), SIGHUP);
  EXPECT_EQ(Interrupted(SIGHUP).exit_status(), 129);
  EXPECT_STREQ(Interrupted(SIGHUP).what(), "interrupted by SIGHUP");
  clear_interrupt();
}

// a signal ignored by whoever started the process (a shell's background job) stays ignored
TEST(Interrupt, ASignalIgnoredAtStartStaysIgnored) {
  clear_interrupt();
  struct sigaction ignore {
  }, saved{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGINT, &ignore, &saved);
  install_interrupt_handlers();
  ASSERT_EQ(::raise(SIGINT), 0);
  EXPECT_EQ(interrupt_signal(), 0);
  ::sigaction(SIGINT, &saved, nullptr);
}

TEST(ChildProcess, ASignalEndsTheRegisteredChildren) {
  clear_interrupt();
  pid_t child = 0;
  ASSERT_EQ(spawn_child_process(child, {"sleep", "60"}, nullptr), 0);
  EXPECT_EQ(::getpgid(child), child);  // a process group of its own: no terminal's Ctrl-C
  request_interrupt(SIGINT);           // what the handler does
  const int status = wait_child_process(child);
  ASSERT_TRUE(WIFSIGNALED(status)) << status;
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  clear_interrupt();
}

TEST(ChildProcess, AChildSpawnedAfterTheSignalIsEndedToo) {
  clear_interrupt();
  request_interrupt(SIGTERM);
  pid_t child = 0;
  ASSERT_EQ(spawn_child_process(child, {"sleep", "60"}, nullptr), 0);
  const int status = wait_child_process(child);
  ASSERT_TRUE(WIFSIGNALED(status)) << status;
  EXPECT_EQ(WTERMSIG(status), SIGKILL);
  clear_interrupt();
}

TEST(ChildProcess, AReapedChildIsNoLongerEndedByASignal) {
  clear_interrupt();
  pid_t child = 0;
  ASSERT_EQ(spawn_child_process(child, {"true"}, nullptr), 0);
  const int status = wait_child_process(child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  // its slot is free: a signal now kills no one (the pid may already be someone else's)
  request_interrupt(SIGINT);
  pid_t next = 0;
  ASSERT_EQ(spawn_child_process(next, {"sleep", "60"}, nullptr), 0);
  EXPECT_TRUE(WIFSIGNALED(wait_child_process(next)));
  clear_interrupt();
}

TEST(ChildProcess, NoSuchProgramIsENOENT) {
  pid_t child = 0;
  EXPECT_EQ(spawn_child_process(child, {"depotwin-no-such-program"}, nullptr), ENOENT);
  EXPECT_EQ(spawn_child_process(child, {"/nonexistent/gnuplot"}, nullptr), ENOENT);
}

// a parent killed outright (SIGKILL: no handler runs) takes its children with it
TEST(ChildProcess, TheKernelEndsAChildWhoseParentIsKilled) {
  if (find_program("setpriv").empty()) GTEST_SKIP() << "util-linux's setpriv is not installed";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    // the parent: spawn a long child, say its pid, wait to be killed
    pid_t child = 0;
    if (spawn_child_process(child, {"sleep", "60"}, nullptr) != 0) ::_exit(1);
    if (::write(fds[1], &child, sizeof child) != sizeof child) ::_exit(1);
    ::pause();
    ::_exit(0);
  }
  ::close(fds[1]);
  pid_t child = 0;
  ASSERT_EQ(::read(fds[0], &child, sizeof child), static_cast<ssize_t>(sizeof child));
  ::close(fds[0]);
  // once it runs sleep (setpriv has set the parent-death signal and executed it)
  for (int i = 0; i < 500; ++i) {
    std::ifstream comm("/proc/" + std::to_string(child) + "/comm");
    std::string name;
    std::getline(comm, name);
    if (name == "sleep") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(::kill(parent, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(parent, &status, 0), parent);
  // the orphan is killed at once; give a loaded machine up to 10 s to show it
  char state = process_state(child);
  for (int i = 0; i < 1000 && state != 0 && state != 'Z' && state != 'X'; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    state = process_state(child);
  }
  EXPECT_TRUE(state == 0 || state == 'Z' || state == 'X') << "state " << state;
  if (state != 0 && state != 'Z' && state != 'X') ::kill(child, SIGKILL);
}

}  // namespace
}  // namespace depotwin
