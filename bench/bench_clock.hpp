// Clocks shared by the benchmark programs: this thread's CPU time and wall time since a start.
#pragma once

#include <time.h>

#include <chrono>

namespace depotwin::bench {

using Clock = std::chrono::steady_clock;

// CPU seconds used by the calling thread so far
inline double thread_cpu_s() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// wall seconds since `start`
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace depotwin::bench
