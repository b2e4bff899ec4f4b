// Reproductions of Thompson & Yoon 2014 (papers/000), Figs. 7-12, on the plan.
#include <gtest/gtest.h>

#include <cmath>

#include "contract/planner_checks.hpp"
#include "metrics/motion_metrics.hpp"
#include "planners/motion/lspb_mtt.hpp"
#include "planners/motion/stop_and_go.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {
namespace {

PrintPath segment(Vec3 a, Vec3 b, int index) {
  PrintPath path;
  path.points = {a, b};
  path.speed_mm_s = 3.0;
  path.source_index = index;
  return path;
}

// the geometry of scenarios/thompson_fig7.yaml
Toolpath fig7() {
  Toolpath t;
  t.start_mm = Vec3(-5, -5, 0);
  t.end_mm = Vec3(15, -5, 0);
  t.paths = {segment({0, 0, 0}, {5, 0, 0}, 0), segment({5, 0, 0}, {8, 6, 0}, 1),
             segment({8, 6, 0}, {2, 4, 0}, 2), segment({2, 8, 0}, {9, 8, 0}, 3),
             segment({10, 1, 0}, {10, 9, 0}, 4)};
  return t;
}

// speed error at time t of a depositing piece
double speed_error_at(const Trajectory& trajectory, double t) {
  const TrajectorySample s = trajectory.at(t);
  return std::abs(s.velocity_mm_s.norm() - s.desired_speed_mm_s) / s.desired_speed_mm_s;
}

TEST(ThompsonFig7, AcuteJointSpeedErrorIsOneMinusSinHalfAngle) {
  const Toolpath toolpath = fig7();
  const Trajectory plan = LspbMttPlanner().plan(toolpath, MachineLimits::uniform(4, 30));
  EXPECT_TRUE(plan.warnings().empty());
  // pieces: transition, seg 1, seg 2, seg 3, transition, seg 4, transition, seg 5, transition
  const auto& pieces = plan.pieces();
  ASSERT_EQ(pieces.size(), 9u);
  // at the 45 deg joint the averaged velocity has speed v sin(22.5 deg): error 61.7 %
  const double acute = 1.0 - std::sin(22.5 * kPi / 180.0);
  EXPECT_NEAR(speed_error_at(plan, pieces[3].t_begin_s), acute, 1e-9);
  // at the 116.57 deg joint: 1 - sin(58.28 deg) = 14.9 %
  const double obtuse_angle = std::acos(-3.0 / std::sqrt(45.0));
  EXPECT_NEAR(speed_error_at(plan, pieces[2].t_begin_s), 1.0 - std::sin(obtuse_angle / 2), 1e-9);
  // the largest error of the whole print is the acute joint's (the paper's ~60 %)
  const MotionSamples samples = sample_trajectory(plan, 1e-4);
  const VelocityErrorStats stats = velocity_error(samples);
  EXPECT_NEAR(stats.max_rel, acute, 1e-3);
  // the isolated segments 4 and 5 are printed at exactly the desired speed
  for (int piece : {5, 7}) {
    for (double f = 0.0; f <= 1.0; f += 0.05) {
      const double t =
          pieces[piece].t_begin_s + f * (pieces[piece].t_end_s - pieces[piece].t_begin_s);
      EXPECT_LT(speed_error_at(plan, t), 1e-9);
    }
  }
  // position error below 1.1 % of the 10 mm feature (the paper's Fig. 10b)
  EXPECT_LT(path_error(samples, toolpath).max_mm, 0.011 * 10.0);
}

TEST(ThompsonFig7, TransitionsAreShutterClosedMinimumTimeMoves) {
  const Trajectory plan = LspbMttPlanner().plan(fig7(), MachineLimits::uniform(4, 30));
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (piece.depositing) continue;
    // the paper notes that each Fig. 7 transition reaches v_max on one axis
    const auto& axes = std::get<PhaseMotion>(piece.motion).axes;
    const double peak = std::max(axes[0].peak_speed(), axes[1].peak_speed());
    EXPECT_NEAR(peak, 4.0, 1e-9);
  }
}

