// The `uniform` planner end to end: an isolated straight line against the analytic
// jerk-limited move (`depotwin move --jmax` calls motion/sync.hpp's synchronized_move), the
// corner choices at 170 and 10 degree joints, the tolerance band, the extruder's flow through
// its lag, the material balance of the predicted deposit, and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "deposition/deposition_metrics.hpp"
#include "metrics/motion_metrics.hpp"
#include "motion/sync.hpp"
#include "planners/motion/plan_figure.hpp"
#include "planners/motion/transition.hpp"
#include "planners/motion/uniform/corner_choice.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

namespace depotwin {
namespace {

PlanningContext context_for(ProcessType type, double tau_s = 0.05, bool retract = false) {
  DepositionSettings process;
  process.type = type;
  process.tau_s = tau_s;
  process.retract = retract;
  process.bead_width_mm = 0.4;
  PlanningContext context;
  context.process = std::make_shared<const DepositionSettings>(process);
  return context;
}

Toolpath single_line(const Vec3& a, const Vec3& b, const Vec3& start, const Vec3& end) {
  Toolpath toolpath;
  toolpath.start_mm = start;
  toolpath.end_mm = end;
  PrintPath path;
  path.points = {a, b};
  path.speed_mm_s = 3.0;
  toolpath.paths.push_back(path);
  return toolpath;
}

// two edges of 4 mm meeting at the joint (interior) angle, printed at 3 mm/s
Toolpath joint(double interior_deg) {
  Toolpath toolpath;
  const double turn = deg_to_rad(180.0 - interior_deg);
  PrintPath path;
  path.speed_mm_s = 3.0;
  path.points = {Vec3(-4, 0, 0), Vec3(0, 0, 0), Vec3(4 * std::cos(turn), 4 * std::sin(turn), 0)};
  toolpath.start_mm = Vec3(-6, -2, 0);
  toolpath.end_mm = Vec3(6, -2, 0);
  toolpath.paths.push_back(path);
  return toolpath;
}

const MachineLimits kLimits = MachineLimits::uniform(4.0, 30.0, 600.0);

// Extrusion, from rest to rest along x, without a flow lag: the print piece is the double-S
// the `move --jmax` code path gives for the same boundary and limits (capped at the print
// speed), phase for phase.
TEST(UniformPlanner, IsolatedLineFromRestEqualsTheAnalyticJerkLimitedMove) {
  const Toolpath toolpath =
      single_line(Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(0, 0, 0), Vec3(10, 0, 0));
  const Trajectory plan = UniformPlanner{UniformSettings{}}.plan_in_context(
      toolpath, kLimits, context_for(ProcessType::extrusion, 0.0));
  ASSERT_EQ(plan.pieces().size(), 1u);
  const TrajectoryPiece& piece = plan.pieces().front();
  const AxisProfile& x = std::get<PhaseMotion>(piece.motion).axes[0];
  AxisMove move;
  move.boundary = AxisBoundary{0.0, 10.0, 0.0, 0.0};
  move.v_max = 3.0;
  move.a_max = 30.0;
  move.j_max = 600.0;
  const SynchronizedMove analytic = synchronized_move({move});
  ASSERT_NEAR(plan.duration_s(), analytic.duration_s, 1e-9);
  for (int k = 0; k <= 500; ++k) {
    const double t = analytic.duration_s * k / 500.0;
    const AxisState a = x.at(t), b = analytic.axes[0].at(t);
    EXPECT_NEAR(a.q, b.q, 1e-9) << "t " << t;
    EXPECT_NEAR(a.v, b.v, 1e-9) << "t " << t;
    EXPECT_NEAR(a.a, b.a, 1e-7) << "t " << t;
  }
}

// Aerosol: the line is entered and left at print speed; the move onto it is the synchronised
// jerk-limited minimum-time move to (start, v u) and the line itself is exactly L / v at v.
TEST(UniformPlanner, IsolatedAerosolLineIsEnteredAtSpeedByTheAnalyticMove) {
  const Vec3 a(1, 2, 0), b(7, 5, 0), start(-3, -1, 0), end(9, -2, 0);
  const Toolpath toolpath = single_line(a, b, start, end);
  const Trajectory plan = UniformPlanner{UniformSettings{}}.plan(toolpath, kLimits);
  ASSERT_EQ(plan.pieces().size(), 3u);
  const Vec3 u = (b - a).normalized();
  const SynchronizedMove entry =
      synchronized_move(axis_moves(start, Vec3::Zero(), a, 3.0 * u, kLimits));
  const TrajectoryPiece& first = plan.pieces()[0];
  ASSERT_NEAR(first.t_end_s, entry.duration_s, 1e-12);
  for (int k = 0; k <= 100; ++k) {
    const double t = entry.duration_s * k / 100.0;
    const TrajectorySample s = plan.at(t);
    for (int axis = 0; axis < 2; ++axis)
      EXPECT_NEAR(s.position_mm[axis], entry.axes[axis].at(t).q, 1e-12);
  }
  const TrajectoryPiece& line = plan.pieces()[1];
  EXPECT_TRUE(line.depositing);
  EXPECT_NEAR(line.t_end_s - line.t_begin_s, (b - a).norm() / 3.0, 1e-12);
  for (double t = line.t_begin_s; t < line.t_end_s; t += 0.01)
    EXPECT_NEAR(plan.at(t).velocity_mm_s.norm(), 3.0, 1e-12);
}

const PlanDecision& only_corner(const Trajectory& plan) {
  EXPECT_EQ(plan.decisions().size(), 1u);
  return plan.decisions().front();
}

// the largest relative speed error over the samples that deposit (the plan every 0.1 ms)
double max_speed_error(const Trajectory& plan) {
  return velocity_error(sample_trajectory(plan, 1e-4)).max_rel;
}

// At a 170 degree joint a blend within the tolerance keeps the print speed: the corner is
// printed at full speed with the path inside the band.
TEST(UniformPlanner, ShallowJointIsBlendedAtFullSpeed) {
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    const Trajectory plan =
        UniformPlanner{UniformSettings{}}.plan_in_context(joint(170.0), kLimits, context_for(type));
    const PlanDecision& corner = only_corner(plan);
    EXPECT_EQ(corner.choice, "blend");
    EXPECT_NEAR(figure(corner, "speed_mm_s"), 3.0, 1e-9);
    EXPECT_LE(figure(corner, "deviation_mm"), 0.05);
    if (type == ProcessType::aerosol) {
      EXPECT_LT(max_speed_error(plan), 1e-6);
    }
  }
}

// On a quicker machine (a_max 300 mm/s^2) a blend within the tolerance keeps the print speed at
// 28 degrees too, but there the two lines still overlap next to the corner: that blend's deposit
// is predicted and weighed against the loops, which trim the overlap (aerosol: a loop wins,
// cheaper by its predicted error than the blend by more than its time). At 100 degrees the
// lines do not overlap and the blend stays the only candidate.
TEST(UniformPlanner, SharpJointAtPrintSpeedIsWeighedAgainstLoops) {
  const MachineLimits quick = MachineLimits::uniform(20.0, 300.0, 30000.0);
  const UniformPlanner planner{UniformSettings{}};
  const PlanDecision sharp =
      only_corner(planner.plan_in_context(joint(28.0), quick, context_for(ProcessType::aerosol)));
  EXPECT_EQ(sharp.choice, "loop");
  EXPECT_GT(figure(sharp, "candidates"), 2.0);
  EXPECT_GT(figure(sharp, "blend_cost_mm"), figure(sharp, "cost_mm"));
  const PlanDecision open =
      only_corner(planner.plan_in_context(joint(100.0), quick, context_for(ProcessType::aerosol)));
  EXPECT_EQ(open.choice, "blend");
  EXPECT_EQ(figure(open, "candidates"), 1.0);
  EXPECT_NEAR(figure(open, "speed_mm_s"), 3.0, 1e-9);
}

// At a 10 degree joint no blend within the tolerance can keep the speed; aerosol does not slow
// down there (its thickness would follow 1/v): it closes the shutter and loops, and every
// deposited sample is at the print speed.
TEST(UniformPlanner, SharpJointIsNotPrintedAtAWrongSpeed) {
  const Trajectory plan = UniformPlanner{UniformSettings{}}.plan(joint(10.0), kLimits);
  const PlanDecision& corner = only_corner(plan);
  EXPECT_EQ(corner.choice, "loop");
  EXPECT_LT(max_speed_error(plan), 1e-6);
  // the loop is a shutter-closed piece between the two printed lines
  int closed_inside = 0;
  bool printed = false;
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (piece.depositing) printed = true;
    if (!piece.depositing && printed && piece.t_end_s < plan.duration_s()) ++closed_inside;
  }
  EXPECT_EQ(closed_inside, 1);
}

