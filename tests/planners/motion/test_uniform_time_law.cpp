// `uniform`'s time law: the 1-D jerk-limited line profiles against the analytic double-S of
// motion/jerk.hpp, the extruder's deceleration rule, and whole plans checked joint by joint
// by finite differences of the planned motion (the XY stage's joints and the linear delta's
// carriages through their inverse kinematics).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "contract/planner_checks.hpp"
#include "kinematics/linear_delta.hpp"
#include "kinematics/xy_stage.hpp"
#include "metrics/motion_metrics.hpp"
#include "motion/jerk.hpp"
#include "planners/motion/polyline_job.hpp"
#include "planners/motion/process_context.hpp"
#include "planners/motion/uniform/line_profile.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

namespace depotwin {
namespace {

// Without a flow lag a line's profile is the time-optimal double-S of motion/jerk.hpp (the
// `depotwin move --jmax` code path) from v0 to v1 over its length: same duration, same
// state at every time.
TEST(UniformLineProfile, EqualsTheAnalyticDoubleS) {
  struct Case {
    double length, v0, v1, v_max, a_max, j_max;
  };
  for (const Case& c :
       {Case{10.0, 0.0, 0.0, 3.0, 30.0, 300.0}, Case{0.2, 0.0, 0.0, 3.0, 30.0, 300.0},
        Case{5.0, 3.0, 1.0, 4.0, 30.0, 3000.0}, Case{2.0, 0.5, 2.5, 3.0, 50.0, 900.0},
        Case{30.0, 20.0, 0.0, 20.0, 1500.0, 150000.0}}) {
    SCOPED_TRACE(testing::Message() << "L " << c.length << " v0 " << c.v0 << " v1 " << c.v1);
    const LineLimits limits{c.v_max, c.a_max, c.j_max, 0.0};
    const AxisProfile ours = line_profile(c.length, c.v0, c.v1, limits);
    const AxisProfile analytic =
        jerk_min_time_move(AxisBoundary{0.0, c.length, c.v0, c.v1}, c.v_max, c.a_max, c.j_max);
    ASSERT_NEAR(ours.duration_s(), analytic.duration_s(), 1e-9 * analytic.duration_s());
    for (int k = 0; k <= 200; ++k) {
      const double t = analytic.duration_s() * k / 200.0;
      const AxisState a = ours.at(t), b = analytic.at(t);
      EXPECT_NEAR(a.q, b.q, 1e-9 * c.length) << "t " << t;
      EXPECT_NEAR(a.v, b.v, 1e-7 * c.v_max) << "t " << t;
      EXPECT_NEAR(a.a, b.a, 1e-6 * c.a_max) << "t " << t;
    }
    EXPECT_NEAR(ours.q_end(), c.length, 1e-12 * c.length);
    EXPECT_NEAR(ours.v_end(), c.v1, 1e-12 * c.v_max);
  }
}

// reachable_speed is the largest speed whose change fits the length, and never above the cap
TEST(UniformLineProfile, ReachableSpeedFitsTheLengthExactly) {
  const LineLimits limits{5.0, 30.0, 500.0, 0.0};
  for (const double length : {0.01, 0.1, 0.4, 3.0}) {
    const double v = reachable_speed(0.5, length, 5.0, limits, true);
    if (v < 5.0) {
      EXPECT_NEAR(speed_change_distance(v, 0.5, limits), length, 1e-9 * length);
    } else {
      EXPECT_LE(speed_change_distance(v, 0.5, limits), length);
    }
    // accelerating towards the end: the same distance by symmetry of the S-curve
    EXPECT_NEAR(reachable_speed(0.5, length, 5.0, limits, false), v, 1e-9);
  }
  EXPECT_EQ(reachable_speed(2.0, 0.0, 5.0, limits, true), 2.0);  // nothing to change on
}

// With an extruder's flow lag tau, a deceleration never falls faster than v / tau (down to 2 %
// of its starting speed), so a flow that leads the speed by tau never goes negative there;
// accelerations are not held back.
TEST(UniformLineProfile, DecelerationsFollowTheFlowLag) {
  const double tau = 0.05;
  const LineLimits limits{20.0, 1500.0, 150000.0, tau};
  const AxisProfile stop = line_profile(30.0, 0.0, 0.0, limits);
  EXPECT_NEAR(stop.q_end(), 30.0, 1e-9);
  bool accelerated_fast = false;
  for (int k = 0; k <= 20000; ++k) {
    const double t = stop.duration_s() * k / 20000.0;
    const AxisState s = stop.at(t);
    if (s.a < 0.0 && s.v > 0.02 * 20.0) {
      EXPECT_GE(s.a, -s.v / tau * (1 + 1e-9)) << "t " << t << " v " << s.v;
    }
    if (s.a > 20.0 / tau) accelerated_fast = true;
    ASSERT_GE(s.v, -1e-9);
  }
  EXPECT_TRUE(accelerated_fast);
  // duration and distance of the staged change agree with its phases
  AxisProfile change(0.0, 20.0, 0.0);
  append_speed_change(change, 20.0, 1.0, limits);
  EXPECT_NEAR(change.duration_s(), speed_change_duration(20.0, 1.0, limits), 1e-12);
  EXPECT_NEAR(change.q_end(), speed_change_distance(20.0, 1.0, limits), 1e-9);
  EXPECT_NEAR(change.v_end(), 1.0, 1e-9);
}

// A zig-zag with corners from 160 to 10 degrees (every treatment occurs), planned for aerosol
// and for extrusion, sampled every millisecond.
Toolpath zig_zag(double speed_mm_s) {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-5, -5, 0);
  toolpath.end_mm = Vec3(5, -5, 0);
  PrintPath path;
  path.speed_mm_s = speed_mm_s;
  Vec3 p(-10, 0, 0);
  double heading_deg = 15.0;
  path.points.push_back(p);
  int k = 0;
  for (const double joint_deg : {160.0, 120.0, 90.0, 60.0, 30.0, 10.0}) {
    p += 3.0 * Vec3(std::cos(deg_to_rad(heading_deg)), std::sin(deg_to_rad(heading_deg)), 0.0);
    path.points.push_back(p);
    heading_deg += (k++ % 2 == 0 ? 1.0 : -1.0) * (180.0 - joint_deg);
  }
  p += 3.0 * Vec3(std::cos(deg_to_rad(heading_deg)), std::sin(deg_to_rad(heading_deg)), 0.0);
  path.points.push_back(p);
  toolpath.paths.push_back(path);
  PrintPath line;  // and an isolated line
  line.speed_mm_s = speed_mm_s;
  line.points = {Vec3(0, -3, 0), Vec3(6, -2, 0)};
  line.source_index = 1;
  toolpath.paths.push_back(line);
  return toolpath;
}

// Every joint's speed, acceleration (and, where the machine's joints are its axes, jerk) by
// finite differences of the joint positions the machine's inverse kinematics gives along the
// plan every millisecond. A third difference over dt^3 is a weighted mean of the jerk over
// three periods, so it cannot exceed the largest jerk; the slack covers the cubic
// interpolation of the blends' samples.
void expect_joint_limits(const Trajectory& plan, const Machine& machine, const JointLimit& joint,
                         bool check_jerk) {
  const double dt = 0.001;
  std::vector<JointVector> q;
  for (double t = 0.0; t <= plan.duration_s(); t += dt) {
    JointVector joints;
    ASSERT_TRUE(machine.inverse(Pose(plan.at(t).position_mm), joints)) << "t " << t;
    q.push_back(joints);
  }
  double peak_v = 0.0, peak_a = 0.0, peak_j = 0.0;
  for (size_t k = 0; k + 3 < q.size(); ++k) {
    for (size_t j = 0; j < q[k].size(); ++j) {
      peak_v = std::max(peak_v, std::abs(q[k + 1][j] - q[k][j]) / dt);
      peak_a = std::max(peak_a, std::abs(q[k + 2][j] - 2 * q[k + 1][j] + q[k][j]) / (dt * dt));
      peak_j =
          std::max(peak_j, std::abs(q[k + 3][j] - 3 * q[k + 2][j] + 3 * q[k + 1][j] - q[k][j]) /
                               (dt * dt * dt));
    }
  }
  EXPECT_LE(peak_v, joint.v_max * (1 + 1e-6));
  EXPECT_LE(peak_a, joint.a_max * (1 + 1e-3));
  if (check_jerk) {
    EXPECT_LE(peak_j, joint.j_max * (1 + 1e-2));
  }
  // the limits are used: the plan is not slack
  EXPECT_GT(peak_a, 0.5 * joint.a_max);
}

TEST(UniformTimeLaw, XyStageJointsWithinSpeedAccelerationAndJerk) {
  const std::unique_ptr<Machine> stage = make_xy_stage();
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, 600.0);
  JointLimit joint;
  joint.v_max = 4.0;
  joint.a_max = 30.0;
  joint.j_max = 600.0;
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    SCOPED_TRACE(process_type_name(type));
    PlanningContext context;
    DepositionSettings process;
    process.type = type;
    context.process = std::make_shared<const DepositionSettings>(process);
    const UniformPlanner planner{UniformSettings{}};
    const Trajectory plan = planner.plan_in_context(zig_zag(3.0), limits, context);
    expect_joint_limits(plan, *stage, joint, true);
  }
}

