// The conformal planner (Shembekar et al. 2018, papers/002): fly-by zone blends, the time law
// under joint limits through a joint map written here, the paper's velocity control
// (none / speed / flow / both), lifted transitions and the offset-point gap test.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>

#include "contract/planner_checks.hpp"
#include "core/error.hpp"
#include "core/segment_distance.hpp"
#include "metrics/motion_metrics.hpp"
#include "planners/motion/conformal.hpp"
#include "planners/motion/path_parametrization.hpp"
#include "planners/motion/process_context.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

namespace depotwin {
namespace {

ConformalPlanner planner_with(ConformalControl control, double zone_mm = 0.25,
                              double lift_mm = 1.0) {
  ConformalSettings settings;
  settings.control = control;
  settings.zone_mm = zone_mm;
  settings.lift_mm = lift_mm;
  return ConformalPlanner(settings);
}

std::vector<const TrajectoryPiece*> print_pieces(const Trajectory& trajectory) {
  std::vector<const TrajectoryPiece*> result;
  for (const TrajectoryPiece& piece : trajectory.pieces())
    if (piece.depositing) result.push_back(&piece);
  return result;
}

const SampledMotion& samples_of(const TrajectoryPiece& piece) {
  return std::get<SampledMotion>(piece.motion);
}

Toolpath one_path(const PrintPath& path) {
  Toolpath toolpath;
  toolpath.start_mm = path.front() + Vec3(0, 0, 5);
  toolpath.end_mm = path.back() + Vec3(0, 0, 5);
  toolpath.paths = {path};
  return toolpath;
}

// A machine written for the test: three prismatic joints that are the TCP position, and a
// tilt joint that is the tool axis' angle from +z in the xz-plane (atan2(n_x, n_z)), slow:
// it must turn fast where the tool axis turns, as an arm's wrist does at a fillet.
constexpr double kTiltVmax = 1.0;   // rad/s
constexpr double kTiltAmax = 50.0;  // rad/s^2
std::shared_ptr<JointMap> tilt_joint_map() {
  auto map = std::make_shared<JointMap>();
  map->limits = {JointLimit{"x", -1e3, 1e3, 1e4, 1e6, 0}, JointLimit{"y", -1e3, 1e3, 1e4, 1e6, 0},
                 JointLimit{"z", -1e3, 1e3, 1e4, 1e6, 0},
                 JointLimit{"tilt", -kPi, kPi, kTiltVmax, kTiltAmax, 0}};
  map->turns_tool = true;
  map->solve = [](const std::vector<Pose>& poses, std::vector<JointVector>& joints, std::string*) {
    joints.resize(poses.size());
    for (size_t i = 0; i < poses.size(); ++i) {
      const Pose& p = poses[i];
      joints[i] = {p.position_mm.x(), p.position_mm.y(), p.position_mm.z(),
                   std::atan2(p.tool_axis.x(), p.tool_axis.z())};
    }
    return true;
  };
  return map;
}

const MachineLimits kFastTcp = MachineLimits::uniform(1000.0, 5000.0);

TcpLimits with_tilt_joint(const MachineLimits& tcp = kFastTcp) {
  return TcpLimits(
      tcp, [tcp](const Vec3&, const Vec3&) { return tcp; }, tilt_joint_map());
}

// A print path over a floor, a concave fillet of radius 2 mm turning 45 deg, and a 45 deg
// slope, in the xz-plane, points about 0.5 mm apart, normals the surface's: on the fillet the
// tool axis turns 1 / R = 0.5 rad per mm, so the tilt joint (1 rad/s) allows 2 mm/s there.
constexpr double kFilletR = 2.0;
constexpr int kFilletEdges = 3;
PrintPath fillet_path(double speed_mm_s) {
  PrintPath path;
  path.speed_mm_s = speed_mm_s;
  for (int i = 0; i <= 20; ++i) {  // floor, x = 0 .. 10
    path.points.emplace_back(0.5 * i, 0.0, 0.0);
    path.normals.push_back(Vec3::UnitZ());
  }
  const Vec3 centre(10.0, 0.0, kFilletR);
  for (int i = 1; i <= kFilletEdges; ++i) {  // the fillet, theta -90 .. -45 deg
    const double theta = -kPi / 2 + (kPi / 4) * i / kFilletEdges;
    const Vec3 p = centre + kFilletR * Vec3(std::cos(theta), 0.0, std::sin(theta));
    path.points.push_back(p);
    path.normals.push_back((centre - p).normalized());
  }
  const Vec3 up = Vec3(1, 0, 1).normalized(), normal = Vec3(-1, 0, 1).normalized();
  const Vec3 slope_start = path.points.back();
  for (int i = 1; i <= 20; ++i) {  // the slope, 10 mm
    path.points.push_back(slope_start + 0.5 * i * up);
    path.normals.push_back(normal);
  }
  return path;
}

// the steepest tool-axis rate on the fillet: inside it the blends (touching) run the axis
// linearly in the Bezier parameter, so the rate peaks at a blend's apex where the parabola is
// slowest: phi / (L cos(phi / 2)), phi the angle per edge and L the chord
double fillet_peak_rate() {
  const double phi = (kPi / 4) / kFilletEdges;
  const double chord = 2 * kFilletR * std::sin(phi / 2);
  return phi / (chord * std::cos(phi / 2));
}

// the tilt joint at every sample of a piece (the test machine's inverse)
std::vector<double> tilt_of(const SampledMotion& motion) {
  std::vector<double> tilt;
  for (const Vec3& axis : motion.tool_axis) tilt.push_back(std::atan2(axis.x(), axis.z()));
  return tilt;
}

// the tilt joint's velocity and acceleration by differences of the 1 ms samples, as a servo
// forms its references, against its limits (relative excess)
void tilt_excess(const Trajectory& trajectory, double& velocity, double& acceleration) {
  velocity = acceleration = 0.0;
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    const SampledMotion& motion = samples_of(piece);
    const std::vector<double> q = tilt_of(motion);
    const double h = motion.period_s;
    for (size_t k = 0; k + 1 < q.size(); ++k)
      velocity = std::max(velocity, std::abs(q[k + 1] - q[k]) / h / kTiltVmax - 1.0);
    for (size_t k = 1; k + 1 < q.size(); ++k)
      acceleration = std::max(acceleration,
                              std::abs(q[k + 1] - 2 * q[k] + q[k - 1]) / (h * h) / kTiltAmax - 1.0);
  }
}

// ---------------------------------------------------------------------------------------
// registry and parameters

TEST(ConformalPlanner, DeclaresItsParametersWithRanges) {
  PlannerSpec spec;
  spec.name = "conformal";
  EXPECT_EQ(check_planner_spec(spec), "");
  EXPECT_TRUE(find_planner("conformal")->honours_jerk_limit);
  spec.choices["control"] = "both";
  spec.params["zone_mm"] = {0.5};
  spec.params["zone_ori_deg"] = {3.0};
  spec.params["gap_offset_mm"] = {3.0};
  spec.params["lift_mm"] = {0.0};
  spec.params["period_s"] = {0.002};
  spec.params["ds_mm"] = {0.02};
  spec.params["lead_in"] = {1.0};
  EXPECT_EQ(check_planner_spec(spec), "");
  const ConformalSettings settings = conformal_settings(spec);
  EXPECT_EQ(settings.control, ConformalControl::both);
  EXPECT_EQ(settings.zone_mm, 0.5);
  EXPECT_EQ(settings.zone_ori_deg, 3.0);
  EXPECT_EQ(settings.gap_offset_mm, 3.0);
  EXPECT_EQ(settings.lift_mm, 0.0);
  EXPECT_EQ(settings.period_s, 0.002);
  EXPECT_EQ(settings.ds_mm, 0.02);
  EXPECT_TRUE(settings.lead_in);
  EXPECT_EQ(conformal_settings(PlannerSpec{"conformal", {}, 0}).control, ConformalControl::none);
  EXPECT_FALSE(conformal_settings(PlannerSpec{"conformal", {}, 0}).lead_in);

  spec.params["lead_in"] = {0.5};  // a switch: 0 or 1
  EXPECT_NE(check_planner_spec(spec).find("'lead_in'"), std::string::npos);
  EXPECT_THROW(conformal_settings(spec), InputError);
  spec.params.erase("lead_in");

  spec.choices["control"] = "fast";
  EXPECT_NE(check_planner_spec(spec).find("not one of none | speed | flow | both"),
            std::string::npos);
  spec.choices["control"] = "speed";
  spec.params["ds_mm"] = {0.0};
  EXPECT_NE(check_planner_spec(spec).find("'ds_mm'"), std::string::npos);
  spec.params.erase("ds_mm");
  spec.params["zone_mm"] = {-1.0};
  EXPECT_NE(check_planner_spec(spec).find("'zone_mm'"), std::string::npos);
}

// ---------------------------------------------------------------------------------------
// a straight path under TCP limits only: the desired speed between the ramps, nominal flow

TEST(ConformalPlanner, StraightPathRunsAtTheDesiredSpeedBetweenRamps) {
  PrintPath path;
  path.speed_mm_s = 10.0;
  for (int i = 0; i <= 40; ++i) path.points.emplace_back(0.5 * i, 3.0, 1.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 200.0);
  const Trajectory plan = planner_with(ConformalControl::none).plan(one_path(path), limits);
  const auto printing = print_pieces(plan);
  ASSERT_EQ(printing.size(), 1u);
  const TrajectoryPiece& piece = *printing.front();
  EXPECT_EQ(piece.path_index, 0);
  EXPECT_EQ(piece.desired_speed_mm_s, 10.0);
  const SampledMotion& motion = samples_of(piece);
  EXPECT_EQ(motion.position_mm.front(), path.front());
  EXPECT_EQ(motion.position_mm.back(), path.back());
  // ramps: 10 / (0.99 * 200) s, 15 % slower over the first 10 periods (the late start), and
  // the few samples whose velocity the fit touched at the switch to cruise
  const double ramp_s = 10.0 / 198.0 + 0.012;
  int cruising = 0;
  for (size_t k = 0; k < motion.position_mm.size(); ++k) {
    EXPECT_EQ(motion.flow_fraction[k], 1.0);
    const double t = k * motion.period_s;
    if (t < ramp_s || t > piece.t_end_s - piece.t_begin_s - ramp_s) continue;
    ++cruising;
    EXPECT_NEAR(motion.velocity_mm_s[k].x(), 10.0, 1e-6) << "k " << k;
    EXPECT_NEAR(motion.velocity_mm_s[k].y(), 0.0, 1e-9) << "k " << k;
    EXPECT_NEAR(motion.velocity_mm_s[k].z(), 0.0, 1e-9) << "k " << k;
  }
  EXPECT_GT(cruising, 1800);
  // the vertical nozzle of a path without normals, exactly
  for (const Vec3& axis : motion.tool_axis) EXPECT_EQ(axis, vertical_tool_axis());
  EXPECT_TRUE(plan.warnings().empty());
}

// ---------------------------------------------------------------------------------------
// the fillet: the paper's velocity control against a slow wrist

struct FilletRun {
  Trajectory plan;
  ConformalPlanReport report;
  const TrajectoryPiece* piece = nullptr;
  // the cruise: samples 50 ms or more from the piece's ends
  std::vector<size_t> cruise;
};

FilletRun run_fillet(ConformalControl control) {
  FilletRun run;
  const PrintPath path = fillet_path(10.0);
  run.plan = planner_with(control).plan(one_path(path), with_tilt_joint(), &run.report);
  run.piece = print_pieces(run.plan).front();
  const SampledMotion& motion = samples_of(*run.piece);
  const size_t margin = 50;
  for (size_t k = margin; k + margin < motion.position_mm.size(); ++k) run.cruise.push_back(k);
  return run;
}

TEST(ConformalPlanner, NoControlSlowsAtTheFilletWithNominalFlow) {
  const FilletRun run = run_fillet(ConformalControl::none);
  const SampledMotion& motion = samples_of(*run.piece);
  double slowest = 1e9;
  size_t slowest_k = 0;
  for (const size_t k : run.cruise) {
    EXPECT_EQ(motion.flow_fraction[k], 1.0);
    const double speed = motion.velocity_mm_s[k].norm();
    if (speed < slowest) {
      slowest = speed;
      slowest_k = k;
    }
  }
  // the wrist's limit: v_j / |q_j'| at the steepest rate (the plan keeps its headroom)
  const double wrist_speed = kJointLimitHeadroom * kTiltVmax / fillet_peak_rate();
  EXPECT_NEAR(slowest, wrist_speed, 1e-3 * wrist_speed);
  // on the floor at the desired speed; material per mm (flow / speed) rises by v_des / v there
  const double floor_speed = motion.velocity_mm_s[run.cruise.front()].norm();
  EXPECT_NEAR(floor_speed, 10.0, 1e-6);
  const double per_mm_fillet = motion.flow_fraction[slowest_k] * 10.0 / slowest;
  const double per_mm_floor = motion.flow_fraction[run.cruise.front()] * 10.0 / floor_speed;
  EXPECT_NEAR(per_mm_fillet / per_mm_floor, 10.0 / slowest, 1e-9);
  EXPECT_GT(per_mm_fillet / per_mm_floor, 5.0);
  ASSERT_EQ(run.report.paths.size(), 1u);
  EXPECT_NEAR(run.report.paths[0].constant_speed_bound_mm_s, wrist_speed, 1e-3 * wrist_speed);
  EXPECT_EQ(run.report.paths[0].line_speed_mm_s, 10.0);
}

TEST(ConformalPlanner, FlowControlFollowsThePlannedSpeed) {
  const FilletRun none = run_fillet(ConformalControl::none);
  const FilletRun run = run_fillet(ConformalControl::flow);
  const SampledMotion& motion = samples_of(*run.piece);
  // the motion is that of `none`; the flow is |v| / v_des at every sample, ramps included
  EXPECT_EQ(samples_of(*none.piece).position_mm, motion.position_mm);
  double lowest = 1.0;
  for (size_t k = 0; k < motion.position_mm.size(); ++k) {
    EXPECT_NEAR(motion.flow_fraction[k], motion.velocity_mm_s[k].norm() / 10.0, 1e-12);
    // at most the desired speed, but where the velocity fit for the cubic interpolation lifted
    // a sample's speed at the switch to cruise (by at most a_max T / 6)
    const double lift = kFastTcp.axes[0].a_max_mm_s2 * 0.001 / 6.0;
    EXPECT_LE(motion.flow_fraction[k], 1.0 + lift / 10.0);
    if (k >= run.cruise.front() && k <= run.cruise.back())
      lowest = std::min(lowest, motion.flow_fraction[k]);
  }
  EXPECT_NEAR(lowest, kJointLimitHeadroom * kTiltVmax / fillet_peak_rate() / 10.0, 1e-4);
  EXPECT_EQ(motion.flow_fraction.front(), 0.0);
}

TEST(ConformalPlanner, SpeedControlPrintsTheLineAtTheWristsSpeed) {
  const FilletRun run = run_fillet(ConformalControl::speed);
  const SampledMotion& motion = samples_of(*run.piece);
  // the smallest joint-allowed speed (with the plan's headroom)
  const double line_speed = kJointLimitHeadroom * kTiltVmax / fillet_peak_rate();
  EXPECT_NEAR(run.report.paths[0].line_speed_mm_s, line_speed, 1e-3 * line_speed);
  const double planned = run.report.paths[0].line_speed_mm_s;
  for (const size_t k : run.cruise)
    EXPECT_NEAR(motion.velocity_mm_s[k].norm(), planned, 1e-6 * planned) << "k " << k;
  for (const double flow : motion.flow_fraction) EXPECT_EQ(flow, planned / 10.0);
  EXPECT_EQ(run.piece->flow_fraction, planned / 10.0);
  // slower than `none`, which printed the floor and the slope at 10 mm/s
  EXPECT_GT(run.plan.duration_s(), run_fillet(ConformalControl::none).plan.duration_s());
}

TEST(ConformalPlanner, BothControlsCombine) {
  const FilletRun run = run_fillet(ConformalControl::both);
  const FilletRun speed = run_fillet(ConformalControl::speed);
  const SampledMotion& motion = samples_of(*run.piece);
  EXPECT_EQ(motion.position_mm, samples_of(*speed.piece).position_mm);
  const double planned = run.report.paths[0].line_speed_mm_s;
  for (const size_t k : run.cruise)
    EXPECT_NEAR(motion.velocity_mm_s[k].norm(), planned, 1e-6 * planned) << "k " << k;
  for (size_t k = 0; k < motion.position_mm.size(); ++k)
    EXPECT_NEAR(motion.flow_fraction[k], motion.velocity_mm_s[k].norm() / 10.0, 1e-12);
}

TEST(ConformalPlanner, EveryJointLimitHoldsAtEverySample) {
  // the tilt joint's rates by differences of the 1 ms samples (as the servo forms its
  // references): within its limits to 0.5 % (the time law holds them exactly at its grid
  // points; between them q' and q'' change while sdot^2 is linear in s)
  for (const ConformalControl control : {ConformalControl::none, ConformalControl::speed,
                                         ConformalControl::flow, ConformalControl::both}) {
    const FilletRun run = run_fillet(control);
    double velocity = 0.0, acceleration = 0.0;
    tilt_excess(run.plan, velocity, acceleration);
    EXPECT_LE(velocity, 5e-3) << "control " << int(control);
    EXPECT_LE(acceleration, 5e-3) << "control " << int(control);
  }
}

// ---------------------------------------------------------------------------------------
// zone blends

TEST(ConformalPlanner, BlendsStayWithinTheStatedDeviation) {
  // a zigzag of 90 deg corners, edges 2 mm: blends of zone 0.25 pass each corner at
  // (0.25 / 2) sin(45 deg) = 0.0884 mm, the stated bound zone/2 sin(theta/2)
  PrintPath path;
  path.speed_mm_s = 5.0;
  for (int i = 0; i <= 8; ++i) path.points.emplace_back(2.0 * i, (i % 2) * 2.0, 0.0);
  ConformalPlanReport report;
  const Trajectory plan = planner_with(ConformalControl::none, 0.25)
                              .plan(one_path(path), MachineLimits::uniform(50, 500), &report);
  const double bound = 0.125 * std::sin(kPi / 4);
  EXPECT_NEAR(report.paths[0].max_blend_deviation_mm, bound, 1e-9);
  EXPECT_EQ(report.blend_deviation_bound_mm, 0.125);
  EXPECT_TRUE(plan.warnings().empty());
  const SampledMotion& motion = samples_of(*print_pieces(plan).front());
  for (size_t i = 1; i + 1 < path.points.size(); ++i) {
    double nearest = 1e9;
    for (const Vec3& p : motion.position_mm)
      nearest = std::min(nearest, (p - path.points[i]).norm());
    // the samples lie on the blend, 1 ms apart: the nearest is the apex to 1e-4 mm
    EXPECT_LE(nearest, bound + 1e-4) << "corner " << i;
    EXPECT_GE(nearest, bound - 1e-9) << "corner " << i;
  }
  EXPECT_EQ(report.paths[0].stop_points, 0);
}

// A faceted convex arc (a surface's triangles crossed): radius 20 mm over 45 deg in 32 chords of
// 0.491 mm, each point turning phi = 1.41 deg, the tool axis the arc's normal, under a TCP jerk
// limit of 1e4 mm/s^3: the jerk-limited law's quartic blends turn the tangent over 2 delta, so
// a short blend caps the speed.
PrintPath faceted_arc(double speed_mm_s) {
  PrintPath path;
  path.speed_mm_s = speed_mm_s;
  const double radius = 20.0;
  const Vec3 centre(0, 0, -radius);
  for (int i = 0; i <= 32; ++i) {
    const double angle = -kPi / 8 + (kPi / 4) * i / 32;
    const Vec3 normal(std::sin(angle), 0, std::cos(angle));
    path.points.push_back(centre + radius * normal);
    path.normals.push_back(normal);
  }
  return path;
}

// zone_bounds_deviation_only: zone_mm bounds a blend's deviation, not its size; each blend of
// the arc is then half a chord long (zone_mm / sin(phi / 2) = 8.1 mm is longer), its deviation
// the quartic's (3/8) delta sin(phi / 2) = 0.0011 mm, within zone_mm / 2, and the line keeps
// the desired speed where 0.1 mm blends held it to 8.2 mm/s. The same blends as a zone of half
// a chord: the same plan.
TEST(ConformalPlanner, AZoneThatBoundsTheDeviationOnlyFliesFacetsByOverHalfTheirChords) {
  const PrintPath path = faceted_arc(10.0);
  const double chord = (path.points[1] - path.points[0]).norm();
  const double phi = (kPi / 4) / 32;
  const MachineLimits tcp = MachineLimits::uniform(1000.0, 5000.0, 1e4);
  const TcpLimits limits = with_tilt_joint(tcp);
  const auto plan = [&](double zone_mm, bool deviation_only, ConformalPlanReport& report) {
    ConformalSettings settings;
    settings.control = ConformalControl::speed;
    settings.zone_mm = zone_mm;
    settings.zone_bounds_deviation_only = deviation_only;
    return ConformalPlanner(settings).plan(one_path(path), limits, &report);
  };
  ConformalPlanReport sized, bounded, half_chord;
  const Trajectory sized_plan = plan(0.1, false, sized);
  const Trajectory bounded_plan = plan(0.1, true, bounded);
  const Trajectory half_chord_plan = plan(0.5 * chord, false, half_chord);
  EXPECT_LT(sized.paths[0].line_speed_mm_s, 0.9 * 10.0);
  EXPECT_EQ(bounded.paths[0].line_speed_mm_s, 10.0);
  EXPECT_NEAR(bounded.paths[0].max_blend_deviation_mm, 0.375 * 0.5 * chord * std::sin(phi / 2),
              1e-9);
  EXPECT_LE(bounded.paths[0].max_blend_deviation_mm, bounded.blend_deviation_bound_mm);
  EXPECT_EQ(bounded.blend_deviation_bound_mm, 0.05);
  EXPECT_TRUE(bounded_plan.warnings().empty());
  EXPECT_EQ(bounded_plan.duration_s(), half_chord_plan.duration_s());
  EXPECT_LT(bounded_plan.duration_s(), sized_plan.duration_s());
  // within the tilt joint's limits and the TCP's (its jerk too) by finite differences
  double velocity = 0.0, acceleration = 0.0;
  tilt_excess(bounded_plan, velocity, acceleration);
  EXPECT_LE(velocity, 5e-3);
  EXPECT_LE(acceleration, 5e-3);
  testing_support::expect_finite_difference_limits(bounded_plan, tcp, 0.01);
  // every printing sample within zone_mm / 2 of the polyline
  EXPECT_LE(path_error(sample_trajectory(bounded_plan, 1e-3), one_path(path)).max_mm, 0.05);
}

TEST(ConformalPlanner, ReversalsAndZoneZeroAreFinePoints) {
  // a reversal cannot be flown by: the path stops there, with a warning
  PrintPath path;
  path.speed_mm_s = 5.0;
  path.points = {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(1, 0.01, 0)};
  ConformalPlanReport report;
  const MachineLimits limits = MachineLimits::uniform(50, 500);
  Trajectory plan = planner_with(ConformalControl::none).plan(one_path(path), limits, &report);
  ASSERT_EQ(plan.warnings().size(), 1u);
  EXPECT_NE(plan.warnings()[0].find("stops at point 1"), std::string::npos) << plan.warnings()[0];
  EXPECT_EQ(report.paths[0].stop_points, 1);
  // zone 0: every interior point is a fine point: the TCP is at rest there
  path.points = {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5, 5, 0), Vec3(10, 5, 0)};
  plan = planner_with(ConformalControl::none, 0.0).plan(one_path(path), limits, &report);
  EXPECT_EQ(report.paths[0].stop_points, 2);
  const SampledMotion& motion = samples_of(*print_pieces(plan).front());
  for (const size_t corner : {1, 2}) {
    size_t nearest = 0;
    for (size_t k = 0; k < motion.position_mm.size(); ++k)
      if ((motion.position_mm[k] - path.points[corner]).norm() <
          (motion.position_mm[nearest] - path.points[corner]).norm())
        nearest = k;
    // within one sample of the stop: at most a_max * T away from rest
    EXPECT_LE(motion.velocity_mm_s[nearest].norm(), 500 * 0.001 * std::sqrt(2.0) + 1e-9);
    EXPECT_LT((motion.position_mm[nearest] - path.points[corner]).norm(), 1e-3);
  }
}