// 14 connected segments, joint angles 125, 115, ..., 5 deg (scenarios/thompson_fig11.yaml)
Toolpath fig11(std::vector<double>& joint_angles_deg) {
  Toolpath t;
  double heading = 0.0;
  Vec3 p(0, 0, 0);
  joint_angles_deg.clear();
  for (int k = 0; k < 14; ++k) {
    const Vec3 q = p + 3.0 * Vec3(std::cos(heading), std::sin(heading), 0);
    t.paths.push_back(segment(p, q, k));
    p = q;
    if (k < 13) {
      const double angle = 125.0 - 10.0 * k;
      joint_angles_deg.push_back(angle);
      heading += (k % 2 == 0 ? 1 : -1) * (180.0 - angle) * kPi / 180.0;
    }
  }
  t.start_mm = Vec3::Zero();
  t.end_mm = p + Vec3(3, 0, 0);
  return t;
}

TEST(ThompsonFig11, PeakSpeedErrorGrowsAsTheJointAngleShrinks) {
  std::vector<double> angles;
  const Toolpath toolpath = fig11(angles);
  const Trajectory plan = LspbMttPlanner().plan(toolpath, MachineLimits::uniform(4, 30));
  // print pieces are 1..14 (piece 0 is the first transition)
  const auto& pieces = plan.pieces();
  ASSERT_EQ(pieces.size(), 16u);
  double previous_peak = 0.0;
  for (int joint = 0; joint < 13; ++joint) {
    // the peak error between the middles of the two segments meeting at this joint
    const TrajectoryPiece& a = pieces[1 + joint];
    const TrajectoryPiece& b = pieces[2 + joint];
    double peak = 0.0;
    const double from = 0.5 * (a.t_begin_s + a.t_end_s), to = 0.5 * (b.t_begin_s + b.t_end_s);
    for (double t = from; t <= to; t += 1e-4) peak = std::max(peak, speed_error_at(plan, t));
    EXPECT_GT(peak, previous_peak) << "joint " << joint << " angle " << angles[joint];
    EXPECT_GE(peak, 1.0 - std::sin(angles[joint] * kPi / 360.0) - 1e-9);
    previous_peak = peak;
  }
  // a 5 deg joint is nearly a full reversal: close to the paper's "100 % at 0 deg"
  EXPECT_GT(previous_peak, 0.95);
  // position error <= 1.5 % of the pattern's extent (the paper's Fig. 12b)
  Vec3 lo, hi;
  toolpath.bounds(lo, hi);
  const double extent = (hi - lo).head<2>().maxCoeff();
  const PathErrorStats error = path_error(sample_trajectory(plan, 1e-3), toolpath);
  EXPECT_LE(error.max_mm, 0.015 * extent) << "extent " << extent;
}

// sampled every period, a plan whose end lies a fraction of a nanosecond after a sample: the
// end takes that sample's place (trajectory.csv writes microseconds, where the two rows would
// share a time), and the final rest state is still the last sample (the plan's own end state:
// at rest to the roundoff of its blend times)
TEST(StopAndGo, AnEndJustAfterASampleReplacesIt) {
  const TcpLimits limits(MachineLimits::uniform(4.0, 30.0));
  const Trajectory plan("test", {transition_piece(0.0, Vec3(0, 0, 0), Vec3::Zero(), Vec3(10, 0, 0),
                                                  Vec3::Zero(), limits)});
  const double duration = plan.duration_s();
  for (double after : {2e-10, 4e-7}) {
    const double period = (duration - after) / 1000.0;
    const MotionSamples samples = sample_trajectory(plan, period);
    ASSERT_EQ(samples.size(), 1001u) << after;
    EXPECT_EQ(samples.t_s.back(), duration);
    EXPECT_NEAR(samples.t_s[999], 999.0 * period, 1e-15);
    EXPECT_EQ(samples.velocity_mm_s.back(), plan.at(duration).velocity_mm_s);
    EXPECT_LT(samples.velocity_mm_s.back().norm(), 1e-12);
  }
  // an end farther after its sample is a sample of its own
  const MotionSamples apart = sample_trajectory(plan, (duration - 1e-6) / 1000.0);
  EXPECT_EQ(apart.size(), 1002u);
}