// An aerosol job on the XY stage (travel +-50 mm) whose paths end, start and turn within a
// stopping distance (20^2 / (2 x 400) = 0.5 mm) of the travel's end: a transition or a loop
// at print speed runs past it (the run's pose check then stops with exit 2). The plan keeps
// every joint within its travel instead: the chains are entered or left at rest there and
// their corners taken without loops, and each such chain reports it (`within_travel`). A job
// away from the edge is planned exactly as without the machine's travel.
TEST(UniformTravel, AerosolChainsNearTheTravelsEndStayWithinIt) {
  const std::unique_ptr<Machine> stage = make_xy_stage();
  const MachineLimits requested = MachineLimits::uniform(40.0, 400.0);
  const TcpLimits stage_limits = stage->tcp_limits(requested);
  PlanningContext context;
  DepositionSettings aerosol;
  aerosol.type = ProcessType::aerosol;
  context.process = std::make_shared<const DepositionSettings>(aerosol);
  const UniformPlanner planner{UniformSettings{}};
  const auto job = [](const std::vector<std::vector<Vec3>>& polylines) {
    Toolpath toolpath;
    for (const std::vector<Vec3>& points : polylines) {
      PrintPath path;
      path.points = points;
      path.speed_mm_s = 20.0;
      path.source_index = static_cast<int>(toolpath.paths.size());
      toolpath.paths.push_back(path);
    }
    return toolpath;  // from and back to the origin
  };
  // a plan's joints within the travel every 0.5 ms, and its within_travel reports as
  // (path, enters at rest, leaves at rest, loops allowed)
  const auto check = [&](const Trajectory& plan) {
    JointVector joints;
    std::string why;
    for (double t = 0.0; t <= plan.duration_s(); t += 5e-4) {
      const bool reachable = stage->inverse(plan.at(t).pose(), joints, &why);
      EXPECT_TRUE(reachable) << "t = " << t << " s: " << why;
      if (!reachable) break;
    }
    std::vector<std::array<int, 4>> reports;
    for (const PlanDecision& d : plan.decisions()) {
      if (d.choice != "within_travel") continue;
      std::array<int, 4> report{d.path_index, -1, -1, -1};
      for (const PlanFigure& f : d.figures) {
        if (f.name == "enters_at_rest") report[1] = static_cast<int>(f.value);
        if (f.name == "leaves_at_rest") report[2] = static_cast<int>(f.value);
        if (f.name == "loops_allowed") report[3] = static_cast<int>(f.value);
      }
      reports.push_back(report);
    }
    return reports;
  };
  using Reports = std::vector<std::array<int, 4>>;
  {
    SCOPED_TRACE(
        "path 1 starts 0.5 mm from x = 50 at print speed towards -x, ends 0.5 mm "
        "from x = -50");
    const Trajectory plan = planner.plan_in_context(
        job({{{-49, -49, 0}, {49, -49, 0}, {49, 49, 0}}, {{49.5, 48, 0}, {-49.5, 48, 0}}}),
        stage_limits, context);
    EXPECT_EQ(check(plan), (Reports{{0, 0, 1, 1}, {1, 1, 1, 1}}));
  }
  {
    SCOPED_TRACE("a square 0.2 mm inside the travel: loops at its corners would leave it");
    const Trajectory plan = planner.plan_in_context(job({{{-49.8, -49.8, 0},
                                                          {49.8, -49.8, 0},
                                                          {49.8, 49.8, 0},
                                                          {-49.8, 49.8, 0},
                                                          {-49.8, -49.8, 0}}}),
                                                    stage_limits, context);
    EXPECT_EQ(check(plan), (Reports{{0, 1, 1, 0}}));
    for (const PlanDecision& d : plan.decisions()) EXPECT_NE(d.choice, "loop");
  }
  {
    SCOPED_TRACE("the same square at half the size: as if the travel had no end");
    const std::vector<std::vector<Vec3>> square{{{-24.9, -24.9, 0},
                                                 {24.9, -24.9, 0},
                                                 {24.9, 24.9, 0},
                                                 {-24.9, 24.9, 0},
                                                 {-24.9, -24.9, 0}}};
    const Trajectory plan = planner.plan_in_context(job(square), stage_limits, context);
    EXPECT_TRUE(check(plan).empty());
    const Trajectory free_plan = planner.plan_in_context(job(square), requested, context);
    EXPECT_EQ(plan.duration_s(), free_plan.duration_s());
    ASSERT_EQ(plan.decisions().size(), free_plan.decisions().size());
    for (size_t i = 0; i < plan.decisions().size(); ++i)
      EXPECT_EQ(plan.decisions()[i].choice, free_plan.decisions()[i].choice);
  }
}