// The corner prediction runs in the corner's own frame: the same corner anywhere on the bed
// (here moved by a distance that is no multiple of the prediction's cells) gets the same
// candidates, predicted errors and choice, where a prediction on the bed's own cell grid
// differs by the discretisation.
TEST(UniformPlanner, CornerChoiceDoesNotDependOnWhereTheCornerLies) {
  const Vec3 shift(23.713, -41.327, 0.0);
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    for (const double interior_deg : {45.0, 100.0}) {
      SCOPED_TRACE(std::string(process_type_name(type)) + " " + std::to_string(interior_deg));
      const Toolpath here = joint(interior_deg);
      Toolpath there = here;
      there.start_mm += shift;
      there.end_mm += shift;
      for (Vec3& p : there.paths[0].points) p += shift;
      const UniformPlanner planner{UniformSettings{}};
      const PlanDecision a = only_corner(planner.plan_in_context(here, kLimits, context_for(type)));
      const PlanDecision b =
          only_corner(planner.plan_in_context(there, kLimits, context_for(type)));
      EXPECT_EQ(a.choice, b.choice);
      EXPECT_EQ(figure(a, "candidates"), figure(b, "candidates"));
      const double error = figure(a, "predicted_error_mm");
      EXPECT_GT(error, 0.0);
      // (rounding may flip a batch split of the deposit: up to a few 1e-6; predicted on the
      // bed's own grid, as before, these corners differed by 7-14 %)
      EXPECT_NEAR(figure(b, "predicted_error_mm"), error, 1e-4 * error);
    }
  }
}

