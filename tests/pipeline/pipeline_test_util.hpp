// Helpers for the end-to-end tests: scenario files written to a fresh temporary folder.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace depotwin::testing_support {

// a fresh, empty temporary folder per test (removed at the start, left for inspection)
inline std::string fresh_directory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("depotwin_test_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

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

}  // namespace depotwin::testing_support
