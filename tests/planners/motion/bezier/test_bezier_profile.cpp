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

}  // namespace
}  // namespace depotwin
