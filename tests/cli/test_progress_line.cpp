// The progress line of long steps: rewritten in place on a terminal after a second, a plain
// line per period elsewhere, nothing when off; driven by a hand-set clock.
#include "pipeline/progress_line.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace depotwin {
namespace {

// a ProgressLine writing into a memory buffer, its clock set by hand
struct Capture {
  explicit Capture(ProgressLine::Style style, double log_period_s = 5.0)
      : file(::open_memstream(&buffer, &size)),
        line(
            "job/lspb_mtt: simulating", style, file, [this] { return now_s; }, log_period_s) {}
  ~Capture() {
    std::fclose(file);
    std::free(buffer);
  }
  std::string text() {
    std::fflush(file);
    return std::string(buffer, size);
  }
  // the clock reads `t_s` and the step is `fraction` done
  void at(double t_s, double fraction) {
    now_s = t_s;
    line.update(fraction);
  }

  char* buffer = nullptr;
  size_t size = 0;
  double now_s = 100.0;  // any origin: times below are relative to the start
  std::FILE* file;
  ProgressLine line;
};

TEST(ProgressLine, TerminalRewritesOneLineAfterASecond) {
  Capture c(ProgressLine::Style::terminal);
  c.at(100.5, 0.1);  // under a second: nothing yet
  EXPECT_EQ(c.text(), "");
  c.at(101.5, 0.25);
  c.at(102.0, 0.5);
  c.now_s = 103.0;
  c.line.finish();
  EXPECT_EQ(c.text(),
            "\rjob/lspb_mtt: simulating  25 % (1.5 s)"
            "\rjob/lspb_mtt: simulating  50 % (2.0 s)"
            "\rjob/lspb_mtt: simulating done in 3.0 s        \n");
}

// a detail after the time (a sweep's tasks and ETA); a shorter line blanks what a longer one left
TEST(ProgressLine, DetailFollowsTheTimeAndShorterLinesAreBlankedOut) {
  Capture c(ProgressLine::Style::terminal);
  c.now_s = 101.5;
  c.line.update(0.5, "2/4 tasks, ETA 12 s");
  c.now_s = 102.0;
  c.line.update(0.75, "3/4");
  c.now_s = 103.0;
  c.line.finish();
  const std::string first = "\rjob/lspb_mtt: simulating  50 % (1.5 s) 2/4 tasks, ETA 12 s";
  const std::string second = "\rjob/lspb_mtt: simulating  75 % (2.0 s) 3/4";
  const std::string done = "\rjob/lspb_mtt: simulating done in 3.0 s";
  EXPECT_EQ(c.text(), first + second + std::string(first.size() - second.size(), ' ') + done +
                          std::string(first.size() - done.size(), ' ') + "\n");
}

TEST(ProgressLine, LogPrintsAPlainLinePerPeriod) {
  Capture c(ProgressLine::Style::log, 5.0);
  for (int k = 1; k <= 48; ++k) c.at(100.0 + 0.25 * k, k / 48.0);  // every 0.25 s, 12 s
  c.line.finish();
  // lines at 5 s and 10 s (the first update at or after each), then the closing line
  EXPECT_EQ(c.text(),
            "job/lspb_mtt: simulating  42 % (5.0 s)\n"
            "job/lspb_mtt: simulating  83 % (10.0 s)\n"
            "job/lspb_mtt: simulating done in 12.0 s\n");
}

TEST(ProgressLine, ShortLogStepAndOffPrintNothing) {
  Capture short_step(ProgressLine::Style::log, 5.0);
  short_step.at(104.0, 1.0);
  short_step.line.finish();
  EXPECT_EQ(short_step.text(), "");
  Capture off(ProgressLine::Style::off);
  off.at(200.0, 0.5);
  off.line.finish();
  EXPECT_EQ(off.text(), "");
}

// quiet wins whatever stderr is
TEST(ProgressLine, QuietIsOff) {
  EXPECT_EQ(ProgressLine::style_for_stderr(false), ProgressLine::Style::off);
  EXPECT_NE(ProgressLine::style_for_stderr(true), ProgressLine::Style::off);
}

}  // namespace
}  // namespace depotwin
