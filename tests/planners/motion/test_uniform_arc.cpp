// `uniform`'s arc runs (arc_run.hpp): a run of corners along a finely chorded circle taken as
// one clothoid-arc-clothoid curve at the print speed, where each corner alone cannot keep it.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "core/error.hpp"
#include "core/segment_distance.hpp"
#include "metrics/motion_metrics.hpp"
#include "planners/motion/plan_figure.hpp"
#include "planners/motion/polyline_job.hpp"
#include "planners/motion/process_context.hpp"
#include "planners/motion/uniform/arc_run.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

namespace depotwin {
namespace {

// A slot's outline: a 10 mm line along x, a half circle of radius r in chords of about 0.2 mm
// (turning left), and the line back, at z = 0.2.
std::vector<Vec3> slot(double r) {
  std::vector<Vec3> points = {Vec3(0, 0, 0.2), Vec3(10, 0, 0.2)};
  const int chords = static_cast<int>(std::ceil(kPi * r / 0.2));
  for (int k = 1; k <= chords; ++k) {
    const double angle = -0.5 * kPi + kPi * k / chords;
    points.emplace_back(10.0 + r * std::cos(angle), r + r * std::sin(angle), 0.2);
  }
  points.emplace_back(0, 2 * r, 0.2);
  return points;
}

// the runs the planner finds on a polyline (merged and measured as it does)
struct Found {
  PrintChain given;
  MergedChain merged;
  std::vector<CornerGeometry> geometry;
  std::vector<std::shared_ptr<const ArcRun>> runs;
};
Found find_runs(const std::vector<Vec3>& points, double speed, const TcpLimits& limits,
                bool at_speed, double tolerance = 0.05) {
  Found found;
  found.given = print_chains(polyline_job(points, speed)).front();
  found.merged = merge_fine_edges(found.given, 0.5 * tolerance);
  found.geometry =
      corner_geometry(found.merged.chain.points, tolerance, found.merged.edge_error_mm);
  PathMotionOptions options;
  options.enter_at_speed = options.leave_at_speed = at_speed;
  found.runs = find_arc_runs(found.merged, found.given, found.geometry, tolerance, limits, options);
  return found;
}

// The largest acceleration and jerk of any axis over [t0, t1], by finite differences of the
// positions every dt (the XY stage's and the gantry's joints are their axes)
struct AxisPeaks {
  double acceleration = 0.0, jerk = 0.0;
};
AxisPeaks finite_difference_peaks(const Trajectory& plan, double t0, double t1, double dt) {
  std::vector<Vec3> q;
  for (double t = t0; t <= t1; t += dt) q.push_back(plan.at(t).position_mm);
  AxisPeaks peaks;
  for (size_t k = 0; k + 3 < q.size(); ++k) {
    peaks.acceleration = std::max(
        peaks.acceleration, ((q[k + 2] - 2 * q[k + 1] + q[k]) / (dt * dt)).cwiseAbs().maxCoeff());
    peaks.jerk = std::max(
        peaks.jerk,
        ((q[k + 3] - 3 * q[k + 2] + 3 * q[k + 1] - q[k]) / (dt * dt * dt)).cwiseAbs().maxCoeff());
  }
  return peaks;
}

// The curve of a run: continuous in position, tangent and curvature, its derivatives those of
// its position (central differences), the curvature 0 at its ends and 1 / R on the arc; it
// leaves and joins its end edges tangentially, stays within the tolerance of the given
// polyline, and keeps the limits at the print speed.
TEST(ArcRun, CurveIsCurvatureContinuousTangentToItsEdgesAndWithinTheTolerance) {
  const TcpLimits limits = with_jerk_limits(MachineLimits::uniform(100.0, 1000.0), 0.01);
  const double speed = 50.0, tolerance = 0.05, r = 3.0;
  const Found found = find_runs(slot(r), speed, limits, true, tolerance);
  ASSERT_EQ(found.runs.size(), 1u);
  const ArcRun& run = *found.runs.front();
  const PrintChain& chain = found.merged.chain;
  // the whole half circle: every corner but those of the straight lines' ends
  EXPECT_EQ(run.first_corner(), 1u);
  EXPECT_EQ(run.last_corner(), chain.points.size() - 2);
  EXPECT_NEAR(run.radius_mm(), r, tolerance);
  EXPECT_GE(run.speed_bound_mm_s, speed * (1 - 1e-9));

  // derivatives by central differences, inside each section
  const double h = 1e-4;
  double s0 = 0.0;
  for (int section = 0; section < 3; ++section) {
    const double length = run.section_length_mm(section);
    ASSERT_GT(length, 10 * h);
    for (int k = 1; k < 10; ++k) {
      const double s = s0 + length * k / 10.0;
      Vec3 p, d1, d2, d3, pa, d1a, d2a, d3a, pb, d1b, d2b, d3b;
      run.at(s, p, d1, d2, d3);
      run.at(s - h, pa, d1a, d2a, d3a);
      run.at(s + h, pb, d1b, d2b, d3b);
      EXPECT_NEAR(d1.norm(), 1.0, 1e-12);
      EXPECT_LT(((pb - pa) / (2 * h) - d1).norm(), 1e-6) << "section " << section;
      EXPECT_LT(((d1b - d1a) / (2 * h) - d2).norm(), 1e-6) << "section " << section;
      EXPECT_LT(((d2b - d2a) / (2 * h) - d3).norm(), 1e-5) << "section " << section;
      if (section == 1) {
        EXPECT_NEAR(d2.norm(), 1.0 / run.radius_mm(), 1e-12);
      }
    }
    // continuity where the sections meet
    const double joint = s0 + length;
    if (section < 2) {
      Vec3 p, d1, d2, d3, q, e1, e2, e3;
      run.at(joint - 1e-9, p, d1, d2, d3);
      run.at(joint + 1e-9, q, e1, e2, e3);
      EXPECT_LT((p - q).norm(), 1e-8);
      EXPECT_LT((d1 - e1).norm(), 1e-8);
      EXPECT_LT((d2 - e2).norm(), 1e-7);
    }
    s0 += length;
  }
  // the ends: on their edges, along them, at zero curvature
  Vec3 p, d1, d2, d3;
  const size_t a = run.first_corner(), b = run.last_corner();
  run.at(0.0, p, d1, d2, d3);
  EXPECT_LT(point_segment_distance(p, chain.points[a - 1], chain.points[a]), 1e-9);
  EXPECT_NEAR((chain.points[a] - p).norm(), run.entry_trim_mm, 1e-9);
  EXPECT_LT((d1 - found.geometry[a].d_in).norm(), 1e-12);
  EXPECT_LT(d2.norm(), 1e-12);
  run.at(run.length_mm(), p, d1, d2, d3);
  EXPECT_LT(point_segment_distance(p, chain.points[b], chain.points[b + 1]), 1e-9);
  EXPECT_NEAR((p - chain.points[b]).norm(), run.exit_trim_mm, 1e-9);
  EXPECT_LT((d1 - found.geometry[b].d_out).norm(), 1e-9);
  EXPECT_LT(d2.norm(), 1e-9);
  // within the tolerance of the given polyline, as reported
  double farthest = 0.0;
  for (double s = 0.0; s <= run.length_mm(); s += 0.001) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t e = 0; e + 1 < found.given.points.size(); ++e)
      nearest = std::min(nearest, point_segment_distance(run.position(s), found.given.points[e],
                                                         found.given.points[e + 1]));
    farthest = std::max(farthest, nearest);
  }
  EXPECT_LE(farthest, run.deviation_mm);
  EXPECT_LE(run.deviation_mm, tolerance);
  EXPECT_GT(farthest, 0.5 * run.deviation_mm);  // (the reported figure is not slack)

