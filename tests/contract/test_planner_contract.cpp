// One contract test over every registered planner (OMPL's PlannerTest, toppra's typed
// suites): planar paths and 3-D paths whose tool axes vary; with a jerk limit, every planner
// honours it (finite-difference jerk on its 1 ms samples).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <variant>

#include "contract/planner_checks.hpp"
#include "core/error.hpp"
#include "kinematics/arm6.hpp"
#include "planners/planner.hpp"
#include "posture/arm_posture.hpp"

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

// On the 6-DOF arm: 3-D paths with tilted tool axes, their rolls chosen by the arm's posture, the
// arm's own TCP limits (with its joint map). Every planner keeps the contract, brings the roll
// to each path point it reaches and turns it continuously, and the arm follows without a jump
// (inverse_near along the plan every 1 ms); a planner that plans on the joint map (conformal)
// keeps every joint within its speed limit.
TEST_P(PlannerContract, ArmPathsWithRolls) {
  const Arm6 arm;
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  const MachineLimits requested = MachineLimits::uniform(30.0, 300.0);
  const TcpLimits limits = arm.tcp_limits(requested);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    Toolpath toolpath = testing_support::random_toolpath_3d(seed, 10.0);
    toolpath.start_mm = toolpath.end_mm = Vec3(0, 0, 30);
    const ArmPosture posture =
        choose_arm_posture(arm, nullptr, toolpath, {}, [](size_t path, size_t point) {
          return "path " + std::to_string(path) + ", point " + std::to_string(point);
        });
    Arm6 configured;
    configured.set_branch(posture.branch);
    const TcpLimits configured_limits = configured.tcp_limits(requested);
    const Toolpath& rolled = posture.toolpath;
    const Trajectory plan = planner->plan(rolled, configured_limits);
    testing_support::expect_contract(plan, rolled, requested);
    testing_support::expect_tool_axis_contract(plan, rolled);
    if (HasFatalFailure()) return;
    // the roll: each path's own where a print piece starts or ends on a path point, and turning
    // continuously everywhere
    for (const TrajectoryPiece& piece : plan.pieces()) {
      if (!piece.depositing) continue;
      const PrintPath& path = rolled.paths[piece.path_index];
      const TrajectorySample s = plan.at(piece.t_begin_s);
      for (size_t i = 0; i < path.points.size(); ++i) {
        if ((path.points[i] - s.position_mm).norm() < 1e-9) {
          EXPECT_NEAR(s.roll_rad, path.roll(i), 1e-6) << "path " << piece.path_index;
        }
      }
    }
    // the arm follows: no joint jumps between 1 ms samples, within speed on the joint map
    JointVector q, previous;
    const bool joint_limited = GetParam() == "conformal";
    const std::vector<JointLimit>& joint_limits = configured.joint_limits();
    for (double t = 0.0; t <= plan.duration_s(); t += 0.001) {
      const TrajectorySample s = plan.at(t);
      const bool solved = previous.empty() ? configured.inverse(s.pose(), q)
                                           : configured.inverse_near(s.pose(), previous, q);
      ASSERT_TRUE(solved) << "t " << t;
      if (!previous.empty()) {
        for (size_t j = 0; j < q.size(); ++j) {
          // a jump is a change of solution (a wrist flip turns a joint by about pi), not fast
          // motion: near the wrist's singularity a TCP-limited plan (the papers' planners) may
          // turn a wrist joint at tens of rad/s (README, Known gaps), 0.07 rad in 1 ms measured
          ASSERT_LT(std::abs(q[j] - previous[j]), 0.2) << "joint " << j << " jumps at t " << t;
          if (joint_limited) {
            ASSERT_LE(std::abs(q[j] - previous[j]) / 0.001, joint_limits[j].v_max * 1.01)
                << "joint " << j << " t " << t;
          }
        }
      }
      previous = q;
    }
  }
}

// Every planner honours j_max (the registry says so, and a j_max in force is no error): on
// random planar toolpaths its plan keeps the contract, and sampled every 1 ms its per-axis
// jerk by finite differences (finite_difference_peaks) stays within j_max + 1 %: the stencils
// average the true jerk, so the 1 % covers only the sampled plans' cubic interpolation between
// their 1 ms samples. A plan of constant-jerk phases is also checked exactly, phase by phase.
TEST_P(PlannerContract, JerkLimitIsHonoured) {
  const PlannerSpec spec{GetParam(), {}, 0};
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, 200.0);
  ASSERT_TRUE(find_planner(spec.name)->honours_jerk_limit);
  EXPECT_EQ(check_planner_limits(spec, limits), "");
  const auto planner = make_planner(spec);
  double worst = 0.0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const Trajectory jerk_limited = planner->plan(toolpath, limits);
    testing_support::expect_contract(jerk_limited, toolpath, limits);
    testing_support::expect_finite_difference_limits(jerk_limited, limits, 0.01);
    worst = std::max(
        worst, testing_support::finite_difference_peaks(jerk_limited, limits).max_jerk_ratio());
    const bool phases = std::all_of(jerk_limited.pieces().begin(), jerk_limited.pieces().end(),
                                    [](const TrajectoryPiece& piece) {
                                      return std::holds_alternative<PhaseMotion>(piece.motion);
                                    });
    if (phases) testing_support::expect_jerk_limited(jerk_limited, limits);
    // the jerk limit costs time: never faster than without it
    const Trajectory free = planner->plan(toolpath, MachineLimits::uniform(4.0, 30.0));
    EXPECT_GE(jerk_limited.duration_s(), free.duration_s() - 1e-9);
    if (HasFatalFailure()) return;
  }
  // a limit that binds: the largest jerk reaches at least half of j_max somewhere
  EXPECT_GT(worst, 0.5);
  std::printf("%s: largest finite-difference jerk / j_max on random toolpaths: %.4f\n",
              spec.name.c_str(), worst);
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

// The firmware baseline's other look-ahead (Klipper: square-corner velocity, minimum cruise
// ratio, the short-move centripetal cap) keeps the same contract on the same toolpaths.
TEST(PlannerContractModes, FirmwareKlipperMode) {
  const auto planner = make_planner(PlannerSpec{"firmware", {}, 0, {{"mode", "klipper"}}});
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
    testing_support::expect_contract(planner->plan(toolpath, limits), toolpath, limits);
    const Toolpath toolpath_3d = testing_support::random_toolpath_3d(seed, 3.0);
    const Trajectory plan_3d = planner->plan(toolpath_3d, limits);
    testing_support::expect_contract(plan_3d, toolpath_3d, limits);
    testing_support::expect_tool_axis_contract(plan_3d, toolpath_3d);
    if (HasFatalFailure()) return;
  }
}

TEST(PlannerRegistry, UnknownNamesAndParametersAreRejected) {
  EXPECT_NE(check_planner_spec({"warp_drive", {}, 0}).find("unknown planner"), std::string::npos);
  EXPECT_NE(check_planner_spec({"lspb_mtt", {{"delta", {0.3}}}, 0}).find("no parameter 'delta'"),
            std::string::npos);
  EXPECT_EQ(check_planner_spec({"lspb_mtt", {}, 0}), "");
  EXPECT_THROW(make_planner({"warp_drive", {}, 0}), InputError);
}

}  // namespace
}  // namespace depotwin
