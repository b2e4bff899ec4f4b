// A simulated joint beyond its limits is said in metrics.json's warnings, one line per joint
// and quantity, in the report's units; a peak at its limit is not beyond it. An arm's
// collisions too.
#include <gtest/gtest.h>

#include "metrics/metrics_report.hpp"
#include "metrics/run_report.hpp"

namespace depotwin {
namespace {

// two joints: a slide (mm) and a hinge (deg), each with speed, acceleration and force limits
ActuatorStats two_joints() {
  ActuatorStats stats;
  stats.joint_names = {"y", "j5"};
  stats.revolute = {false, true};
  stats.limit_vel = {200.0, 320.0};
  stats.limit_acc = {2000.0, 1280.0};
  stats.limit_force = {50.0, 0.0};  // the hinge has no force limit
  stats.peak_vel = {150.0, 320.0};  // the hinge exactly at its limit
  stats.peak_acc = {1000.0, 1000.0};
  stats.peak_force = {10.0, 1e6};
  return stats;
}

TEST(ActuatorWarnings, NoneWithinTheLimits) {
  EXPECT_TRUE(actuator_limit_warnings(two_joints()).empty());
  // a servo tracking a speed planned at the limit reads it back rounded above it (15 mm/s
  // "above" 15 by +7.7e-9 %, a slicer's file on the cartesian printer's z): no warning, no
  // violation counted; 1e-7 above is one
  ActuatorStats stats = two_joints();
  stats.peak_vel[0] = 200.0 * (1.0 + 7.7e-11);
  EXPECT_TRUE(actuator_limit_warnings(stats).empty());
  stats.peak_vel[0] = 200.0 * (1.0 + 1e-7);
  EXPECT_EQ(actuator_limit_warnings(stats).size(), 1u);
}

TEST(ActuatorWarnings, OneLinePerQuantityBeyondItsLimit) {
  ActuatorStats stats = two_joints();
  stats.peak_vel[0] = 733.0;    // the kp_scale 1e300 run: 733 mm/s against 200
  stats.peak_acc[1] = 14400.0;  // shembekar_beam's lspb_mtt wrist: 14 400 deg/s^2 vs 1 280
  stats.peak_force[0] = 50.5;
  const std::vector<std::string> warnings = actuator_limit_warnings(stats);
  ASSERT_EQ(warnings.size(), 3u);
  // the excess in per cent too: where the peak rounds to the limit (15.003 against 15) the
  // figures alone read "15 above 15"
  EXPECT_EQ(warnings[0],
            "joint y: peak speed 733 mm/s above its limit 200 mm/s (+266.5 %) in the simulation");
  EXPECT_EQ(warnings[1],
            "joint y: peak actuator force 50.5 N above its limit 50 N (+1 %) in the simulation");
  EXPECT_EQ(warnings[2],
            "joint j5: peak acceleration 1.44e+04 deg/s^2 above its limit 1280 deg/s^2 (+1025 %) "
            "in the simulation");
  stats = two_joints();
  stats.peak_vel[0] = 200.03;
  EXPECT_EQ(actuator_limit_warnings(stats).at(0),
            "joint y: peak speed 200 mm/s above its limit 200 mm/s (+0.015 %) in the simulation");
}

// An arm's collisions: no warning without one; else the events by kind and the first MuJoCo
// contact (the table's, as Simulation logs it)
TEST(ArmCollisionWarning, CountsTheEventsByKindAndNamesTheFirstContact) {
  ArmStats arm;
  ContactLog contacts;
  EXPECT_EQ(arm_collision_warning(arm, contacts), "");
  arm.table_contacts = 2;
  arm.part_contacts = 1;
  arm.collisions = 3;
  contacts.other_events = 2;
  contacts.first = "t = 0.75 s: table / tool_nozzle_tip";
  EXPECT_EQ(arm_collision_warning(arm, contacts),
            "collisions in the simulation: 3 contact event(s), 2 with the table, 1 with the part, "
            "0 of the arm with itself (the first MuJoCo contact at t = 0.75 s: table / "
            "tool_nozzle_tip)");
  // a contact with the part alone is measured by clearance, not logged by MuJoCo
  arm.table_contacts = 0;
  arm.collisions = 1;
  EXPECT_EQ(arm_collision_warning(arm, ContactLog{}),
            "collisions in the simulation: 1 contact event(s), 0 with the table, 1 with the part, "
            "0 of the arm with itself");
}

// thickness scores resting on no target cell or too few (paths hardly longer than the line is
// wide: ends are left out) are said, so their 0 is not read as a perfect deposit
TEST(ThicknessCoverage, ScoresOnTooFewCellsOrSamplesAreSaid) {
  ThicknessStats stats;
  stats.cells = 0;
  stats.line_samples = 0;
  const std::string none = thickness_coverage_warning(stats);
  EXPECT_NE(none.find("cv, min_rel and max_rel (no target cells) and line_cv (no centreline "
                      "samples) measure too little"),
            std::string::npos)
      << none;
  stats.cells = kFewestScoredCells - 1;
  stats.line_samples = kFewestScoredSamples;
  const std::string few = thickness_coverage_warning(stats);
  EXPECT_EQ(
      few.rfind("thickness mean_um, cv, min_rel and max_rel (only 9 target cells) measure", 0), 0u)
      << few;
  EXPECT_EQ(few.find("line_cv"), std::string::npos) << few;
  stats.cells = kFewestScoredCells;
  EXPECT_EQ(thickness_coverage_warning(stats), "");
}

}  // namespace
}  // namespace depotwin