  // at the print speed every axis keeps its acceleration and jerk limits (the blends' share)
  const MachineLimits& axes = limits.requested();
  for (double s = 0.0; s <= run.length_mm(); s += 0.0005) {
    run.at(s, p, d1, d2, d3);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(speed * speed * std::abs(d2[axis]), axes.axes[axis].a_max_mm_s2 * (1 + 1e-9));
      EXPECT_LE(std::pow(speed, 3) * std::abs(d3[axis]), axes.axes[axis].j_max_mm_s3 * (1 + 1e-9));
    }
  }
}

// Where a run is not for: corners that keep the print speed on their own (a slower print, a
// larger circle), a helix (not one plane), an oriented chain; and no run's curve leaves the
// tolerance of a given polyline whose points are noisy.
TEST(ArcRun, OnlyWhereCornersCannotKeepTheSpeedAndWithinTheTolerance) {
  const TcpLimits limits = with_jerk_limits(MachineLimits::uniform(100.0, 1000.0), 0.01);
  EXPECT_EQ(find_runs(slot(3.0), 50.0, limits, true).runs.size(), 1u);
  EXPECT_TRUE(find_runs(slot(3.0), 20.0, limits, true).runs.empty());
  EXPECT_TRUE(find_runs(slot(12.0), 50.0, limits, true).runs.empty());
  // a helix: the same slot climbing 0.5 mm over its half circle
  std::vector<Vec3> helix = slot(3.0);
  for (size_t k = 2; k + 1 < helix.size(); ++k)
    helix[k].z() += 0.5 * static_cast<double>(k - 1) / static_cast<double>(helix.size() - 3);
  helix.back().z() = helix[helix.size() - 2].z();
  EXPECT_TRUE(find_runs(helix, 50.0, limits, true).runs.empty());
  // noisy points: every run found stays within the tolerance of the given polyline
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  int with_runs = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3> noisy = slot(3.0);
    for (size_t k = 2; k + 2 < noisy.size(); ++k) noisy[k] += Vec3(noise(rng), noise(rng), 0.0);
    const Found found = find_runs(noisy, 50.0, limits, true);
    with_runs += found.runs.empty() ? 0 : 1;
    for (const auto& run : found.runs) {
      for (double s = 0.0; s <= run->length_mm(); s += 0.002) {
        double nearest = std::numeric_limits<double>::infinity();
        for (size_t e = 0; e + 1 < noisy.size(); ++e)
          nearest =
              std::min(nearest, point_segment_distance(run->position(s), noisy[e], noisy[e + 1]));
        ASSERT_LE(nearest, 0.05) << "trial " << trial << " s " << s;
      }
    }
  }
  EXPECT_GT(with_runs, 0);
}