// The delta's carriages' peak speed and acceleration along a plan, by finite differences of
// 1 ms samples of the inverse kinematics
struct CarriagePeaks {
  double speed = 0.0, acceleration = 0.0;
};
CarriagePeaks carriage_peaks(const LinearDelta& delta, const Trajectory& plan) {
  CarriagePeaks peaks;
  const double dt = 0.001;
  JointVector previous, before;
  for (double t = 0.0; t <= plan.duration_s(); t += dt) {
    JointVector joints;
    EXPECT_TRUE(delta.inverse(Pose(plan.at(t).position_mm), joints)) << t;
    if (!previous.empty())
      for (size_t j = 0; j < 3; ++j)
        peaks.speed = std::max(peaks.speed, std::abs(joints[j] - previous[j]) / dt);
    if (!before.empty())
      for (size_t j = 0; j < 3; ++j)
        peaks.acceleration = std::max(
            peaks.acceleration, std::abs(joints[j] - 2 * previous[j] + before[j]) / (dt * dt));
    before = previous;
    previous = joints;
  }
  return peaks;
}

// A slicer's jitter of 0.02 mm chords at 100 mm/s on the delta, where its limits over each
// chord's box allow that speed: a corner after an edge too short for a window of its own has
// its window taken on straight past the edge's end (39 mm here), where the delta's limits fall
// to 94 mm/s on x; planned under those, the window refused the whole plan ("needs 99.3 mm/s on
// axis x"). The window is planned under the limits over the corner's own edges; every axis
// keeps within the limits the machine maps over each edge's box.
TEST(UniformTimeLaw, ADeltaCornerAfterAShortEdgeIsWeighedUnderItsOwnLimits) {
  LinearDelta delta;
  const TcpLimits limits = delta.tcp_limits(MachineLimits::uniform(100.0, 1000.0));
  const std::vector<Vec3> jitter = {
      {16.4561, -8.7678, 0.2}, {16.4366, -8.7537, 0.2}, {16.4255, -8.7344, 0.2},
      {16.4064, -8.7441, 0.2}, {16.3866, -8.7544, 0.2}, {16.3947, -8.7509, 0.2},
      {16.4085, -8.7442, 0.2}, {16.4236, -8.7386, 0.2}, {16.4127, -8.7513, 0.2},
      {16.4100, -8.7609, 0.2}, {16.4258, -8.7712, 0.2}, {16.4343, -8.7849, 0.2},
      {16.4336, -8.8042, 0.2}, {16.4344, -8.7977, 0.2}, {16.4502, -8.8046, 0.2}};
  // (the premise: each chord's speed within the limits over its own box)
  for (size_t k = 0; k + 1 < jitter.size(); ++k) {
    const MachineLimits along = limits.along(jitter[k], jitter[k + 1]);
    const Vec3 u = (jitter[k + 1] - jitter[k]).normalized();
    for (int axis = 0; axis < 3; ++axis)
      ASSERT_LE(100.0 * std::abs(u[axis]), along.axes[axis].v_max_mm_s) << k;
  }
  PlanningContext context;
  DepositionSettings extrusion;
  extrusion.type = ProcessType::extrusion;
  extrusion.bead_width_mm = 0.45;
  context.process = std::make_shared<const DepositionSettings>(extrusion);
  Trajectory plan;
  ASSERT_NO_THROW(plan = UniformPlanner{UniformSettings{}}.plan_in_context(
                      polyline_job(jitter, 100.0), limits, context));
  // the carriages within their speed limit
  const CarriagePeaks peaks = carriage_peaks(delta, plan);
  EXPECT_GT(peaks.speed, 0.0);
  EXPECT_LE(peaks.speed, delta.joint_limits().front().v_max);
}

