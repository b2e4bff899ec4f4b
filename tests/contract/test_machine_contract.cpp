// One contract test over every registered machine (kinematics/registry.cpp), on seeded random
// reachable poses: inverse and forward agree, the Jacobian is the derivative of forward, an
// unreachable pose is a clear error, and a planned trajectory never asks a joint for more
// speed or acceleration (or jerk, where the machine takes a joint jerk limit) than its own.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/trajectory.hpp"
#include "kinematics/machine.hpp"
#include "planners/planner.hpp"

namespace depotwin {
namespace {

class MachineContract : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    machine_ = make_machine(GetParam());
    ASSERT_NE(machine_, nullptr);
  }

  // Seeded random reachable joint positions: around the joints of the work frame's origin
  // (a reachable pose on every machine), within `spread` of each joint's range, kept when
  // forward gives a pose that inverse accepts.
  std::vector<JointVector> reachable_joints(std::uint64_t seed, size_t count,
                                            double spread = 0.3) const {
    JointVector home;
    std::string why;
    EXPECT_TRUE(machine_->inverse(Pose(Vec3::Zero()), home, &why)) << why;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<JointVector> samples;
    JointVector back;
    for (int attempt = 0; attempt < 100000 && samples.size() < count; ++attempt) {
      JointVector q = home;
      for (size_t j = 0; j < q.size(); ++j) {
        const JointLimit& limit = machine_->joint_limits()[j];
        q[j] = std::clamp(home[j] + spread * (limit.max - limit.min) * unit(rng), limit.min,
                          limit.max);
      }
      const Pose pose = machine_->forward(q);
      if (pose.position_mm.allFinite() && machine_->inverse(pose, back)) samples.push_back(q);
    }
    EXPECT_EQ(samples.size(), count) << "too few reachable poses found";
    return samples;
  }

  std::unique_ptr<Machine> machine_;
};

// forward(inverse(pose)) is the pose (position, tool axis and roll); a machine with several
// solutions per pose returns, near a seed, the seed's own (inverse_near: forward∘inverse and
// inverse∘forward are both the identity)
TEST_P(MachineContract, InverseAndForwardAgree) {
  double worst_mm = 0.0, worst_joint = 0.0, worst_roll = 0.0;
  for (const JointVector& q : reachable_joints(1, 300)) {
    const Pose pose = machine_->forward(q);
    JointVector back, near;
    std::string why;
    ASSERT_TRUE(machine_->inverse(pose, back, &why)) << why;
    ASSERT_EQ(back.size(), q.size());
    ASSERT_EQ(static_cast<int>(back.size()), machine_->joint_count());
    const Pose again = machine_->forward(back);
    worst_mm = std::max(worst_mm, (again.position_mm - pose.position_mm).norm());
    worst_roll =
        std::max(worst_roll, std::abs(std::remainder(again.roll_rad - pose.roll_rad, 2.0 * kPi)));
    EXPECT_NEAR(again.tool_axis.norm(), 1.0, 1e-12);
    EXPECT_LT(axis_angle_rad(again.tool_axis, pose.tool_axis), 1e-9);
    ASSERT_TRUE(machine_->inverse_near(pose, q, near, &why)) << why;
    for (size_t j = 0; j < q.size(); ++j)
      worst_joint = std::max(worst_joint, std::abs(near[j] - q[j]));
  }
  EXPECT_LT(worst_mm, 1e-9);
  EXPECT_LT(worst_joint, 1e-9);
  EXPECT_LT(worst_roll, 1e-9);
}

