// The bezier planner under a jerk limit: S-curves on the sample grid along the lines, the
// curvature-continuous quartic blends at the corners, arcs as chords. Every 1 ms sample within
// v_max, a_max and j_max by finite differences; the contract kept; without j_max nothing changes
// (the other bezier tests).
#include <gtest/gtest.h>

#include <cstdio>

#include <Eigen/Geometry>  // cross products

#include "bezier_checks.hpp"
#include "contract/planner_checks.hpp"
#include "planners/motion/bezier/bezier.hpp"
#include "planners/motion/bezier/bezier_curve.hpp"

namespace depotwin {
namespace {
using namespace bezier_test;

BezierPlanner planner_with(double delta_mm, bool lead_in = false, double period_s = 0.001) {
  BezierSettings settings;
  settings.delta_mm = delta_mm;
  settings.lead_in = lead_in;
  settings.period_s = period_s;
  return BezierPlanner(settings);
}

// the quartic's curvature is 0 at both ends (its first and last three control points are
// collinear), it leaves the corner by 3/8 delta sin(theta / 2) at w = 1, and its derivatives
// match finite differences
TEST(BezierJerk, QuarticBlendIsCurvatureContinuousWithItsLines) {
  const Vec3 corner(10, 0, 0), in(1, 0, 0), out = Vec3(-1, 1, 0).normalized();
  const double delta = 0.8;
  const BezierBlend blend =
      BezierBlend::curvature_continuous_at_corner(corner, in, out, delta, 1.0);
  Vec3 p, d1, d2, d3;
  for (const double u : {0.0, 1.0}) {
    blend.derivatives(u, p, d1, d2, d3);
    EXPECT_LT(d1.cross(d2).norm() / std::pow(d1.norm(), 3), 1e-12) << u;
  }
  EXPECT_LT((blend.point(0.0) - (corner - delta * in)).norm(), 1e-12);
  EXPECT_LT((blend.point(1.0) - (corner + delta * out)).norm(), 1e-12);
  const double theta = std::acos(-in.dot(out));  // the interior angle, 45 deg
  EXPECT_NEAR((blend.point(0.5) - corner).norm(), 3.0 / 8.0 * delta * std::cos(theta / 2), 1e-12);
  // derivatives against central differences, also with a weight
  const BezierBlend weighted =
      BezierBlend::curvature_continuous_at_corner(corner, in, out, delta, 2.5);
  const double du = 1e-4;
  for (const double u : {0.1, 0.37, 0.5, 0.8}) {
    Vec3 pm, d1m, d2m, pp, d1p, d2p;
    weighted.derivatives(u, p, d1, d2, d3);
    weighted.derivatives(u - du, pm, d1m, d2m);
    weighted.derivatives(u + du, pp, d1p, d2p);
    EXPECT_LT((d1 - (pp - pm) / (2 * du)).norm(), 1e-6 * d1.norm()) << u;
    EXPECT_LT((d2 - (d1p - d1m) / (2 * du)).norm(), 1e-5 * (1 + d2.norm())) << u;
    EXPECT_LT((d3 - (d2p - d2m) / (2 * du)).norm(), 1e-4 * (1 + d3.norm())) << u;
  }
}

// A gentle path (corners turning 30 deg) under j_max: the quartic blends keep the print speed,
// the central part runs at it (the paper's measure, Sec. 4.1), every 1 ms sample within every
// limit by finite differences, and the plan takes longer than without the jerk limit
TEST(BezierJerk, GentleCornersKeepThePrintSpeed) {
  const std::vector<Vec3> points{Vec3(0, 0, 0), Vec3(30, 0, 0),
                                 Vec3(30 + 30 * std::cos(kPi / 6), 30 * std::sin(kPi / 6), 0),
                                 Vec3(60, 30, 0)};
  const Toolpath toolpath = single_path(points, 10.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 500.0, 20000.0);
  const Trajectory plan = planner_with(1.0).plan(toolpath, limits);
  EXPECT_TRUE(plan.warnings().empty());
  testing_support::expect_contract(plan, toolpath, limits, 1.0);
  testing_support::expect_finite_difference_limits(plan, limits, 0.01);
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (!piece.depositing) continue;
    const SpeedVariation variation = speed_variation(sampled(piece), 10.0);
    EXPECT_GT(variation.central_samples, 7000u);
    EXPECT_LT(variation.max_rel, 1e-4);
  }
  const Trajectory free = planner_with(1.0).plan(toolpath, MachineLimits::uniform(50.0, 500.0));
  EXPECT_GT(plan.duration_s(), free.duration_s());
}

// The paper's four-point path (135 deg and 90 deg turns) at 10 mm/s under j_max = 5000: a
// 0.5 mm quartic turning 135 deg would need about 2.3 mm/s to keep its jerk, so both corners
// stop instead (named in the warnings, the jerk limit the reason), within every limit
TEST(BezierJerk, SharpCornersStopWhenTheirBlendsWouldBeSlower) {
  const Toolpath toolpath = single_path(four_point_path(), 10.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 500.0, 5000.0);
  const Trajectory plan = planner_with(0.5).plan(toolpath, limits);
  ASSERT_EQ(plan.warnings().size(), 2u);
  for (const std::string& warning : plan.warnings()) {
    EXPECT_NE(warning.find("j_max"), std::string::npos) << warning;
    EXPECT_NE(warning.find("stopping at the corner is faster"), std::string::npos) << warning;
  }
  testing_support::expect_contract(plan, toolpath, limits, 0.5);
  testing_support::expect_finite_difference_limits(plan, limits, 0.01);
}

// Random 3-D polylines (sharp turns, reversals, short edges) with and without lead-in, and the
// contract's random toolpaths: within every limit by finite differences
TEST(BezierJerk, RandomToolpathsStayWithinTheJerkLimit) {
  double worst = 0.0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = random_polylines(seed, 4);
    for (const MachineLimits& limits :
         {MachineLimits::uniform(25.0, 300.0, 3000.0), MachineLimits::uniform(60.0, 3000.0, 1e5)}) {
      const Trajectory plan = planner_with(0.5, seed % 2 == 0).plan(toolpath, limits);
      expect_contract(plan, toolpath, limits, 0.5);
      testing_support::expect_finite_difference_limits(plan, limits, 0.01);
      worst =
          std::max(worst, testing_support::finite_difference_peaks(plan, limits).max_jerk_ratio());
    }
    const Toolpath planar = testing_support::random_toolpath(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, 200.0);
    const Trajectory plan = planner_with(0.5).plan(planar, limits);
    testing_support::expect_contract(plan, planar, limits);
    testing_support::expect_finite_difference_limits(plan, limits, 0.01);
    worst =
        std::max(worst, testing_support::finite_difference_peaks(plan, limits).max_jerk_ratio());
    if (HasFatalFailure()) return;
  }
  std::printf("bezier: largest finite-difference jerk / j_max on random toolpaths: %.4f\n", worst);
}