TEST(UniformTimeLaw, DeltaCarriagesWithinTheirLimits) {
  LinearDelta delta;
  ASSERT_EQ(delta.set_joint_limits(AxisLimits{200.0, 3000.0, 0.0}), "");
  const TcpLimits limits = delta.tcp_limits(MachineLimits::uniform(100.0, 1500.0, 60000.0));
  Toolpath toolpath = zig_zag(20.0);
  PlanningContext context;
  DepositionSettings extrusion;
  extrusion.type = ProcessType::extrusion;
  extrusion.bead_width_mm = 0.45;
  context.process = std::make_shared<const DepositionSettings>(extrusion);
  const Trajectory plan =
      UniformPlanner{UniformSettings{}}.plan_in_context(toolpath, limits, context);
  JointLimit carriage = delta.joint_limits().front();
  // the planner holds the TCP limits the machine maps over each move's box; the carriages stay
  // within theirs (jerk: the delta has no carriage jerk limit)
  const CarriagePeaks peaks = carriage_peaks(delta, plan);
  EXPECT_LE(peaks.speed, carriage.v_max);
  EXPECT_LE(peaks.acceleration, carriage.a_max);
  EXPECT_GT(peaks.speed, 0.0);
}

// Plans an extrusion polyline at `speed` with curved ramps and without (speeds changing on the
// lines only) and checks the ramps' plan: quicker than below_ratio x the other, the same corner
// choices, within the tolerance, every axis within its limits by finite differences, the
// extruder's deceleration rule kept (the led flow v + tau dv/dt never below 0), at rest at the
// path's ends. Returns the two plans (with ramps first).
std::pair<Trajectory, Trajectory> expect_quicker_with_curved_ramps(const std::vector<Vec3>& points,
                                                                   double speed,
                                                                   const MachineLimits& axes,
                                                                   double below_ratio) {
  const UniformSettings settings;
  UniformSettings lines_only;
  lines_only.curved_ramps = false;
  const PlanningContext extrusion = process_context(ProcessType::extrusion);
  const double lag_s = extrusion.process->tau_s;
  MachineLimits jerk_limited = axes;
  for (AxisLimits& axis : jerk_limited.axes)
    axis.j_max_mm_s3 = axis.a_max_mm_s2 / settings.jerk_ramp_s;
  const Toolpath toolpath = polyline_job(points, speed);
  Trajectory plan = UniformPlanner{settings}.plan_in_context(toolpath, axes, extrusion);
  Trajectory chord_by_chord = UniformPlanner{lines_only}.plan_in_context(toolpath, axes, extrusion);
  EXPECT_LT(plan.duration_s(), below_ratio * chord_by_chord.duration_s());
  EXPECT_EQ(plan.decisions().size(), chord_by_chord.decisions().size());
  for (size_t k = 0; k < std::min(plan.decisions().size(), chord_by_chord.decisions().size()); ++k)
    EXPECT_EQ(plan.decisions()[k].choice, chord_by_chord.decisions()[k].choice) << "corner " << k;
  const MotionSamples samples = sample_trajectory(plan, 1e-4);
  EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm);
  testing_support::expect_finite_difference_limits(plan, jerk_limited, 0.01);
  for (size_t k = 0; k < samples.size(); ++k) {
    const Vec3& v = samples.velocity_mm_s[k];
    if (!samples.depositing[k] || !(v.norm() > 0.03 * speed)) continue;
    const double rate = v.dot(plan.at(samples.t_s[k]).acceleration_mm_s2) / v.norm();
    EXPECT_GE(v.norm() + lag_s * rate, -0.01 * speed) << "t " << samples.t_s[k];
  }
  for (const double t : {0.0, plan.duration_s()}) {
    EXPECT_LT(plan.at(t).velocity_mm_s.norm(), 1e-9) << "t " << t;
  }
  EXPECT_LT((plan.at(0.0).position_mm - points.front()).norm(), 1e-9);
  EXPECT_LT((plan.at(plan.duration_s()).position_mm - points.back()).norm(), 1e-9);
  return {std::move(plan), std::move(chord_by_chord)};
}