// ---------------------------------------------------------------------------------------
// transitions

TEST(ConformalPlanner, TransitionsLiftAlongTheToolAxis) {
  // two parallel lines on the floor, then a third on a 30 deg tilted axis
  Toolpath toolpath;
  toolpath.start_mm = Vec3(0, -3, 0);
  toolpath.end_mm = Vec3(0, 8, 0);
  PrintPath a, b;
  a.speed_mm_s = b.speed_mm_s = 5.0;
  a.points = {Vec3(0, 0, 0), Vec3(10, 0, 0)};
  b.points = {Vec3(10, 2, 0), Vec3(0, 2, 0)};
  PrintPath c = a;
  c.points = {Vec3(0, 5, 0), Vec3(10, 5, 0)};
  const Vec3 tilted(std::sin(kPi / 6), 0.0, std::cos(kPi / 6));
  c.normals = {tilted, tilted};
  toolpath.paths = {a, b, c};
  const double lift = 1.5;
  const Trajectory plan = planner_with(ConformalControl::none, 0.25, lift)
                              .plan(toolpath, MachineLimits::uniform(40, 400));
  const auto& pieces = plan.pieces();
  ASSERT_EQ(pieces.size(),
            7u);  // transition, print, transition, print, transition, print, transition
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(pieces[i].depositing, i % 2 == 1);
    EXPECT_EQ(pieces[i].path_index, i % 2 == 1 ? int(i / 2) : -1);
  }
  // a -> b: up 1.5 mm, over, down: the highest point is the lift
  const SampledMotion& ab = samples_of(pieces[2]);
  double top = -1.0;
  for (const Vec3& p : ab.position_mm) top = std::max(top, p.z());
  EXPECT_NEAR(top, lift, 1e-9);
  EXPECT_EQ(ab.position_mm.front(), a.back());
  EXPECT_EQ(ab.position_mm.back(), b.front());
  for (const double flow : ab.flow_fraction) EXPECT_EQ(flow, 0.0);
  EXPECT_EQ(plan.at(0.5 * (pieces[2].t_begin_s + pieces[2].t_end_s)).flow_fraction, 0.0);
  // the first part of the lift is straight up, the last of the lowering straight down
  for (size_t k = 1; k < ab.position_mm.size(); ++k) {
    const Vec3 rise = ab.position_mm[k] - a.back();
    if (rise.z() > 0.5 * lift) break;
    EXPECT_NEAR(rise.x(), 0.0, 1e-12);
    EXPECT_NEAR(rise.y(), 0.0, 1e-12);
  }
  // b -> c: c's axis is tilted: the lowering comes in along it, and the axis turns smoothly
  const SampledMotion& bc = samples_of(pieces[4]);
  EXPECT_LT(axis_angle_rad(bc.tool_axis.front(), vertical_tool_axis()), 1e-12);
  EXPECT_LT(axis_angle_rad(bc.tool_axis.back(), tilted), 1e-9);
  // the lowering is straight along c's axis up to where the corner's blend begins, half the
  // lift (a transition's corners blend over half the shorter leg)
  double straight_along_axis = 0.0;
  for (size_t k = 0; k < bc.position_mm.size(); ++k) {
    const Vec3 offset = bc.position_mm[k] - c.front();
    if (offset.cross(tilted).norm() < 1e-9 * (1 + offset.norm()))
      straight_along_axis = std::max(straight_along_axis, offset.dot(tilted));
    if (k > 0) {
      EXPECT_LT(axis_angle_rad(bc.tool_axis[k - 1], bc.tool_axis[k]), 0.01);
    }
    if (offset.norm() < 0.5 * lift) {
      EXPECT_LT(offset.cross(tilted).norm(), 1e-9 * (1 + offset.norm())) << "k " << k;
      EXPECT_LT(axis_angle_rad(bc.tool_axis[k], tilted), 1e-9);
    }
  }
  EXPECT_NEAR(straight_along_axis, 0.5 * lift, 0.01);
  // from the start and to the end, at rest
  EXPECT_EQ(plan.at(0.0).position_mm, toolpath.start_mm);
  EXPECT_EQ(plan.at(plan.duration_s()).position_mm, toolpath.end_mm);
  EXPECT_LT(plan.at(plan.duration_s()).velocity_mm_s.norm(), 1e-9);
}