// the chain of two 8 mm edges meeting at the joint (interior) angle, printed at 3 mm/s, as
// choose_corner takes it
PrintChain joint_chain(double interior_deg) {
  const double turn = deg_to_rad(180.0 - interior_deg);
  PrintChain chain;
  chain.points = {Vec3(-8, 0, 0), Vec3(0, 0, 0), Vec3(8 * std::cos(turn), 8 * std::sin(turn), 0)};
  chain.orientations.assign(3, ToolOrientation{});
  chain.edge_speed_mm_s = {3.0, 3.0};
  chain.edge_path = {0, 0};
  chain.edge_source = {0, 0};
  chain.point_path = {0, 0, 0};
  chain.point_index = {0, 1, 2};
  return chain;
}

// its corner decided under two deposit models (tolerance 0.05 mm, time_weight 0.2 mm/s)
std::pair<CornerDecision, CornerDecision> decide_under(const PrintChain& chain,
                                                       const PathMotionOptions& options,
                                                       const DepositModel& first,
                                                       const DepositModel& second) {
  const std::vector<CornerGeometry> geometry = corner_geometry(chain.points, 0.05);
  PredictionScratch first_scratch, second_scratch;
  return {choose_corner(chain, 1, geometry, kLimits, options, first, 0.2, first_scratch),
          choose_corner(chain, 1, geometry, kLimits, options, second, 0.2, second_scratch)};
}

// An aerosol corner's candidates steady on their window's ends take those ends' deposit from the
// steady line predicted once per corner (the slowed blends beyond their speed change, the
// loops beyond their trims) and predict only the rest. Against every candidate's whole window
// predicted: the same candidates and choice, each predicted error within 2 % (the two step
// grids meet the shutter's ramps differently: up to 0.7 % for the loops here, 3e-5 for the
// slowed blends).
TEST(UniformPlanner, SharedWindowEndsPredictAsTheWholeWindow) {
  for (const double interior_deg : {110.0, 60.0, 25.0}) {
    SCOPED_TRACE(std::to_string(interior_deg));
    PathMotionOptions options;
    options.enter_at_speed = options.leave_at_speed = true;
    DepositModel shared, whole;
    whole.share_window_ends = false;
    // (every candidate predicted to its end)
    shared.abandon_costly_predictions = whole.abandon_costly_predictions = false;
    const auto [a, b] = decide_under(joint_chain(interior_deg), options, shared, whole);
    ASSERT_EQ(a.candidates.size(), b.candidates.size());
    ASSERT_GE(a.candidates.size(), 2u);  // loops and slowed blends
    EXPECT_EQ(a.chosen.name, b.chosen.name);
    EXPECT_EQ(a.chosen.plan.trim_in_mm, b.chosen.plan.trim_in_mm);
    EXPECT_EQ(a.chosen.plan.trim_out_mm, b.chosen.plan.trim_out_mm);
    EXPECT_EQ(a.chosen.plan.half_length_mm, b.chosen.plan.half_length_mm);
    for (size_t k = 0; k < a.candidates.size(); ++k) {
      EXPECT_EQ(a.candidates[k].name, b.candidates[k].name);
      EXPECT_EQ(a.candidates[k].extra_time_s, b.candidates[k].extra_time_s);
      EXPECT_GT(b.candidates[k].error_mm, 0.0);
      EXPECT_NEAR(a.candidates[k].error_mm, b.candidates[k].error_mm,
                  0.02 * b.candidates[k].error_mm);
    }
  }
}

