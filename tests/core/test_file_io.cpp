// Atomic writes: the file holds exactly what was written, an older file is replaced whole,
// no temporary is left behind, and a failure leaves the target untouched; a file a scenario
// names that is missing, a directory or not a regular file is told apart, and read_text_file
// refuses it before it opens it.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
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

// a full disk: the error says so, the file is as it was and no temporary is left (a tmpfs of
// 64 KiB; mounting one needs root, elsewhere the test is skipped)
TEST(FileIo, AFullDiskIsNamedAsTheSystemSaysIt) {
  const fs::path directory = fresh_directory("file_io_full");
  fs::create_directories(directory / "volume");
  const std::string mount =
      "mount -t tmpfs -o size=64k tmpfs '" + (directory / "volume").string() + "' 2>/dev/null";
  if (::geteuid() != 0 || std::system(mount.c_str()) != 0)
    GTEST_SKIP() << "mounting a tmpfs needs root";
  const fs::path target = directory / "volume" / "metrics.json";
  write_file_atomically(target.string(), "kept");
  std::string message;
  try {
    write_file_atomically(target.string(), std::string(1 << 20, 'x'));
  } catch (const InternalError& error) {
    message = error.what();
  }
  const std::size_t left = static_cast<std::size_t>(
      std::distance(fs::directory_iterator(directory / "volume"), fs::directory_iterator()));
  const std::string kept = read_text(target.string());
  EXPECT_EQ(std::system(("umount '" + (directory / "volume").string() + "'").c_str()), 0);
  EXPECT_EQ(message, "cannot write " + target.string() + ": No space left on device");
  EXPECT_EQ(kept, "kept");
  EXPECT_EQ(left, 1u);  // no temporary
  fs::remove_all(directory);
}

// The four answers: a regular file (no problem), a directory, something else that exists (a
// FIFO), nothing there.
TEST(FileIo, MissingFileProblemSaysWhatIsThereInstead) {
  const fs::path directory = fresh_directory("file_io_missing");
  const fs::path file = directory / "part.gcode";
  write_file_atomically(file.string(), "G1 X1\n");
  EXPECT_EQ(missing_file_problem("G-code", "part.gcode", file.string()), "");
  EXPECT_EQ(missing_file_problem("G-code", "jobs", directory.string()),
            "G-code file 'jobs' is a directory (" + directory.string() + "), not a file");
  const fs::path fifo = directory / "pipe.gcode";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(missing_file_problem("G-code", "pipe.gcode", fifo.string()),
            "G-code file 'pipe.gcode' is not a regular file (" + fifo.string() + ")");
  const fs::path nowhere = directory / "none.stl";
  EXPECT_EQ(missing_file_problem("STL", "none.stl", nowhere.string()),
            "STL file 'none.stl' not found (looked for " + nowhere.string() + ")");
  // a path the system cannot follow is not "not found": a loop of links, a name too long
  const fs::path loop_a = directory / "a.yaml", loop_b = directory / "b.yaml";
  fs::create_symlink(loop_b, loop_a);
  fs::create_symlink(loop_a, loop_b);
  EXPECT_EQ(missing_file_problem("scenario", "a.yaml", loop_a.string()),
            "scenario file 'a.yaml' cannot be opened (" + loop_a.string() +
                "): " + std::make_error_code(std::errc::too_many_symbolic_link_levels).message());
  const fs::path long_name = directory / (std::string(300, 'a') + ".yaml");
  EXPECT_NE(missing_file_problem("scenario", "", long_name.string()).find("cannot be opened: "),
            std::string::npos);
}

// read_text_file checks before it opens: a FIFO is refused at once (reading it would wait
// for a writer), as are a directory and a missing file; the message names the path
// What a rename would replace itself is refused before any write: a FIFO, a device, a symbolic
// link, a directory, "-"; a regular file or a new name may be written.
TEST(FileIo, ReplaceableFileProblemRefusesDevicesLinksAndFifos) {
  const fs::path directory = fresh_directory("file_io_replaceable");
  const fs::path file = directory / "job.gcode";
  EXPECT_EQ(replaceable_file_problem(file.string()), "");  // not there yet
  write_file_atomically(file.string(), "G1 X1\n");
  EXPECT_EQ(replaceable_file_problem(file.string()), "");
  const fs::path fifo = directory / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(replaceable_file_problem(fifo.string()).find("is not a regular file"),
            std::string::npos);
  EXPECT_NE(replaceable_file_problem("/dev/null").find("is not a regular file"), std::string::npos);
  const fs::path link = directory / "latest.gcode";
  fs::create_symlink(file, link);
  EXPECT_NE(replaceable_file_problem(link.string()).find("is a symbolic link (to '"),
            std::string::npos);
  EXPECT_NE(replaceable_file_problem(directory.string()).find("is a directory"), std::string::npos);
  EXPECT_NE(replaceable_file_problem("-").find("standard output"), std::string::npos);
  fs::remove_all(directory);
}

TEST(FileIo, ReadTextFileRefusesWhatIsNotARegularFile) {
  const fs::path directory = fresh_directory("file_io_read");
  const fs::path fifo = directory / "pipe.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::vector<std::pair<fs::path, std::string>> cases = {
      {fifo, "file is not a regular file"},
      {directory, "file is a directory, not a file"},
      {directory / "none.json", "file not found"}};
  for (const auto& [path, message] : cases) {
    try {
      read_text_file(path.string());
      ADD_FAILURE() << "no InputError for " << path;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()), path.string() + ": " + message);
    }
  }
  write_file_atomically((directory / "a.json").string(), "{}\n");
  EXPECT_EQ(read_text_file((directory / "a.json").string()), "{}\n");
}

}  // namespace
}  // namespace depotwin