// ---------------------------------------------------------------------------------------
// the offset-point gap test

TEST(ConformalGapTest, ArcsAreConvexOrConcaveByOnePlusOffsetOverRadius) {
  // an arc of radius R in the xz-plane, normals radial: the offset points lie on the arc of
  // radius R + d (outward normals, convex) or R - d (inward, concave) and subtend the same
  // angles, so every gap ratio is (R +- d) / R exactly (to rounding, 1e-12)
  const double r = 10.0, d = 2.0;
  PrintPath convex, concave;
  convex.speed_mm_s = concave.speed_mm_s = 5.0;
  for (int i = 0; i <= 12; ++i) {
    const double theta = kPi / 2 + 0.6 * (i - 6) / 6.0;
    const Vec3 radial(std::cos(theta), 0.0, std::sin(theta));
    convex.points.push_back(r * radial);
    convex.normals.push_back(radial);
    concave.points.push_back(Vec3(0, 0, 2 * r) - r * radial);  // a bowl: the arc below a centre
    concave.normals.push_back(radial);
  }
  for (size_t k = 0; k + 1 < convex.points.size(); ++k) {
    EXPECT_NEAR(gap_ratio(convex.points[k], convex.normals[k], convex.points[k + 1],
                          convex.normals[k + 1], d),
                1 + d / r, 1e-12);
    EXPECT_NEAR(gap_ratio(concave.points[k], concave.normals[k], concave.points[k + 1],
                          concave.normals[k + 1], d),
                1 - d / r, 1e-12);
  }
  Toolpath toolpath;
  PrintPath flat;
  flat.speed_mm_s = 5.0;
  flat.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  toolpath.paths = {flat, convex, concave};
  const GapReport report = conformal_report(toolpath, d);
  EXPECT_EQ(report.offset_mm, d);
  EXPECT_EQ(report.flat, 2);
  EXPECT_EQ(report.convex, 12);
  EXPECT_EQ(report.concave, 12);
  EXPECT_NEAR(report.max_ratio, 1 + d / r, 1e-12);
  EXPECT_NEAR(report.min_ratio, 1 - d / r, 1e-12);
  EXPECT_EQ(report.max_path, 1);
  EXPECT_EQ(report.min_path, 2);
  // the fillet path is concave where the axis turns, flat elsewhere
  Toolpath fillet;
  fillet.paths = {fillet_path(10.0)};
  const GapReport fillet_report = conformal_report(fillet, 1.0);
  EXPECT_EQ(fillet_report.convex, 0);
  EXPECT_EQ(fillet_report.concave, kFilletEdges);
  EXPECT_EQ(fillet_report.flat, int(fillet.paths[0].points.size()) - 1 - kFilletEdges);
  EXPECT_NEAR(fillet_report.min_ratio, 1 - 1.0 / kFilletR, 1e-12);
}

