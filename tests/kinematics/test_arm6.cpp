// The 6-DOF arm's kinematics (kinematics/arm6): ABB's zero pose, forward∘inverse on all eight
// branches and inverse∘forward through inverse_near, the joint 6 turns, clear reasons, the
// singularity measures, the Jacobian against finite differences, the Cartesian limit mapping
// against sampled joint rates, and the link frames and collision shapes.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "kinematics/arm6.hpp"

namespace depotwin {
namespace {

Arm6Joints from_deg(double a, double b, double c, double d, double e, double f) {
  return {deg_to_rad(a), deg_to_rad(b), deg_to_rad(c), deg_to_rad(d), deg_to_rad(e), deg_to_rad(f)};
}

JointVector to_vector(const Arm6Joints& q) {
  return JointVector(q.begin(), q.end());
}

double roll_difference(double a, double b) {
  return std::abs(std::remainder(a - b, 2.0 * kPi));
}

// a uniformly random joint position within the ranges (joint 6 over its whole +-400 deg)
Arm6Joints random_joints(const Arm6& arm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Arm6Joints q;
  for (int j = 0; j < 6; ++j) {
    const JointLimit& limit = arm.joint_limits()[j];
    q[j] = limit.min + (limit.max - limit.min) * unit(rng);
  }
  return q;
}

// the TCP frame of a pose in the work frame
Eigen::Matrix3d pose_frame(const Pose& pose) {
  return tool_frame(pose.tool_axis, pose.roll_rad);
}

TEST(Arm6, ZeroPoseIsAbbsCalibrationPosition) {
  const Arm6 arm;
  const Arm6Joints zero{};
  // ABB IRB 120 at q = 0: wrist centre (302, 0, 630), flange (374, 0, 630) facing +x, tool0's
  // x pointing down
  EXPECT_LT((arm.wrist_centre_in_base(zero) - Vec3(302, 0, 630)).norm(), 1e-12);
  const Eigen::Isometry3d flange = arm.flange_in_base(zero);
  EXPECT_LT((flange.translation() - Vec3(374, 0, 630)).norm(), 1e-12);
  EXPECT_LT((flange.linear().col(2) - Vec3::UnitX()).norm(), 1e-15);
  EXPECT_LT((flange.linear().col(0) + Vec3::UnitZ()).norm(), 1e-15);

  // the tip (-40, 0, 113) in tool0 is (374 + 113, 0, 630 + 40) in the base frame, which is
  // (360, 0, -50) from the work frame; the tool axis is Ry(90 + 150 deg) z
  const Pose pose = arm.forward(zero);
  EXPECT_LT((pose.position_mm - Vec3(487 - 360, 0, 670 + 50)).norm(), 1e-12);
  EXPECT_LT((pose.tool_axis - Vec3(std::sin(deg_to_rad(240)), 0, std::cos(deg_to_rad(240)))).norm(),
            1e-15);
  EXPECT_EQ(arm.branch_of(zero), 0);

  // the tool transform: 120 mm from the flange to the tip, 40 mm off the joint 6 axis, the
  // nozzle 30 deg off the flange normal
  const Eigen::Isometry3d& tool = arm.tool_transform();
  EXPECT_NEAR(tool.translation().norm(), std::hypot(40.0, 113.0), 1e-12);
  EXPECT_NEAR(tool.translation().head<2>().norm(), 40.0, 1e-12);
  EXPECT_NEAR(rad_to_deg(axis_angle_rad(-tool.linear().col(2), Vec3::UnitZ())), 30.0, 1e-12);

  // the datasheet's ranges and speeds, accelerations 4 x v_max per second, in rad
  const double range_deg[6][2] = {{-165, 165}, {-110, 110}, {-110, 70},
                                  {-160, 160}, {-120, 120}, {-400, 400}};
  const double speed_deg_s[6] = {250, 250, 250, 320, 320, 420};
  ASSERT_EQ(arm.joint_limits().size(), 6u);
  for (int j = 0; j < 6; ++j) {
    const JointLimit& limit = arm.joint_limits()[j];
    EXPECT_EQ(limit.name, "j" + std::to_string(j + 1));
    EXPECT_NEAR(rad_to_deg(limit.min), range_deg[j][0], 1e-12);
    EXPECT_NEAR(rad_to_deg(limit.max), range_deg[j][1], 1e-12);
    EXPECT_NEAR(rad_to_deg(limit.v_max), speed_deg_s[j], 1e-12);
    EXPECT_NEAR(rad_to_deg(limit.a_max), 4 * speed_deg_s[j], 1e-12);
  }
  EXPECT_EQ(arm.model_file(), "arm6.xml");
  EXPECT_EQ(arm.joint_count(), 6);
}

// The nozzle vertical over the work origin at roll 0: the natural posture (branch 0), joints
// 4 and 6 at 0, the arm reaching down in front of itself
TEST(Arm6, VerticalNozzleOverTheWorkOriginIsTheNaturalPosture) {
  const Arm6 arm;
  JointVector q;
  std::string why;
  ASSERT_TRUE(arm.inverse(Pose(Vec3::Zero()), q, &why)) << why;
  EXPECT_EQ(arm.branch_of(q), 0);
  EXPECT_NEAR(q[0], 0.0, 1e-12);
  EXPECT_NEAR(q[3], 0.0, 1e-12);
  EXPECT_NEAR(q[5], 0.0, 1e-12);
  EXPECT_NEAR(rad_to_deg(q[1]), 68.0, 0.1);
  EXPECT_NEAR(rad_to_deg(q[2]), 2.3, 0.1);
  EXPECT_NEAR(rad_to_deg(q[4]), 49.7, 0.1);
  EXPECT_GT(rad_to_deg(arm.joint_margin_rad(q)), 30.0);
  EXPECT_GT(arm.wrist_alignment(q), 0.6);
  // the wrist centre 57.9 mm beyond the tip (away from the robot) and 180.2 mm above it
  const Vec3 centre = arm.wrist_centre_in_base({q[0], q[1], q[2], q[3], q[4], q[5]});
  EXPECT_NEAR(centre.x() - 360.0, 57.86, 0.01);
  EXPECT_NEAR(centre.z() + 50.0, 180.21, 0.01);
}

// forward(solution) is the pose for every branch's solution of >= 1000 random poses, each
// returned solution is within the ranges, and the joints the pose came from are among them.
// The roll is measured from tool_frame(axis, 0), which is singular at a tool axis of -z (the
// nozzle pointing straight up, core/pose.hpp): its rounding grows as 1e-16 / sin(angle to -z),
// so the 1e-12 rad bound on axis and roll holds 10 deg or more away from -z; everywhere the
// solution's TCP frame is the pose's, tool_frame(axis, roll), to 1e-12.
TEST(Arm6, ForwardOfEveryBranchSolutionIsThePose) {
  const Arm6 arm;
  std::mt19937_64 rng(11);
  std::array<int, 8> recovered_per_branch{};
  double worst_mm = 0.0, worst_axis = 0.0, worst_roll = 0.0, worst_frame = 0.0, worst_joint = 0.0;
  int poses = 0, solutions_checked = 0;
  const auto tcp_frame = [&arm](const Arm6Joints& q) {
    return Eigen::Matrix3d((arm.flange_in_base(q) * arm.tool_transform()).linear());
  };
  const auto compare = [&](const Arm6Joints& solution, const Pose& pose) {
    const Pose again = arm.forward(solution);
    worst_mm = std::max(worst_mm, (again.position_mm - pose.position_mm).norm());
    const Eigen::Matrix3d frame = arm.work_in_base().linear() * pose_frame(pose);
    worst_frame = std::max(worst_frame, (tcp_frame(solution) - frame).norm());
    if (axis_angle_rad(pose.tool_axis, -Vec3::UnitZ()) < deg_to_rad(10.0)) return;
    worst_axis = std::max(worst_axis, axis_angle_rad(again.tool_axis, pose.tool_axis));
    worst_roll = std::max(worst_roll, roll_difference(again.roll_rad, pose.roll_rad));
  };
  for (; poses < 1500; ++poses) {
    const Arm6Joints q = random_joints(arm, rng);
    const Pose pose = arm.forward(q);

    // the eight branches, ranges not checked: each one's forward is the pose
    Arm6Branches branches;
    ASSERT_TRUE(arm.branch_solutions(pose, branches));
    for (int b = 0; b < 8; ++b) compare(branches[b], pose);

    // every solution within the ranges (all branches and turns of joint 6)
    Arm6Solutions solutions;
    const int count = arm.solutions(pose, solutions);
    ASSERT_GE(count, 1);
    double nearest = 1e9;
    int nearest_branch = -1;
    for (int k = 0; k < count; ++k) {
      const Arm6Solution& solution = solutions[k];
      ++solutions_checked;
      EXPECT_EQ(arm.branch_of(solution.q), solution.branch);
      EXPECT_GE(arm.joint_margin_rad(to_vector(solution.q)), 0.0);
      compare(solution.q, pose);
      double difference = 0.0;
      for (int j = 0; j < 6; ++j) difference = std::max(difference, std::abs(solution.q[j] - q[j]));
      if (difference < nearest) {
        nearest = difference;
        nearest_branch = solution.branch;
      }
    }
    worst_joint = std::max(worst_joint, nearest);
    EXPECT_EQ(nearest_branch, arm.branch_of(q));
    if (nearest_branch >= 0) ++recovered_per_branch[nearest_branch];
  }
  std::printf(
      "%d poses, %d solutions within the ranges: max |tcp error| %.2e mm, frame %.2e, axis "
      "%.2e rad, roll %.2e rad, |q - recovered q| %.2e rad; poses per branch:",
      poses, solutions_checked, worst_mm, worst_frame, worst_axis, worst_roll, worst_joint);
  for (int count : recovered_per_branch) std::printf(" %d", count);
  std::printf("\n");
  EXPECT_LT(worst_mm, 1e-9);
  EXPECT_LT(worst_frame, 1e-12);
  EXPECT_LT(worst_axis, 1e-12);
  EXPECT_LT(worst_roll, 1e-12);
  EXPECT_LT(worst_joint, 1e-9);
  // every branch is exercised by poses whose own joints lie on it
  for (int b = 0; b < 8; ++b) EXPECT_GE(recovered_per_branch[b], 20) << "branch " << b;
}

// inverse_near recovers the joints a pose came from, also from a nearby seed; inverse returns
// the configured branch
TEST(Arm6, InverseNearRecoversTheJointsOfEveryBranch) {
  Arm6 arm;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0.0, 0.01);
  double worst = 0.0;
  int noisy = 0;
  for (int i = 0; i < 1000; ++i) {
    const Arm6Joints q = random_joints(arm, rng);
    const Pose pose = arm.forward(q);
    JointVector seed = to_vector(q), near;
    std::string why;
    ASSERT_TRUE(arm.inverse_near(pose, seed, near, &why)) << why;
    for (int j = 0; j < 6; ++j) worst = std::max(worst, std::abs(near[j] - q[j]));
    // from a seed 0.01 rad off, where every other solution is well apart (near the elbow,
    // shoulder or wrist singularity the nearest solution to a noisy seed may be another)
    Arm6Solutions solutions;
    const int count = arm.solutions(pose, solutions);
    double other = 1e9;
    for (int k = 0; k < count; ++k) {
      double distance = 0.0;
      for (int j = 0; j < 6; ++j)
        distance += (solutions[k].q[j] - q[j]) * (solutions[k].q[j] - q[j]);
      if (distance > 1e-12) other = std::min(other, std::sqrt(distance));
    }
    if (other > 0.3) {
      ++noisy;
      for (double& value : seed) value += noise(rng);
      ASSERT_TRUE(arm.inverse_near(pose, seed, near, &why)) << why;
      for (int j = 0; j < 6; ++j) worst = std::max(worst, std::abs(near[j] - q[j]));
    }

    // inverse() on the pose's own branch gives the same joints up to a turn of joint 6
    arm.set_branch(arm.branch_of(q));
    JointVector configured;
    ASSERT_TRUE(arm.inverse(pose, configured, &why)) << why;
    EXPECT_EQ(arm.branch_of(configured), arm.branch_of(q));
    for (int j = 0; j < 5; ++j) EXPECT_NEAR(configured[j], q[j], 1e-9);
    EXPECT_NEAR(std::remainder(configured[5] - q[5], 2 * kPi), 0.0, 1e-9);
    EXPECT_LE(std::abs(configured[5]), kPi + 1e-12);  // the turn nearest 0
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(noisy, 800);
  EXPECT_THROW(arm.set_branch(8), std::out_of_range);
  EXPECT_THROW(arm.set_branch(-1), std::out_of_range);
}

TEST(Arm6, BranchBitsAndTheConfiguredBranch) {
  Arm6 arm;
  // a posture with q4 = 40 deg, so that the flipped wrist (q4 = -140 deg) is within range too
  const Pose pose = arm.forward(from_deg(10, 60, 5, 40, 45, 30));
  Arm6Branches branches;
  ASSERT_TRUE(arm.branch_solutions(pose, branches));
  for (int b = 0; b < 8; ++b) EXPECT_EQ(arm.branch_of(branches[b]), b);
  // bit 2: the wrist flip (q4 + pi, -q5, q6 + pi) with the same arm
  for (int j = 0; j < 3; ++j) EXPECT_EQ(branches[4][j], branches[0][j]);
  EXPECT_NEAR(branches[4][4], -branches[0][4], 1e-15);
  EXPECT_NEAR(std::remainder(branches[4][3] - branches[0][3] - kPi, 2 * kPi), 0.0, 1e-15);
  // bit 0: the shoulder turned half a turn
  EXPECT_NEAR(std::remainder(branches[1][0] - branches[0][0] - kPi, 2 * kPi), 0.0, 1e-15);
  // bit 1: the elbow below the stretched angle psi - 90 deg
  const double stretched = std::atan2(70.0, 302.0) - 0.5 * kPi;
  EXPECT_GT(branches[0][2], stretched);
  EXPECT_LT(branches[2][2], stretched);

  JointVector q;
  ASSERT_TRUE(arm.inverse(pose, q));
  EXPECT_EQ(arm.branch(), 0);
  EXPECT_EQ(arm.branch_of(q), 0);
  arm.set_branch(4);
  ASSERT_TRUE(arm.inverse(pose, q));
  EXPECT_EQ(arm.branch_of(q), 4);
  EXPECT_LT(q[4], 0.0);
}

// a pose whose joint 6 is at 30 deg is also reached with joint 6 at 390 and -330 deg
TEST(Arm6, JointSixTurnsWithinItsRange) {
  const Arm6 arm;
  const Arm6Joints q = from_deg(10, 60, 5, 20, 45, 30);
  const Pose pose = arm.forward(q);
  Arm6Solutions solutions;
  const int count = arm.solutions(pose, solutions);
  std::vector<double> turns_deg;
  for (int k = 0; k < count; ++k) {
    if (solutions[k].branch != 0) continue;
    for (int j = 0; j < 5; ++j) EXPECT_NEAR(solutions[k].q[j], q[j], 1e-9);
    turns_deg.push_back(rad_to_deg(solutions[k].q[5]));
  }
  ASSERT_EQ(turns_deg.size(), 3u);
  std::sort(turns_deg.begin(), turns_deg.end());
  EXPECT_NEAR(turns_deg[0], -330.0, 1e-9);
  EXPECT_NEAR(turns_deg[1], 30.0, 1e-9);
  EXPECT_NEAR(turns_deg[2], 390.0, 1e-9);

  // inverse: the turn nearest 0; inverse_near: the one nearest the seed
  JointVector joints;
  ASSERT_TRUE(arm.inverse(pose, joints));
  EXPECT_NEAR(rad_to_deg(joints[5]), 30.0, 1e-9);
  JointVector seed = to_vector(q);
  seed[5] = deg_to_rad(370.0);
  ASSERT_TRUE(arm.inverse_near(pose, seed, joints));
  EXPECT_NEAR(rad_to_deg(joints[5]), 390.0, 1e-9);
  seed[5] = deg_to_rad(-250.0);
  ASSERT_TRUE(arm.inverse_near(pose, seed, joints));
  EXPECT_NEAR(rad_to_deg(joints[5]), -330.0, 1e-9);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(joints[j], q[j], 1e-9);
}

TEST(Arm6, UnreachablePosesGiveClearReasons) {
  const Arm6 arm;
  JointVector q;
  std::string why;

  // far away: out of reach, by how much (the wrist centre's distance from the shoulder)
  const Pose far(Vec3(2000, 0, 0));
  EXPECT_FALSE(arm.inverse(far, q, &why));
  const Eigen::Isometry3d tcp_in_base = arm.work_in_base() * Eigen::Translation3d(far.position_mm) *
                                        Eigen::Isometry3d(tool_frame(far.tool_axis, far.roll_rad));
  const Eigen::Isometry3d flange = tcp_in_base * arm.tool_transform().inverse();
  const Vec3 centre = flange.translation() - 72.0 * flange.linear().col(2);
  const double distance_mm = (centre - Vec3(0, 0, 290)).norm();
  const double reach_mm = 270.0 + std::hypot(302.0, 70.0);
  char expected[64];
  std::snprintf(expected, sizeof expected, "%.1f mm beyond the arm's reach of %.1f mm",
                distance_mm - reach_mm, reach_mm);
  EXPECT_NE(why.find("out of reach"), std::string::npos) << why;
  EXPECT_NE(why.find(expected), std::string::npos) << why << " / " << expected;

  // too close: the wrist centre 10 mm from the shoulder, inside the arm's smallest reach
  // |c2 - L| = 40.0 mm
  Eigen::Isometry3d close_flange = Eigen::Isometry3d::Identity();
  close_flange.translation() = Vec3(10, 0, 290 + 72);  // flange facing up
  const Eigen::Isometry3d close_tcp =
      arm.work_in_base().inverse() * close_flange * arm.tool_transform();
  const Pose close(close_tcp.translation(), close_tcp.linear().col(2),
                   roll_of_frame(close_tcp.linear()));
  why.clear();
  EXPECT_FALSE(arm.inverse(close, q, &why));
  EXPECT_NE(why.find("10.00 mm from the shoulder (joint 2 axis), 30.01 mm inside the arm's "
                     "smallest reach of 40.01 mm"),
            std::string::npos)
      << why;

  // joint 4 at 170 deg (beyond its 160) on the configured branch 0: the reason names the
  // joint and the angle, and the flipped wrist (branch 4, q4 = -10 deg) that reaches the pose
  why.clear();
  EXPECT_FALSE(arm.inverse(arm.forward(from_deg(5, 60, 5, 170, 45, 30)), q, &why));
  EXPECT_NE(why.find("joint j4 would be at 170.00 deg, outside its range [-160, 160] deg on the "
                     "configured branch 0 (shoulder front, elbow up, wrist not flipped); branch 4 "
                     "reaches this pose"),
            std::string::npos)
      << why;

  // joint 1 at 170 deg (beyond its 165): no branch within the ranges, each one's first joint
  // outside its range named
  const Pose behind = arm.forward(from_deg(170, 68, 2.3, 0, 49.7, 0));
  why.clear();
  EXPECT_FALSE(arm.inverse(behind, q, &why));
  EXPECT_NE(why.find("no branch reaches this pose within the joint ranges: branch 0 (configured): "
                     "joint j1 would be at 170.00 deg, outside its range [-165, 165] deg; "
                     "branch 1: joint j2 would be at"),
            std::string::npos)
      << why;
  Arm6Solutions solutions;
  EXPECT_EQ(arm.solutions(behind, solutions), 0);
  why.clear();
  EXPECT_FALSE(arm.inverse_near(behind, JointVector(6, 0.0), q, &why));
  EXPECT_NE(why.find("no branch reaches this pose"), std::string::npos) << why;

  // not finite, not a unit axis
  why.clear();
  EXPECT_FALSE(arm.inverse(Pose(Vec3(NAN, 0, 0)), q, &why));
  EXPECT_NE(why.find("position is not finite"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(arm.inverse(Pose(Vec3::Zero(), Vec3(0, NAN, 1)), q, &why));
  EXPECT_NE(why.find("axis is not finite"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(arm.inverse(Pose(Vec3::Zero(), Vec3::UnitZ(), INFINITY), q, &why));
  EXPECT_NE(why.find("roll"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(arm.inverse(Pose(Vec3::Zero(), Vec3(0, 0.5, 0.5)), q, &why));
  EXPECT_NE(why.find("not a unit vector"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(arm.inverse_near(Pose(Vec3(0, 0, 1e6)), JointVector(6, 0.0), q, &why));
  EXPECT_NE(why.find("out of reach"), std::string::npos) << why;
}

// Singular poses are solved; the measures say where they are
TEST(Arm6, SingularPosesAreSolvedAndMeasured) {
  const Arm6 arm;
  // wrist singularity: q5 = 0 (joints 4 and 6 aligned)
  const Arm6Joints wrist = from_deg(5, 40, 10, 25, 0, -35);
  const JointVector wrist_q = to_vector(wrist);
  EXPECT_LT(arm.manipulability(wrist_q), 1e-12);
  EXPECT_EQ(arm.wrist_alignment(wrist_q), 0.0);
  const Pose wrist_pose = arm.forward(wrist);
  JointVector q;
  std::string why;
  ASSERT_TRUE(arm.inverse(wrist_pose, q, &why)) << why;
  EXPECT_LT((arm.forward(q).position_mm - wrist_pose.position_mm).norm(), 1e-9);
  EXPECT_LT(axis_angle_rad(arm.forward(q).tool_axis, wrist_pose.tool_axis), 1e-12);
  EXPECT_LT(roll_difference(arm.forward(q).roll_rad, wrist_pose.roll_rad), 1e-12);
  EXPECT_NEAR(q[3], 0.0, 1e-12);  // inverse keeps q4 at 0, q6 takes the sum
  EXPECT_NEAR(q[5], deg_to_rad(25 - 35), 1e-9);
  // inverse_near keeps the seed's q4 and recovers the joints exactly
  ASSERT_TRUE(arm.inverse_near(wrist_pose, wrist_q, q, &why)) << why;
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(q[j], wrist_q[j], 1e-9) << j;

  // shoulder singularity: the wrist centre on the joint 1 axis. With q2 = -20 deg,
  // c2 sin q2 + L cos(q2 + q3 - psi) = 0 gives q3.
  const double psi = std::atan2(70.0, 302.0), length = std::hypot(302.0, 70.0);
  const double q2 = deg_to_rad(-20.0);
  const double q3 = -std::acos(-270.0 * std::sin(q2) / length) + psi - q2;
  const Arm6Joints shoulder{0.3, q2, q3, 0.5, 0.7, 0.2};
  const JointVector shoulder_q = to_vector(shoulder);
  EXPECT_LT(arm.wrist_centre_offset_mm(shoulder_q), 1e-9);
  EXPECT_LT(arm.manipulability(shoulder_q), 1e-12);
  const Pose shoulder_pose = arm.forward(shoulder);
  ASSERT_TRUE(arm.inverse_near(shoulder_pose, shoulder_q, q, &why)) << why;
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(q[j], shoulder_q[j], 1e-6) << j;
  EXPECT_LT((arm.forward(q).position_mm - shoulder_pose.position_mm).norm(), 1e-9);

  // away from both, the natural posture is well conditioned
  ASSERT_TRUE(arm.inverse(Pose(Vec3::Zero()), q, &why)) << why;
  EXPECT_GT(arm.manipulability(q), 0.01);
  EXPECT_GT(arm.wrist_centre_offset_mm(q), 300.0);
  double margin = 1e9;
  for (int j = 0; j < 6; ++j)
    margin = std::min({margin, q[j] - arm.joint_limits()[j].min, arm.joint_limits()[j].max - q[j]});
  EXPECT_EQ(arm.joint_margin_rad(q), margin);
}

TEST(Arm6, JacobianMatchesFiniteDifferences) {
  const Arm6 arm;
  std::mt19937_64 rng(13);
  const double h = 1e-6;
  double worst_linear = 0.0, worst_angular = 0.0;
  for (int i = 0; i < 300; ++i) {
    const Arm6Joints q = random_joints(arm, rng);
    const Eigen::Matrix<double, 6, 6> jacobian = arm.jacobian(q);
    for (int j = 0; j < 6; ++j) {
      Arm6Joints plus = q, minus = q;
      plus[j] += h;
      minus[j] -= h;
      const Pose p1 = arm.forward(plus), p0 = arm.forward(minus);
      const Vec3 linear = (p1.position_mm - p0.position_mm) / (2 * h);
      // the angular velocity from the rotation between the two frames
      const Eigen::AngleAxisd turn(pose_frame(p1) * pose_frame(p0).transpose());
      const Vec3 angular = turn.angle() * turn.axis() / (2 * h);
      worst_linear = std::max(worst_linear, (linear - jacobian.block<3, 1>(0, j)).norm());
      worst_angular = std::max(worst_angular, (angular - jacobian.block<3, 1>(3, j)).norm());
    }
    // the Machine interface gives the same, and joint_velocity inverts it exactly
    EXPECT_EQ(arm.jacobian(to_vector(q)), Jacobian(jacobian));
    Eigen::Matrix<double, 6, 1> rate;
    rate << 0.3, -0.2, 0.1, 0.5, -0.4, 0.6;
    const Eigen::Matrix<double, 6, 1> task = jacobian * rate;
    const JointVector solved =
        arm.joint_velocity(to_vector(q), PoseRate(task.head<3>(), task.tail<3>()));
    if (arm.manipulability(to_vector(q)) > 1e-4) {
      for (int j = 0; j < 6; ++j) EXPECT_NEAR(solved[j], rate[j], 1e-7);
    }
  }
  std::printf("Jacobian vs central differences: max %.2e mm/rad, %.2e rad/rad\n", worst_linear,
              worst_angular);
  EXPECT_LT(worst_linear, 1e-5);
  EXPECT_LT(worst_angular, 1e-8);
}

// manipulability is |det J| with the linear rows in m: sqrt(det(J J^T))
TEST(Arm6, ManipulabilityIsYoshikawasMeasureInMetres) {
  const Arm6 arm;
  const Arm6Joints q = from_deg(15, 50, 10, 30, 60, -20);
  Eigen::Matrix<double, 6, 6> jacobian = arm.jacobian(q);
  jacobian.topRows<3>() /= 1000.0;
  const double expected = std::sqrt((jacobian * jacobian.transpose()).determinant());
  EXPECT_NEAR(arm.manipulability(to_vector(q)), expected, 1e-12 * expected);
  EXPECT_NEAR(arm.wrist_alignment(to_vector(q)), std::sin(deg_to_rad(60)), 1e-15);
  // j2 (110 - 50), j3 (70 - 10) and j5 (120 - 60) are 60 deg from an end of their ranges
  EXPECT_NEAR(arm.joint_margin_rad(to_vector(q)), deg_to_rad(60), 1e-12);
}

// The TCP limits over a box: sampled joint rates and accelerations of straight moves at those
// limits (nozzle vertical, roll 0, anywhere in the box, any direction within the per-axis
// limits) stay within the joints' own limits; never looser than requested.
TEST(Arm6, CartesianLimitsBoundTheJointsOverTheBox) {
  Arm6 arm;
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const MachineLimits huge = MachineLimits::uniform(1e5, 1e7);
  struct Box {
    Vec3 lo, hi;
  };
  const Box boxes[] = {{Vec3(-5, -5, 0), Vec3(5, 5, 2)},
                       {Vec3(-75, -65, 0), Vec3(75, 65, 40)},
                       {Vec3(30, -60, 10), Vec3(70, 20, 20)}};
  for (const Box& box : boxes) {
    const MachineLimits limits = arm.cartesian_limits(huge, box.lo, box.hi);
    double worst_v = 0.0, worst_a = 0.0;  // fractions of the joint limits
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(limits.axes[axis].v_max_mm_s, huge.axes[axis].v_max_mm_s);
      EXPECT_LE(limits.axes[axis].a_max_mm_s2, huge.axes[axis].a_max_mm_s2);
      EXPECT_GT(limits.axes[axis].v_max_mm_s, 50.0);  // print speeds stay free
    }
    for (int i = 0; i < 2000; ++i) {
      Vec3 point, velocity, acceleration;
      for (int axis = 0; axis < 3; ++axis) {
        point[axis] =
            0.5 * (box.lo[axis] + box.hi[axis]) + 0.5 * (box.hi[axis] - box.lo[axis]) * unit(rng);
        // the worst cases sit at the corners of the velocity box
        velocity[axis] = (unit(rng) < 0 ? -1 : 1) * limits.axes[axis].v_max_mm_s;
        acceleration[axis] = (unit(rng) < 0 ? -1 : 1) * limits.axes[axis].a_max_mm_s2;
      }
      // joints along p(t) = p + v t + a t^2 / 2 at t = -dt, 0, dt
      const double dt = 1e-4;
      JointVector q[3];
      for (int k = 0; k < 3; ++k) {
        const double t = (k - 1) * dt;
        ASSERT_TRUE(arm.inverse(Pose(point + velocity * t + 0.5 * acceleration * t * t), q[k]));
      }
      for (int j = 0; j < 6; ++j) {
        const JointLimit& limit = arm.joint_limits()[j];
        const double rate = (q[2][j] - q[0][j]) / (2 * dt);
        const double second = (q[2][j] - 2 * q[1][j] + q[0][j]) / (dt * dt);
        worst_v = std::max(worst_v, std::abs(rate) / limit.v_max);
        worst_a = std::max(worst_a, std::abs(second) / limit.a_max);
      }
    }
    std::printf(
        "box [%g %g %g]..[%g %g %g]: v_max %.0f %.0f %.0f mm/s, a_max %.0f %.0f %.0f mm/s^2; "
        "worst sampled joint speed %.3f, acceleration %.3f of the limits\n",
        box.lo.x(), box.lo.y(), box.lo.z(), box.hi.x(), box.hi.y(), box.hi.z(),
        limits.axes[0].v_max_mm_s, limits.axes[1].v_max_mm_s, limits.axes[2].v_max_mm_s,
        limits.axes[0].a_max_mm_s2, limits.axes[1].a_max_mm_s2, limits.axes[2].a_max_mm_s2, worst_v,
        worst_a);
    EXPECT_LE(worst_v, 1.0);
    EXPECT_LE(worst_a, 1.0);
    EXPECT_GT(worst_v + worst_a, 0.3);  // and not absurdly conservative
  }

  // requests the joints easily honour come back unchanged
  const MachineLimits gentle = MachineLimits::uniform(20.0, 200.0);
  const MachineLimits kept = arm.cartesian_limits(gentle, Vec3(-10, -10, 0), Vec3(10, 10, 5));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(kept.axes[axis].v_max_mm_s, 20.0);
    EXPECT_EQ(kept.axes[axis].a_max_mm_s2, 200.0);
  }
}

TEST(Arm6, JointLimitsFromTheScenario) {
  Arm6 arm;
  EXPECT_EQ(arm.set_joint_limits(AxisLimits{90.0, 360.0, 0.0}), "");
  for (const JointLimit& limit : arm.joint_limits()) {
    EXPECT_NEAR(limit.v_max, deg_to_rad(90.0), 1e-15);
    EXPECT_NEAR(limit.a_max, deg_to_rad(360.0), 1e-15);
  }
  const std::string refused = arm.set_joint_limits(AxisLimits{90.0, 360.0, 5000.0});
  EXPECT_NE(refused.find("j_max"), std::string::npos) << refused;
  EXPECT_NE(arm.set_joint_limits(AxisLimits{0.0, 360.0, 0.0}), "");
  EXPECT_NEAR(arm.joint_limits()[0].v_max, deg_to_rad(90.0), 1e-15);  // unchanged
}

// A 20 mm radius circle with the tool tilted 30 deg towards its centre, turning with it (the
// roll follows the angle): inverse_near stays on one branch, every joint moves a little per
// step, and joint 6 (+-400 deg) takes the whole turn while the wrist stays clear of q5 = 0
TEST(Arm6, InverseNearIsContinuousAlongATiltedToolTurningWithACircle) {
  const Arm6 arm;
  JointVector q, previous, first;
  std::string why;
  double largest_step = 0.0, smallest_alignment = 1.0;
  for (int k = 0; k <= 720; ++k) {
    const double angle = 2 * kPi * k / 720;  // 0.17 mm steps
    const Vec3 radial(std::cos(angle), std::sin(angle), 0);
    const Vec3 axis = std::cos(deg_to_rad(30)) * Vec3::UnitZ() - std::sin(deg_to_rad(30)) * radial;
    const Pose pose(Vec3(60, 0, 20) + 20.0 * radial, axis, angle);
    const bool solved =
        k == 0 ? arm.inverse(pose, q, &why) : arm.inverse_near(pose, previous, q, &why);
    ASSERT_TRUE(solved) << "step " << k << ": " << why;
    if (k == 0) first = q;
    if (k > 0) {
      EXPECT_EQ(arm.branch_of(q), 0);
      for (int j = 0; j < 6; ++j)
        largest_step = std::max(largest_step, std::abs(q[j] - previous[j]));
    }
    smallest_alignment = std::min(smallest_alignment, arm.wrist_alignment(q));
    previous = q;
  }
  EXPECT_LT(largest_step, deg_to_rad(1.0));
  EXPECT_GT(smallest_alignment, 0.3);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(q[j], first[j], 1e-9);
  EXPECT_NEAR(std::abs(q[5] - first[5]), 2 * kPi, 1e-9);
}

TEST(Arm6, LinkFramesAndCollisionShapes) {
  const Arm6 arm;
  const Arm6Joints q = from_deg(20, 50, 10, -30, 60, 45);
  const std::vector<Eigen::Isometry3d> frames = arm.link_frames(to_vector(q));
  ASSERT_EQ(frames.size(), 8u);
  // base at the base frame's origin; links 4..6 at the wrist centre; 7 the flange
  EXPECT_LT((frames[0].translation() + arm.geometry().work_origin_mm).norm(), 1e-12);
  const Vec3 centre = arm.work_in_base().inverse() * arm.wrist_centre_in_base(q);
  for (int link = 4; link <= 6; ++link)
    EXPECT_LT((frames[link].translation() - centre).norm(), 1e-12);
  const Eigen::Isometry3d flange = arm.work_in_base().inverse() * arm.flange_in_base(q);
  EXPECT_LT((frames[7].matrix() - flange.matrix()).norm(), 1e-12);
  // the TCP is the flange frame times the tool transform
  const Eigen::Isometry3d tcp = frames[7] * arm.tool_transform();
  const Pose pose = arm.forward(q);
  EXPECT_LT((tcp.translation() - pose.position_mm).norm(), 1e-12);
  EXPECT_LT((tcp.linear() - pose_frame(pose)).norm(), 1e-12);
  // joint axes: 1 about the base z, 4 and 6 along the forearm and flange normal
  EXPECT_LT((frames[1].linear().col(2) - Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_LT((frames[6].linear().col(0) - frames[7].linear().col(2)).norm(), 1e-15);

  // links 2..6 and the tool, sizes positive; the nozzle's shapes stop 3 mm short of the tip
  const std::vector<CollisionShape>& shapes = arm.collision_shapes();
  ASSERT_EQ(shapes.size(), 12u);
  for (const CollisionShape& shape : shapes) {
    EXPECT_GE(shape.link, 2) << shape.name;
    EXPECT_LE(shape.link, 7) << shape.name;
    EXPECT_GT(shape.size_mm.x(), 0.0) << shape.name;
  }
  const Eigen::Isometry3d tip = arm.tool_transform();
  double nearest_mm = 1e9;
  for (const CollisionShape& shape : shapes) {
    if (shape.link != 7 || shape.type != CollisionShape::Type::cylinder) continue;
    // the cylinder's end nearest the tip, along the tool axis
    const Vec3 axis = shape.in_link.linear().col(2);
    for (double side : {-1.0, 1.0}) {
      const Vec3 end = shape.in_link.translation() + side * shape.size_mm.y() * axis;
      nearest_mm = std::min(nearest_mm, (end - tip.translation()).norm());
    }
  }
  EXPECT_NEAR(nearest_mm, 3.0, 1e-12);
}

TEST(Arm6, RegisteredAsArm6) {
  const std::unique_ptr<Machine> machine = make_machine("arm6");
  ASSERT_NE(machine, nullptr);
  EXPECT_EQ(machine->name(), "arm6");
  EXPECT_EQ(machine->joint_count(), 6);
}

}  // namespace
}  // namespace depotwin