// The planner on the slot at 50 mm/s on a 1000 mm/s^2 stage (each corner alone could keep
// about 42 mm/s): aerosol prints it all at the print speed, every half-circle corner reported
// as one arc run, within the tolerance, every axis within its acceleration and jerk limits by
// finite differences; extrusion takes the run at print speed too, ramping on the lines.
TEST(UniformPlanner, ChordedHalfCircleIsOneArcAtPrintSpeed) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const double speed = 50.0, r = 3.0;
  const std::vector<Vec3> points = slot(r);
  const Toolpath toolpath = polyline_job(points, speed);
  const UniformSettings settings;
  const UniformPlanner planner{settings};
  double length = 0.0;
  for (size_t k = 0; k + 1 < points.size(); ++k) length += (points[k + 1] - points[k]).norm();
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    SCOPED_TRACE(process_type_name(type));
    const Trajectory plan = planner.plan_in_context(toolpath, axes, process_context(type));
    int arcs = 0;
    for (const PlanDecision& decision : plan.decisions()) {
      ASSERT_EQ(decision.kind, "corner");
      EXPECT_EQ(decision.choice, "arc") << "point " << decision.point_index;
      EXPECT_NEAR(figure(decision, "speed_mm_s"), speed, 1e-9 * speed);
      EXPECT_NEAR(figure(decision, "radius_mm"), r, settings.tolerance_mm);
      EXPECT_LE(figure(decision, "deviation_mm"), settings.tolerance_mm);
      ++arcs;
    }
    EXPECT_GT(arcs, 10);
    const MotionSamples samples = sample_trajectory(plan, 1e-4);
    EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm);
    if (type == ProcessType::aerosol) {
      // at the print speed throughout (the arc's samples interpolated: to 1e-5)
      for (size_t k = 0; k < samples.size(); ++k) {
        if (!samples.depositing[k]) continue;
        EXPECT_NEAR(samples.velocity_mm_s[k].norm(), speed, 1e-5 * speed) << "t " << samples.t_s[k];
      }
      double printing_s = 0.0;
      for (const TrajectoryPiece& piece : plan.pieces())
        if (piece.depositing) printing_s += piece.t_end_s - piece.t_begin_s;
      EXPECT_LE(printing_s, length / speed);
      EXPECT_GT(printing_s, 0.99 * length / speed);
    }
    // every axis by finite differences every millisecond (the slack covers the cubic
    // interpolation of the samples)
    const double j_max = axes.axes[0].a_max_mm_s2 / settings.jerk_ramp_s;
    const AxisPeaks peaks = finite_difference_peaks(plan, 0.0, plan.duration_s(), 0.001);
    EXPECT_LE(peaks.acceleration, axes.axes[0].a_max_mm_s2 * (1 + 1e-3));
    EXPECT_LE(peaks.jerk, j_max * (1 + 1e-2));
    EXPECT_GT(peaks.acceleration, 0.5 * axes.axes[0].a_max_mm_s2);
    // quicker than its corners one by one (aerosol: loops; extrusion: slowed corners)
    UniformSettings one_by_one;
    one_by_one.arc_runs = false;
    const Trajectory corners =
        UniformPlanner{one_by_one}.plan_in_context(toolpath, axes, process_context(type));
    EXPECT_LT(plan.duration_s(), corners.duration_s());
  }
}