// ---------------------------------------------------------------------------------------

TEST(ConformalPlanner, PlansAreDeterministic) {
  const PrintPath path = fillet_path(10.0);
  const ConformalPlanner planner = planner_with(ConformalControl::both);
  const Trajectory a = planner.plan(one_path(path), with_tilt_joint());
  const Trajectory b = planner.plan(one_path(path), with_tilt_joint());
  ASSERT_EQ(a.pieces().size(), b.pieces().size());
  for (size_t i = 0; i < a.pieces().size(); ++i) {
    EXPECT_EQ(a.pieces()[i].t_end_s, b.pieces()[i].t_end_s);
    EXPECT_EQ(samples_of(a.pieces()[i]).position_mm, samples_of(b.pieces()[i]).position_mm);
    EXPECT_EQ(samples_of(a.pieces()[i]).velocity_mm_s, samples_of(b.pieces()[i]).velocity_mm_s);
    EXPECT_EQ(samples_of(a.pieces()[i]).flow_fraction, samples_of(b.pieces()[i]).flow_fraction);
  }
}

TEST(ConformalPlanner, BadPathsAreInputErrors) {
  PrintPath path;
  path.speed_mm_s = 5.0;
  path.points = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const ConformalPlanner planner = planner_with(ConformalControl::none);
  EXPECT_THROW(planner.plan(one_path(path), MachineLimits::uniform(10, 100)), InputError);
  path.points = {Vec3(0, 0, 0), Vec3(1, 0, 0)};
  path.normals = {Vec3::UnitZ()};
  EXPECT_THROW(planner.plan(one_path(path), MachineLimits::uniform(10, 100)), InputError);
  path.normals.clear();
  path.speed_mm_s = 0.0;
  EXPECT_THROW(planner.plan(one_path(path), MachineLimits::uniform(10, 100)), InputError);
}