// An aerosol's slowed corner is abandoned once its deposit so far exceeds the targets by more
// than the best candidate's cost: the deposit only grows, so that excess is a lower bound of
// its error.
// Against the same corners with every slowed corner predicted to its end: each abandoned
// candidate's bound is at most its full error and above the chosen one's cost, and the choice
// and every other candidate are the same.
TEST(UniformPlanner, AbandonedSlowedCornersCouldNotHaveWon) {
  int abandoned = 0;
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    for (const double interior_deg : {110.0, 60.0, 25.0, 8.0}) {
      SCOPED_TRACE(std::string(process_type_name(type)) + " " + std::to_string(interior_deg));
      const bool aerosol = type == ProcessType::aerosol;
      PathMotionOptions options;
      options.enter_at_speed = options.leave_at_speed = aerosol;
      options.lag_s = aerosol ? 0.0 : 0.05;
      options.flow_follows_speed = options.loops_at_rest = !aerosol;
      DepositModel quick, full;
      quick.settings = full.settings = *context_for(type).process;
      full.abandon_costly_predictions = false;
      const auto [a, b] = decide_under(joint_chain(interior_deg), options, quick, full);
      ASSERT_EQ(a.candidates.size(), b.candidates.size());
      EXPECT_EQ(a.chosen.name, b.chosen.name);
      EXPECT_EQ(a.chosen.cost, b.chosen.cost);
      EXPECT_FALSE(a.chosen.abandoned);
      for (size_t k = 0; k < a.candidates.size(); ++k) {
        const CornerCandidate &quick_one = a.candidates[k], &full_one = b.candidates[k];
        EXPECT_EQ(quick_one.name, full_one.name);
        EXPECT_FALSE(full_one.abandoned);
        if (!quick_one.abandoned) {
          EXPECT_EQ(quick_one.cost, full_one.cost);
          continue;
        }
        ++abandoned;
        EXPECT_EQ(type, ProcessType::aerosol);  // (an extruder's slowed corners run in full)
        EXPECT_EQ(quick_one.name, "slow");
        EXPECT_GT(quick_one.error_mm, 0.0);
        EXPECT_LE(quick_one.error_mm, full_one.error_mm);
        EXPECT_GT(quick_one.cost, a.chosen.cost);
      }
    }
  }
  EXPECT_GT(abandoned, 0);  // (the bound did fire)
}

// An extruder cannot close a shutter, but it can stop: at a sharp joint its loop ends the line
// at rest short of the corner, travels with the flow off and starts the next line from rest
// past it, so the two beads do not double up where they overlap. Weighed against the stop and
// the slowed blends; chosen here when the deposit alone decides (time_weight 0).
TEST(UniformPlanner, SharpExtrusionJointLoopsAtRestPastTheOverlap) {
  UniformSettings settings;
  settings.time_weight_mm_s = 0.0;
  const Trajectory plan = UniformPlanner{settings}.plan_in_context(
      joint(20.0), kLimits, context_for(ProcessType::extrusion));
  const PlanDecision& corner = only_corner(plan);
  EXPECT_EQ(corner.choice, "loop");
  EXPECT_GT(figure(corner, "trim_in_mm") + figure(corner, "trim_out_mm"), 0.0);
  // the loop's cost beats the stop's (both weighed)
  EXPECT_LT(figure(corner, "loop_cost_mm"), figure(corner, "stop_cost_mm"));
  // one piece with the flow off between the two printed lines, from rest to rest
  int loops = 0;
  bool printed = false;
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (piece.depositing) printed = true;
    if (!piece.depositing && printed && piece.t_end_s < plan.duration_s()) {
      ++loops;
      TrajectoryCursor cursor(plan);
      EXPECT_LT(cursor.at(piece.t_begin_s).velocity_mm_s.norm(), 1e-9);
      EXPECT_LT(cursor.at(piece.t_end_s).velocity_mm_s.norm(), 1e-9);
    }
  }
  EXPECT_EQ(loops, 1);
}

// Every deposited sample lies within the tolerance of its path (blends and lines), for several
// tolerances and joint angles.
TEST(UniformPlanner, BlendsStayInsideTheToleranceBand) {
  for (const double tolerance : {0.02, 0.05, 0.2}) {
    UniformSettings settings;
    settings.tolerance_mm = tolerance;
    for (const double angle : {150.0, 120.0, 90.0, 45.0}) {
      const Toolpath toolpath = joint(angle);
      const Trajectory plan = UniformPlanner{settings}.plan(toolpath, kLimits);
      const MotionSamples samples = sample_trajectory(plan, 1e-4);
      EXPECT_LE(path_error(samples, toolpath).max_mm, tolerance * (1 + 1e-9))
          << "tolerance " << tolerance << " joint " << angle;
    }
  }
}

