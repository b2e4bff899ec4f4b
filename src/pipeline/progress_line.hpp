// The progress of a long step on stderr. On a terminal: one line rewritten in place
// ("\r<label>  42 % (3.1 s)") once the step has taken a second. Elsewhere (a log file, a
// pipe, CI): a plain line every few seconds, so logs show the run is alive without \r
// clutter. Either way a closing "<label> done in 12.3 s" line once anything was shown.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <utility>

#include <unistd.h>

namespace depotwin {

class ProgressLine {
 public:
  enum class Style { off, terminal, log };
  using Clock = std::function<double()>;  // seconds since any fixed origin

  // a terminal line starts after this long
  static constexpr double kTerminalDelay_s = 1.0;
  // a log line every this often (DEPOTWIN_PROGRESS_PERIOD_S overrides it; 0: every update)
  static constexpr double kLogPeriod_s = 5.0;

  // terminal when stderr is one, log otherwise; off when not wanted (--quiet)
  static Style style_for_stderr(bool wanted) {
    if (!wanted) return Style::off;
    return ::isatty(STDERR_FILENO) ? Style::terminal : Style::log;
  }
  // the log period: the environment's DEPOTWIN_PROGRESS_PERIOD_S when it is a number >= 0
  static double log_period_s() {
    const char* text = std::getenv("DEPOTWIN_PROGRESS_PERIOD_S");
    if (text == nullptr || *text == '\0') return kLogPeriod_s;
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    return *end == '\0' && value >= 0.0 ? value : kLogPeriod_s;
  }
  static double steady_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }

  ProgressLine(std::string label, Style style, std::FILE* out = stderr,
               Clock clock = &ProgressLine::steady_seconds, double log_period = log_period_s())
      : label_(std::move(label)),
        style_(style),
        out_(out),
        clock_(std::move(clock)),
        log_period_s_(log_period),
        start_s_(clock_()) {}
  // a line left open (an exception, an interrupt) ends here, so what follows starts afresh
  ~ProgressLine() {
    if (shown_ && style_ == Style::terminal) {
      std::fputc('\n', out_);
      std::fflush(out_);
    }
  }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // the step is `fraction` (0..1) done; `detail` follows the time (e.g. "12/27 tasks, ETA 5 s")
  void update(double fraction, const std::string& detail = "") {
    if (style_ == Style::off) return;
    const double elapsed = clock_() - start_s_;
    const std::string tail = detail.empty() ? "" : " " + detail;
    if (style_ == Style::terminal) {
      if (elapsed < kTerminalDelay_s) return;
      // spaces over what a longer line before left
      const int length = std::fprintf(out_, "\r%s %3.0f %% (%.1f s)%s", label_.c_str(),
                                      100.0 * fraction, elapsed, tail.c_str());
      if (length < last_length_) std::fprintf(out_, "%*s", last_length_ - length, "");
      last_length_ = std::max(length, last_length_);  // what the terminal line now shows
    } else {
      // the first line after one period, then one per period
      if (elapsed < last_log_s_ + log_period_s_) return;
      last_log_s_ = elapsed;
      std::fprintf(out_, "%s %3.0f %% (%.1f s)%s\n", label_.c_str(), 100.0 * fraction, elapsed,
                   tail.c_str());
    }
    std::fflush(out_);
    shown_ = true;
  }

  // the step is over: close the line (only when one was shown)
  void finish() {
    if (!shown_) return;
    const double elapsed = clock_() - start_s_;
    if (style_ == Style::terminal) {
      // spaces over the rest of the last line
      const int length = std::fprintf(out_, "\r%s done in %.1f s", label_.c_str(), elapsed);
      std::fprintf(out_, "%*s\n", std::max(8, last_length_ - length), "");
    } else {
      std::fprintf(out_, "%s done in %.1f s\n", label_.c_str(), elapsed);
    }
    std::fflush(out_);
    shown_ = false;
  }

 private:
  std::string label_;
  Style style_;
  std::FILE* out_;
  Clock clock_;
  double log_period_s_;
  double start_s_;
  double last_log_s_ = 0.0;  // elapsed time of the last log line (0: none yet)
  int last_length_ = 0;      // characters of the last terminal line
  bool shown_ = false;
};

}  // namespace depotwin