// The worst deceleration of a print piece's samples against |v| / lag (by differences of the
// 1 ms samples), above a speed floor; 0 when it never decelerates there
double worst_deceleration_over_lag(const Trajectory& trajectory, double lag_s, double floor_mm_s) {
  double worst = 0.0;
  for (const TrajectoryPiece* piece : print_pieces(trajectory)) {
    const SampledMotion& motion = samples_of(*piece);
    const double h = motion.period_s;
    for (size_t k = 1; k + 1 < motion.velocity_mm_s.size(); ++k) {
      const double speed = motion.velocity_mm_s[k].norm();
      const double rate =
          (motion.velocity_mm_s[k + 1].norm() - motion.velocity_mm_s[k - 1].norm()) / (2 * h);
      if (speed > floor_mm_s && rate < 0.0) worst = std::max(worst, -rate * lag_s / speed);
    }
  }
  return worst;
}

// flow_lag_s (what `uniform` sets for an extruder): the speed falls at most by |v| / lag, which
// the lagging flow can follow when its command leads the speed; without it the law brakes into
// the fillet and to rest as hard as the limits allow
TEST(ConformalPlanner, FlowLagBoundsTheDecelerations) {
  const double lag_s = 0.02, speed_mm_s = 20.0;
  ConformalSettings settings;
  settings.control = ConformalControl::flow;
  settings.ds_mm = 0.01;
  const Toolpath toolpath = one_path(fillet_path(speed_mm_s));
  const Trajectory free = ConformalPlanner(settings).plan(toolpath, with_tilt_joint());
  settings.flow_lag_s = lag_s;
  const Trajectory bounded = ConformalPlanner(settings).plan(toolpath, with_tilt_joint());
  // above 2.5 x kLagFloorShare of the speed (below it the law brakes to rest); the bound holds
  // on the grid (0.01 mm), so between its points a low speed may fall a little faster
  // (measured: at most 1.13 x |v| / lag above this floor; 20.2 x without the bound)
  const double floor_mm_s = 0.05 * speed_mm_s;
  const double free_worst = worst_deceleration_over_lag(free, lag_s, floor_mm_s);
  const double bounded_worst = worst_deceleration_over_lag(bounded, lag_s, floor_mm_s);
  std::printf("[ lag ] worst deceleration / (|v| / lag): %.3f free, %.3f bounded; %.3f s, %.3f s\n",
              free_worst, bounded_worst, free.duration_s(), bounded.duration_s());
  EXPECT_GT(free_worst, 5.0);
  EXPECT_LE(bounded_worst, 1.25);
  double velocity = 0.0, acceleration = 0.0;
  tilt_excess(bounded, velocity, acceleration);
  EXPECT_LE(velocity, 5e-3);
  EXPECT_LE(acceleration, 5e-3);
}

