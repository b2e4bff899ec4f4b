// Grid-aligned along-line speed profiles of the bezier planner.
#include <gtest/gtest.h>

#include <random>

#include "planners/motion/bezier/bezier_profile.hpp"

namespace depotwin {
namespace {

struct ProfileCase {
  double distance, v_in, v_out, v_cap, a, period;
};

ProfileCase random_case(std::mt19937_64& rng, bool stop) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ProfileCase c;
  c.v_cap = 1.0 + 40.0 * unit(rng);
  c.a = 20.0 + 5000.0 * unit(rng);
  c.period = unit(rng) < 0.5 ? 0.001 : 0.0005 + 0.002 * unit(rng);
  c.v_in = unit(rng) < 0.3 ? 0.0 : c.v_cap * unit(rng);
  c.v_out = stop ? 0.0 : c.v_cap * (0.05 + 0.95 * unit(rng));
  // long enough for the ramps by reachable_speed, plus a random extra (sometimes none)
  const double need = std::max(c.v_in, c.v_out);
  double length = 0.0;
  while (reachable_speed(std::min(c.v_in, c.v_out), length, c.a, c.period) < need)
    length = 1.1 * length + 1e-3;
  c.distance =
      length * (1.0 + (unit(rng) < 0.3 ? 0.0 : 5.0 * unit(rng))) - c.v_in * c.period * unit(rng);
  return c;
}

// every phase within a_max, every speed within [0, v_cap] (v_in may be above the cap only
// if given so)
void expect_within_limits(const GridProfile& profile, const ProfileCase& c) {
  double v = profile.v_start_mm_s;
  for (const GridPhase& phase : profile.phases) {
    EXPECT_GE(phase.steps, 0);
    EXPECT_LE(std::abs(phase.accel_mm_s2), c.a * (1 + 1e-9));
    v += phase.accel_mm_s2 * phase.steps * c.period;
    EXPECT_GE(v, -1e-9);
    EXPECT_LE(v, std::max(c.v_cap, c.v_in) * (1 + 1e-9));
  }
}

TEST(BezierProfile, ExactEndLandsOnTheLineEndAtRest) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 400; ++i) {
    const ProfileCase c = random_case(rng, true);
    const auto profile = plan_grid_profile(c.distance, c.v_in, 0.0, c.v_cap, c.a, c.period, true);
    ASSERT_TRUE(profile) << i;
    EXPECT_NEAR(profile->distance_mm(c.period), c.distance, 1e-9 * (1 + c.distance)) << i;
    double v = 0, a = 0;
    profile->at_step(profile->total_steps(), c.period, v, a);
    EXPECT_EQ(v, 0.0);
    expect_within_limits(*profile, c);
  }
}

// a line shorter than one period at a 256th of the cap, from rest to rest: 1e-5 mm at a 3 mm/s
// cap (one step at 3/256 mm/s is 1.2e-5 mm) had no profile, and the planner an internal error;
// down to 1e-9 mm, and up to the caps of a fast printer
TEST(BezierProfile, ALineShorterThanTheScansLowestPeakStillLandsAtRest) {
  for (const double distance : {1e-5, 1e-7, 1e-9})
    for (const double cap : {3.0, 300.0}) {
      const ProfileCase c{distance, 0.0, 0.0, cap, 30.0, 0.001};
      const auto profile = plan_grid_profile(c.distance, 0.0, 0.0, c.v_cap, c.a, c.period, true);
      ASSERT_TRUE(profile) << distance << " mm at cap " << cap;
      // (the knee's rounding: 1e-12 mm, which the planner's last sample snaps to the line's end)
      EXPECT_NEAR(profile->distance_mm(c.period), distance, 2e-12);
      double v = 0, a = 0;
      profile->at_step(profile->total_steps(), c.period, v, a);
      EXPECT_EQ(v, 0.0);
      expect_within_limits(*profile, c);
    }
}

TEST(BezierProfile, OpenEndStopsLessThanOneCruiseStepBeforeTheJoint) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 400; ++i) {
    const ProfileCase c = random_case(rng, false);
    const auto profile =
        plan_grid_profile(c.distance, c.v_in, c.v_out, c.v_cap, c.a, c.period, false);
    ASSERT_TRUE(profile) << i;
    const double left = c.distance - profile->distance_mm(c.period);
    EXPECT_GE(left, -1e-9) << i;
    EXPECT_LT(left, c.v_cap * c.period * (1 + 1e-9)) << i;
    double v = 0, a = 0;
    profile->at_step(profile->total_steps(), c.period, v, a);
    EXPECT_NEAR(v, c.v_out, 1e-9 * c.v_cap) << i;
    expect_within_limits(*profile, c);
  }
}

