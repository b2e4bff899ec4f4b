// Shared helpers for the scenario tests: a fresh temporary directory per test, inline
// files written into it, and assertions on the reported problems.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "scenario/scenario.hpp"

namespace depotwin::testing_scenario {

namespace fs = std::filesystem;

// every test gets its own directory, removed afterwards
class ScenarioFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / ("depotwin_scenario_" + std::string(info->test_suite_name()) +
                                     "_" + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // write `text` (a leading newline is dropped so raw strings can start on their own line)
  std::string write(const std::string& name, std::string text) const {
    if (!text.empty() && text.front() == '\n') text.erase(0, 1);
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  // the problems of a scenario written as `scenario.yaml`
  std::vector<Problem> problems_of(const std::string& yaml) const {
    return validate_scenario_file(write("scenario.yaml", yaml));
  }

  std::string scenario_path() const { return (dir_ / "scenario.yaml").string(); }

  fs::path dir_;
};

// all problems as text, for failure messages
inline std::string dump(const std::vector<Problem>& problems) {
  std::string text;
  for (const Problem& p : problems) text += "  " + p.str() + "\n";
  return text;
}

// Exactly one problem names `key`; it is on `line` of `file`, its message contains
// `words`, and its text reads "file:line: key: ...".
inline void expect_problem(const std::vector<Problem>& problems, const std::string& file,
                           const std::string& key, int line, const std::string& words) {
  int matches = 0;
  for (const Problem& p : problems) {
    if (p.key != key) continue;
    ++matches;
    EXPECT_EQ(p.file, file);
    EXPECT_EQ(p.line, line) << p.str();
    EXPECT_NE(p.message.find(words), std::string::npos) << "message: " << p.message;
    const std::string prefix = file + ":" + std::to_string(line) + ": " + key + ": ";
    EXPECT_EQ(p.str().rfind(prefix, 0), 0u) << p.str();
  }
  EXPECT_EQ(matches, 1) << "problems naming '" << key << "':\n" << dump(problems);
}

}  // namespace depotwin::testing_scenario