// lead_in: the law's ramps on straight extensions of the end edges, the material off there.
// On the faceted arc (the tool on the normal, the tilt joint, a jerk limit) the print piece runs
// from the path's first point to its last exactly, at the constant speed throughout; without
// it the print starts and ends at rest. The leads are the end edges' lines, begin and end at
// rest, the tool turning on them at the arc's own rate; every limit holds across the cuts.
TEST(ConformalPlanner, LeadInPrintsThePathAtItsCruiseSpeedFromEndToEnd) {
  const PrintPath path = faceted_arc(10.0);
  const MachineLimits tcp = MachineLimits::uniform(1000.0, 5000.0, 1e4);
  const TcpLimits limits = with_tilt_joint(tcp);
  const auto plan = [&](bool lead_in, ConformalPlanReport& report) {
    ConformalSettings settings;
    settings.control = ConformalControl::speed;
    settings.zone_mm = 0.1;
    settings.zone_bounds_deviation_only = true;
    settings.lead_in = lead_in;
    return ConformalPlanner(settings).plan(one_path(path), limits, &report);
  };
  ConformalPlanReport plain_report, led_report;
  const Trajectory plain = plan(false, plain_report);
  const Trajectory led = plan(true, led_report);
  EXPECT_TRUE(led.warnings().empty());
  ASSERT_EQ(print_pieces(plain).size(), 1u);
  ASSERT_EQ(print_pieces(led).size(), 1u);
  EXPECT_EQ(samples_of(*print_pieces(plain)[0]).velocity_mm_s.front().norm(), 0.0);
  EXPECT_EQ(plain_report.paths[0].lead_in_mm, 0.0);

  // transition, lead-in, print, lead-out, transition
  const std::vector<TrajectoryPiece>& pieces = led.pieces();
  ASSERT_EQ(pieces.size(), 5u);
  const TrajectoryPiece& lead_in = pieces[1];
  const TrajectoryPiece& print = pieces[2];
  const TrajectoryPiece& lead_out = pieces[3];
  EXPECT_FALSE(lead_in.depositing);
  EXPECT_FALSE(lead_out.depositing);
  EXPECT_EQ(lead_in.path_index, -1);
  ASSERT_TRUE(print.depositing);

  // the print piece: from the first point to the last, at the constant speed, 10 mm/s
  const double speed = led_report.paths[0].line_speed_mm_s;
  EXPECT_EQ(speed, 10.0);
  const SampledMotion& printed = samples_of(print);
  EXPECT_LT((printed.position_mm.front() - path.points.front()).norm(), 1e-9);
  EXPECT_LT((printed.position_mm.back() - path.points.back()).norm(), 1e-9);
  for (const Vec3& v : printed.velocity_mm_s) EXPECT_NEAR(v.norm(), speed, 1e-6 * speed);
  EXPECT_LE(printed.period_s, 0.001);
  // its duration: the polyline's length at that speed, less the blends' shortcuts (31 blends
  // over 1.4 deg turns, about 2e-5 mm each)
  const double printed_mm = (print.t_end_s - print.t_begin_s) * speed;
  EXPECT_LE(printed_mm, path.length_mm());
  EXPECT_GE(printed_mm, path.length_mm() - 31 * 3e-5);

  // the leads: on the end edges' lines, as long as reported, from and to rest
  const size_t n = path.points.size();
  const Vec3 u_in = (path.points[1] - path.points[0]).normalized();
  const Vec3 u_out = (path.points[n - 1] - path.points[n - 2]).normalized();
  const Vec3 lead_start = path.points[0] - led_report.paths[0].lead_in_mm * u_in;
  const Vec3 lead_end = path.points[n - 1] + led_report.paths[0].lead_out_mm * u_out;
  for (const Vec3& q : samples_of(lead_in).position_mm)
    EXPECT_LT(point_segment_distance(q, lead_start, path.points[0]), 1e-9);
  for (const Vec3& q : samples_of(lead_out).position_mm)
    EXPECT_LT(point_segment_distance(q, path.points[n - 1], lead_end), 1e-9);
  EXPECT_NEAR((samples_of(lead_in).position_mm.front() - path.points[0]).norm(),
              led_report.paths[0].lead_in_mm, 1e-9);
  EXPECT_NEAR((samples_of(lead_out).position_mm.back() - path.points[n - 1]).norm(),
              led_report.paths[0].lead_out_mm, 1e-9);
  EXPECT_EQ(samples_of(lead_in).velocity_mm_s.front().norm(), 0.0);
  EXPECT_LT(samples_of(lead_out).velocity_mm_s.back().norm(), 1e-9);
  // the tool turns on the leads at the arc's rate (pi/4 over its length), not held still
  const double rate = (kPi / 4) / path.length_mm();
  const double lead_turn = axis_angle_rad(samples_of(lead_in).tool_axis.front(), path.normals[0]);
  EXPECT_NEAR(lead_turn, rate * led_report.paths[0].lead_in_mm, 1e-3 * lead_turn);
  // and where the print starts and ends, the path's own axis within zone_ori_deg
  EXPECT_LT(axis_angle_rad(printed.tool_axis.front(), path.normals.front()), deg_to_rad(1.5));
  EXPECT_LT(axis_angle_rad(printed.tool_axis.back(), path.normals.back()), deg_to_rad(1.5));

  // the limits by finite differences, through the cuts
  double velocity = 0.0, acceleration = 0.0;
  tilt_excess(led, velocity, acceleration);
  EXPECT_LE(velocity, 5e-3);
  EXPECT_LE(acceleration, 5e-3);
  testing_support::expect_finite_difference_limits(led, tcp, 0.01);
  testing_support::expect_contract(led, one_path(path), tcp);
}

