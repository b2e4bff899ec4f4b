// The conformal planner under a jerk limit: curvature-continuous zone blends and the
// jerk-limited law over the TOPP-RA profile (jerk_time_law.hpp). Every 1 ms sample within the
// TCP's v_max, a_max and j_max by finite differences, the joints within their limits, the
// contract kept; without j_max nothing changes (test_conformal.cpp).
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "contract/planner_checks.hpp"
#include "core/error.hpp"
#include "planners/motion/conformal.hpp"
#include "planners/motion/jerk_time_law.hpp"

namespace depotwin {
namespace {

ConformalPlanner planner_with(ConformalControl control, double zone_mm = 0.25) {
  ConformalSettings settings;
  settings.control = control;
  settings.zone_mm = zone_mm;
  return ConformalPlanner(settings);
}

Toolpath one_path(const PrintPath& path) {
  Toolpath toolpath;
  toolpath.start_mm = path.front() + Vec3(0, 0, 5);
  toolpath.end_mm = path.back() + Vec3(0, 0, 5);
  toolpath.paths = {path};
  return toolpath;
}

// a straight line at 10 mm/s, a_max 200, j_max 4000: the double-S of the jerk-limited move
// (d / v + v / a + a / j) within the sampling's rounding, the print speed held between ramps
TEST(ConformalJerk, StraightLineIsTheDoubleSMove) {
  PrintPath path;
  path.speed_mm_s = 10.0;
  for (int i = 0; i <= 40; ++i) path.points.emplace_back(0.5 * i, 3.0, 1.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 200.0, 4000.0);
  const Toolpath toolpath = one_path(path);
  const Trajectory plan = planner_with(ConformalControl::none).plan(toolpath, limits);
  const TrajectoryPiece* line = nullptr;
  for (const TrajectoryPiece& piece : plan.pieces())
    if (piece.depositing) line = &piece;
  ASSERT_NE(line, nullptr);
  // the ramps keep kJerkAccelShare of a_max (and TOPP-RA's own margin) and kJerkShare of j_max
  const double a = kJerkAccelShare * kSampledAccelMargin * 200.0, j = kJerkShare * 4000.0;
  const double expected = 20.0 / 10.0 + 10.0 / a + a / j;
  EXPECT_NEAR(line->t_end_s - line->t_begin_s, expected, 0.002);
  const SampledMotion& motion = std::get<SampledMotion>(line->motion);
  int cruising = 0;
  for (const Vec3& v : motion.velocity_mm_s)
    if (std::abs(v.norm() - 10.0) < 1e-9) ++cruising;
  EXPECT_GT(cruising, 1800);
  testing_support::expect_contract(plan, toolpath, limits);
  testing_support::expect_finite_difference_limits(plan, limits, 0.01);
}

// the contract's random planar and 3-D toolpaths (tool axes turning) under a jerk limit
TEST(ConformalJerk, RandomToolpathsStayWithinTheJerkLimit) {
  const auto planner = make_planner({"conformal", {}, 0});
  double worst = 0.0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath planar = testing_support::random_toolpath(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, 200.0);
    const Trajectory plan = planner->plan(planar, limits);
    testing_support::expect_contract(plan, planar, limits);
    testing_support::expect_finite_difference_limits(plan, limits, 0.01);
    worst =
        std::max(worst, testing_support::finite_difference_peaks(plan, limits).max_jerk_ratio());
    const Toolpath spatial = testing_support::random_toolpath_3d(seed, 3.0);
    const MachineLimits limits_3d = MachineLimits::uniform(5.0, 40.0, 600.0);
    const Trajectory plan_3d = planner->plan(spatial, limits_3d);
    testing_support::expect_contract(plan_3d, spatial, limits_3d);
    testing_support::expect_tool_axis_contract(plan_3d, spatial);
    testing_support::expect_finite_difference_limits(plan_3d, limits_3d, 0.01);
    worst = std::max(worst,
                     testing_support::finite_difference_peaks(plan_3d, limits_3d).max_jerk_ratio());
    // never faster than without the jerk limit
    const Trajectory free = planner->plan(planar, MachineLimits::uniform(4.0, 30.0));
    EXPECT_GE(plan.duration_s(), free.duration_s() - 1e-9);
    if (HasFatalFailure()) return;
  }
  std::printf("conformal: largest finite-difference jerk / j_max on random toolpaths: %.4f\n",
              worst);
}

}  // namespace
}  // namespace depotwin