// A line with a zig-zag of 1e-4 mm teeth at tolerance 1e-4 mm: the teeth are no fine chords
// (each 1e-4 mm off the chord past it, more than half the tolerance) and their corners' blends
// must fit 1e-4 mm, far below what the print speed needs. Each corner's window takes its edges
// on straight (too short to hold a target of their own): the crawl through the teeth is seen to
// pile the aerosol (every corner's predicted error above 0) and the shutter closes for it, every
// deposited sample at the print speed; the corners' extra times add up to what the plan takes
// beyond the straight line (3.45 s; cut at the teeth, each window was 2e-4 mm long, every error
// 0 and the crawl at 0.016 mm/s chosen, its extra time 9 x low).
TEST(UniformPlanner, CornersBetweenHairEdgesAreWeighedOnTheLinesGoingOn) {
  Toolpath toolpath = single_line(Vec3(0, 0, 0), Vec3(6, 0, 0), Vec3(-6, -7, 0), Vec3(7, -7, 0));
  toolpath.paths[0].points = {Vec3(0, 0, 0)};
  for (int k = 0; k <= 10; ++k)
    toolpath.paths[0].points.emplace_back(3.0 + 1e-4 * k, 1e-4 * (k % 2), 0.0);
  toolpath.paths[0].points.emplace_back(6, 0, 0);
  UniformSettings settings;
  settings.tolerance_mm = 1e-4;
  const Trajectory plan = UniformPlanner{settings}.plan(toolpath, kLimits);
  ASSERT_EQ(plan.decisions().size(), 11u);
  double extra_s = 0.0;
  for (const PlanDecision& corner : plan.decisions()) {
    EXPECT_GT(figure(corner, "predicted_error_mm"), 0.0) << "point " << corner.point_index;
    extra_s += figure(corner, "extra_time_s");
  }
  EXPECT_LT(max_speed_error(plan), 1e-6);
  const Trajectory straight = UniformPlanner{settings}.plan(
      single_line(Vec3(0, 0, 0), Vec3(6, 0, 0), Vec3(-6, -7, 0), Vec3(7, -7, 0)), kLimits);
  EXPECT_NEAR(extra_s, plan.duration_s() - straight.duration_s(),
              0.05 * (plan.duration_s() - straight.duration_s()));
}

// A slicer's arc is a run of short chords; blends sized for the print speed fill them whole,
// leaving no line to change speed on. An extruder's path that ends on such an arc (a
// perimeter's last corner, rounded_square_3_layers.gcode) must still slow down only near its
// end: the arc's 4.7 mm (a quarter circle of radius 3 in 14 chords, at 30 mm/s) take at most
// 1.1 x what the same length of straight line ending at rest takes (0.344 s; 0.348 s measured,
// the stop a curved ramp along the arc). With speeds changing on the lines only it took
// 0.47 s (its chords merged within half the tolerance, held blends resized for 1.5 x their
// speed); before the planner resized the blends the look-ahead held back, the arc crawled at
// 3 mm/s: 1.64 s.
TEST(UniformPlanner, PathEndingOnAChordedArcSlowsDownOnlyNearItsEnd) {
  const MachineLimits limits = MachineLimits::uniform(100.0, 1000.0);
  const auto print_time_from = [&](const std::vector<Vec3>& points, const Vec3& from) {
    Toolpath toolpath;
    PrintPath path;
    path.points = points;
    path.speed_mm_s = 30.0;
    toolpath.paths.push_back(path);
    toolpath.start_mm = points.front();
    toolpath.end_mm = points.back();
    const Trajectory plan = UniformPlanner{UniformSettings{}}.plan_in_context(
        toolpath, limits, context_for(ProcessType::extrusion));
    // from the first sample at or past x = from.x (the arc's start; the chords' merging and
    // their blends may pass it up to the tolerance away) to the end of the printed part
    double t_from = -1.0, t_end = 0.0;
    for (const TrajectoryPiece& piece : plan.pieces())
      if (piece.depositing) t_end = std::max(t_end, piece.t_end_s);
    for (double t = 0.0; t <= t_end && t_from < 0.0; t += 1e-4)
      if (plan.at(t).position_mm.x() >= from.x()) t_from = t;
    EXPECT_GE(t_from, 0.0);
    return t_end - t_from;
  };
  const double radius = 3.0, quarter = 0.5 * kPi * radius;
  std::vector<Vec3> arc = {Vec3(0, 0, 0)};
  for (int k = 0; k <= 14; ++k) {
    const double angle = 0.5 * kPi * k / 14.0;
    arc.push_back(Vec3(14.0 + radius * std::sin(angle), radius - radius * std::cos(angle), 0));
  }
  const double on_arc = print_time_from(arc, Vec3(14, 0, 0));
  const double on_line =
      print_time_from({Vec3(0, 0, 0), Vec3(14.0 + quarter, 0, 0)}, Vec3(14, 0, 0));
  EXPECT_GT(on_line, quarter / 30.0);
  EXPECT_LE(on_arc, 1.1 * on_line) << "arc " << on_arc << " s, line " << on_line << " s";
}