// A plan of one path whose lead-in and lead-out were not taken: the warning naming the first
// reason (`first`), no lead reported, three pieces (the print from rest between transitions)
// and the planner contract
void expect_leads_not_taken(const Trajectory& plan, const ConformalPlanReport& report,
                            const PrintPath& path, const MachineLimits& tcp,
                            const std::string& first) {
  ASSERT_FALSE(plan.warnings().empty());
  EXPECT_NE(plan.warnings()[0].find("1 path(s) printed without a lead-in and lead-out, from rest "
                                    "to rest (first: " +
                                    first),
            std::string::npos)
      << plan.warnings()[0];
  EXPECT_EQ(report.paths[0].lead_in_mm, 0.0);
  ASSERT_EQ(plan.pieces().size(), 3u);
  EXPECT_EQ(samples_of(*print_pieces(plan)[0]).velocity_mm_s.front().norm(), 0.0);
  testing_support::expect_contract(plan, one_path(path), tcp);
}

// A lead the machine cannot reach is not taken: the path is printed from rest to rest, and a
// warning says so. The tilt machine here cannot reach x beyond the arc's end by 0.01 mm.
TEST(ConformalPlanner, ALeadOutOfReachIsNotTakenAndSaysSo) {
  const PrintPath path = faceted_arc(10.0);
  const double x_reach = path.points.back().x() + 0.01;
  auto map = tilt_joint_map();
  const auto solve = map->solve;
  map->solve = [solve, x_reach](const std::vector<Pose>& poses, std::vector<JointVector>& joints,
                                std::string* why) {
    for (size_t i = 0; i < poses.size(); ++i)
      if (poses[i].position_mm.x() > x_reach) {
        if (why) *why = "pose " + std::to_string(i) + " beyond x " + std::to_string(x_reach);
        return false;
      }
    return solve(poses, joints, why);
  };
  const MachineLimits tcp = MachineLimits::uniform(1000.0, 5000.0, 1e4);
  const TcpLimits limits(
      tcp, [tcp](const Vec3&, const Vec3&) { return tcp; }, map);
  ConformalSettings settings;
  settings.control = ConformalControl::speed;
  settings.lead_in = true;
  ConformalPlanReport report;
  const Trajectory plan = ConformalPlanner(settings).plan(one_path(path), limits, &report);
  // (and the transition to the end, lifting along the tilted axis, goes straight: a second)
  expect_leads_not_taken(plan, report, path, tcp,
                         "toolpath path 0 with its lead-in: the machine cannot follow the path");
}

