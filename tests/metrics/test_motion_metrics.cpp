// The speed error over the whole printed length and outside the start and end ramps (the
// papers' figure), against closed forms on hand-built trapezoids; the actuators' units.
#include <gtest/gtest.h>

#include <cmath>

#include "core/types.hpp"
#include "metrics/motion_metrics.hpp"
#include "metrics/run_report.hpp"

namespace depotwin {
namespace {

// One printed stretch along x at desired speed v: a ramp up at constant acceleration over
// ramp_s, a cruise at v with, in its middle, a triangular dip to (1 - dip_depth) v over
// 2 dip_half_s (at whose bottom the path index changes: a joint between two connected
// paths), and a ramp down over ramp_s; sampled every period_s, resting (not depositing) for
// rest_s before and after.
struct Trapezoid {
  double v = 3.0, ramp_s = 0.1, cruise_s = 1.0, dip_half_s = 0.05, dip_depth = 0.5;
  double rest_s = 0.2;

  double printing_s() const { return 2 * ramp_s + cruise_s; }
  double speed(double t) const {  // t from the stretch's start
    if (t < ramp_s) return v * t / ramp_s;
    if (t > printing_s() - ramp_s) return v * (printing_s() - t) / ramp_s;
    const double from_middle = std::abs(t - 0.5 * printing_s());
    if (from_middle < dip_half_s) return v * (1.0 - dip_depth * (1.0 - from_middle / dip_half_s));
    return v;
  }
  MotionSamples sample(double period_s) const {
    MotionSamples s;
    const long n = std::lround((printing_s() + 2 * rest_s) / period_s);
    double x = 0.0;
    for (long k = 0; k <= n; ++k) {
      const double t = k * period_s, local = t - rest_s;
      const bool printing = local >= 0.0 && local <= printing_s() + 1e-12;
      const double speed = printing ? this->speed(local) : 0.0;
      x += speed * period_s;
      const int path = !printing ? -1 : local < 0.5 * printing_s() ? 0 : 1;
      s.push_back(t, Vec3(x, 0, 0), Vec3(speed, 0, 0), printing, path, printing ? v : 0.0);
    }
    return s;
  }
};

// the closed forms: over the ramps e = 1 - t / ramp_s, over the dip e falls linearly from
// dip_depth to 0 over dip_half_s on either side; rms is time-weighted
//   whole:  integral e^2 = 2 ramp_s / 3 + 2 dip_depth^2 dip_half_s / 3, over printing_s
//   steady: integral e^2 = 2 dip_depth^2 dip_half_s / 3, over printing_s - 2 ramp_s
TEST(SpeedRamps, SteadyErrorLeavesOutTheRampsOnATrapezoid) {
  const Trapezoid trap;
  const MotionSamples planned = trap.sample(1e-4);
  const std::vector<TimeSpan> ramps = speed_ramps(planned);
  ASSERT_EQ(ramps.size(), 2u);  // the joint at the dip's bottom is not a ramp
  EXPECT_NEAR(ramps[0].begin_s, trap.rest_s, 1e-4);
  // each ramp takes in its first sample at speed (1e-4 s)
  EXPECT_NEAR(ramps[0].end_s, trap.rest_s + trap.ramp_s + 1e-4, 1e-4);
  EXPECT_NEAR(ramps[1].begin_s, trap.rest_s + trap.printing_s() - trap.ramp_s - 1e-4, 1e-4);
  EXPECT_NEAR(total_time_s(ramps), 2 * trap.ramp_s + 2e-4, 3e-4);

  const VelocityErrorStats whole = velocity_error(planned);
  const VelocityErrorStats steady = velocity_error(planned, ramps);
  const double dip_sq = 2.0 * trap.dip_depth * trap.dip_depth * trap.dip_half_s / 3.0;
  EXPECT_NEAR(whole.max_rel, 1.0, 1e-9);
  EXPECT_NEAR(whole.rms_rel, std::sqrt((2.0 * trap.ramp_s / 3.0 + dip_sq) / trap.printing_s()),
              1e-3);
  EXPECT_NEAR(steady.max_rel, trap.dip_depth, 1e-3);
  EXPECT_NEAR(steady.rms_rel, std::sqrt(dip_sq / (trap.printing_s() - 2 * trap.ramp_s)), 1e-3);
  // the steady figures never exceed the whole ones
  EXPECT_LE(steady.max_rel, whole.max_rel);
  EXPECT_LE(steady.rms_rel, whole.rms_rel);
  EXPECT_LE(steady.p95_rel, whole.p95_rel);
}

// The plan's ramps exclude the same stretches of time from samples taken at other times (the
// simulation's): the first ramp's samples drop out, the dip stays.
TEST(SpeedRamps, SpansApplyToSamplesAtOtherTimes) {
  const Trapezoid trap;
  const std::vector<TimeSpan> ramps = speed_ramps(trap.sample(1e-3));
  const MotionSamples finer = trap.sample(2.5e-4);
  const VelocityErrorStats steady = velocity_error(finer, ramps);
  EXPECT_NEAR(steady.max_rel, trap.dip_depth, 1e-3);
  EXPECT_NEAR(velocity_error(finer).max_rel, 1.0, 1e-9);
}

// A stretch held below its desired speed on purpose (a cruise at 3 mm/s against 4 mm/s: the
// limits, or conformal's constant scale-down) has a steady part, the cruise at its own top
// speed, and its steady error is the shortfall 1 - 3/4 throughout, not 0 over no length.
TEST(SpeedRamps, ACruiseBelowTheDesiredSpeedIsSteadyAtItsShortfall) {
  Trapezoid trap;
  trap.dip_depth = 0.0;
  MotionSamples planned = trap.sample(1e-3);
  for (double& v : planned.desired_speed_mm_s) v = v > 0 ? 4.0 : 0.0;
  const std::vector<TimeSpan> ramps = speed_ramps(planned);
  ASSERT_EQ(ramps.size(), 2u);  // the same ramps as against 3 mm/s
  EXPECT_NEAR(ramps[0].end_s, trap.rest_s + trap.ramp_s + 1e-3, 1e-3);
  EXPECT_NEAR(total_time_s(ramps), 2 * trap.ramp_s + 2e-3, 3e-3);
  const VelocityErrorStats steady = velocity_error(planned, ramps);
  EXPECT_NEAR(steady.max_rel, 0.25, 1e-9);
  EXPECT_NEAR(steady.rms_rel, 0.25, 1e-9);
  EXPECT_NEAR(steady.counted_s, trap.cruise_s, 3e-3);
}

// A stretch that only peaks below its desired speed is ramp throughout: nothing steady is
// left, and the steady figures cover no time (n/a, not 0).
TEST(SpeedRamps, AStretchNeverAtSpeedIsAllRamp) {
  Trapezoid trap;
  trap.cruise_s = 0.0;  // a triangle: up to v at one instant only ...
  trap.v = 3.0;
  MotionSamples planned = trap.sample(1e-3);
  for (double& v : planned.desired_speed_mm_s) v = v > 0 ? 4.0 : 0.0;  // ... against 4 mm/s
  const std::vector<TimeSpan> ramps = speed_ramps(planned);
  ASSERT_EQ(ramps.size(), 1u);
  EXPECT_NEAR(total_time_s(ramps), trap.printing_s() + 1e-3, 1e-9);
  const VelocityErrorStats steady = velocity_error(planned, ramps);
  EXPECT_EQ(steady.max_rel, 0.0);
  EXPECT_EQ(steady.rms_rel, 0.0);
  EXPECT_EQ(steady.counted_s, 0.0);
  EXPECT_GT(velocity_error(planned).counted_s, trap.printing_s() - 1e-3);
}

// Connected short moves, each a triangle up to the same 3 mm/s (against 4 mm/s) and down to
// rest at the joint: peaks, not a cruise, however many: ramp throughout (the stops between the
// first and last peak were counted as steady error, 100 %, or not, as the peaks' last digits
// fell)
TEST(SpeedRamps, RepeatedPeaksBelowTheSpeedAreAllRamp) {
  MotionSamples planned;
  const double period_s = 1e-3, ramp_s = 0.1, v = 3.0;
  double x = 0.0;
  for (int k = 0; k <= 600; ++k) {
    const double t = k * period_s, within = std::fmod(t, 2 * ramp_s);
    const double speed = v * (within < ramp_s ? within : 2 * ramp_s - within) / ramp_s;
    x += speed * period_s;
    planned.push_back(t, Vec3(x, 0, 0), Vec3(speed, 0, 0), true, k / 200, 4.0);
  }
  const std::vector<TimeSpan> ramps = speed_ramps(planned);
  ASSERT_EQ(ramps.size(), 1u);
  EXPECT_EQ(velocity_error(planned, ramps).counted_s, 0.0);
}

// A stretch at its desired speed at one sample only (a triangle whose top sample is exactly
// at speed): its start and end ramps share that sample, one span whose time counts it once,
// not more than the stretch lasts (it was two spans, 1 ms over the print time)
TEST(SpeedRamps, AStretchAtSpeedAtOneSampleIsOneRamp) {
  Trapezoid trap;
  trap.cruise_s = 0.0;
  const MotionSamples planned = trap.sample(1e-3);
  const std::vector<TimeSpan> ramps = speed_ramps(planned);
  ASSERT_EQ(ramps.size(), 1u);
  EXPECT_NEAR(total_time_s(ramps), trap.printing_s() + 1e-3, 1e-9);
  EXPECT_EQ(velocity_error(planned, ramps).counted_s, 0.0);
}

// A cruise exactly at speed from the first sample (LSPB entering at print speed): no ramp.
TEST(SpeedRamps, AStretchStartingAtSpeedHasNoStartRamp) {
  MotionSamples s;
  for (int k = 0; k <= 100; ++k)
    s.push_back(1e-3 * k, Vec3(3e-3 * k, 0, 0), Vec3(3, 0, 0), k > 0 && k < 100, 0, 3.0);
  EXPECT_TRUE(speed_ramps(s).empty());
}

// Revolute joints are reported in degrees, prismatic ones in mm; the ratio is unitless.
TEST(ActuatorStats, HingesInDegreesSlidesInMillimetres) {
  RecordedRun run;
  run.joint_count = 2;
  run.joint_names = {"slide", "hinge"};
  run.t_s = {0.0, 0.001};
  run.joint_velocity = {1.0, 0.5, -2.0, -1.0};
  run.joint_acceleration = {10.0, 4.0, 0.0, 0.0};
  run.actuator_force = {3.0, 0.2, 0.0, 0.0};
  run.reference_peak_acceleration = {5.0, 2.0};
  JointLimit slide, hinge;
  slide.v_max = 4.0, slide.a_max = 30.0;
  hinge.v_max = 0.9, hinge.a_max = 8.0, hinge.revolute = true;
  const ActuatorStats a = actuator_stats(run, {slide, hinge}, {0.0, 0.0});
  const double deg = 180.0 / kPi;
  EXPECT_EQ(a.revolute, (std::vector<bool>{false, true}));
  EXPECT_DOUBLE_EQ(a.peak_vel[0], 2.0);
  EXPECT_DOUBLE_EQ(a.peak_vel[1], 1.0 * deg);
  EXPECT_DOUBLE_EQ(a.limit_vel[1], 0.9 * deg);
  EXPECT_DOUBLE_EQ(a.peak_acc[1], 4.0 * deg);
  EXPECT_DOUBLE_EQ(a.plan_peak_acc[1], 2.0 * deg);
  EXPECT_DOUBLE_EQ(a.peak_acc_over_plan[1], 2.0);
  EXPECT_EQ(a.limit_violations, 1);  // the hinge's 1 rad/s against 0.9
}

}  // namespace
}  // namespace depotwin
