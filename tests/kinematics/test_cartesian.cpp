// The cartesian (XYZ gantry) machine's kinematics: the identity within a 200 x 200 x 150 mm
// travel (Klipper's `cartesian`), each TCP axis limited by its own joint.
#include <gtest/gtest.h>

#include <random>

#include "kinematics/cartesian.hpp"
#include "kinematics/machine.hpp"

namespace depotwin {
namespace {

TEST(Cartesian, DescribesItselfAndIsRegistered) {
  const auto machine = make_cartesian();
  EXPECT_EQ(machine->name(), "cartesian");
  EXPECT_EQ(machine->model_file(), "cartesian.xml");
  ASSERT_EQ(machine->joint_count(), 3);
  const auto& limits = machine->joint_limits();
  ASSERT_EQ(limits.size(), 3u);
  EXPECT_EQ(limits[0].name, "x");
  EXPECT_EQ(limits[1].name, "y");
  EXPECT_EQ(limits[2].name, "z");
  // 200 x 200 mm around the bed's centre, 150 mm of z
  EXPECT_DOUBLE_EQ(limits[0].max - limits[0].min, 200.0);
  EXPECT_DOUBLE_EQ(limits[1].max - limits[1].min, 200.0);
  EXPECT_DOUBLE_EQ(limits[2].max, 150.0);
  EXPECT_DOUBLE_EQ(limits[2].min, -10.0);
  const auto registered = make_machine("cartesian");
  ASSERT_NE(registered, nullptr);
  EXPECT_EQ(registered->name(), "cartesian");
}

TEST(Cartesian, InverseIsTheIdentityAndForwardUndoesIt) {
  const auto machine = make_cartesian();
  for (const Vec3& tcp :
       {Vec3(0, 0, 0), Vec3(12.5, -3.25, 0.2), Vec3(-100, 100, 150), Vec3(99.999, -99.999, -1)}) {
    JointVector joints;
    std::string why;
    ASSERT_TRUE(machine->inverse(Pose(tcp), joints, &why)) << why;
    ASSERT_EQ(joints.size(), 3u);
    for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(joints[i], tcp[i]);
    EXPECT_EQ(machine->forward(joints).position_mm, tcp);
  }
  const JointVector rate = machine->joint_velocity({1, 2, 3}, PoseRate(Vec3(2.5, -1.5, 0.25)));
  EXPECT_EQ(rate, (JointVector{2.5, -1.5, 0.25}));
}

TEST(Cartesian, RejectsPointsOutsideTheTravelNamingTheAxis) {
  const auto machine = make_cartesian();
  JointVector joints;
  std::string why;
  EXPECT_FALSE(machine->inverse(Pose(Vec3(0, 0, 150.5)), joints, &why));
  EXPECT_EQ(
      why,
      "the cartesian machine's z axis at 150.5 mm is outside its travel [-10, 150] mm, by 0.5 mm");
  EXPECT_FALSE(machine->inverse(Pose(Vec3(-100.25, 0, 0)), joints, &why));
  EXPECT_EQ(why,
            "the cartesian machine's x axis at -100.2 mm is outside its travel [-100, 100] mm, by "
            "0.25 mm");
  // within the z travel but in the bed: a CNC file zeroed on its stock's top, a slicer's
  // negative z offset (before, z = -8 printed as if on the bed)
  EXPECT_FALSE(machine->inverse(Pose(Vec3(0, 0, -8)), joints, &why));
  EXPECT_EQ(why, "z = -8 mm puts the nozzle more than 1 mm into the bed (its top is z = 0)");
  EXPECT_TRUE(machine->inverse(Pose(Vec3(0, 0, -1)), joints, &why));
  EXPECT_FALSE(machine->inverse(Pose(Vec3(0, 0, -1.0001)), joints, &why));
  EXPECT_EQ(why, "z = -1.0001 mm puts the nozzle more than 1 mm into the bed (its top is z = 0)");
}

TEST(Cartesian, TcpLimitsAreTheTighterOfTheRequestedAndTheJoints) {
  const auto machine = make_cartesian();
  const MachineLimits limits =
      machine->cartesian_limits(MachineLimits::uniform(500.0, 1000.0), Vec3::Zero(), Vec3::Ones());
  EXPECT_DOUBLE_EQ(limits.axes[0].v_max_mm_s, 300.0);
  EXPECT_DOUBLE_EQ(limits.axes[0].a_max_mm_s2, 1000.0);
  EXPECT_DOUBLE_EQ(limits.axes[1].v_max_mm_s, 300.0);
  EXPECT_DOUBLE_EQ(limits.axes[2].v_max_mm_s, 15.0);
  EXPECT_DOUBLE_EQ(limits.axes[2].a_max_mm_s2, 300.0);
}

// A machine that declares its TCP limits free of the position (each TCP axis one joint: the
// gantry and the XY stage) gives the same limits over every box, and its TcpLimits say so
// (uniform's corner decisions are then reused across layers); the delta's and the arm's
// depend on where the box is, and theirs do not.
TEST(Machines, LimitsDeclaredFreeOfThePositionAreTheSameOverEveryBox) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(-150.0, 150.0), size(0.0, 40.0);
  const MachineLimits requested = MachineLimits::uniform(80.0, 900.0, 20000.0);
  for (const std::string& name : machine_names()) {
    SCOPED_TRACE(name);
    const auto machine = make_machine(name);
    const TcpLimits limits = machine->tcp_limits(requested);
    EXPECT_EQ(limits.same_everywhere(), machine->limits_ignore_position());
    if (!machine->limits_ignore_position()) continue;
    const MachineLimits first = limits.over(Vec3::Zero(), Vec3::Zero());
    bool all_same = true;
    for (int k = 0; k < 50; ++k) {
      const Vec3 lo(coordinate(rng), coordinate(rng), 0.5 * coordinate(rng));
      const MachineLimits box = limits.over(lo, lo + Vec3(size(rng), size(rng), size(rng)));
      for (int axis = 0; axis < 3; ++axis)
        all_same = all_same && box.axes[axis].v_max_mm_s == first.axes[axis].v_max_mm_s &&
                   box.axes[axis].a_max_mm_s2 == first.axes[axis].a_max_mm_s2 &&
                   box.axes[axis].j_max_mm_s3 == first.axes[axis].j_max_mm_s3;
    }
    EXPECT_TRUE(all_same);
  }
  for (const char* free_of_position : {"cartesian", "xy_stage"})
    EXPECT_TRUE(make_machine(free_of_position)->limits_ignore_position()) << free_of_position;
  for (const char* position_bound : {"linear_delta", "arm6"})
    EXPECT_FALSE(make_machine(position_bound)->limits_ignore_position()) << position_bound;
}

}  // namespace
}  // namespace depotwin
