#include "plots/gnuplot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/child_process.hpp"
#include "core/file_io.hpp"
#include "core/interrupt.hpp"

extern char** environ;

namespace depotwin::plots {

namespace fs = std::filesystem;

GnuplotNotFound::GnuplotNotFound()
    : InternalError(
          "gnuplot not found: install the Debian package gnuplot-nox (scripts/setup.sh does)") {}

namespace {

bool is_executable_file(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) &&
         ::access(path.c_str(), X_OK) == 0;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// the environment of the child: ours with LC_ALL=C (numbers with a decimal point)
std::vector<std::string> child_environment() {
  std::vector<std::string> entries;
  for (char** entry = environ; entry != nullptr && *entry != nullptr; ++entry) {
    if (std::strncmp(*entry, "LC_ALL=", 7) == 0) continue;
    entries.emplace_back(*entry);
  }
  entries.emplace_back("LC_ALL=C");
  return entries;
}

}  // namespace

std::string find_gnuplot(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    if (is_executable_file(program)) return program;
    throw GnuplotNotFound();
  }
  const char* search_path = std::getenv("PATH");
  std::string directories = search_path != nullptr ? search_path : "/usr/bin:/bin";
  std::istringstream parts(directories);
  std::string directory;
  while (std::getline(parts, directory, ':')) {
    if (directory.empty()) directory = ".";
    const std::string candidate = directory + "/" + program;
    if (is_executable_file(candidate)) return candidate;
  }
  throw GnuplotNotFound();
}

std::vector<std::string> run_gnuplot(const std::string& executable, const std::string& script_path,
                                     const std::string& stderr_path) {
  throw_if_interrupted();  // no new child once a signal has asked to stop
  // stdin and stdout from/to /dev/null, stderr to a file we read afterwards
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const std::vector<std::string> arguments = {executable, "-d", script_path};
  std::vector<std::string> environment = child_environment();
  std::vector<char*> envp;
  for (std::string& entry : environment) envp.push_back(entry.data());
  envp.push_back(nullptr);

  // under depotwin's control: a signal that stops the run ends it (core/child_process.hpp)
  pid_t child = 0;
  const int spawn_error = spawn_child_process(child, arguments, &actions, envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error == ENOENT) throw GnuplotNotFound();
  if (spawn_error != 0)
    throw EnvironmentError("cannot start " + executable + ": " + std::strerror(spawn_error));

  // wait for it; killed because a signal stopped the run, it did not fail: the run stops
  const int status = wait_child_process(child);
  throw_if_interrupted();
  const std::string messages = read_file(stderr_path);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                              : "signal " + std::to_string(WTERMSIG(status));
    throw InternalError("gnuplot failed (" + how + ") on " + script_path + ":\n" + messages);
  }
  std::vector<std::string> warnings;
  std::istringstream lines(messages);
  std::string line;
  while (std::getline(lines, line))
    if (!line.empty()) warnings.push_back(line);
  return warnings;
}

TemporaryDirectory::TemporaryDirectory(const std::string& parent) {
  std::error_code error;
  fs::create_directories(parent, error);
  std::string pattern = (parent.empty() ? std::string(".") : parent) + "/.plots-XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr)
    throw EnvironmentError("cannot create a temporary directory in " + parent + ": " +
                           std::strerror(errno));
  path_ = fs::absolute(pattern).lexically_normal().string();
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

void write_text_file(const std::string& path, const std::string& content) {
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.flush();
  if (!out) {
    const int why = errno;  // a full disk: "No space left on device"
    throw EnvironmentError("cannot write " + path + system_reason(why));
  }
}

void move_into_place(const std::string& from, const std::string& to) {
  std::error_code error;
  fs::rename(from, to, error);
  if (error) throw EnvironmentError("cannot move " + from + " to " + to + ": " + error.message());
}

}  // namespace depotwin::plots
