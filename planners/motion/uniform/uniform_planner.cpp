#include "planners/motion/uniform/uniform_planner.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "planners/motion/conformal.hpp"
#include "planners/motion/transition.hpp"
#include "planners/motion/uniform/arc_run.hpp"

namespace depotwin {

namespace {

// arcs become chords within this share of the tolerance before their corners are blended
constexpr double kArcChordShare = 0.1;

// the toolpath with its arcs as chords within kArcChordShare of the tolerance (their corners
// are blended like any other)
Toolpath with_arcs_chorded(const Toolpath& toolpath, double tolerance_mm) {
  Toolpath chorded = toolpath;
  for (PrintPath& path : chorded.paths)
    if (path.has_arcs()) path = path.chorded(kArcChordShare * tolerance_mm);
  return chorded;
}

// A transition's samples for the travel check: at most kTravelSamplePeriod_s apart (and at
// least kTravelMinSamples), plus each instant an axis turns back (its velocity crosses zero,
// found by bisection), where that axis' overshoot peaks
constexpr double kTravelSamplePeriod_s = 2e-3;
constexpr int kTravelMinSamples = 16, kTravelMaxSamples = 4096, kTurnBisections = 48;
// how many times a plan is made again for its moves beyond the travel (each time more chains
// at rest at their ends or without loops)
constexpr int kTravelAttempts = 2;

// true when the transition piece takes some joint beyond its travel (or a pose out of
// reach): a move that leaves or enters a path at speed overshoots that path's end, which
// near the travel's end lies outside it
bool leaves_travel(const TrajectoryPiece& piece, const JointMap& joint_map) {
  const double duration_s = piece.t_end_s - piece.t_begin_s;
  if (!(duration_s > 0.0)) return false;
  const int n = std::clamp(static_cast<int>(std::ceil(duration_s / kTravelSamplePeriod_s)),
                           kTravelMinSamples, kTravelMaxSamples);
  // the pose at each sample (with its time, and its velocity to find the turns between
  // samples) and at each turn, put in time order: the joint map solves each pose nearest the
  // one before
  std::vector<std::pair<double, Pose>> timed;
  std::vector<Vec3> velocities;
  timed.reserve(n + 8);
  velocities.reserve(n + 1);
  const auto pose_at = [&piece](double tau, Vec3* velocity_out) {
    Vec3 position, velocity, acceleration, tool_axis, turning;
    double roll = 0.0;
    evaluate_motion(piece, tau, position, velocity, acceleration);
    evaluate_tool_axis(piece, tau, position, velocity, tool_axis, turning, roll);
    if (velocity_out) *velocity_out = velocity;
    return Pose(position, tool_axis, roll);
  };
  for (int k = 0; k <= n; ++k) {
    const double tau = duration_s * k / n;
    Vec3 velocity;
    timed.emplace_back(tau, pose_at(tau, &velocity));
    velocities.push_back(velocity);
  }
  for (int k = 0; k < n; ++k)
    for (int axis = 0; axis < 3; ++axis) {
      if (!(velocities[k][axis] * velocities[k + 1][axis] < 0.0)) continue;
      double lo = timed[k].first, hi = timed[k + 1].first;
      const bool rising = velocities[k][axis] < 0.0;
      for (int i = 0; i < kTurnBisections; ++i) {
        const double mid = 0.5 * (lo + hi);
        Vec3 position, velocity, acceleration;
        evaluate_motion(piece, mid, position, velocity, acceleration);
        ((velocity[axis] < 0.0) == rising ? lo : hi) = mid;
      }
      const double turn = 0.5 * (lo + hi);
      timed.emplace_back(turn, pose_at(turn, nullptr));
    }
  std::stable_sort(timed.begin(), timed.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Pose> poses;
  poses.reserve(timed.size());
  for (const auto& [tau, pose] : timed) poses.push_back(pose);
  std::vector<JointVector> joints;
  if (!joint_map.solve(poses, joints, nullptr)) return true;
  for (const JointVector& q : joints)
    for (size_t j = 0; j < q.size() && j < joint_map.limits.size(); ++j)
      if (q[j] < joint_map.limits[j].min - kTravelRounding_mm ||
          q[j] > joint_map.limits[j].max + kTravelRounding_mm)
        return true;
  return false;
}

// a `kind: path` decision about a whole chain, at its first point, with its print speed
PlanDecision chain_decision(const PrintChain& chain, const char* choice) {
  PlanDecision d;
  d.path_index = chain.point_path.front();
  d.point_index = chain.point_index.front();
  d.kind = "path";
  d.choice = choice;
  d.figures.push_back({"print_speed_mm_s", chain.edge_speed_mm_s.front(), "mm/s"});
  return d;
}

// fine edges are merged within this share of the tolerance (merge_fine_edges); the blends keep
// to the rest
constexpr double kMergeShare = 0.5;
// the look-ahead's blend resizing (resize_held_blends): a blend planned below this share of
// the print speed is resized for kResizeGrowth times its planned speed, at most this many times
// (1.5 rather than 4: the ramps on a merged 10 mm circle of fine chords, 50 mm/s from rest,
// 1.67 -> 1.58 s, gcode_rounded_square 8.905 -> 8.697 s; 12 passes still take a 3 mm/s crawl
// to 30 mm/s)
constexpr double kResizeBelowShare = 0.9;
constexpr double kResizeGrowth = 1.5;
constexpr int kResizePasses = 12;

// Blends sized for the print speed may fill short edges whole (a finely chorded arc leaves
// its chords no straight remnant), and speed changes happen on the straight lines only. Where
// the path must come to rest (an extruder's path end, a stop) the look-ahead then holds a
// whole curve at the speed its last line can stop from: 3 mm/s over a 4.7 mm arc at 30 mm/s.
// Each blend the look-ahead planned below kResizeBelowShare of its print speed is resized to
// the least blend that allows kResizeGrowth times that speed, and never beyond the chosen one
// (`chosen`): the smaller blend frees its lines to change speed, the larger lets the next pass
// take the corner faster. True when some blend changed; the caller plans the chain again.
bool resize_held_blends(const PrintChain& chain, const std::vector<CornerGeometry>& geometry,
                        const std::vector<double>& corner_speeds, const TcpLimits& limits,
                        const std::vector<CornerPlan>& chosen, std::vector<CornerPlan>& corners) {
  bool changed = false;
  for (size_t i = 1; i + 1 < chain.points.size(); ++i) {
    CornerPlan& plan = corners[i];
    if (plan.treatment != CornerTreatment::blend) continue;
    const double print_speed = chain.corner_print_speed_mm_s(i);
    const double speed = corner_speeds[i];
    if (!(speed > 0.0 && speed < kResizeBelowShare * print_speed)) continue;
    const CornerGeometry& g = geometry[i];
    const MachineLimits box = corner_blend_limits(g, chosen[i].half_length_mm, limits);
    const double wanted = std::clamp(
        blend_half_length_for_speed(g.shape, std::min(print_speed, kResizeGrowth * speed), box),
        1e-9 * g.max_half_length_mm, chosen[i].half_length_mm);
    if (std::abs(wanted - plan.half_length_mm) > 1e-9 * plan.half_length_mm) {
      plan.half_length_mm = wanted;
      changed = true;
    }
  }
  return changed;
}

PlanDecision corner_report(const PrintChain& chain, size_t corner, const CornerGeometry& g,
                           const CornerDecision& decision) {
  const CornerCandidate& c = decision.chosen;
  PlanDecision d;
  d.path_index = chain.point_path[corner];
  d.point_index = chain.point_index[corner];
  d.kind = "corner";
  d.choice = c.name;
  d.figures.push_back({"interior_angle_deg", g.interior_deg, "deg"});
  d.figures.push_back({"speed_mm_s", c.speed_mm_s, "mm/s"});
  d.figures.push_back({"print_speed_mm_s", chain.corner_print_speed_mm_s(corner), "mm/s"});
  // (a corner blended at print speed had nothing to weigh: its deposit was not predicted)
  if (!c.pruned) d.figures.push_back({"predicted_error_mm", c.error_mm, "mm"});
  // (a corner of a chain at constant speed has no time of its own: the path decision has it)
  // (nor one of an arc run: the run is planned as a whole)
  if (c.name != "constant_speed" && c.name != "arc")
    d.figures.push_back({"extra_time_s", c.extra_time_s, "s"});
  if (!c.pruned) d.figures.push_back({"cost_mm", c.cost, "mm"});
  double deviation = 0.0;
  if (c.plan.treatment == CornerTreatment::blend)
    deviation = c.plan.half_length_mm * g.deviation_per_length;
  if (c.plan.treatment == CornerTreatment::arc) deviation = c.plan.arc->deviation_mm;
  d.figures.push_back({"deviation_mm", deviation, "mm"});
  // (an arc run's circle, and how many corners it takes)
  if (c.plan.treatment == CornerTreatment::arc) {
    d.figures.push_back({"radius_mm", c.plan.arc->radius_mm(), "mm"});
    d.figures.push_back(
        {"run_corners",
         static_cast<double>(c.plan.arc->last_corner() - c.plan.arc->first_corner() + 1), "count"});
  }
  d.figures.push_back({"trim_in_mm", c.plan.trim_in_mm, "mm"});
  d.figures.push_back({"trim_out_mm", c.plan.trim_out_mm, "mm"});
  // the best of each other kind, for comparison (of a kind whose every prediction was
  // abandoned, the least cost it was known to exceed)
  int pruned = 0, abandoned = 0;
  for (const char* kind : {"blend", "slow", "loop", "stop"}) {
    double best = std::numeric_limits<double>::infinity();
    double above = std::numeric_limits<double>::infinity();
    for (const CornerCandidate& other : decision.candidates) {
      if (other.name != kind || other.pruned) continue;
      if (other.abandoned)
        above = std::min(above, other.cost);
      else
        best = std::min(best, other.cost);
    }
    if (std::isfinite(best))
      d.figures.push_back({std::string(kind) + "_cost_mm", best, "mm"});
    else if (std::isfinite(above))
      d.figures.push_back({std::string(kind) + "_cost_above_mm", above, "mm"});
  }
  // candidates whose extra time alone cost more than the best before them, and whose deposit
  // partway did
  for (const CornerCandidate& other : decision.candidates) {
    pruned += other.pruned ? 1 : 0;
    abandoned += other.abandoned ? 1 : 0;
  }
  d.figures.push_back({"candidates", static_cast<double>(decision.candidates.size()), "count"});
  d.figures.push_back({"pruned_by_time", static_cast<double>(pruned), "count"});
  d.figures.push_back({"abandoned", static_cast<double>(abandoned), "count"});
  return d;
}

// The misplaced line (mm) an extrusion path leaves, predicted from its plan: the extruder's
// flow lags its command by tau (first order, as the simulated extruder), so the flow f (a
// fraction of the nominal) drifts from |v| / v_desired where the commanded lead cannot make up
// for the lag (a command clamped at 0 under a deceleration faster than |v| / tau). The error is
// the integral of |f v_desired - |v|| dt, plus what the flow still lays at rest after the path
// ends (f_end tau v_desired).
double predicted_line_error_mm(const TrajectoryPiece& piece, double tau_s) {
  constexpr double kStep_s = 5e-4;
  const double duration_s = piece.t_end_s - piece.t_begin_s;
  const double desired = piece.desired_speed_mm_s;
  const double keep = tau_s > 0.0 ? std::exp(-kStep_s / tau_s) : 0.0;
  double flow = 0.0, error_mm = 0.0;
  Vec3 position, velocity, acceleration;
  for (double t = 0.5 * kStep_s; t < duration_s; t += kStep_s) {
    evaluate_motion(piece, t, position, velocity, acceleration);
    const double command = evaluate_flow_fraction(piece, t, velocity, acceleration);
    flow = keep * flow + (1.0 - keep) * command;
    error_mm += std::abs(flow * desired - velocity.norm()) *
                std::min(kStep_s, duration_s - t + 0.5 * kStep_s);
  }
  return error_mm + flow * tau_s * desired;
}

// true when the job turns the tool: some pose (a path's point, the end) holds another tool axis
// or roll than the start's
bool turns_tool(const Toolpath& toolpath) {
  const ToolOrientation start = toolpath.start_orientation();
  const auto turned = [&start](const ToolOrientation& o) {
    return std::abs(o.roll_rad - start.roll_rad) > 1e-12 || (o.axis - start.axis).norm() > 1e-12;
  };
  if (turned(toolpath.end_orientation())) return true;
  for (const PrintPath& path : toolpath.paths)
    for (size_t i = 0; i < path.points.size(); ++i)
      if (turned(path.orientation(i))) return true;
  return false;
}

// On a machine whose joints turn the tool (an arm), in a job that turns it, the TCP limits over
// a box bound the translation only: following each edge's tool axis at print speed asked the
// fillet's wrist for 1000x its acceleration limit. There each print path is timed on the joints by
// the TOPP-RA law `conformal` uses (path_parametrization.hpp, jerk_time_law.hpp: every joint's
// speed and acceleration limit along the path, the TCP jerk limits of `jerk_limits`), its corners
// flown by within the tolerance (zone_mm = 2 x tolerance: a blend passes zone_mm / 2 from its
// point; each as long as that allows, zone_bounds_deviation_only: a short blend's curvature
// rate holds a jerk-limited law back on a faceted surface's slight turns) by
// curvature-continuous blends. Per path, two time laws:
//   flow   time-optimal under one more bound, decelerations of at most |v| / tau
//          (ConformalSettings::flow_lag_s), the flow following the planned speed led by the
//          lag (pressure advance, never a negative command): the lagging flow keeps up;
//   speed  the path at the largest constant speed no joint slows (Shembekar's scale-down), the
//          flow scaled and led the same way: even, and slower.
// The bound holds on the time law's grid (0.05 mm): where the joints slow the nozzle to a few
// mm/s (|v| tau = 0.03 mm at 1.4 mm/s on the fillet) the speed falls faster between its points,
// and the prediction sees what that leaves.
// Extrusion takes the one of less predicted line error + time_weight x time; aerosol, whose
// stream cannot follow a speed, the constant speed, its ramps on a lead-in and a lead-out with
// the shutter closed (ConformalSettings::lead_in), so the path is printed at that speed from
// end to end. One decision per path reports it.
Trajectory plan_on_joints(const Toolpath& toolpath, const TcpLimits& jerk_limits,
                          const UniformSettings& settings, const DepositModel& model) {
  const bool aerosol = model.aerosol();
  const double tau_s = aerosol ? 0.0 : model.settings.tau_s;
  // (the joints' law takes polylines)
  const Toolpath chorded = with_arcs_chorded(toolpath, settings.tolerance_mm);
  // (a report only where it is read: with one, conformal also computes each path's constant
  // speed bound)
  const auto plan_with = [&](ConformalControl control, ConformalPlanReport* report) {
    ConformalSettings conformal;
    conformal.zone_mm = 2.0 * settings.tolerance_mm;
    conformal.zone_bounds_deviation_only = true;
    // aerosol: the ramps on extensions of the end edges, the shutter closed there (the stream
    // cannot follow a speed, so a ramp printed from rest would thicken the line's ends)
    conformal.lead_in = aerosol;
    conformal.period_s = settings.period_s;
    conformal.control = control;
    // decelerations the led flow can follow (any, when the extruder may retract)
    conformal.flow_lag_s = model.settings.retract ? 0.0 : tau_s;
    Trajectory timed = ConformalPlanner(conformal).plan(chorded, jerk_limits, report);
    std::vector<TrajectoryPiece> pieces = timed.pieces();
    if (!aerosol)
      for (TrajectoryPiece& piece : pieces)
        if (piece.depositing) {
          piece.flow_lead_s = tau_s;  // pressure advance
          piece.flow_may_retract = model.settings.retract;
        }
    return std::make_pair(std::move(pieces), timed.warnings());
  };
  ConformalPlanReport constant_report;
  auto [constant, warnings] =
      plan_with(aerosol ? ConformalControl::speed : ConformalControl::both, &constant_report);
  std::vector<TrajectoryPiece> follow;
  if (!aerosol) follow = plan_with(ConformalControl::flow, nullptr).first;
  // both plans share their transitions (rest to rest between the same poses): per path, the
  // chosen piece; then every piece placed after the one before
  const bool comparable = follow.size() == constant.size();
  std::vector<PlanDecision> decisions;
  size_t path = 0;
  double t = 0.0;
  for (size_t k = 0; k < constant.size(); ++k) {
    TrajectoryPiece& piece = constant[k];
    if (piece.depositing && path < constant_report.paths.size()) {
      const ConformalPathReport& report = constant_report.paths[path];
      PlanDecision d;
      d.path_index = piece.path_index;
      d.kind = "path";
      d.choice = "constant_speed";
      d.figures.push_back({"print_speed_mm_s", report.desired_speed_mm_s, "mm/s"});
      d.figures.push_back({"constant_speed_mm_s", report.line_speed_mm_s, "mm/s"});
      d.figures.push_back({"deviation_mm", report.max_blend_deviation_mm, "mm"});
      if (aerosol) {
        d.figures.push_back({"lead_in_mm", report.lead_in_mm, "mm"});
        d.figures.push_back({"lead_out_mm", report.lead_out_mm, "mm"});
      }
      if (comparable && follow[k].depositing && follow[k].path_index == piece.path_index) {
        const double constant_error = predicted_line_error_mm(piece, tau_s);
        const double follow_error = predicted_line_error_mm(follow[k], tau_s);
        const double constant_time = piece.t_end_s - piece.t_begin_s;
        const double follow_time = follow[k].t_end_s - follow[k].t_begin_s;
        const double constant_cost = constant_error + settings.time_weight_mm_s * constant_time;
        const double follow_cost = follow_error + settings.time_weight_mm_s * follow_time;
        d.figures.push_back({"constant_speed_error_mm", constant_error, "mm"});
        d.figures.push_back({"constant_speed_time_s", constant_time, "s"});
        d.figures.push_back({"flow_follows_error_mm", follow_error, "mm"});
        d.figures.push_back({"flow_follows_time_s", follow_time, "s"});
        if (follow_cost < constant_cost) {
          d.choice = "flow_follows_speed";
          piece = std::move(follow[k]);
        }
      }
      decisions.push_back(std::move(d));
      ++path;
    }
    const double duration_s = piece.t_end_s - piece.t_begin_s;
    piece.t_begin_s = t;
    piece.t_end_s = t += duration_s;
  }
  return Trajectory("uniform", std::move(constant), std::move(warnings), std::move(decisions));
}

// How the machine's travel bounds a chain (aerosol: its transitions at speed and its loops
// run past its points; see the attempt loop in plan_in_context)
struct TravelFlags {
  bool enter_at_rest = false;  // entered at rest instead of at print speed
  bool leave_at_rest = false;  // left at rest instead of at print speed
  bool without_loops = false;  // no corner looped
  bool any() const { return enter_at_rest || leave_at_rest || without_loops; }
  bool operator!=(const TravelFlags& other) const {
    return enter_at_rest != other.enter_at_rest || leave_at_rest != other.leave_at_rest ||
           without_loops != other.without_loops;
  }
};

// One chain planned under its travel flags: its motion from 0, its reports, its ends
struct ChainPlan {
  TravelFlags flags;
  PlannedPath planned;
  std::vector<PlanDecision> decisions;
  Vec3 first_point, last_point;
  ToolOrientation first_orientation, last_orientation;
  // its pieces' times from 0 while the pieces are lent to the job (moved into its pieces)
  std::vector<std::pair<double, double>> piece_times_s;
};

// whether the plan takes corner i at its print speed (to rounding)
bool at_print_speed(const PlannedPath& planned, const PrintChain& chain, size_t i) {
  return planned.corner_speed_mm_s[i] >= (1.0 - 1e-9) * chain.corner_print_speed_mm_s(i);
}

// Plans the chains of a job one at a time: each corner's treatment by the predicted deposit,
// the runs along circles, the aerosol chain at one constant speed; equal corners decided once
// for the whole job (CornerDecisionCache).
class ChainPlanner {
 public:
  ChainPlanner(const UniformSettings& settings, const TcpLimits& jerk_limits,
               const DepositModel& model, const PathMotionOptions& base_options)
      : settings_(settings),
        jerk_limits_(jerk_limits),
        model_(model),
        base_options_(base_options),
        aerosol_(model.aerosol()),
        decided_(jerk_limits, settings.reuse_corner_decisions),
        decided_without_loops_(jerk_limits, settings.reuse_corner_decisions) {}

  ChainPlan plan(const PrintChain& given, const TravelFlags& flags);

 private:
  // one chain's working state
  struct Work {
    PathMotionOptions options;
    MergedChain merged;  // fine chords merged (merge_fine_edges)
    std::vector<CornerGeometry> geometry;
    std::vector<std::shared_ptr<const ArcRun>> runs;
    std::vector<CornerPlan> corners;                           // per point, its treatment
    std::vector<std::pair<size_t, CornerDecision>> decisions;  // per decided corner
    PlannedPath planned;
    const PrintChain& chain() const { return merged.chain; }
  };
  CornerPlan decide(Work& work, size_t corner);
  PlannedPath plan_resizing(const Work& work, std::vector<CornerPlan>& corners) const;
  void weigh_runs_against_corners(Work& work);
  bool take_constant_speed(Work& work, std::vector<PlanDecision>& reports) const;

  const UniformSettings& settings_;
  const TcpLimits& jerk_limits_;
  const DepositModel& model_;
  const PathMotionOptions& base_options_;
  const bool aerosol_;
  PredictionScratch scratch_;  // the corner predictions' processes, reused
  // (a corner's decision does not depend on how its chain's ends are taken: its window enters
  // and leaves at speed; it does on whether loops are allowed)
  CornerDecisionCache decided_, decided_without_loops_;
};

ChainPlan ChainPlanner::plan(const PrintChain& given, const TravelFlags& flags) {
  ChainPlan result;
  result.flags = flags;
  Work work;
  work.options = base_options_;
  work.options.enter_at_speed = base_options_.enter_at_speed && !flags.enter_at_rest;
  work.options.leave_at_speed = base_options_.leave_at_speed && !flags.leave_at_rest;
  work.options.loops_allowed = !flags.without_loops;
  // what the travel changed, reported at the chain's first point
  if (flags.any()) {
    PlanDecision d = chain_decision(given, "within_travel");
    d.figures.push_back({"enters_at_rest", flags.enter_at_rest ? 1.0 : 0.0, "flag"});
    d.figures.push_back({"leaves_at_rest", flags.leave_at_rest ? 1.0 : 0.0, "flag"});
    d.figures.push_back({"loops_allowed", flags.without_loops ? 0.0 : 1.0, "flag"});
    result.decisions.push_back(std::move(d));
  }
  // fine chords merged into edges their corners' blends fit (merge_fine_edges), each corner's
  // blend within the tolerance left by its edges' merging
  work.merged = merge_fine_edges(given, kMergeShare * settings_.tolerance_mm, &jerk_limits_);
  const PrintChain& chain = work.chain();
  work.geometry = corner_geometry(chain.points, settings_.tolerance_mm, work.merged.edge_error_mm);
  // runs of corners along a circle taken as one curve at one constant speed (arc_run.hpp),
  // where a corner alone cannot keep the print speed: at the print speed, not weighed (an
  // even line within the tolerance); below it, weighed below; their corners reported as "arc"
  if (settings_.arc_runs)
    work.runs = find_arc_runs(work.merged, given, work.geometry, settings_.tolerance_mm,
                              jerk_limits_, work.options);
  work.corners.resize(chain.points.size());
  for (const std::shared_ptr<const ArcRun>& run : work.runs)
    for (size_t i = run->first_corner(); i <= run->last_corner(); ++i) {
      work.corners[i].treatment = CornerTreatment::arc;
      work.corners[i].arc = run;
    }
  // each other corner's treatment, by the predicted deposit
  for (size_t i = 1; i + 1 < chain.points.size(); ++i) {
    if (taken_straight_on(work.geometry[i]) || work.corners[i].treatment == CornerTreatment::arc)
      continue;
    work.corners[i] = decide(work, i);
  }
  work.planned = plan_resizing(work, work.corners);
  weigh_runs_against_corners(work);
  // the runs' corners, reported in order with the others
  for (size_t i = 1; i + 1 < chain.points.size(); ++i)
    if (work.corners[i].treatment == CornerTreatment::arc) {
      CornerDecision taken;
      taken.chosen.name = "arc";
      taken.chosen.pruned = true;  // (its deposit not predicted: an even line, see above)
      taken.chosen.plan = work.corners[i];
      work.decisions.emplace_back(i, taken);
    }
  std::sort(work.decisions.begin(), work.decisions.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  const bool at_constant_speed = take_constant_speed(work, result.decisions);
  // each corner reported as planned: its blend (deviation) and the speed it is taken at (at
  // the chain's constant speed: that choice, the corner's own candidates for comparison)
  for (auto& [i, decision] : work.decisions) {
    if (at_constant_speed) {
      decision.chosen = CornerCandidate{};
      decision.chosen.name = "constant_speed";
      decision.chosen.pruned = true;  // (its deposit is the chain's: no error of its own)
    }
    decision.chosen.plan = work.corners[i];
    decision.chosen.speed_mm_s = work.planned.corner_speed_mm_s[i];
    result.decisions.push_back(corner_report(chain, i, work.geometry[i], decision));
  }
  result.first_point = chain.points.front();
  result.last_point = chain.points.back();
  result.first_orientation = chain.orientations.front();
  result.last_orientation = chain.orientations.back();
  result.planned = std::move(work.planned);
  return result;
}

// the treatment of interior point `corner`, by its predicted deposit (an equal corner's, where
// one was decided before), recorded in work.decisions
CornerPlan ChainPlanner::decide(Work& work, size_t corner) {
  CornerDecisionCache& cache = work.options.loops_allowed ? decided_ : decided_without_loops_;
  work.decisions.emplace_back(corner, cache.decision(work.chain(), corner, work.geometry, [&]() {
    return choose_corner(work.chain(), corner, work.geometry, jerk_limits_, work.options, model_,
                         settings_.time_weight_mm_s, scratch_);
  }));
  return work.decisions.back().second.chosen.plan;
}

// The chain planned from 0 with `corners` (then placed after the transition that brings the
// nozzle to its start); blends that hold the look-ahead back are shrunk and the chain planned
// again: the quickest plan kept, its corners in `corners`
PlannedPath ChainPlanner::plan_resizing(const Work& work, std::vector<CornerPlan>& corners) const {
  const PrintChain& chain = work.chain();
  PlannedPath planned = plan_chain(chain, work.geometry, corners, jerk_limits_, work.options, 0.0);
  const std::vector<CornerPlan> chosen = corners;
  std::vector<CornerPlan> trial = corners;
  // (the look-ahead's corner speeds, without curved ramps: the trials are the same with or
  // without them, each plan with them no slower)
  std::vector<double> trial_speeds = planned.lookahead_corner_speed_mm_s;
  for (int pass = 0; pass < kResizePasses && resize_held_blends(chain, work.geometry, trial_speeds,
                                                                jerk_limits_, chosen, trial);
       ++pass) {
    PlannedPath replanned =
        plan_chain(chain, work.geometry, trial, jerk_limits_, work.options, 0.0);
    trial_speeds = replanned.lookahead_corner_speed_mm_s;
    if (replanned.t_end_s < planned.t_end_s) {
      planned = std::move(replanned);
      corners = trial;
    }
  }
  return planned;
}

// A run below the print speed (sized below it for its arc, or held by the look-ahead on a
// circle an extrusion path starts or ends on, at rest), or one from rest to rest (its ramps on
// the curve, under limits lowered for the curve's own terms, may take longer than lines ramping
// between blends at the print speed), may cost more than its corners one by one: those are
// then chosen too and the chain planned without such runs, and the cheaper plan kept: their
// predicted errors plus time_weight x its time, against the runs' plan's time_weight x time
// and, for a stream that cannot follow the speed (aerosol), the thicker line it lays on the
// runs and their ramps (run_speed_deficit_mm x even_line_error_per_mm); an extruder's flow
// follows the speed: its bead stays even.
void ChainPlanner::weigh_runs_against_corners(Work& work) {
  const PrintChain& chain = work.chain();
  std::vector<CornerPlan> without = work.corners;
  const size_t decided_before = work.decisions.size();
  for (const std::shared_ptr<const ArcRun>& run : work.runs) {
    const size_t first = run->first_corner();
    if (!run->from_rest_to_rest && at_print_speed(work.planned, chain, first)) continue;
    for (size_t i = first; i <= run->last_corner(); ++i) without[i] = decide(work, i);
  }
  if (work.decisions.size() == decided_before) return;
  PlannedPath alternative = plan_resizing(work, without);
  double corners_error_mm = 0.0;
  for (size_t k = decided_before; k < work.decisions.size(); ++k)
    if (!work.decisions[k].second.chosen.pruned)
      corners_error_mm += work.decisions[k].second.chosen.error_mm;
  // (aerosol: two loops closer than the shutter's travel v T leave the line between them barely
  // open, d / (2 T) of it let through, d = e / v < T; each corner's window sees its neighbours
  // printed in full, so that loss is added here: on a finely chorded arc looped corner by
  // corner almost nothing is printed)
  if (aerosol_) {
    double unopened_mm = 0.0;
    for (const std::shared_ptr<const ArcRun>& run : work.runs)
      for (size_t i = run->first_corner(); i < run->last_corner(); ++i) {
        if (without[i].treatment != CornerTreatment::loop ||
            without[i + 1].treatment != CornerTreatment::loop)
          continue;
        const double edge = (chain.points[i + 1] - chain.points[i]).norm();
        const double travel = chain.edge_speed_mm_s[i] * model_.shutter_time_s;
        if (edge < travel) unopened_mm += edge * (1.0 - edge / (2.0 * travel));
      }
    corners_error_mm += unopened_mm * even_line_error_per_mm(model_);
  }
  const double runs_error_mm =
      aerosol_ ? work.planned.run_speed_deficit_mm * even_line_error_per_mm(model_) : 0.0;
  if (corners_error_mm + settings_.time_weight_mm_s * alternative.t_end_s <
      runs_error_mm + settings_.time_weight_mm_s * work.planned.t_end_s) {
    work.planned = std::move(alternative);
    work.corners = std::move(without);
  } else {
    work.decisions.resize(decided_before);
  }
}

// Aerosol: the whole chain at one constant speed instead (constant_speed_chain), where some
// corner is not taken at print speed and the even, thicker line costs less than the corners'
// own choices (their predicted errors and the chain's time); true when taken (reported in
// `reports`)
bool ChainPlanner::take_constant_speed(Work& work, std::vector<PlanDecision>& reports) const {
  if (!aerosol_ || work.decisions.empty()) return false;
  const PrintChain& chain = work.chain();
  const bool all_at_print_speed =
      std::all_of(work.decisions.begin(), work.decisions.end(), [&](const auto& entry) {
        const size_t i = entry.first;
        return (work.corners[i].treatment == CornerTreatment::blend ||
                work.corners[i].treatment == CornerTreatment::arc) &&
               at_print_speed(work.planned, chain, i);
      });
  if (all_at_print_speed) return false;
  double corners_error_mm = 0.0;
  for (const auto& entry : work.decisions)
    if (!entry.second.chosen.pruned) corners_error_mm += entry.second.chosen.error_mm;
  const double corners_cost = corners_error_mm + settings_.time_weight_mm_s * work.planned.t_end_s;
  ConstantSpeedChain constant =
      constant_speed_chain(chain, work.geometry, settings_.tolerance_mm, work.merged.edge_error_mm,
                           jerk_limits_, work.options, model_, corners_cost);
  if (!(constant.speed_mm_s > 0.0)) return false;
  const double constant_cost =
      constant.error_mm + settings_.time_weight_mm_s * constant.planned.t_end_s;
  if (!(constant_cost < corners_cost)) return false;
  PlanDecision d = chain_decision(chain, "constant_speed");
  d.figures.push_back({"constant_speed_mm_s", constant.speed_mm_s, "mm/s"});
  d.figures.push_back({"constant_speed_error_mm", constant.error_mm, "mm"});
  d.figures.push_back({"constant_speed_time_s", constant.planned.t_end_s, "s"});
  d.figures.push_back({"corners_error_mm", corners_error_mm, "mm"});
  d.figures.push_back({"corners_time_s", work.planned.t_end_s, "s"});
  reports.push_back(std::move(d));
  work.planned = std::move(constant.planned);
  work.corners = std::move(constant.corners);
  return true;
}

}  // namespace

Trajectory UniformPlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  return plan_in_context(toolpath, limits, PlanningContext{});
}

Trajectory UniformPlanner::plan_in_context(const Toolpath& toolpath, const TcpLimits& limits,
                                           const PlanningContext& context) const {
  const std::string limits_problem = limits.requested().validate();
  if (!limits_problem.empty()) throw InputError("limits", limits_problem);
  DepositModel model;
  if (context.process) model.settings = *context.process;
  model.shutter_time_s = context.shutter_time_s;
  const bool aerosol = model.aerosol();
  const TcpLimits jerk_limits = with_jerk_limits(limits, settings_.jerk_ramp_s);
  // a job that turns the tool on a machine whose joints turn it: timed on the joints
  if (const JointMap* joints = limits.joint_map();
      joints != nullptr && joints->turns_tool && turns_tool(toolpath))
    return plan_on_joints(toolpath, jerk_limits, settings_, model);

  PathMotionOptions base_options;
  base_options.enter_at_speed = base_options.leave_at_speed = aerosol;
  base_options.lag_s = aerosol ? 0.0 : model.settings.tau_s;
  base_options.flow_follows_speed = !aerosol;
  base_options.flow_may_retract = !aerosol && model.settings.retract;
  base_options.loops_at_rest = !aerosol;
  base_options.period_s = settings_.period_s;
  base_options.curved_ramps = settings_.curved_ramps;

  const Toolpath chorded = with_arcs_chorded(toolpath, settings_.tolerance_mm);
  const std::vector<PrintChain> chains = print_chains(chorded);
  // (aerosol) per chain, whether it is entered or left at rest instead of at print speed (the
  // transition at speed took a joint beyond its travel) and whether its corners may not be
  // looped (a loop did): see the end of the attempt loop
  std::vector<TravelFlags> travel(chains.size());
  // each chain's pieces [first, end) in `pieces`
  std::vector<std::pair<size_t, size_t>> chain_pieces(chains.size());
  const JointMap* joint_map = jerk_limits.joint_map();

  std::vector<TrajectoryPiece> pieces;
  std::vector<PlanDecision> decisions;
  double t = 0.0;
  Vec3 position = toolpath.start_mm, velocity = Vec3::Zero();
  ToolOrientation orientation = toolpath.start_orientation();
  // each transition: its piece and the chains it leaves and enters (-1: the job's start, end)
  struct ChainTransition {
    size_t piece = 0;
    int from_chain = -1, to_chain = -1;
  };
  std::vector<ChainTransition> transitions;
  int current_chain = -1;
  const auto add_transition = [&](const Vec3& to, const Vec3& to_velocity,
                                  const ToolOrientation& to_orientation, int to_chain) {
    if ((to - position).norm() <= 1e-12 && (to_velocity - velocity).norm() <= 1e-12) return;
    transitions.push_back(ChainTransition{pieces.size(), current_chain, to_chain});
    pieces.push_back(transition_piece(t, position, velocity, to, to_velocity, jerk_limits,
                                      orientation, to_orientation));
    t = pieces.back().t_end_s;
  };
  ChainPlanner chain_planner(settings_, jerk_limits, model, base_options);
  // each chain's plan, kept across the attempts: a chain whose travel flags did not change is
  // not planned again
  std::vector<std::optional<ChainPlan>> chain_plans(chains.size());
  for (int attempt = 0;; ++attempt) {
    pieces.clear();
    decisions.clear();
    transitions.clear();
    t = 0.0;
    position = toolpath.start_mm, velocity = Vec3::Zero();
    orientation = toolpath.start_orientation();
    current_chain = -1;
    for (size_t c = 0; c < chains.size(); ++c) {
      if (!chain_plans[c] || chain_plans[c]->flags != travel[c])
        chain_plans[c] = chain_planner.plan(chains[c], travel[c]);
      ChainPlan& plan = *chain_plans[c];
      decisions.insert(decisions.end(), plan.decisions.begin(), plan.decisions.end());
      add_transition(plan.first_point, plan.planned.start_velocity, plan.first_orientation,
                     static_cast<int>(c));
      chain_pieces[c].first = pieces.size();
      plan.piece_times_s.clear();
      for (TrajectoryPiece& piece : plan.planned.pieces) {
        plan.piece_times_s.emplace_back(piece.t_begin_s, piece.t_end_s);
        piece.t_begin_s += t;
        piece.t_end_s += t;
        pieces.push_back(std::move(piece));
      }
      chain_pieces[c].second = pieces.size();
      t += plan.planned.t_end_s;
      position = plan.last_point;
      velocity = plan.planned.end_velocity;
      orientation = plan.last_orientation;
      current_chain = static_cast<int>(c);
    }
    add_transition(toolpath.end_mm, Vec3::Zero(), toolpath.end_orientation(), -1);
    // A transition that leaves or enters a chain at speed overshoots the chain's end by the
    // stopping distance, and a corner's loop (shutter closed) runs past the corner: near the
    // travel's end either can go beyond it. Such chains are planned again to stop (and start)
    // at rest at that end, as stop_and_go does (a move between two points at rest stays
    // between them), or without loops (a blend, a slowed or a stopped corner stays inside the
    // corner). Aerosol only: an extruder's ends and loops are at rest already.
    if (attempt >= kTravelAttempts || joint_map == nullptr ||
        !(base_options.enter_at_speed || base_options.leave_at_speed))
      break;
    bool replan = false;
    for (const ChainTransition& transition : transitions) {
      if (!leaves_travel(pieces[transition.piece], *joint_map)) continue;
      if (transition.from_chain >= 0) travel[transition.from_chain].leave_at_rest = true;
      if (transition.to_chain >= 0) travel[transition.to_chain].enter_at_rest = true;
      replan = true;
    }
    for (size_t c = 0; c < chains.size(); ++c) {
      if (travel[c].without_loops) continue;
      for (size_t k = chain_pieces[c].first; k < chain_pieces[c].second; ++k)
        if (!pieces[k].depositing && leaves_travel(pieces[k], *joint_map)) {
          travel[c].without_loops = true;
          replan = true;
          break;
        }
    }
    if (!replan) break;
    // the pieces lent to the job back to their chains' plans, timed from 0 again
    for (size_t c = 0; c < chains.size(); ++c) {
      ChainPlan& plan = *chain_plans[c];
      for (size_t k = 0; k < plan.planned.pieces.size(); ++k) {
        plan.planned.pieces[k] = std::move(pieces[chain_pieces[c].first + k]);
        std::tie(plan.planned.pieces[k].t_begin_s, plan.planned.pieces[k].t_end_s) =
            plan.piece_times_s[k];
      }
    }
  }
  if (pieces.empty()) {
    // nothing to print and nowhere to go: at rest at the start
    pieces.push_back(transition_piece(0.0, position, velocity, position, velocity, jerk_limits,
                                      orientation, orientation));
  }
  return Trajectory("uniform", std::move(pieces), {}, std::move(decisions));
}

std::vector<PlannerParameter> uniform_parameters() {
  return {
      {"tolerance_mm",
       0.05,
       1e-4,
       10.0,
       "corners are blended within this distance of the polyline (LinuxCNC's G64 P): the blended "
       "path never leaves the band",
       false,
       {},
       "mm"},
      {"time_weight",
       0.2,
       0.0,
       1e6,
       "what a second of extra time is worth in mm of misplaced line when a corner's treatment "
       "is chosen (cost = predicted thickness error + time_weight x extra time); 0: the deposit "
       "alone decides",
       false,
       {},
       "mm/s"},
      {"jerk_ramp_s",
       0.01,
       1e-4,
       1.0,
       "without a j_max in the limits, each axis' jerk limit is a_max / jerk_ramp_s (the "
       "acceleration ramps up in this time)",
       false,
       {},
       "s"},
      {"period_s",
       0.001,
       1e-5,
       0.01,
       "longest sample period of a blend (its samples are the exact clothoid)",
       false,
       {},
       "s"},
  };
}

UniformSettings uniform_settings(const PlannerSpec& spec) {
  UniformSettings settings;
  settings.tolerance_mm = spec.get("tolerance_mm", settings.tolerance_mm);
  settings.time_weight_mm_s = spec.get("time_weight", settings.time_weight_mm_s);
  settings.jerk_ramp_s = spec.get("jerk_ramp_s", settings.jerk_ramp_s);
  settings.period_s = spec.get("period_s", settings.period_s);
  return settings;
}

std::unique_ptr<Planner> make_uniform_planner(const PlannerSpec& spec) {
  return std::make_unique<UniformPlanner>(uniform_settings(spec));
}

}  // namespace depotwin
