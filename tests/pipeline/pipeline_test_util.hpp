// Helpers for the end-to-end tests (XY and delta pipelines, CLI, examples): scenario files
// written to a fresh temporary folder, files read back, quiet run settings, the built CLI.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "scratch_folder.hpp"

namespace depotwin::testing_support {

inline std::string write_text(const std::string& directory, const std::string& name,
                              const std::string& text) {
  const std::string path = directory + "/" + name;
  std::ofstream(path) << text;
  return path;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::string scenario_path(const std::string& name) {
  return std::string(DEPOTWIN_SCENARIOS_DIR) + "/" + name;
}

// what the built CLI returned
struct CliResult {
  int status = -1;
  std::string output;  // stdout and stderr
};

// run a shell command: its stdout and stderr together, and its exit status
inline CliResult shell(const std::string& command) {
  CliResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// run the built CLI with arguments (shell-quoted by the caller where needed)
inline CliResult depotwin(const std::string& arguments) {
  return shell(std::string(DEPOTWIN_BINARY_DIR) + "/depotwin " + arguments);
}

}  // namespace depotwin::testing_support
