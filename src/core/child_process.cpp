#include "core/child_process.hpp"

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <sstream>

#include "core/interrupt.hpp"

extern char** environ;

namespace depotwin {

namespace {

bool is_executable_file(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
         ::access(path.c_str(), X_OK) == 0;
}

// util-linux's setpriv, which sets the parent-death signal and executes the program
const std::string& setpriv_path() {
  static const std::string path = find_program("setpriv");
  return path;
}

}  // namespace

std::string find_program(const std::string& program) {
  if (program.find('/') != std::string::npos) return is_executable_file(program) ? program : "";
  const char* search_path = std::getenv("PATH");
  std::istringstream directories(search_path != nullptr ? search_path : "/usr/bin:/bin");
  std::string directory;
  while (std::getline(directories, directory, ':')) {
    const std::string candidate = (directory.empty() ? "." : directory) + "/" + program;
    if (is_executable_file(candidate)) return candidate;
  }
  return "";
}

int spawn_child_process(pid_t& pid, const std::vector<std::string>& arguments,
                        const posix_spawn_file_actions_t* actions, char* const* environment) {
  if (arguments.empty()) return EINVAL;
  const std::string program = find_program(arguments.front());
  if (program.empty()) return ENOENT;

  // setpriv --pdeathsig KILL -- program arguments...
  std::vector<std::string> command;
  if (!setpriv_path().empty()) command = {setpriv_path(), "--pdeathsig", "KILL", "--"};
  command.push_back(program);
  command.insert(command.end(), arguments.begin() + 1, arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : command) argv.push_back(argument.data());
  argv.push_back(nullptr);

  // its own process group, an empty signal mask, the stop signals and SIGPIPE at default
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes,
                           POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  posix_spawnattr_setpgroup(&attributes, 0);
  sigset_t signals;
  sigemptyset(&signals);
  posix_spawnattr_setsigmask(&attributes, &signals);
  for (const int signal_number : {SIGINT, SIGTERM, SIGPIPE}) sigaddset(&signals, signal_number);
  posix_spawnattr_setsigdefault(&attributes, &signals);

  const int failure = ::posix_spawn(&pid, argv.front(), actions, &attributes, argv.data(),
                                    environment != nullptr ? environment : environ);
  posix_spawnattr_destroy(&attributes);
  if (failure != 0) return failure;
  // the handler ends it from here on; a full table leaves it to the owner's own cleanup
  register_child_process(pid);
  return 0;
}

int wait_child_process(pid_t pid) {
  // wait without reaping, leave the handler's table, then reap: the pid is never reused while
  // the handler might still kill it
  siginfo_t info{};
  while (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
  }
  unregister_child_process(pid);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return status;
}

void end_child_process(pid_t pid) {
  ::kill(pid, SIGKILL);
  wait_child_process(pid);
}

}  // namespace depotwin
