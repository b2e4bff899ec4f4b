// One writer at a time, nothing left behind: the output lock (a second writer refused or kept
// waiting, the holder named, the lock file gone after use, one left by a killed writer taken
// over), stale staging of dead writers removed, and an interrupt before the commit leaving the
// earlier result.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "core/child_process.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "report/output_dir.hpp"
#include "scratch_folder.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;

using testing_support::fresh_directory;

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::vector<std::string> names_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// the message of the only problem of an InputError
std::string refusal(const InputError& error) {
  return error.problems().size() == 1
             ? error.problems().front().key + ": " + error.problems().front().message
             : error.what();
}

// a pid no process has: a child that ran and was reaped
pid_t dead_pid() {
  pid_t child = 0;
  if (spawn_child_process(child, {"true"}, nullptr) != 0) return 0;
  wait_child_process(child);
  return child;
}

TEST(OutputLock, ASecondWriterIsRefusedWithTheHolderNamed) {
  const std::string dir = fresh_directory("lock_refused");
  const std::string out = dir + "/results";
  OutputLock first(out, "results", "compare", true);
  EXPECT_EQ(first.lock_path(), out + ".lock");
  EXPECT_EQ(read_text(out + ".lock"),
            "depotwin lock held by pid " + std::to_string(::getpid()) + " (`depotwin compare`)\n");
  try {
    OutputLock second(out, "shown/results", "run", false);
    ADD_FAILURE() << "a second writer took the lock";
  } catch (const InputError& error) {
    EXPECT_EQ(refusal(error), "--out: shown/results: is being written by pid " +
                                  std::to_string(::getpid()) + " (`depotwin compare`) (" + out +
                                  ".lock is locked); run again when it is done, or without "
                                  "--no-wait to wait for it");
  }
  // let go: the lock file is gone and the next writer gets it at once
  first.release();
  EXPECT_FALSE(fs::exists(out + ".lock"));
  OutputLock third(out, "results", "plan", false);
  EXPECT_TRUE(fs::exists(out + ".lock"));
  third.release();
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(OutputLock, AWaitingWriterGoesOnWhenTheHolderLetsGo) {
  const std::string dir = fresh_directory("lock_waits");
  const std::string out = dir + "/results";
  auto first = std::make_unique<OutputLock>(out, "results", "run", true);
  std::atomic<bool> second_holds{false};
  testing::internal::CaptureStderr();
  std::thread second([&] {
    OutputLock lock(out, "results", "plan", true);
    second_holds = true;
    EXPECT_EQ(read_text(out + ".lock"),
              "depotwin lock held by pid " + std::to_string(::getpid()) + " (`depotwin plan`)\n");
  });
  // it waits as long as the lock is held (here 0.5 s), whatever the machine's load
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_FALSE(second_holds);
  first.reset();
  second.join();
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(second_holds);
  EXPECT_EQ(said, "waiting: results is being written by pid " + std::to_string(::getpid()) +
                      " (`depotwin run`); this run goes on when it is done (--no-wait: exit "
                      "instead)\n");
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(OutputLock, AWaitingWriterStopsForASignal) {
  const std::string dir = fresh_directory("lock_interrupted");
  const std::string out = dir + "/results";
  OutputLock first(out, "results", "run", true);
  clear_interrupt();
  std::thread signal_later([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    request_interrupt(SIGINT);
  });
  testing::internal::CaptureStderr();
  EXPECT_THROW(OutputLock(out, "results", "plan", true), Interrupted);
  testing::internal::GetCapturedStderr();
  signal_later.join();
  clear_interrupt();
}

// a writer killed outright (SIGKILL) leaves its lock file but not its lock
TEST(OutputLock, ALockFileLeftByAKilledWriterBlocksNoOne) {
  const std::string dir = fresh_directory("lock_stale");
  const std::string out = dir + "/results";
  write_text(out + ".lock",
             "depotwin lock held by pid " + std::to_string(dead_pid()) + " (`depotwin run`)\n");
  OutputLock lock(out, "results", "run", false);
  EXPECT_EQ(read_text(out + ".lock"),
            "depotwin lock held by pid " + std::to_string(::getpid()) + " (`depotwin run`)\n");
  lock.release();
  EXPECT_TRUE(names_in(dir).empty());
}

// a file of that name that depotwin did not write is neither used nor removed
TEST(OutputLock, SomeoneElsesFileOfThatNameIsKept) {
  const std::string dir = fresh_directory("lock_foreign");
  const std::string out = dir + "/results";
  write_text(out + ".lock", "my notes\n");
  try {
    OutputLock lock(out, "results", "run", false);
    ADD_FAILURE() << "someone else's file taken as the lock";
  } catch (const InputError& error) {
    EXPECT_EQ(refusal(error),
              "--out: results: " + out + ".lock exists and is not depotwin's lock file; remove it");
  }
  EXPECT_EQ(read_text(out + ".lock"), "my notes\n");
}

TEST(StaleStaging, ADeadWritersLeftoversGoALiveOnesStay) {
  const std::string dir = fresh_directory("stale_staging");
  const std::string out = dir + "/results";
  const std::string dead = std::to_string(dead_pid());
  const std::string alive = std::to_string(::getppid());  // whoever started this test
  for (const std::string& name : std::vector<std::string>{
           "results.partial-" + dead, "results.old-" + dead, "results.partial-" + alive,
           "results.partial-x" + dead, "other.partial-" + dead, "results"}) {
    fs::create_directories(dir + "/" + name);
    write_text(dir + "/" + name + "/" + kOutputMarker, "depotwin output folder\n");
  }
  write_text(dir + "/results.tmp-" + dead, std::string(kExportedGcodeStart) + " 0.1\nG1 X");
  remove_stale_staging(out);
  EXPECT_EQ(names_in(dir),
            (std::vector<std::string>{"other.partial-" + dead, "results",
                                      "results.partial-" + alive, "results.partial-x" + dead}));
}

// a dead pid's name alone is not enough: what the user keeps under such a name stays (a
// backup folder `results.old-2023`, a file of theirs), what a killed writer leaves goes (a
// staging folder killed before or while its marker was written, an empty temporary file)
TEST(StaleStaging, TheUsersFoldersAndFilesOfSuchNamesStay) {
  const std::string dir = fresh_directory("stale_staging_users");
  const std::string out = dir + "/results";
  const std::string dead = std::to_string(dead_pid());
  const std::string other_dead = std::to_string(dead_pid());
  fs::create_directories(dir + "/results.old-" + dead);
  write_text(dir + "/results.old-" + dead + "/thesis.txt", "chapter 1\n");
  write_text(dir + "/results.tmp-" + dead, "my notes\n");
  fs::create_directories(dir + "/results.partial-" + dead);
  write_text(dir + "/results.partial-" + dead + "/" + kOutputMarker + ".tmp-" + dead, "depot");
  fs::create_directories(dir + "/results.partial-" + other_dead);
  write_text(dir + "/results.tmp-" + other_dead, "");
  remove_stale_staging(out);
  EXPECT_EQ(names_in(dir),
            (std::vector<std::string>{"results.old-" + dead, "results.tmp-" + dead}));
  EXPECT_EQ(read_text(dir + "/results.old-" + dead + "/thesis.txt"), "chapter 1\n");
  EXPECT_EQ(read_text(dir + "/results.tmp-" + dead), "my notes\n");
}

// the output as it was before when a signal stops the verb before its commit; after the
// commit, the new one
TEST(OutputFolder, AnInterruptBeforeTheCommitLeavesTheEarlierResult) {
  const std::string dir = fresh_directory("folder_interrupted");
  const std::string out = dir + "/results";
  fs::create_directories(out + "/stop_and_go");
  write_text(out + "/" + kOutputMarker, "depotwin output folder\n");
  write_text(out + "/stop_and_go/metrics.json", "{\"planner\": \"stop_and_go\"}\n");
  clear_interrupt();
  {
    OutputFolder folder(out, "run", "", false);
    EXPECT_EQ(folder.path(), out + ".partial-" + std::to_string(::getpid()));
    fs::create_directories(folder.path() + "/lspb_mtt");
    write_text(folder.path() + "/lspb_mtt/metrics.json", "{\"planner\": \"lspb_mtt\"}\n");
    request_interrupt(SIGTERM);
    EXPECT_THROW(folder.commit(), Interrupted);
  }
  clear_interrupt();
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"});  // no staging, no lock
  EXPECT_EQ(names_in(out), (std::vector<std::string>{kOutputMarker, "stop_and_go"}));
  EXPECT_EQ(read_text(out + "/stop_and_go/metrics.json"), "{\"planner\": \"stop_and_go\"}\n");

  // uninterrupted: the new result whole, the lock free for the next writer at once
  {
    OutputFolder folder(out, "run", "", false);
    fs::create_directories(folder.path() + "/lspb_mtt");
    write_text(folder.path() + "/lspb_mtt/metrics.json", "{\"planner\": \"lspb_mtt\"}\n");
    folder.commit();
    OutputLock next(fs::absolute(out).string(), out, "plan", false);
  }
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"results"});
  EXPECT_EQ(names_in(out), (std::vector<std::string>{kOutputMarker, "lspb_mtt"}));
}

// a second OutputFolder for the same DIR refuses (no wait) while the first stages
TEST(OutputFolder, OneWriterAtATime) {
  const std::string dir = fresh_directory("folder_exclusive");
  const std::string out = dir + "/results";
  OutputFolder first(out, "compare", "", false);
  try {
    OutputFolder second(out, "run", "", false);
    ADD_FAILURE() << "two writers staged one folder";
  } catch (const InputError& error) {
    EXPECT_NE(refusal(error).find("--out: " + out + ": is being written by pid " +
                                  std::to_string(::getpid()) + " (`depotwin compare`)"),
              std::string::npos)
        << refusal(error);
  }
  EXPECT_EQ(names_in(dir), (std::vector<std::string>{
                               "results.lock", "results.partial-" + std::to_string(::getpid())}));
}

}  // namespace
}  // namespace depotwin