TEST_P(MachineContract, JacobianMatchesFiniteDifferences) {
  const double h = 1e-6;  // joint units (mm or rad)
  for (const JointVector& q : reachable_joints(2, 100)) {
    const Jacobian jacobian = machine_->jacobian(q);
    ASSERT_EQ(jacobian.cols(), machine_->joint_count());
    const Pose pose = machine_->forward(q);
    for (int j = 0; j < machine_->joint_count(); ++j) {
      JointVector plus = q, minus = q;
      plus[j] += h;
      minus[j] -= h;
      const Pose p1 = machine_->forward(plus), p0 = machine_->forward(minus);
      // position rows: d tcp / dq_j; angular rows: d axis / dq_j = omega_j x axis
      const Vec3 d_position = (p1.position_mm - p0.position_mm) / (2 * h);
      const Vec3 d_axis = (p1.tool_axis - p0.tool_axis) / (2 * h);
      const Vec3 linear = jacobian.block<3, 1>(0, j), angular = jacobian.block<3, 1>(3, j);
      EXPECT_LT((d_position - linear).norm(), 1e-5 * (1.0 + linear.norm())) << "joint " << j;
      EXPECT_LT((d_axis - angular.cross(pose.tool_axis)).norm(), 1e-5) << "joint " << j;
    }
    // joint_velocity inverts the Jacobian on the task the machine can move
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    JointVector q_rate(q.size());
    Eigen::VectorXd q_rate_vector(q.size());
    for (size_t j = 0; j < q.size(); ++j) q_rate_vector[j] = q_rate[j] = 10.0 * unit(rng);
    const Eigen::Matrix<double, 6, 1> task = jacobian * q_rate_vector;
    const JointVector solved =
        machine_->joint_velocity(q, PoseRate(task.head<3>(), task.tail<3>()));
    for (size_t j = 0; j < q.size(); ++j) EXPECT_NEAR(solved[j], q_rate[j], 1e-8);
  }
}

TEST_P(MachineContract, UnreachablePosesAreClearErrors) {
  JointVector joints;
  for (const Vec3& far : {Vec3(1e6, 0, 0), Vec3(0, -1e6, 0), Vec3(0, 0, 1e6)}) {
    std::string why;
    EXPECT_FALSE(machine_->inverse(Pose(far), joints, &why));
    EXPECT_FALSE(why.empty());
  }
  std::string why;
  EXPECT_FALSE(machine_->inverse(Pose(Vec3(NAN, 0, 0)), joints, &why));
  EXPECT_FALSE(why.empty());
  why.clear();
  EXPECT_FALSE(machine_->inverse(Pose(Vec3::Zero(), Vec3(0, 0, 2)), joints, &why));
  EXPECT_NE(why.find("unit"), std::string::npos) << why;
}

// Seeded random toolpaths through reachable points near the origin, planned by every planner
// under TCP limits far above the machine's (the machine's mapping must bind): sampled every
// 1 ms, no joint exceeds its speed or acceleration limit.
TEST_P(MachineContract, PlansNeverAskJointsForMoreThanTheirLimits) {
  const std::vector<JointVector> joints = reachable_joints(3, 60, 0.04);
  std::vector<Vec3> points;
  for (const JointVector& q : joints) {
    const Vec3 p = machine_->forward(q).position_mm;
    if (p.norm() < 100.0) points.push_back(p);
  }
  ASSERT_GE(points.size(), 8u);
  Toolpath toolpath;
  toolpath.start_mm = points[0];
  toolpath.end_mm = points[1];
  for (size_t i = 2; i + 1 < points.size() && toolpath.paths.size() < 4; i += 2) {
    PrintPath path;
    path.points = {points[i], points[i + 1]};
    // (below every machine's slowest axis, the cartesian's z at 15 mm/s: a steep segment is
    // then still printable at its speed)
    path.speed_mm_s = 10.0;
    path.source_index = static_cast<int>(toolpath.paths.size());
    toolpath.paths.push_back(path);
  }
  const TcpLimits limits = machine_->tcp_limits(MachineLimits::uniform(1e4, 1e6));
  const std::vector<JointLimit>& joint_limits = machine_->joint_limits();
  for (const PlannerInfo& info : planner_registry()) {
    SCOPED_TRACE(info.name);
    const Trajectory plan = make_planner(PlannerSpec{info.name, {}, 0})->plan(toolpath, limits);
    const double h = 1e-4;
    JointVector q, q_before, q_after;
    for (double t = h; t < plan.duration_s() - h; t += 0.001) {
      const TrajectorySample s = plan.at(t);
      ASSERT_TRUE(machine_->inverse(s.pose(), q)) << "t " << t;
      const JointVector rate = machine_->joint_velocity(q, PoseRate(s.velocity_mm_s));
      // joint acceleration: central difference of the joint velocities
      ASSERT_TRUE(machine_->inverse(plan.at(t - h).pose(), q_before));
      ASSERT_TRUE(machine_->inverse(plan.at(t + h).pose(), q_after));
      const JointVector rate_before =
          machine_->joint_velocity(q_before, PoseRate(plan.at(t - h).velocity_mm_s));
      const JointVector rate_after =
          machine_->joint_velocity(q_after, PoseRate(plan.at(t + h).velocity_mm_s));
      for (size_t j = 0; j < q.size(); ++j) {
        const double acceleration = (rate_after[j] - rate_before[j]) / (2 * h);
        ASSERT_LE(std::abs(rate[j]), joint_limits[j].v_max * (1 + 1e-6))
            << "joint " << joint_limits[j].name << " t " << t;
        ASSERT_LE(std::abs(acceleration), joint_limits[j].a_max * (1 + 1e-3))
            << "joint " << joint_limits[j].name << " t " << t;
      }
    }
  }
}

