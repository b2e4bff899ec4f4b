// Atomic writes: the file holds exactly what was written, an older file is replaced whole,
// no temporary is left behind, and a failure leaves the target untouched.
#include <gtest/gtest.h>

#include <filesystem>
#include <iterator>
#include <string>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "pipeline/pipeline_test_util.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::read_text;

TEST(FileIo, WritesReplacesAndLeavesNoTemporary) {
  const fs::path directory = fresh_directory("file_io");
  const fs::path target = directory / "out.bin";
  const std::string first("first\0with a zero byte", 22);
  write_file_atomically(target.string(), first);
  EXPECT_EQ(read_text(target.string()), first);
  write_file_atomically(target.string(), "second");
  EXPECT_EQ(read_text(target.string()), "second");
  EXPECT_EQ(std::distance(fs::directory_iterator(directory), fs::directory_iterator()), 1);
  fs::remove_all(directory);
}

TEST(FileIo, FailureNamesTheFileAndLeavesTheTargetUntouched) {
  const fs::path directory = fresh_directory("file_io_fail");
  const fs::path target = directory / "kept.txt";
  write_file_atomically(target.string(), "kept");
  // the target's name taken by a directory: the rename over it fails
  const fs::path blocked = directory / "blocked";
  fs::create_directories(blocked / "inside");
  try {
    write_file_atomically(blocked.string(), "new");
    FAIL() << "no InternalError";
  } catch (const InternalError& error) {
    EXPECT_NE(std::string(error.what()).find(blocked.string()), std::string::npos) << error.what();
  }
  EXPECT_EQ(read_text(target.string()), "kept");
  EXPECT_TRUE(fs::is_directory(blocked / "inside"));
  EXPECT_EQ(std::distance(fs::directory_iterator(directory), fs::directory_iterator()), 2);
  fs::remove_all(directory);
}

}  // namespace
}  // namespace depotwin