TEST(BezierProfile, LongLineCruisesAtFullSpeedAndRampsAtFullAcceleration) {
  // 100 mm from rest to rest at 20 mm/s, 1000 mm/s^2, T = 1 ms: 20 ramp steps at exactly
  // a_max, a cruise at exactly 20 mm/s, and a short knee that takes up the grid rounding
  const auto profile = plan_grid_profile(100.0, 0.0, 0.0, 20.0, 1000.0, 0.001, true);
  ASSERT_TRUE(profile);
  EXPECT_EQ(profile->phases[0].steps, 20);
  EXPECT_DOUBLE_EQ(profile->phases[0].accel_mm_s2, 1000.0);
  double v = 0, a = 0;
  profile->at_step(profile->phases[0].steps + 1, 0.001, v, a);
  EXPECT_DOUBLE_EQ(v, 20.0);
  EXPECT_EQ(a, 0.0);
  // the whole move takes the continuous trapezoid's time (5.02 s) within a few steps
  EXPECT_NEAR(profile->total_steps() * 0.001, 100.0 / 20.0 + 20.0 / 1000.0, 0.004);
}

TEST(BezierProfile, ReachableSpeedIsMonotoneAndAtLeastTheStartSpeed) {
  double previous = 0.0;
  for (double v = 0.0; v < 30.0; v += 0.5) {
    const double reach = reachable_speed(v, 2.0, 500.0, 0.001);
    EXPECT_GE(reach, v);
    EXPECT_GE(reach, previous);
    previous = reach;
  }
  // no length: no change of speed; without the grid margin it is the classic sqrt(2 a L)
  EXPECT_DOUBLE_EQ(reachable_speed(7.0, 0.0, 500.0, 0.001), 7.0);
  EXPECT_NEAR(reachable_speed(0.0, 2.0, 500.0, 1e-9), std::sqrt(2 * 500.0 * 2.0), 1e-4);
}

// ---------------------------------------------------------------------------------------
// jerk-limited grid profiles

struct JerkCase {
  double distance, v_in, v_out, v_cap, a, j, period;
};

JerkCase random_jerk_case(std::mt19937_64& rng, bool stop) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  JerkCase c;
  c.v_cap = 1.0 + 40.0 * unit(rng);
  c.a = 20.0 + 5000.0 * unit(rng);
  c.j = c.a * (2.0 + 200.0 * unit(rng));  // a / j from 5 ms to 0.5 s
  c.period = unit(rng) < 0.5 ? 0.001 : 0.0005 + 0.002 * unit(rng);
  c.v_in = unit(rng) < 0.3 ? 0.0 : c.v_cap * unit(rng);
  c.v_out = stop ? 0.0 : c.v_cap * (0.05 + 0.95 * unit(rng));
  // the room jerk_grid_room asks, less the entry offset (up to one step), plus a random extra
  const double room = jerk_grid_room(c.v_in, c.v_out, c.a, c.j, c.period);
  c.distance =
      room * (1.0 + (unit(rng) < 0.3 ? 0.0 : 5.0 * unit(rng))) - c.v_in * c.period * unit(rng);
  return c;
}

// every phase within a_max and j_max, the acceleration back to 0 at the end, every speed in
// [0, max(v_cap, v_in)]; returns the speed at the end of the phases
double expect_jerk_profile_within_limits(const JerkGridProfile& profile, const JerkCase& c, int i) {
  double v = profile.v_start_mm_s, a = 0.0;
  for (const JerkPhase& phase : profile.phases) {
    EXPECT_GT(phase.steps, 0) << i;
    EXPECT_LE(std::abs(phase.jerk_mm_s3), c.j * (1 + 1e-9)) << i;
    const double t = phase.steps * c.period;
    // the speed's extreme inside a phase is where the acceleration crosses zero
    if (phase.jerk_mm_s3 != 0.0) {
      const double t0 = -a / phase.jerk_mm_s3;
      if (t0 > 0.0 && t0 < t) {
        const double v_turn = v + t0 * (a + 0.5 * phase.jerk_mm_s3 * t0);
        EXPECT_GE(v_turn, -1e-9) << i;
      }
    }
    v += t * (a + 0.5 * phase.jerk_mm_s3 * t);
    a += phase.jerk_mm_s3 * t;
    EXPECT_LE(std::abs(a), c.a * (1 + 1e-9)) << i;
    EXPECT_GE(v, -1e-9) << i;
    EXPECT_LE(v, std::max(c.v_cap, c.v_in) * (1 + 1e-9)) << i;
  }
  EXPECT_NEAR(a, 0.0, 1e-9 * c.a) << i;
  return v;
}

