// The job's long steps on stderr (pipeline/step_heartbeat.hpp): the step named, with its time,
// once it has lasted; a terminal's line rewritten in place and ended when the step ends; nothing
// when off, for a step named "", for a second heartbeat or for another thread's steps. The
// heartbeat writes from its own thread, so each test waits (up to a minute) for a line it
// expects, and a line it must not see would have come within a few of its periods.
#include "pipeline/step_heartbeat.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <thread>

#include "scratch_folder.hpp"

namespace depotwin {
namespace {

using namespace std::chrono_literals;

// a file the heartbeat writes to, read back by its path (the heartbeat's thread writes while
// the test reads)
struct Output {
  explicit Output(const std::string& name)
      : path(testing_support::scratch_file(name)), file(std::fopen(path.c_str(), "w")) {}
  ~Output() {
    if (file != nullptr) std::fclose(file);
  }
  std::string text() const {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  // whether `wanted` shows within a minute
  bool shows(const std::string& wanted) const {
    for (int i = 0; i < 6000; ++i) {
      if (text().find(wanted) != std::string::npos) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }

  std::string path;
  std::FILE* file;
};

constexpr double kPeriod_s = 0.05;  // a line every 50 ms (the thread looks as often)
// several periods: what has not shown by then would not show
constexpr auto kSeveralPeriods = 400ms;

TEST(StepHeartbeat, ALogShowsTheStepWithItsTimeWhileItLasts) {
  Output out("log.txt");
  {
    StepHeartbeat heartbeat("job", ProgressLine::Style::log, out.file, 1.0, kPeriod_s);
    {
      const WorkingStep step("planning uniform");
      ASSERT_TRUE(out.shows("job: planning uniform ("));
    }
    // no step: no more lines
    const std::string after = out.text();
    std::this_thread::sleep_for(kSeveralPeriods);
    EXPECT_EQ(out.text(), after);
  }
  // plain lines, each "job: planning uniform (T s)" with a time of at least one period
  const std::string text = out.text();
  EXPECT_EQ(text.find('\r'), std::string::npos);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  double seconds = 0.0;
  char tail[8] = {};
  EXPECT_EQ(std::sscanf(text.c_str(), "job: planning uniform (%lf s%1[)]", &seconds, tail), 2)
      << text;
  EXPECT_GE(seconds, kPeriod_s);
}

TEST(StepHeartbeat, ATerminalLineIsRewrittenAndEndedWithTheStep) {
  Output out("terminal.txt");
  {
    StepHeartbeat heartbeat("job", ProgressLine::Style::terminal, out.file, 0.0, kPeriod_s);
    {
      const WorkingStep step("choosing the arm's posture");
      ASSERT_TRUE(out.shows("\rjob: choosing the arm's posture ("));
    }
    // the step's line ended with its whole time, then the next step on a line of its own
    const std::string ended = out.text();
    ASSERT_FALSE(ended.empty());
    EXPECT_EQ(ended.back(), '\n');
    EXPECT_EQ(ended.find('\n'), ended.size() - 1);  // one line, rewritten in place
    const WorkingStep next("planning conformal");
    ASSERT_TRUE(out.shows("\n\rjob: planning conformal ("));
  }
  // the heartbeat's end ends the open line
  const std::string text = out.text();
  EXPECT_EQ(text.back(), '\n');
}

TEST(StepHeartbeat, AnUnnamedStepOffStyleSecondHeartbeatOrOtherThreadShowNothing) {
  Output out("nothing.txt");
  {
    // off: nothing at all
    StepHeartbeat off("job", ProgressLine::Style::off, out.file, 0.0, kPeriod_s);
    const WorkingStep step("planning uniform");
    std::this_thread::sleep_for(kSeveralPeriods);
  }
  EXPECT_EQ(out.text(), "");

  Output second("second.txt");
  {
    StepHeartbeat first("job", ProgressLine::Style::log, out.file, 0.0, kPeriod_s);
    {
      // a second heartbeat while one shows: silent
      StepHeartbeat nested("nested", ProgressLine::Style::log, second.file, 0.0, kPeriod_s);
      // a step named "" (a stretch with its own progress line) inside a named one
      const WorkingStep outer("simulating");
      std::optional<WorkingStep> silent(std::in_place, "");
      // another thread's step
      std::thread other([] {
        const WorkingStep elsewhere("writing images");
        std::this_thread::sleep_for(kSeveralPeriods);
      });
      other.join();
      EXPECT_EQ(out.text(), "");
      // leaving the unnamed step: the named one shows again
      silent.reset();
      ASSERT_TRUE(out.shows("job: simulating ("));
    }
  }
  EXPECT_EQ(second.text(), "");
  EXPECT_EQ(out.text().find("writing images"), std::string::npos);
}

}  // namespace
}  // namespace depotwin