// A print path that comes to rest on a curve (a slicer's rounded corner at a perimeter's end:
// a 10 mm line, then a quarter circle of 3 mm radius in 0.2 mm chords), or starts from rest on
// one (the same reversed), at 30 mm/s. The chords' blends leave the lines between them too
// short for the speed to change on: the look-ahead alone crawls the curve chord by chord,
// and coming to rest under the extruder's deceleration rule (|dv/dt| <= v / tau) that costs
// most. A curved ramp changes speed on the curve itself: quicker than with curved_ramps off
// (ending on the curve by more than 10 %; starting on it, where accelerations have no such
// rule, by less), with the checks of expect_quicker_with_curved_ramps.
TEST(UniformTimeLaw, RampToAndFromRestOnACurveChangesSpeedOnTheCurve) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const double r = 3.0;
  std::vector<Vec3> ending = {Vec3(0, 0, 0.2)};
  const int chords = static_cast<int>(std::ceil(0.5 * kPi * r / 0.2));
  for (int k = 0; k <= chords; ++k) {
    const double angle = -0.5 * kPi + 0.5 * kPi * k / chords;
    ending.emplace_back(10.0 + r * std::cos(angle), r + r * std::sin(angle), 0.2);
  }
  const std::vector<Vec3> starting(ending.rbegin(), ending.rend());
  {
    SCOPED_TRACE("ends on the curve");
    expect_quicker_with_curved_ramps(ending, 30.0, axes, 0.9);
  }
  {
    SCOPED_TRACE("starts on the curve");
    expect_quicker_with_curved_ramps(starting, 30.0, axes, 1.0);
  }
}

