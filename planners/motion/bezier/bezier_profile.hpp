// The speed law of the bezier planner along one straight line, on the sample grid.
// Every change of acceleration falls on a sample instant, so the trapezoidal ramps of
// eq. (5) are followed exactly by the Taylor update (on a line d2p/du2 = 0) and a cubic
// Hermite interpolation of the samples reproduces them without overshoot.
#pragma once

#include <array>
#include <optional>
#include <vector>

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

// ---------------------------------------------------------------------------------------
// Under a jerk limit: S-curves on the grid. Every change of jerk falls on a sample instant, so
// the motion between two samples is a cubic in time, which the Taylor update follows exactly on
// a line and the cubic Hermite interpolation of the samples reproduces: the acceleration is
// continuous (every S-curve starts and ends at zero acceleration) and within a_max, the jerk
// within j_max, at every instant.

// `steps` sample periods at constant jerk
struct JerkPhase {
  int steps = 0;
  double jerk_mm_s3 = 0.0;
};

// The step counts of an S-curve on the grid: n_jerk periods of rising |acceleration|, n_flat at
// constant acceleration, n_jerk of falling. For a speed change dv its jerk is
// dv / (n_jerk (n_jerk + n_flat) T^2) and its peak acceleration dv / ((n_jerk + n_flat) T); it
// covers (v0 + v1) / 2 times its duration.
struct GridSCurve {
  int n_jerk = 0;
  int n_flat = 0;
  int steps() const { return 2 * n_jerk + n_flat; }
  // within a_max and j_max for a speed change |dv| (rounding allowed)
  bool holds(double dv, double a_max, double j_max, double period_s) const;
};
// the fewest steps that change the speed by |dv| within a_max and j_max (none for dv = 0)
GridSCurve grid_s_curve(double dv, double a_max, double j_max, double period_s);

struct JerkGridProfile {
  double v_start_mm_s = 0.0;  // at zero acceleration
  std::vector<JerkPhase> phases;
  double v_after_mm_s = 0.0;  // speed once the phases are over (cruise to the line end)

  int total_steps() const;
  // along-line speed, acceleration and jerk at the start of step `step` (0 = the entry sample);
  // the jerk holds over the step
  void at_step(int step, double period_s, double& speed_mm_s, double& accel_mm_s2,
               double& jerk_mm_s3) const;
  double distance_mm(double period_s) const;
  // distance covered in the first `steps` steps (phases, then cruise at v_after)
  double distance_after(int steps, double period_s) const;
  // the S-curve `curve` changing the speed by dv (dv = 0: its steps at constant speed)
  void append_s_curve(const GridSCurve& curve, double dv, double period_s);
  void append_cruise(int steps);
};

// The fastest jerk-limited grid profile from v_in to v_out over `distance_mm`: an S-curve to a
// peak <= v_cap, a cruise at the peak, an S-curve to v_out. exact_end: the phases end exactly at
// `distance_mm` with v_out; the cruise keeps whole steps and what is left of a step is taken up
// by the final S-curve's stopping a little above v_out first (an S-curve down to x, then one
// from x to v_out, x solved for the distance), so the cruise stays at the peak. Otherwise the
// phases end at most one cruise step before the line end and the rest is covered at v_out.
// A moving entry (v_in > 0) first holds v_in for kJerkGuardSteps, an open end holds v_out for
// as many before the line's end: a blend's jerk starts inside a sample period at the joint,
// which the cubic interpolation of the samples rounds, and the S-curves' own jerk keeps clear
// of it. nullopt when the line is too short.
std::optional<JerkGridProfile> plan_jerk_grid_profile(double distance_mm, double v_in_mm_s,
                                                      double v_out_mm_s, double v_cap_mm_s,
                                                      double a_max_mm_s2, double j_max_mm_s3,
                                                      double period_s, bool exact_end);

constexpr int kJerkGuardSteps = 4;
// The length a line needs to change its speed between v_a and v_b by a grid S-curve, with the
// margin the profiles above need (entry offset, step rounding, the exact end's final S-curve,
// the guards: kJerkGridMarginSteps periods at the higher speed); 0 when v_a = v_b.
constexpr int kJerkGridMarginSteps = 8 + 2 * kJerkGuardSteps;
double jerk_grid_room(double v_a_mm_s, double v_b_mm_s, double a_max_mm_s2, double j_max_mm_s3,
                      double period_s);

}  // namespace depotwin