// Extrusion: the commanded flow leads the planned speed by the lag, so the nozzle's lagging
// flow (dQ/dt = (Qc - Q) / tau, integrated exactly per 0.1 ms with Qc held) keeps the material
// per millimetre at w h through the start, the corners and the stop: within 1 % wherever the
// nozzle moves faster than 2 % of the print speed.
TEST(UniformPlanner, ExtrusionFlowFollowsTheSpeedThroughTheLag) {
  const double tau = 0.05;
  const Trajectory plan = UniformPlanner{UniformSettings{}}.plan_in_context(
      joint(60.0), kLimits, context_for(ProcessType::extrusion, tau));
  const double dt = 1e-4;
  double q = 0.0;  // lagged flow as a fraction of the nominal at the desired speed
  int checked = 0;
  for (double t = 0.0; t < plan.duration_s(); t += dt) {
    const TrajectorySample s = plan.at(t);
    const double command = s.depositing ? s.flow_fraction : 0.0;
    q = command + (q - command) * std::exp(-dt / tau);
    const TrajectorySample next = plan.at(t + dt);
    const double speed = next.velocity_mm_s.norm();
    if (!next.depositing || speed < 0.02 * 3.0) continue;
    // material per mm relative to the nominal: (q v_des) / speed
    EXPECT_NEAR(q * 3.0 / speed, 1.0, 0.01) << "t " << t + dt << " speed " << speed;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// An extruder that may retract (process.retract): the led flow goes below 0 in the
// decelerations, which are no longer held to |v| / tau, and the lagging flow (stopping at 0)
// still keeps the material per millimetre within 1 % of w h; the plan is shorter than the one
// that keeps the command non-negative.
TEST(UniformPlanner, RetractingExtruderDeceleratesFasterWithAnEvenBead) {
  const double tau = 0.05;
  const UniformPlanner planner{UniformSettings{}};
  const Trajectory held =
      planner.plan_in_context(joint(60.0), kLimits, context_for(ProcessType::extrusion, tau));
  const Trajectory plan =
      planner.plan_in_context(joint(60.0), kLimits, context_for(ProcessType::extrusion, tau, true));
  EXPECT_LT(plan.duration_s(), held.duration_s());
  const double dt = 1e-4;
  double q = 0.0;  // lagged flow as a fraction of the nominal at the desired speed
  int checked = 0;
  double lowest_command = 0.0, steepest = 0.0;  // steepest: max over samples of -dv/dt tau / v
  for (double t = 0.0; t < plan.duration_s(); t += dt) {
    const TrajectorySample s = plan.at(t);
    const double command = s.depositing ? s.flow_fraction : 0.0;
    lowest_command = std::min(lowest_command, command);
    q = std::max(0.0, command + (q - command) * std::exp(-dt / tau));
    const TrajectorySample next = plan.at(t + dt);
    const double speed = next.velocity_mm_s.norm();
    if (!next.depositing || speed < 0.02 * 3.0) continue;
    const double speed_rate = next.velocity_mm_s.dot(next.acceleration_mm_s2) / speed;
    steepest = std::max(steepest, -speed_rate * tau / speed);
    EXPECT_NEAR(q * 3.0 / speed, 1.0, 0.01) << "t " << t + dt << " speed " << speed;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(lowest_command, -0.1);  // the extruder retracts
  EXPECT_GT(steepest, 2.0);         // decelerations beyond |v| / tau
}

// The planned motion deposited with the project's own process model (the shutter's ideal
// ramps, or the extruder's lag) conserves material: emitted = on target + overspray + captured
// to 1e-6, and the same plan gives the same deposit twice.
TEST(UniformPlanner, MaterialBalanceAndDeterminism) {
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    SCOPED_TRACE(process_type_name(type));
    const PlanningContext context = context_for(type);
    Toolpath toolpath = joint(45.0);
    toolpath.paths.push_back(
        single_line(Vec3(-3, -1, 0), Vec3(3, -1.5, 0), Vec3::Zero(), Vec3::Zero()).paths[0]);
    const UniformPlanner planner{UniformSettings{}};
    const Trajectory a = planner.plan_in_context(toolpath, kLimits, context);
    const Trajectory b = planner.plan_in_context(toolpath, kLimits, context);
    ASSERT_EQ(a.duration_s(), b.duration_s());
    ASSERT_EQ(a.decisions().size(), b.decisions().size());
    for (size_t i = 0; i < a.decisions().size(); ++i)
      EXPECT_EQ(a.decisions()[i].choice, b.decisions()[i].choice);
    std::vector<double> totals;
    for (const Trajectory* plan : {&a, &b}) {
      std::unique_ptr<Process> process = make_process(*context.process);
      TrajectoryCursor cursor(*plan);
      TrajectorySample before = cursor.at(0.0);
      const double dt = 0.001;
      for (double t = 0.0; t < plan->duration_s(); t += dt) {
        const TrajectorySample after = cursor.at(t + dt);
        DepositionStep step;
        step.t0_s = t;
        step.t1_s = t + dt;
        step.p0_mm = before.position_mm;
        step.p1_mm = after.position_mm;
        step.open0 = before.depositing ? 1.0 : 0.0;
        step.open1 = after.depositing ? 1.0 : 0.0;
        step.flow_command = before.depositing ? before.flow_fraction : 0.0;
        step.desired_speed_mm_s = before.desired_speed_mm_s;
        process->advance(step);
        before = after;
      }
      const DepositionMetrics metrics = evaluate_deposition(
          process->field(), toolpath, process->line_width_mm(), process->account());
      const MaterialSplit& m = metrics.material;
      EXPECT_GT(m.emitted_mm3, 0.0);
      EXPECT_NEAR(m.on_target_mm3 + m.overspray_mm3 + m.captured_mm3, m.emitted_mm3,
                  1e-6 * m.emitted_mm3);
      totals.push_back(process->field().total_volume_mm3());
    }
    EXPECT_EQ(totals[0], totals[1]);
  }
}

// every figure of one corner decision equal to the other's, to the bit
void expect_same_decision(const CornerDecision& a, const CornerDecision& b) {
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (size_t k = 0; k <= a.candidates.size(); ++k) {
    const CornerCandidate& x = k < a.candidates.size() ? a.candidates[k] : a.chosen;
    const CornerCandidate& y = k < b.candidates.size() ? b.candidates[k] : b.chosen;
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.plan.treatment, y.plan.treatment);
    EXPECT_EQ(x.plan.half_length_mm, y.plan.half_length_mm);
    EXPECT_EQ(x.plan.trim_in_mm, y.plan.trim_in_mm);
    EXPECT_EQ(x.plan.trim_out_mm, y.plan.trim_out_mm);
    EXPECT_EQ(x.error_mm, y.error_mm);
    EXPECT_EQ(x.extra_time_s, y.extra_time_s);
    EXPECT_EQ(x.cost, y.cost);
    EXPECT_EQ(x.speed_mm_s, y.speed_mm_s);
    EXPECT_EQ(x.pruned, y.pruned);
    EXPECT_EQ(x.abandoned, y.abandoned);
  }
}

// A planar corner decided at one height is taken from the cache at another (a slicer's next
// layer): the same decision to the bit as predicting it there. A corner moved in (x, y), one
// whose points are not at one height, and any corner under limits that depend on the position
// are predicted afresh, as is one printed at another speed.
TEST(UniformPlanner, CornerDecisionCacheReusesOnlyEqualCorners) {
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    for (const double interior_deg : {45.0, 100.0, 150.0}) {
      SCOPED_TRACE(std::string(process_type_name(type)) + " " + std::to_string(interior_deg));
      PathMotionOptions options;
      DepositModel model;
      model.settings.type = type;
      model.settings.bead_width_mm = 0.4;
      model.settings.tau_s = 0.05;
      if (type == ProcessType::aerosol) {
        options.enter_at_speed = options.leave_at_speed = true;
      } else {
        options.lag_s = 0.05;
        options.flow_follows_speed = options.loops_at_rest = true;
      }
      const TcpLimits limits = with_jerk_limits(kLimits, 0.01);
      const auto fresh = [&](const PrintChain& chain) {
        PredictionScratch scratch;
        return choose_corner(chain, 1, corner_geometry(chain.points, 0.05), limits, options, model,
                             0.2, scratch);
      };
      // decides `chain` through the cache, counting whether it was predicted
      int predicted = 0;
      PredictionScratch scratch;
      const auto through = [&](CornerDecisionCache& cache, const PrintChain& chain) {
        const std::vector<CornerGeometry> geometry = corner_geometry(chain.points, 0.05);
        return cache.decision(chain, 1, geometry, [&]() {
          ++predicted;
          return choose_corner(chain, 1, geometry, limits, options, model, 0.2, scratch);
        });
      };
      const auto moved = [](PrintChain chain, const Vec3& by) {
        for (Vec3& p : chain.points) p += by;
        return chain;
      };
      const PrintChain first = joint_chain(interior_deg);
      const PrintChain layer_up = moved(first, Vec3(0, 0, 0.2));
      PrintChain tilted = layer_up;
      tilted.points[2].z() += 0.1;
      const PrintChain shifted = moved(first, Vec3(0.4, 0, 0.2));
      PrintChain slower = layer_up;
      slower.edge_speed_mm_s[1] = 2.0;

      CornerDecisionCache cache(limits, true);
      const CornerDecision decided = through(cache, first);
      const CornerDecision reused = through(cache, layer_up);
      EXPECT_EQ(predicted, 1);
      EXPECT_EQ(cache.reused(), 1u);
      expect_same_decision(reused, fresh(layer_up));
      expect_same_decision(decided, fresh(first));
      through(cache, tilted);
      through(cache, shifted);
      through(cache, slower);
      EXPECT_EQ(predicted, 4);
      EXPECT_EQ(cache.reused(), 1u);
      // (the tilted corner's second visit is reused: its heights are in its key)
      through(cache, tilted);
      EXPECT_EQ(cache.reused(), 2u);

      // limits given per box, not declared the same everywhere (a delta's): nothing kept
      const TcpLimits per_box(limits.requested(),
                              [&](const Vec3&, const Vec3&) { return limits.requested(); });
      CornerDecisionCache off(per_box, true);
      through(off, first);
      through(off, layer_up);
      EXPECT_EQ(off.reused(), 0u);
      EXPECT_EQ(predicted, 6);
    }
  }
}

