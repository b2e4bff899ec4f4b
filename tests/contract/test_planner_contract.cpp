// One contract test over every registered planner (OMPL's PlannerTest, toppra's typed
// suites): planar paths and 3-D paths whose tool axes vary; with a jerk limit, every planner
// that honours it stays jerk-limited and the others refuse it.
#include <gtest/gtest.h>

#include "contract/planner_checks.hpp"
#include "core/error.hpp"
#include "planners/planner.hpp"

namespace depotwin {
namespace {

class PlannerContract : public ::testing::TestWithParam<std::string> {};

TEST_P(PlannerContract, SeededRandomToolpaths) {
  const PlannerSpec spec{GetParam(), {}, 0};
  const auto planner = make_planner(spec);
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
    testing_support::expect_contract(planner->plan(toolpath, limits), toolpath, limits);
    if (HasFatalFailure()) return;
  }
}

TEST_P(PlannerContract, PlanarPathsKeepTheNozzleVertical) {
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const Trajectory plan = planner->plan(toolpath, MachineLimits::uniform(4.0, 30.0));
    for (double t = 0.0; t <= plan.duration_s(); t += 0.01) {
      const TrajectorySample s = plan.at(t);
      ASSERT_EQ(s.tool_axis, vertical_tool_axis()) << "t " << t;
      ASSERT_EQ(s.angular_velocity_rad_s, Vec3::Zero()) << "t " << t;
    }
  }
}

TEST_P(PlannerContract, ThreeDimensionalPathsWithVaryingToolAxes) {
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  for (std::uint64_t seed = 1; seed <= 15; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath_3d(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(5.0, 40.0);
    const Trajectory plan = planner->plan(toolpath, limits);
    testing_support::expect_contract(plan, toolpath, limits);
    testing_support::expect_tool_axis_contract(plan, toolpath);
    if (HasFatalFailure()) return;
  }
}

TEST_P(PlannerContract, JerkLimitIsHonouredOrRefused) {
  const PlannerSpec spec{GetParam(), {}, 0};
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, 200.0);
  if (!find_planner(spec.name)->honours_jerk_limit) {
    EXPECT_NE(check_planner_limits(spec, limits).find("does not honour j_max"), std::string::npos);
    EXPECT_EQ(check_planner_limits(spec, MachineLimits::uniform(4.0, 30.0)), "");
    return;
  }
  EXPECT_EQ(check_planner_limits(spec, limits), "");
  const auto planner = make_planner(spec);
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const Trajectory jerk_limited = planner->plan(toolpath, limits);
    testing_support::expect_contract(jerk_limited, toolpath, limits);
    testing_support::expect_jerk_limited(jerk_limited, limits);
    // the jerk limit costs time: never faster than without it
    const Trajectory free = planner->plan(toolpath, MachineLimits::uniform(4.0, 30.0));
    EXPECT_GE(jerk_limited.duration_s(), free.duration_s() - 1e-9);
    if (HasFatalFailure()) return;
  }
}

TEST_P(PlannerContract, DeterministicPlans) {
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  const Toolpath toolpath = testing_support::random_toolpath(99, 2.0);
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  const Trajectory a = planner->plan(toolpath, limits), b = planner->plan(toolpath, limits);
  ASSERT_EQ(a.duration_s(), b.duration_s());
  for (double t = 0; t < a.duration_s(); t += 0.01)
    ASSERT_EQ(a.at(t).position_mm, b.at(t).position_mm);
}

// Limits that depend on where the move is (a machine's TcpLimits): each segment gets those
// over its own box, so a slow region slows only the moves that pass through it.
TEST_P(PlannerContract, PerMoveLimitsFollowTheTool) {
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  const MachineLimits fast = MachineLimits::uniform(10.0, 100.0);
  // half as fast and a quarter of the acceleration wherever a box reaches x > 15 mm
  const TcpLimits position_dependent(fast, [fast](const Vec3& /*lo*/, const Vec3& hi) {
    MachineLimits limits = fast;
    if (hi.x() > 15.0)
      for (AxisLimits& axis : limits.axes) axis = AxisLimits{5.0, 25.0, 0.0};
    return limits;
  });
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const Trajectory plan = planner->plan(toolpath, position_dependent);
    // where the tool is beyond x = 15 mm, the slow limits hold
    for (double t = 0.0; t <= plan.duration_s(); t += 0.001) {
      const TrajectorySample s = plan.at(t);
      if (s.position_mm.x() <= 15.0) continue;
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_LE(std::abs(s.velocity_mm_s[axis]), 5.0 * (1 + 1e-9)) << "t " << t;
        ASSERT_LE(std::abs(s.acceleration_mm_s2[axis]), 25.0 * (1 + 1e-6)) << "t " << t;
      }
    }
  }
}

std::vector<std::string> registered_names() {
  std::vector<std::string> names;
  for (const PlannerInfo& info : planner_registry()) names.push_back(info.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(EveryPlanner, PlannerContract, ::testing::ValuesIn(registered_names()),
                         [](const auto& info) { return info.param; });

TEST(PlannerRegistry, UnknownNamesAndParametersAreRejected) {
  EXPECT_NE(check_planner_spec({"warp_drive", {}, 0}).find("unknown planner"), std::string::npos);
  EXPECT_NE(check_planner_spec({"lspb_mtt", {{"delta", {0.3}}}, 0}).find("no parameter 'delta'"),
            std::string::npos);
  EXPECT_EQ(check_planner_spec({"lspb_mtt", {}, 0}), "");
  EXPECT_THROW(make_planner({"warp_drive", {}, 0}), InputError);
}

}  // namespace
}  // namespace depotwin