// A lead does not go into the work surface (z = 0, the table's or bed's top). The faceted arc
// raised so that its ends are 0.1 mm above it: its end edges slope down at 22.5 deg, so leads
// of over 0.26 mm would end below z = 0, and they are not taken. Raised 5 mm: they are. The
// arc as it is, below z = 0 at its ends (not on a work surface), keeps its leads.
TEST(ConformalPlanner, ALeadIntoTheWorkSurfaceIsNotTakenAndSaysSo) {
  const MachineLimits tcp = MachineLimits::uniform(1000.0, 5000.0, 1e4);
  const TcpLimits limits = with_tilt_joint(tcp);
  ConformalSettings settings;
  settings.control = ConformalControl::speed;
  settings.lead_in = true;
  const PrintPath arc = faceted_arc(10.0);
  const double end_z = arc.points.front().z();  // -1.52 mm, the ends' height
  const auto raised = [&](double dz) {
    PrintPath path = arc;
    for (Vec3& p : path.points) p.z() += dz;
    return path;
  };
  ConformalPlanReport report;
  const PrintPath low = raised(0.1 - end_z);
  const Trajectory grazing = ConformalPlanner(settings).plan(one_path(low), limits, &report);
  expect_leads_not_taken(grazing, report, low, tcp,
                         "toolpath path 0: its lead-in or lead-out would go below the work "
                         "surface (z = 0))");
  for (const TrajectoryPiece& piece : grazing.pieces())
    for (const Vec3& p : samples_of(piece).position_mm) EXPECT_GE(p.z(), 0.1 - 1e-9);

  for (const PrintPath& path : {raised(5.0 - end_z), arc}) {
    ConformalPlanReport taken;
    const Trajectory led = ConformalPlanner(settings).plan(one_path(path), limits, &taken);
    EXPECT_EQ(led.pieces().size(), 5u) << path.points.front().z();
    EXPECT_GT(taken.paths[0].lead_in_mm, 0.26) << path.points.front().z();
    EXPECT_GT(taken.paths[0].lead_out_mm, 0.26) << path.points.front().z();
  }
}

// ---------------------------------------------------------------------------------------
// `uniform` on a machine whose joints turn the tool (uniform_planner.cpp, plan_on_joints)

// On the fillet the tool turns, so `uniform` times the path on the joints: the tilt joint within
// its limits at every 1 ms sample, the corners within the tolerance, and per path the law of
// less predicted line error + time_weight x time (time_weight 0: the constant speed; a second
// worth 1000 mm: the time-optimal law with the flow following the speed). The same path with a
// vertical tool keeps the TCP law and its per-corner choices.
TEST(UniformOnJoints, TimesATurningToolOnTheJointsAndChoosesTheLawPerPath) {
  DepositionSettings extrusion;
  extrusion.type = ProcessType::extrusion;
  extrusion.tau_s = 0.02;
  extrusion.bead_width_mm = 0.4;
  PlanningContext context;
  context.process = std::make_shared<const DepositionSettings>(extrusion);
  const Toolpath toolpath = one_path(fillet_path(20.0));

  std::vector<double> durations;
  for (const auto& [weight, expected] :
       {std::pair<double, const char*>{0.0, "constant_speed"}, {1e3, "flow_follows_speed"}}) {
    UniformSettings settings;
    settings.time_weight_mm_s = weight;
    const Trajectory plan =
        UniformPlanner(settings).plan_in_context(toolpath, with_tilt_joint(), context);
    double velocity = 0.0, acceleration = 0.0;
    tilt_excess(plan, velocity, acceleration);
    EXPECT_LE(velocity, 5e-3) << expected;
    EXPECT_LE(acceleration, 5e-3) << expected;
    ASSERT_EQ(plan.decisions().size(), 1u) << expected;
    const PlanDecision& decision = plan.decisions()[0];
    EXPECT_EQ(decision.kind, "path");
    EXPECT_EQ(decision.choice, expected);
    for (const PlanFigure& figure : decision.figures)
      if (figure.name == "deviation_mm") {
        EXPECT_LE(figure.value, settings.tolerance_mm * (1 + 1e-9));
      }
    // the flow leads the planned speed by the lag
    for (const TrajectoryPiece* piece : print_pieces(plan)) EXPECT_EQ(piece->flow_lead_s, 0.02);
    durations.push_back(plan.duration_s());
  }
  // the time-optimal law is the quicker (the constant speed is the fillet's ~2 mm/s throughout)
  EXPECT_LT(durations[1], 0.5 * durations[0]);

  // aerosol on a faceted arc under a jerk limit: the constant speed is the print speed, each
  // blend half a chord (its zone bounds the deviation only); 0.1 mm blends held it to 8.2 mm/s
  {
    const Trajectory faceted =
        UniformPlanner(UniformSettings{})
            .plan_in_context(one_path(faceted_arc(10.0)),
                             with_tilt_joint(MachineLimits::uniform(1000.0, 5000.0, 1e4)),
                             process_context(ProcessType::aerosol));
    ASSERT_EQ(faceted.decisions().size(), 1u);
    int figures = 0;
    for (const PlanFigure& figure : faceted.decisions()[0].figures) {
      if (figure.name == "constant_speed_mm_s") {
        EXPECT_EQ(figure.value, 10.0);
        ++figures;
      }
      if (figure.name == "deviation_mm") {
        EXPECT_LE(figure.value, 0.05);
        ++figures;
      }
      // with a lead-in and a lead-out: the stream prints the path at that speed throughout
      if (figure.name == "lead_in_mm" || figure.name == "lead_out_mm") {
        EXPECT_GT(figure.value, 0.0) << figure.name;
        ++figures;
      }
    }
    EXPECT_EQ(figures, 4);
    ASSERT_EQ(print_pieces(faceted).size(), 1u);
    for (const Vec3& v : samples_of(*print_pieces(faceted)[0]).velocity_mm_s)
      EXPECT_NEAR(v.norm(), 10.0, 1e-5);
  }

  // a vertical tool throughout: nothing turns, the TCP law with its corner choices
  PrintPath vertical = fillet_path(20.0);
  vertical.normals.clear();
  const Trajectory plan = UniformPlanner(UniformSettings{})
                              .plan_in_context(one_path(vertical), with_tilt_joint(), context);
  ASSERT_FALSE(plan.decisions().empty());
  for (const PlanDecision& decision : plan.decisions()) EXPECT_EQ(decision.kind, "corner");
}

}  // namespace
}  // namespace depotwin