// The cache keeps at most kMaxKept decisions: when full, it starts over (the latest kept).
TEST(UniformPlanner, CornerDecisionCacheIsBounded) {
  PrintChain chain = joint_chain(60.0);
  const std::vector<CornerGeometry> geometry = corner_geometry(chain.points, 0.05);
  CornerDecisionCache cache(with_jerk_limits(kLimits, 0.01), true);
  size_t decided = 0;
  // corners told apart by their point's x alone (the decision itself is not the point here)
  const auto visit = [&](size_t k) {
    chain.points[1].x() = 1e-3 * static_cast<double>(k);
    cache.decision(chain, 1, geometry, [&]() {
      ++decided;
      return CornerDecision{};
    });
  };
  for (size_t k = 0; k < CornerDecisionCache::kMaxKept; ++k) visit(k);
  visit(0);
  EXPECT_EQ(decided, CornerDecisionCache::kMaxKept);
  EXPECT_EQ(cache.reused(), 1u);
  visit(CornerDecisionCache::kMaxKept);  // the one past full: the kept ones start over
  visit(CornerDecisionCache::kMaxKept);
  visit(1);
  EXPECT_EQ(decided, CornerDecisionCache::kMaxKept + 2);
  EXPECT_EQ(cache.reused(), 2u);
}