// A curve between two sharp corners, none of it near rest: a 20 mm line, a 90 deg turn onto
// half an ellipse (semi-axes 3 and 5 mm, 80 chords, no circle an arc run would take), a 70 deg
// turn onto a 15 mm line, at 30 mm/s. Each sharp corner's slow blend holds the chords next to
// it below their caps; a curved ramp from (and to) that held corner changes speed on the
// curve: quicker than speeds changing on the lines only, and the corner before the exit's
// sharp turn taken faster. (Ramps only out of and into rest gain nothing here: the rests sit
// at the ends of the long lines.)
TEST(UniformTimeLaw, RampOutOfAndIntoAHeldSharpCornerChangesSpeedOnTheCurve) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  std::vector<Vec3> points = {Vec3(-10, 0, 0.2), Vec3(10, 0, 0.2)};
  const int chords = 80;
  for (int k = 1; k <= chords; ++k) {
    const double angle = kPi * k / chords;
    points.emplace_back(7.0 + 3.0 * std::cos(angle), 5.0 * std::sin(angle), 0.2);
  }
  points.emplace_back(-10, -5, 0.2);
  const auto [plan, chord_by_chord] = expect_quicker_with_curved_ramps(points, 30.0, axes, 0.999);
  // the last corner reported before the exit's sharp turn (points[chords + 1]): its speed
  const auto last_before_exit = [&](const Trajectory& t) {
    std::pair<int, double> found{-1, 0.0};
    for (const PlanDecision& d : t.decisions())
      if (d.point_index > found.first && d.point_index < chords + 1)
        for (const PlanFigure& f : d.figures)
          if (f.name == "speed_mm_s") found = {d.point_index, f.value};
    return found;
  };
  const std::pair<int, double> ramped = last_before_exit(plan);
  const std::pair<int, double> crawled = last_before_exit(chord_by_chord);
  ASSERT_GT(ramped.first, chords / 2);
  ASSERT_EQ(ramped.first, crawled.first);
  EXPECT_GT(ramped.second, 1.05 * crawled.second) << "corner " << ramped.first;
}

// A 20 mm line, a sharp turn onto half an ellipse (semi-axes 3 and 5 mm) in `chords` chords,
// and a near reversal onto a last line (a loop), at 60 mm/s
Toolpath ellipse_into_a_loop(int chords) {
  std::vector<Vec3> points = {Vec3(-10, 0, 0.2), Vec3(10, 0, 0.2)};
  for (int k = 1; k <= chords; ++k) {
    const double angle = kPi * k / chords;
    points.emplace_back(7.0 + 3.0 * std::cos(angle), 5.0 * std::sin(angle), 0.2);
  }
  points.emplace_back(3, 10, 0.2);
  return polyline_job(points, 60.0);
}