// A closed 4 mm circle of 0.2 mm chords at 50 mm/s, aerosol: its merged closing chords are too
// short for the transitions a tangent start and end need, so the run starts and ends at the
// chain's end point itself (free ends): the whole circle one run at the print speed, within
// the tolerance, entered and left along the run's own end directions, and quicker than the
// constant speed its corners one by one allow (42.5 mm/s).
TEST(UniformPlanner, ClosedAerosolCircleIsOneArcRunFromEndToEnd) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const double speed = 50.0, r = 4.0;
  const int chords = 126;
  std::vector<Vec3> circle;
  for (int k = 0; k <= chords; ++k) {
    const double angle = 2.0 * kPi * k / chords;
    circle.emplace_back(r * std::cos(angle), r * std::sin(angle), 0.2);
  }
  const Toolpath toolpath = polyline_job(circle, speed);
  const UniformSettings settings;
  const PlanningContext aerosol = process_context(ProcessType::aerosol);
  const Trajectory plan = UniformPlanner{settings}.plan_in_context(toolpath, axes, aerosol);
  int arcs = 0;
  for (const PlanDecision& decision : plan.decisions()) {
    ASSERT_EQ(decision.kind, "corner");
    EXPECT_EQ(decision.choice, "arc");
    EXPECT_EQ(figure(decision, "run_corners"), static_cast<double>(plan.decisions().size()));
    EXPECT_NEAR(figure(decision, "radius_mm"), r, settings.tolerance_mm);
    ++arcs;
  }
  EXPECT_GT(arcs, 20);
  const MotionSamples samples = sample_trajectory(plan, 1e-4);
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!samples.depositing[k]) continue;
    EXPECT_NEAR(samples.velocity_mm_s[k].norm(), speed, 1e-5 * speed) << "t " << samples.t_s[k];
  }
  EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm);
  // the transitions meet the run where it starts and ends, at its velocity: the plan's
  // samples are continuous in position and velocity there
  for (const TrajectoryPiece& piece : plan.pieces()) {
    for (const double t : {piece.t_begin_s, piece.t_end_s}) {
      const TrajectorySample before = plan.at(t - 1e-7), after = plan.at(t + 1e-7);
      EXPECT_LT((before.position_mm - after.position_mm).norm(), 1e-4) << "t " << t;
      EXPECT_LT((before.velocity_mm_s - after.velocity_mm_s).norm(), 0.1) << "t " << t;
    }
  }
  UniformSettings one_by_one;
  one_by_one.arc_runs = false;
  EXPECT_LT(plan.duration_s(),
            UniformPlanner{one_by_one}.plan_in_context(toolpath, axes, aerosol).duration_s());
}

}  // namespace
}  // namespace depotwin