// A joint jerk limit: honoured through the TCP limits by the planners that honour j_max, or
// refused by the machine with a reason
TEST_P(MachineContract, JointJerkLimitIsHonouredOrRefused) {
  const JointLimit& first = machine_->joint_limits().front();
  const std::string refused =
      machine_->set_joint_limits(AxisLimits{first.v_max, first.a_max, 5000.0});
  if (!refused.empty()) {
    EXPECT_NE(refused.find("j_max"), std::string::npos) << refused;
    return;
  }
  const MachineLimits over_origin =
      machine_->tcp_limits(MachineLimits::uniform(50.0, 500.0)).over(Vec3::Zero(), Vec3::Zero());
  EXPECT_TRUE(over_origin.jerk_limited());
  for (const AxisLimits& axis : over_origin.axes) EXPECT_LE(axis.j_max_mm_s3, 5000.0 * (1 + 1e-12));
}

std::vector<std::string> registered_machines() {
  return machine_names();
}

INSTANTIATE_TEST_SUITE_P(EveryMachine, MachineContract, ::testing::ValuesIn(registered_machines()),
                         [](const auto& info) { return info.param; });

TEST(MachineRegistry, NamesAreUniqueAndUnknownNamesGiveNothing) {
  const std::vector<std::string> names = machine_names();
  ASSERT_FALSE(names.empty());
  for (size_t i = 0; i < names.size(); ++i)
    for (size_t k = i + 1; k < names.size(); ++k) EXPECT_NE(names[i], names[k]);
  for (const std::string& name : names) EXPECT_EQ(make_machine(name)->name(), name);
  EXPECT_EQ(make_machine("scara"), nullptr);
}

// Only the XY stage holds the TCP at z = 0; there `conformal`'s travels do not lift (every one
// used to try, fail and go straight, and every job warned "4 transition(s) could not lift by
// 1 mm" on thompson_fig7's paths)
TEST(MachineRegistry, OnlyTheXyStageCannotLiftAndItsTravelsDoNotTry) {
  for (const std::string& name : machine_names())
    EXPECT_EQ(make_machine(name)->moves_tcp_z(), name != "xy_stage") << name;
  const std::unique_ptr<Machine> stage = make_machine("xy_stage");
  const TcpLimits limits = stage->tcp_limits(MachineLimits::uniform(4.0, 30.0));
  ASSERT_NE(limits.joint_map(), nullptr);
  EXPECT_FALSE(limits.joint_map()->moves_z);
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-5, -5, 0);
  toolpath.end_mm = Vec3(5, 5, 0);
  for (const double y : {-2.0, 0.0, 2.0}) {
    PrintPath path;
    path.points = {Vec3(-4, y, 0), Vec3(4, y, 0)};
    path.speed_mm_s = 3.0;
    path.source_index = static_cast<int>(toolpath.paths.size());
    toolpath.paths.push_back(path);
  }
  const Trajectory plan = make_planner(PlannerSpec{"conformal", {}, 0})->plan(toolpath, limits);
  EXPECT_TRUE(plan.warnings().empty()) << plan.warnings().front();
  for (double t = 0.0; t <= plan.duration_s(); t += 0.01)
    EXPECT_EQ(plan.at(t).position_mm.z(), 0.0) << "t " << t;
}

}  // namespace
}  // namespace depotwin