// The same curve in more chords plans in about the same time. Half an ellipse (semi-axes 3
// and 5 mm) entered from a 20 mm line at a sharp turn and left by a near reversal (a loop: the
// line ends at rest), in 40 to 200 chords at 60 mm/s, extrusion. Which chords an arc run takes
// and which lines the merge joins change with the count; a curved ramp may now start or end
// next to a run, and a ramp's blends are judged at their own caps, so the crawl into the loop
// no longer depends on them: every count within 3 % of the quickest (it was 10 %, 160 and 200
// chords crawling into the loop), each quicker than with curved_ramps off and within limits.
TEST(UniformTimeLaw, MoreChordsOfTheSameCurveAreNotSlower) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const PlanningContext extrusion = process_context(ProcessType::extrusion);
  UniformSettings lines_only;
  lines_only.curved_ramps = false;
  MachineLimits jerk_limited = axes;
  for (AxisLimits& axis : jerk_limited.axes)
    axis.j_max_mm_s3 = axis.a_max_mm_s2 / UniformSettings().jerk_ramp_s;
  double quickest = std::numeric_limits<double>::infinity(), slowest = 0.0;
  for (const int chords : {40, 80, 120, 160, 200}) {
    SCOPED_TRACE("chords " + std::to_string(chords));
    const Toolpath toolpath = ellipse_into_a_loop(chords);
    const Trajectory plan =
        UniformPlanner{UniformSettings{}}.plan_in_context(toolpath, axes, extrusion);
    const Trajectory chord_by_chord =
        UniformPlanner{lines_only}.plan_in_context(toolpath, axes, extrusion);
    EXPECT_LT(plan.duration_s(), chord_by_chord.duration_s());
    EXPECT_LE(path_error(sample_trajectory(plan, 1e-4), toolpath).max_mm,
              UniformSettings().tolerance_mm);
    testing_support::expect_finite_difference_limits(plan, jerk_limited, 0.01);
    quickest = std::min(quickest, plan.duration_s());
    slowest = std::max(slowest, plan.duration_s());
  }
  EXPECT_LT(slowest, 1.03 * quickest);
}

// The same curve in more chords, aerosol (the stream cannot follow the speed: a corner that
// cannot keep it is looped, or a run of them taken as one arc). In 60 chords the merged edges
// are too short for a run's transitions at the print speed; sized for less (the run below the
// print speed, weighed against its corners) the run fits: 60 chords plan within 1.25 x the
// quickest count (was 2.1 x: 15 corners looped one by one), each within tolerance and limits.
TEST(UniformTimeLaw, MoreChordsOfTheSameCurveAerosol) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const PlanningContext aerosol = process_context(ProcessType::aerosol);
  MachineLimits jerk_limited = axes;
  for (AxisLimits& axis : jerk_limited.axes)
    axis.j_max_mm_s3 = axis.a_max_mm_s2 / UniformSettings().jerk_ramp_s;
  std::map<int, double> duration_s;
  std::map<int, int> arc_corners;
  for (const int chords : {40, 60, 80, 120}) {
    SCOPED_TRACE("chords " + std::to_string(chords));
    const Toolpath toolpath = ellipse_into_a_loop(chords);
    const Trajectory plan =
        UniformPlanner{UniformSettings{}}.plan_in_context(toolpath, axes, aerosol);
    EXPECT_LE(path_error(sample_trajectory(plan, 1e-4), toolpath).max_mm,
              UniformSettings().tolerance_mm);
    testing_support::expect_finite_difference_limits(plan, jerk_limited, 0.01);
    duration_s[chords] = plan.duration_s();
    for (const PlanDecision& d : plan.decisions()) arc_corners[chords] += d.choice == "arc";
  }
  double quickest = std::numeric_limits<double>::infinity();
  for (const auto& [chords, t] : duration_s) quickest = std::min(quickest, t);
  for (const auto& [chords, t] : duration_s) {
    EXPECT_LT(t, 1.25 * quickest) << chords << " chords";
    EXPECT_GT(arc_corners[chords], 0) << chords << " chords";
  }
}

}  // namespace
}  // namespace depotwin