// Layers that repeat (a star of corners from 20 to 160 deg and a random chain of 12 edges of
// 0.6-3 mm, at four heights, 150 mm apart at most): `uniform` with decisions reused plans
// exactly as with every corner predicted, the pieces equal and the motion the same to the bit
// every 10 ms.
TEST(UniformPlanner, ReusedCornerDecisionsPlanAsFreshOnes) {
  std::vector<Vec3> star{Vec3(-8, 0, 0)}, walk{Vec3(3.1416, 7.2983, 0)};
  Vec3 d(1, 0, 0);
  const auto turned = [](const Vec3& d, double interior_deg) {
    const double turn = deg_to_rad(180.0 - interior_deg);
    return Vec3(std::cos(turn) * d.x() - std::sin(turn) * d.y(),
                std::sin(turn) * d.x() + std::cos(turn) * d.y(), 0.0);
  };
  for (const double interior_deg : {160.0, 20.0, 120.0, 45.0, 90.0, 70.0, 135.0, 180.0}) {
    star.push_back(star.back() + 4.0 * d);
    d = turned(d, interior_deg);
  }
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> length(0.6, 3.0), interior(10.0, 175.0);
  for (int edge = 0; edge < 12; ++edge) {
    walk.push_back(walk.back() + length(rng) * d);
    d = turned(d, interior(rng));
  }
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-20, -20, 0);
  toolpath.end_mm = Vec3(20, -20, 0);
  int layer = 0;
  for (const double z : {0.2, 0.4, 150.3, -3.7}) {
    for (const std::vector<Vec3>* points : {&star, &walk}) {
      PrintPath path;
      path.speed_mm_s = 3.0;
      path.layer = layer;
      for (const Vec3& p : *points) path.points.push_back(p + Vec3(0, 0, z));
      toolpath.paths.push_back(path);
    }
    ++layer;
  }
  for (const ProcessType type : {ProcessType::aerosol, ProcessType::extrusion}) {
    SCOPED_TRACE(process_type_name(type));
    UniformSettings fresh_settings;
    fresh_settings.reuse_corner_decisions = false;
    const Trajectory reused =
        UniformPlanner(UniformSettings{}).plan_in_context(toolpath, kLimits, context_for(type));
    const Trajectory fresh =
        UniformPlanner(fresh_settings).plan_in_context(toolpath, kLimits, context_for(type));
    ASSERT_EQ(reused.pieces().size(), fresh.pieces().size());
    ASSERT_EQ(reused.duration_s(), fresh.duration_s());
    ASSERT_EQ(reused.decisions().size(), fresh.decisions().size());
    ASSERT_EQ(reused.decisions().size(), 4u * (7u + 11u));
    for (size_t i = 0; i < reused.decisions().size(); ++i) {
      const PlanDecision &a = reused.decisions()[i], &b = fresh.decisions()[i];
      EXPECT_EQ(a.choice, b.choice);
      ASSERT_EQ(a.figures.size(), b.figures.size());
      for (size_t f = 0; f < a.figures.size(); ++f)
        EXPECT_EQ(a.figures[f].value, b.figures[f].value);
    }
    TrajectoryCursor a(reused), b(fresh);
    for (double t = 0.0; t <= reused.duration_s(); t += 0.01) {
      const TrajectorySample x = a.at(t), y = b.at(t);
      ASSERT_EQ(x.position_mm, y.position_mm) << t;
      ASSERT_EQ(x.velocity_mm_s, y.velocity_mm_s) << t;
      ASSERT_EQ(x.depositing, y.depositing) << t;
      ASSERT_EQ(x.flow_fraction, y.flow_fraction) << t;
    }
  }
}

}  // namespace
}  // namespace depotwin