namespace depotwin {
namespace {

// Where even the arc cannot take the print speed (a 2 mm radius at 50 mm/s needs 1250 mm/s^2
// of a 1000 mm/s^2 stage), a run is sized for 0.9 of what its arc allows, sqrt(0.99 a R), and
// weighed against its corners' own choices (the bound below allows for the run's radius being
// within the tolerance of the circle's). Extrusion, whose bead follows the speed: the slot's
// half circle is one run at that speed, quicker than its slowed corners. Aerosol, whose stream
// lays a run below the print speed thicker (1.25 x here, and on the ramps to it): a closed
// 2 mm circle is one run, where its corners' loops would leave the chords between them
// barely open (a 20 ms shutter); with a 1 ms shutter the loops' predicted errors are less and
// they are kept at the default time_weight, and at 2 mm/s the run's 3.9 s saved are worth
// more.
TEST(UniformPlanner, ArcRunBelowThePrintSpeedIsWeighedAgainstItsCorners) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const double speed = 50.0, r = 2.0;
  // (the run's own radius: within the tolerance of the circle's)
  const double arc_limit = std::sqrt(0.99 * axes.axes[0].a_max_mm_s2 * (r + 0.05));
  UniformSettings one_by_one;
  one_by_one.arc_runs = false;

  const Toolpath slot_job = polyline_job(slot(r), speed);
  const PlanningContext extrusion = process_context(ProcessType::extrusion);
  const Trajectory plan =
      UniformPlanner{UniformSettings{}}.plan_in_context(slot_job, axes, extrusion);
  int arcs = 0;
  for (const PlanDecision& decision : plan.decisions()) {
    if (decision.choice != "arc") continue;
    ++arcs;
    EXPECT_LE(figure(decision, "speed_mm_s"), 0.9 * arc_limit * (1 + 1e-9));
    EXPECT_GT(figure(decision, "speed_mm_s"), 0.85 * arc_limit);
  }
  EXPECT_GT(arcs, 10);
  EXPECT_LE(path_error(sample_trajectory(plan, 1e-4), slot_job).max_mm, 0.05);
  EXPECT_LT(plan.duration_s(),
            UniformPlanner{one_by_one}.plan_in_context(slot_job, axes, extrusion).duration_s());