// A very slow machine (acceleration and jerk limits far below any real one) plans too: the
// planner's own check of its samples once read rounding as a limit exceeded (at a_max 0.1
// mm/s^2 the 9e-12 mm that puts a line's last sample exactly on its end, at 0.01 every ramp; at
// j_max 0.01 and 1e-4 mm/s^3 the S-curves) and stopped with an internal error. Within the
// limits, up to what 1e-11 mm of position rounding per 1 ms sample reads as by finite
// differences (6e-5 mm/s^2, 0.08 mm/s^3: nothing on a real machine, but many times such a
// j_max). Thompson & Yoon's Fig. 7 connected segments.
// the length travelled with material on, sampled every 1 ms
double printed_length(const Trajectory& plan) {
  double length = 0.0;
  TrajectorySample before = plan.at(0.0);
  for (double t = 0.001; t <= plan.duration_s(); t += 0.001) {
    const TrajectorySample after = plan.at(t);
    if (before.depositing && after.depositing)
      length += (after.position_mm - before.position_mm).norm();
    before = after;
  }
  return length;
}

TEST(BezierJerk, VerySlowMachinesPlanWithinTheirLimits) {
  const Toolpath toolpath =
      single_path({Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(8, 6, 0), Vec3(2, 4, 0)}, 3.0);
  constexpr double kRoundingMm = 1e-11, h = 0.001;
  for (const MachineLimits& limits :
       {MachineLimits::uniform(4.0, 0.1), MachineLimits::uniform(4.0, 0.01),
        MachineLimits::uniform(4.0, 30.0, 1e-2), MachineLimits::uniform(4.0, 30.0, 1e-4),
        MachineLimits::uniform(4.0, 0.01, 1e-3)}) {
    const double a_max = limits.axes[0].a_max_mm_s2, j_max = limits.axes[0].j_max_mm_s3;
    SCOPED_TRACE(testing::Message() << "a_max " << a_max << ", j_max " << j_max);
    Trajectory plan("bezier", {});
    ASSERT_NO_THROW(plan = planner_with(0.5).plan(toolpath, limits));
    // at rest at both ends, the whole path printed
    const TrajectorySample first = plan.at(0.0), last = plan.at(plan.duration_s());
    EXPECT_LT((first.position_mm - toolpath.start_mm).norm(), 1e-9);
    EXPECT_LT((last.position_mm - toolpath.end_mm).norm(), 1e-9);
    EXPECT_LT(first.velocity_mm_s.norm() + last.velocity_mm_s.norm(), 1e-9);
    EXPECT_NEAR(printed_length(plan), toolpath.paths[0].length_mm(), 0.5);
    const auto peaks = testing_support::finite_difference_peaks(plan, limits, h);
    EXPECT_LE(peaks.max_speed_ratio(), 1 + 1e-6);
    EXPECT_LE(peaks.max_accel_ratio() * a_max, a_max * (1 + 1e-6) + 6.0 * kRoundingMm / (h * h));
    if (j_max > 0.0) {
      EXPECT_LE(peaks.max_jerk_ratio() * j_max, j_max * 1.01 + 8.0 * kRoundingMm / (h * h * h));
    }
  }
}

}  // namespace
}  // namespace depotwin
