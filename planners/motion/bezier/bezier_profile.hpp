// The speed law of the bezier planner along one straight line, on the sample grid.
// Every change of acceleration falls on a sample instant, so the trapezoidal ramps of
// eq. (5) are followed exactly by the Taylor update (on a line d2p/du2 = 0) and a cubic
// Hermite interpolation of the samples reproduces them without overshoot.
#pragma once

#include <array>
#include <optional>

namespace depotwin {

// `steps` sample periods at constant along-line acceleration
struct GridPhase {
  int steps = 0;
  double accel_mm_s2 = 0.0;
};

struct GridProfile {
  double v_start_mm_s = 0.0;
  std::array<GridPhase, 4> phases{};  // ramp, cruise, knee, ramp (unused ones have 0 steps)
  double v_after_mm_s = 0.0;          // speed once the phases are over (cruise to the line end)

  int total_steps() const;
  // along-line speed and acceleration during step `step` (0 = the step after the entry sample)
  void at_step(int step, double period_s, double& speed_mm_s, double& accel_mm_s2) const;
  // distance covered by the phases
  double distance_mm(double period_s) const;
  // distance covered in the first `steps` steps (phases, then cruise at v_after)
  double distance_after(int steps, double period_s) const;
};

// The fastest grid profile that starts at speed v_in and covers `distance_mm` to reach v_out,
// never faster than v_cap nor accelerating harder than a_max.
// exact_end: the phases end exactly at `distance_mm` with speed v_out (the line end is a
// sample: the path's end, or a stop), absorbing the grid rounding in a short "knee" at the
// start of the last ramp so the cruise stays at full speed. Otherwise the phases end at most
// one cruise step before the line end and the rest is covered at v_out (the next piece runs
// at v_out). nullopt when no such profile exists (the line is too short).
std::optional<GridProfile> plan_grid_profile(double distance_mm, double v_in_mm_s,
                                             double v_out_mm_s, double v_cap_mm_s,
                                             double a_max_mm_s2, double period_s, bool exact_end);

// The highest speed reachable (or from which one can slow down) at the far end of a line of
// length `length_mm` starting at speed v, with the margin the grid profiles above need
// (entry offset, step rounding and knee: 4 periods at the higher speed). Monotone in v,
// so the usual forward/backward passes over a path's corners stay valid.
double reachable_speed(double v_mm_s, double length_mm, double a_max_mm_s2, double period_s);

}  // namespace depotwin