  std::vector<Vec3> circle;
  for (int k = 0; k <= 63; ++k) {
    const double angle = 2.0 * kPi * k / 63;
    circle.emplace_back(r * std::cos(angle), r * std::sin(angle), 0.2);
  }
  const Toolpath circle_job = polyline_job(circle, speed);
  const auto arc_corners = [](const Trajectory& planned) {
    int count = 0;
    for (const PlanDecision& decision : planned.decisions()) count += decision.choice == "arc";
    return count;
  };
  // the scenario's shutter (20 ms): the loops' lines of 0.63 mm (13 ms) would barely open
  const PlanningContext aerosol = process_context(ProcessType::aerosol);
  EXPECT_GT(
      arc_corners(UniformPlanner{UniformSettings{}}.plan_in_context(circle_job, axes, aerosol)),
      10);
  // a shutter of 1 ms: the loops' own predicted errors stand
  PlanningContext quick_shutter = aerosol;
  quick_shutter.shutter_time_s = 0.001;
  const Trajectory by_default =
      UniformPlanner{UniformSettings{}}.plan_in_context(circle_job, axes, quick_shutter);
  EXPECT_EQ(arc_corners(by_default), 0);
  UniformSettings hurried;
  hurried.time_weight_mm_s = 2.0;
  const Trajectory hurried_plan =
      UniformPlanner{hurried}.plan_in_context(circle_job, axes, quick_shutter);
  EXPECT_GT(arc_corners(hurried_plan), 10);
  EXPECT_LT(hurried_plan.duration_s(), 0.25 * by_default.duration_s());
  const MotionSamples samples = sample_trajectory(hurried_plan, 1e-4);
  EXPECT_LE(path_error(samples, circle_job).max_mm, 0.05);
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!samples.depositing[k]) continue;
    EXPECT_LE(samples.velocity_mm_s[k].norm(), 0.9 * arc_limit * (1 + 1e-5));
  }
}

}  // namespace
}  // namespace depotwin