TEST(BezierJerkProfile, GridSCurveIsTheFewestStepsWithinTheLimits) {
  // 20 mm/s at a = 1000, j = 20000, T = 1 ms: a / j = 50 ms > sqrt(dv / j) = 31.6 ms, so the
  // continuous S-curve is triangular, 63.2 ms; on the grid n1 (n1 + n2) >= 1000 steps^2 and
  // n1 + n2 >= 20: 64 steps (32 + 32, or 28 + 8 + 28)
  const GridSCurve triangle = grid_s_curve(20.0, 1000.0, 20000.0, 0.001);
  EXPECT_EQ(triangle.steps(), 64);
  EXPECT_TRUE(triangle.holds(20.0, 1000.0, 20000.0, 0.001));
  // trapezoidal: 100 mm/s at a = 1000, j = 100000: 10 ms of jerk, 90 ms flat (110 steps)
  const GridSCurve trapezoid = grid_s_curve(100.0, 1000.0, 100000.0, 0.001);
  EXPECT_EQ(trapezoid.steps(), 110);
  EXPECT_TRUE(trapezoid.holds(100.0, 1000.0, 100000.0, 0.001));
  EXPECT_FALSE(trapezoid.holds(100.1, 1000.0, 100000.0, 0.001));
  // no step fewer is possible: exhaustive over the splits
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    const double dv = 0.01 + 50 * unit(rng), a = 20 + 3000 * unit(rng),
                 j = a * (2 + 100 * unit(rng));
    const GridSCurve best = grid_s_curve(dv, a, j, 0.001);
    ASSERT_TRUE(best.holds(dv, a, j, 0.001)) << i;
    for (int n1 = 1; 2 * n1 < best.steps(); ++n1)
      for (int n2 = 0; 2 * n1 + n2 < best.steps(); ++n2)
        EXPECT_FALSE((GridSCurve{n1, n2}.holds(dv, a, j, 0.001))) << i;
  }
}

TEST(BezierJerkProfile, ExactEndLandsOnTheLineEndAtRestWithinTheLimits) {
  std::mt19937_64 rng(17);
  for (int i = 0; i < 400; ++i) {
    const JerkCase c = random_jerk_case(rng, true);
    const auto profile =
        plan_jerk_grid_profile(c.distance, c.v_in, 0.0, c.v_cap, c.a, c.j, c.period, true);
    ASSERT_TRUE(profile) << i;
    EXPECT_NEAR(profile->distance_mm(c.period), c.distance, 1e-9 * (1 + c.distance)) << i;
    EXPECT_NEAR(expect_jerk_profile_within_limits(*profile, c, i), 0.0, 1e-9 * c.v_cap) << i;
  }
}

TEST(BezierJerkProfile, OpenEndStopsLessThanOneCruiseStepBeforeTheJoint) {
  std::mt19937_64 rng(19);
  for (int i = 0; i < 400; ++i) {
    const JerkCase c = random_jerk_case(rng, false);
    const auto profile =
        plan_jerk_grid_profile(c.distance, c.v_in, c.v_out, c.v_cap, c.a, c.j, c.period, false);
    ASSERT_TRUE(profile) << i;
    const double left = c.distance - profile->distance_mm(c.period);
    EXPECT_GE(left, -1e-9) << i;
    EXPECT_LT(left, c.v_cap * c.period * (1 + 1e-9)) << i;
    EXPECT_NEAR(expect_jerk_profile_within_limits(*profile, c, i), c.v_out, 1e-9 * c.v_cap) << i;
  }
}

// lines far shorter than the S-curves to the cap / 256 need (1e-4 mm from rest to rest at a
// cap of 40 mm/s): the peak is searched below the scan, the end is exact and within the limits
// (these lines once had no profile: an internal error on a slicer's 0.1 um segment)
TEST(BezierJerkProfile, TinyLineFromRestToRestFindsALowPeak) {
  for (const double distance : {1e-3, 1e-4, 1e-6, 1e-9}) {
    JerkCase c;
    c.v_cap = 40.0;
    c.a = 300.0;
    c.j = 3000.0;
    c.period = 0.001;
    c.distance = distance;
    c.v_in = c.v_out = 0.0;
    const auto profile =
        plan_jerk_grid_profile(c.distance, 0.0, 0.0, c.v_cap, c.a, c.j, c.period, true);
    ASSERT_TRUE(profile) << distance;
    EXPECT_NEAR(profile->distance_mm(c.period), distance, 1e-9 * (1 + distance)) << distance;
    EXPECT_NEAR(expect_jerk_profile_within_limits(*profile, c, 0), 0.0, 1e-9 * c.v_cap);
    // about as fast as the continuous move: rest to rest over d under j alone (four jerk
    // phases) takes (32 d / j)^(1/3); the grid rounds each phase up to whole steps
    EXPECT_LE(profile->total_steps() * c.period, std::cbrt(32.0 * distance / c.j) + 6 * c.period)
        << distance;
  }
}

// a long line from rest to rest cruises at exactly the cap; its time is the continuous
// double-S's (d / v + v / a + a / j) within a few steps
TEST(BezierJerkProfile, LongLineCruisesAtFullSpeed) {
  const auto profile = plan_jerk_grid_profile(100.0, 0.0, 0.0, 20.0, 1000.0, 20000.0, 0.001, true);
  ASSERT_TRUE(profile);
  const GridSCurve up = grid_s_curve(20.0, 1000.0, 20000.0, 0.001);
  double v = 0, a = 0, j = 0;
  profile->at_step(up.steps() + 1, 0.001, v, a, j);
  EXPECT_DOUBLE_EQ(v, 20.0);
  EXPECT_NEAR(a, 0.0, 1e-12);
  const double continuous = 100.0 / 20.0 + 2.0 * std::sqrt(20.0 / 20000.0);
  EXPECT_NEAR(profile->total_steps() * 0.001, continuous, 0.01);
  EXPECT_GE(profile->total_steps() * 0.001, continuous - 1e-9);
}

}  // namespace
}  // namespace depotwin