TEST(StopAndGo, RestToRestSegmentsAtPrintSpeed) {
  const Toolpath toolpath = fig7();
  const Trajectory plan = StopAndGoPlanner().plan(toolpath, MachineLimits::uniform(4, 30));
  // every print piece starts and ends at rest and cruises at exactly 3 mm/s in its middle
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (!piece.depositing) continue;
    EXPECT_LT(plan.at(piece.t_begin_s).velocity_mm_s.norm(), 1e-9);
    const double mid = 0.5 * (piece.t_begin_s + piece.t_end_s);
    EXPECT_NEAR(plan.at(mid).velocity_mm_s.norm(), 3.0, 1e-9);
  }
  // each segment of length L takes L / v + v / a_line (trapezoid) with a_line >= 30
  const TrajectoryPiece& first = plan.pieces()[1];
  EXPECT_NEAR(first.t_end_s - first.t_begin_s, 5.0 / 3.0 + 3.0 / 30.0, 1e-12);
  // stop-and-go prints slower than lspb_mtt and has a 100 % speed error at its ramps
  const Trajectory lspb = LspbMttPlanner().plan(toolpath, MachineLimits::uniform(4, 30));
  EXPECT_GT(plan.duration_s(), lspb.duration_s());
  EXPECT_NEAR(velocity_error(sample_trajectory(plan, 1e-3)).max_rel, 1.0, 1e-9);
}

// A joint between segments whose limits differ (a machine maps its joints' limits per box):
// 100 mm/s along x, joined to a line slowed to 99 mm/s where x's v_max is 99. Eqs. (52)-(53)
// average the joint velocity to 99.5 mm/s on x, over the second segment's limit (an internal
// error then); it is held to 99, and the plan keeps every axis within each segment's limits.
TEST(LspbMtt, AJointVelocityKeepsWithinBothSegmentsLimits) {
  const MachineLimits fast = MachineLimits::uniform(100, 1000);
  MachineLimits slow = fast;
  slow.axes[0].v_max_mm_s = 99.0;
  const TcpLimits limits(fast, [fast, slow](const Vec3& /*lo*/, const Vec3& hi) {
    return hi.x() > 10.0 + 1e-9 ? slow : fast;
  });
  Toolpath toolpath;
  PrintPath first = segment({0, 0, 0}, {10, 0, 0}, 0);
  first.speed_mm_s = 100.0;
  PrintPath second = segment({10, 0, 0}, {20, 0, 0}, 1);
  second.speed_mm_s = 99.0;
  toolpath.paths = {first, second};
  toolpath.start_mm = Vec3(0, 0, 0);
  toolpath.end_mm = Vec3(20, 0, 0);
  Trajectory plan;
  ASSERT_NO_THROW(plan = LspbMttPlanner().plan(toolpath, limits));
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (!piece.depositing) continue;
    const double v_max = piece.path_index == 0 ? 100.0 : 99.0;
    for (double t = piece.t_begin_s; t <= piece.t_end_s; t += 1e-4)
      EXPECT_LE(std::abs(plan.at(t).velocity_mm_s.x()), v_max * (1 + 1e-9))
          << "path " << piece.path_index << " at " << t;
  }
  // the joint at 99 mm/s: the second line runs at its speed from its start
  EXPECT_NEAR(plan.at(plan.pieces()[2].t_begin_s).velocity_mm_s.x(), 99.0, 1e-9);
}

}  // namespace
}  // namespace depotwin

namespace depotwin {
namespace {

TEST(LspbMtt, SegmentTooShortForItsJointVelocitiesIsLengthenedWithAWarning) {
  // the middle segment is 0.07 mm long between two sharp joints: in L / v = 0.024 s the
  // x velocity would have to change by 3 mm/s (127 mm/s^2 > 30), so no LSPB exists
  PrintPath path;
  path.points = {{0, 0, 0}, {5, 0, 0}, {5.05, 0.05, 0}, {0, 0.1, 0}};
  path.speed_mm_s = 3.0;
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-2, -2, 0);
  toolpath.end_mm = Vec3(-2, 2, 0);
  toolpath.paths = {path};
  const MachineLimits limits = MachineLimits::uniform(4, 30);
  const Trajectory plan = LspbMttPlanner().plan(toolpath, limits);
  ASSERT_EQ(plan.warnings().size(), 1u);
  EXPECT_NE(plan.warnings()[0].find("segment 1"), std::string::npos) << plan.warnings()[0];
  const TrajectoryPiece& short_piece = plan.pieces()[2];
  const double nominal = std::sqrt(0.005) / 3.0;
  EXPECT_GT(short_piece.t_end_s - short_piece.t_begin_s, nominal * 1.5);
  // and the lengthened trajectory still honours the contract: limits, continuity, ends
  testing_support::expect_contract(plan, toolpath, limits);
}

}  // namespace
}  // namespace depotwin