namespace depotwin {
namespace {

// A slicer's hole: an extrusion path once around a circle of 0.2 mm chords, from rest to rest
// at its first point, at 50 mm/s on a 1000 mm/s^2 stage. The whole chain is one run whose
// curve starts and ends at that point (free ends, the circle fitted through the ends too),
// its speed changing on the curve: line_profile's law in arc length (decelerations under the
// flow lag's rule), its acceleration and jerk lowered until every axis keeps its limits with
// the curve's own terms. At 4 mm the corners alone cannot keep 50 mm/s (each was slowed:
// 1.11 s); at 6 mm each can, but their lines ramp one at a time between blends at constant
// speeds (1.31 s). Checked: every corner in the run, the plan from rest to rest at the first
// point, the print speed reached and not passed, within the tolerance, every axis within its
// acceleration and jerk limits by finite differences, the led flow command never below 0
// (v + lag dv/dt, above the lag rule's last 3 %), under 0.8 x the corners one by one with
// speeds changing on the lines only, and quicker than them with curved ramps too (0.91 s and
// 1.14 s).
TEST(UniformPlanner, ExtrusionHoleFromRestIsOneRunRampingOnTheCurve) {
  const MachineLimits axes = MachineLimits::uniform(100.0, 1000.0);
  const double speed = 50.0;
  const UniformSettings settings;
  UniformSettings one_by_one;
  one_by_one.arc_runs = false;
  UniformSettings one_by_one_on_lines = one_by_one;
  one_by_one_on_lines.curved_ramps = false;
  const PlanningContext extrusion = process_context(ProcessType::extrusion);
  const double lag_s = extrusion.process->tau_s;
  for (const double r : {4.0, 6.0}) {
    SCOPED_TRACE("r " + std::to_string(r));
    const int chords = static_cast<int>(std::ceil(2.0 * kPi * r / 0.2));
    std::vector<Vec3> hole;
    for (int k = 0; k <= chords; ++k) {
      const double angle = 2.0 * kPi * k / chords;
      hole.emplace_back(10.0 + r * std::cos(angle), 5.0 + r * std::sin(angle), 0.2);
    }
    // the run itself: the whole chain, from its first point to its last
    const TcpLimits limits = with_jerk_limits(axes, settings.jerk_ramp_s);
    const Found found = find_runs(hole, speed, limits, false, settings.tolerance_mm);
    ASSERT_EQ(found.runs.size(), 1u);
    const ArcRun& run = *found.runs.front();
    EXPECT_TRUE(run.from_rest_to_rest);
    EXPECT_EQ(run.first_corner(), 1u);
    EXPECT_EQ(run.last_corner(), found.merged.chain.points.size() - 2);
    EXPECT_EQ(run.start_mm(), hole.front());
    EXPECT_EQ(run.end_mm(), hole.back());
    EXPECT_NEAR(run.radius_mm(), r, settings.tolerance_mm);
    // planned as given, the print speed is still checked against each axis' v_max on every
    // edge: at 50 mm/s on axes of 45 mm/s, an InputError
    {
      std::vector<CornerPlan> corners(found.merged.chain.points.size());
      for (size_t i = run.first_corner(); i <= run.last_corner(); ++i) {
        corners[i].treatment = CornerTreatment::arc;
        corners[i].arc = found.runs.front();
      }
      PathMotionOptions at_rest;
      EXPECT_THROW(
          plan_chain(found.merged.chain, found.geometry, corners,
                     with_jerk_limits(MachineLimits::uniform(45.0, 1000.0), 0.01), at_rest, 0.0),
          InputError);
    }

    const Toolpath toolpath = polyline_job(hole, speed);
    const Trajectory plan = UniformPlanner{settings}.plan_in_context(toolpath, axes, extrusion);
    for (const PlanDecision& decision : plan.decisions()) {
      ASSERT_EQ(decision.kind, "corner");
      EXPECT_EQ(decision.choice, "arc") << "point " << decision.point_index;
      EXPECT_EQ(figure(decision, "run_corners"), static_cast<double>(plan.decisions().size()));
    }
    // from rest to rest at the first point, printing throughout
    const TrajectoryPiece* first = nullptr;
    const TrajectoryPiece* last = nullptr;
    for (const TrajectoryPiece& piece : plan.pieces())
      if (piece.depositing) {
        if (first == nullptr) first = &piece;
        last = &piece;
      }
    ASSERT_NE(first, nullptr);
    for (const double t : {first->t_begin_s, last->t_end_s}) {
      const TrajectorySample at = plan.at(t);
      EXPECT_LT((at.position_mm - hole.front()).norm(), 1e-9) << "t " << t;
      EXPECT_LT(at.velocity_mm_s.norm(), 1e-9) << "t " << t;
    }
    const MotionSamples samples = sample_trajectory(plan, 1e-4);
    EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm);
    double peak_speed = 0.0;
    for (size_t k = 0; k < samples.size(); ++k) {
      if (!samples.depositing[k]) continue;
      const Vec3& v = samples.velocity_mm_s[k];
      peak_speed = std::max(peak_speed, v.norm());
      const TrajectorySample at = plan.at(samples.t_s[k]);
      const double rate = v.norm() > 0.0 ? v.dot(at.acceleration_mm_s2) / v.norm() : 0.0;
      if (v.norm() > 0.03 * speed) {
        EXPECT_GE(v.norm() + lag_s * rate, -0.01 * speed) << "t " << samples.t_s[k];
      }
    }
    // (between the 1 ms samples their cubic interpolation on the circle passes the speed by
    // about (v T / r)^2 / 8 of it)
    EXPECT_NEAR(peak_speed, speed, 1e-4 * speed);
    // every axis by finite differences every millisecond
    const double j_max = axes.axes[0].a_max_mm_s2 / settings.jerk_ramp_s;
    const AxisPeaks peaks = finite_difference_peaks(plan, first->t_begin_s, last->t_end_s, 0.001);
    EXPECT_LE(peaks.acceleration, axes.axes[0].a_max_mm_s2 * (1 + 1e-3));
    EXPECT_LE(peaks.jerk, j_max * (1 + 1e-2));
    // the centripetal v^2 / r at least, on the arc
    EXPECT_GT(peaks.acceleration, 0.99 * speed * speed / r);
    const double corners_on_lines_s =
        UniformPlanner{one_by_one_on_lines}.plan_in_context(toolpath, axes, extrusion).duration_s();
    EXPECT_LT(plan.duration_s(), 0.8 * corners_on_lines_s);
    const double corners_s =
        UniformPlanner{one_by_one}.plan_in_context(toolpath, axes, extrusion).duration_s();
    EXPECT_LT(plan.duration_s(), corners_s);
  }
}

}  // namespace
}  // namespace depotwin
