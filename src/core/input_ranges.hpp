// The bounds of the numbers a user gives that more than one module enforces: the scenario
// schema (scenario/schema.cpp: what a file may say, printed by `depotwin describe` and
// summarised in SCHEMA.md) takes them from here, and so do the modules that check them again
// downstream (the simulation's settings, the deposition grid), so the three cannot disagree.
// Header only: no module needs to link anything for it.
#pragma once

#include <string_view>

namespace depotwin::input_ranges {

// ---- sim ----
// MuJoCo's physics step: below 10 us a job of minutes is billions of steps; above 10 ms the
// servos' sampled control is too coarse for the machines' dynamics
constexpr double kMinTimestep_s = 1e-5;
constexpr double kMaxTimestep_s = 0.01;
// the servo update period: at least one step, at most 10 ms
constexpr double kMaxControlPeriod_s = 0.01;
// the servo gains' multiplier: below 0.1 the delta's platform sags by millimetres under its
// own weight, above 10 the XY stage's servos overshoot their joint speed limits at a 1 ms step
constexpr double kMinKpScale = 0.1;
constexpr double kMaxKpScale = 10.0;
// an explicit servo loop is stable while kp dt^2 stays small: kp_scale (timestep / 1 ms)^2
// at most the machine's figure below, the largest of them for a machine not named. Measured
// with lspb_mtt on each machine's shipped scenarios (2026-12-04), the simulated acceleration
// against the plan's: xy_stage 1.2x at 25 (30 and above diverge); arm6 as at 1 ms up to 25;
// cartesian 1.05x at 16, 190x at 20.25; linear_delta 1.12x at 10 (kp_scale 10, 1 ms), 117x at
// 12.1 (kp_scale 10, 1.1 ms) and 146x at 20 (kp_scale 5, 2 ms), where 25 had been assumed
constexpr double kReferenceTimestep_s = 1e-3;
constexpr double kMaxServoStiffnessPerStep = 25.0;
inline double max_servo_stiffness_per_step(std::string_view machine) {
  if (machine == "linear_delta") return 10.0;
  if (machine == "cartesian") return 16.0;
  return kMaxServoStiffnessPerStep;
}
// simulated time after the trajectory's end
constexpr double kMaxSettle_s = 3600.0;
// the most physics steps a run may take unless the scenario raises sim.max_steps (at 1 ms:
// 2.8 h of motion; the longest shipped job, shembekar_bonnet, is 0.87 M steps)
constexpr double kDefaultMaxSteps = 1e7;
constexpr double kMaxMaxSteps = 1e12;

// ---- deposition grid ----
// the cell against the footprint's sigma: coarser than sigma aliases the Gaussian, finer than
// sigma / 64 makes a step touch ~400 k cells
constexpr double kMinCellSigmas = 1.0 / 64.0;
constexpr double kMaxCellSigmas = 1.0;

// ---- geometry and motion ----
// every coordinate, offset and length (1 km: far beyond any machine, far below where
// squares of it lose their meaning)
constexpr double kMaxCoordinate_mm = 1e6;
// speed, acceleration and jerk limits and print speeds: above these no machine moves, and
// the planners' closed forms (v^2 / a, ...) stay finite
constexpr double kMaxSpeed_mm_s = 1e6;
// the smallest speed, acceleration and (non-zero) jerk limit: 1 nm/s and its kin; below,
// the planners' durations overflow (a jerk of 1e-300 mm/s^3 gives 1e+300 s phases)
constexpr double kMinLimit = 1e-6;
constexpr double kMaxAcceleration_mm_s2 = 1e9;
constexpr double kMaxJerk_mm_s3 = 1e12;

}  // namespace depotwin::input_ranges
