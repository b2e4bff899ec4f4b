// The XY stage's kinematics: the plate moves under a fixed nozzle, so the TCP in the plate
// frame is minus the carriage positions (Thompson & Yoon, papers/000, section II-B).
#include <gtest/gtest.h>

#include <cmath>

#include "kinematics/machine.hpp"
#include "kinematics/xy_stage.hpp"

namespace depotwin {
namespace {

TEST(XyStage, DescribesItself) {
  const auto machine = make_xy_stage();
  EXPECT_EQ(machine->name(), "xy_stage");
  EXPECT_EQ(machine->model_file(), "xy_stage.xml");
  ASSERT_EQ(machine->joint_count(), 2);
  const auto& limits = machine->joint_limits();
  ASSERT_EQ(limits.size(), 2u);
  EXPECT_EQ(limits[0].name, "x");
  EXPECT_EQ(limits[1].name, "y");
  for (const JointLimit& limit : limits) {
    EXPECT_DOUBLE_EQ(limit.min, -50.0);
    EXPECT_DOUBLE_EQ(limit.max, 50.0);
    EXPECT_GT(limit.v_max, 0.0);
    EXPECT_GT(limit.a_max, 0.0);
  }
  // the registry hands out the same machine
  const auto registered = make_machine("xy_stage");
  ASSERT_NE(registered, nullptr);
  EXPECT_EQ(registered->name(), "xy_stage");
}

TEST(XyStage, InverseIsMinusTheTcpAndForwardUndoesIt) {
  const auto machine = make_xy_stage();
  const Vec3 points[] = {Vec3(0, 0, 0), Vec3(12.5, -3.25, 0), Vec3(-50, 50, 0),
                         Vec3(49.999, -49.999, 0)};
  for (const Vec3& tcp : points) {
    JointVector joints;
    std::string why;
    ASSERT_TRUE(machine->inverse(tcp, joints, &why)) << why;
    ASSERT_EQ(joints.size(), 2u);
    EXPECT_DOUBLE_EQ(joints[0], -tcp.x());
    EXPECT_DOUBLE_EQ(joints[1], -tcp.y());
    const Vec3 back = machine->forward(joints).position_mm;
    EXPECT_NEAR((back - tcp).norm(), 0.0, 1e-12);
  }
}

TEST(XyStage, JointVelocityIsMinusTheTcpVelocity) {
  const auto machine = make_xy_stage();
  const JointVector velocity = machine->joint_velocity({3.0, -7.0}, Vec3(2.5, -1.5, 0.0));
  ASSERT_EQ(velocity.size(), 2u);
  EXPECT_DOUBLE_EQ(velocity[0], -2.5);
  EXPECT_DOUBLE_EQ(velocity[1], 1.5);
}

TEST(XyStage, RejectsPointsOutsideTheTravelWithAReason) {
  const auto machine = make_xy_stage();
  JointVector joints;
  std::string why;
  // TCP x = -55 puts carriage x at +55 mm, beyond +50
  EXPECT_FALSE(machine->inverse(Vec3(-55, 0, 0), joints, &why));
  EXPECT_NE(why.find("joint x"), std::string::npos) << why;
  EXPECT_NE(why.find("55"), std::string::npos) << why;
  EXPECT_NE(why.find("travel"), std::string::npos) << why;
  why.clear();
  EXPECT_FALSE(machine->inverse(Vec3(0, 50.5, 0), joints, &why));
  EXPECT_NE(why.find("joint y"), std::string::npos) << why;
  // no z axis: off the substrate plane is unreachable
  why.clear();
  EXPECT_FALSE(machine->inverse(Vec3(0, 0, 0.2), joints, &why));
  EXPECT_NE(why.find("z"), std::string::npos) << why;
  // not a number
  why.clear();
  EXPECT_FALSE(machine->inverse(Vec3(std::nan(""), 0, 0), joints, &why));
  EXPECT_FALSE(why.empty());
  // the travel edge itself is reachable
  EXPECT_TRUE(machine->inverse(Vec3(-50, 50, 0), joints, &why)) << why;
}

TEST(XyStage, CartesianLimitsAreTheTighterOfRequestAndJoint) {
  const auto machine = make_xy_stage();
  const auto& joint = machine->joint_limits();
  // a request well below the stage's capability passes unchanged (Thompson & Yoon: 4, 30)
  const MachineLimits slow = MachineLimits::uniform(4.0, 30.0, 0.0);
  const MachineLimits kept = machine->cartesian_limits(slow, Vec3(-10, -10, 0), Vec3(10, 10, 0));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_DOUBLE_EQ(kept.axes[axis].v_max_mm_s, 4.0);
    EXPECT_DOUBLE_EQ(kept.axes[axis].a_max_mm_s2, 30.0);
  }
  // a request beyond it is cut to the joints' limits on x and y
  const MachineLimits fast = MachineLimits::uniform(1e6, 1e7, 5.0);
  const MachineLimits cut = machine->cartesian_limits(fast, Vec3(-10, -10, 0), Vec3(10, 10, 0));
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_DOUBLE_EQ(cut.axes[axis].v_max_mm_s, joint[axis].v_max);
    EXPECT_DOUBLE_EQ(cut.axes[axis].a_max_mm_s2, joint[axis].a_max);
    EXPECT_DOUBLE_EQ(cut.axes[axis].j_max_mm_s3, 5.0);
  }
}

}  // namespace
}  // namespace depotwin
