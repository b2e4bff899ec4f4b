// `uniform`: beyond the papers, a planner that aims at the deposit itself, time-optimal and
// jerk-limited (issue 16). Every planner from the papers controls the motion and hopes the
// deposit follows; this one predicts the deposit with the project's own model and chooses
// what the motion alone cannot.
//
//  - Path: corners blended within `tolerance_mm` by clothoid pairs (clothoid_blend.hpp): the
//    curvature is continuous, so a constant-speed blend has a continuous acceleration. A run
//    of corners along a chorded circle that cannot keep the print speed one by one is taken
//    as one clothoid-arc-clothoid curve at it, or below it where that costs less than the
//    corners' own choices (arc_run.hpp).
//  - Time law: jerk-limited and time-optimal for its family (path_plan.hpp): speed changes on
//    the straight lines (exact per-axis limits along each line's direction, over its box, so a
//    machine's joint limits come mapped where the line is), constant speed on every blend, a
//    look-ahead that makes every line's profile feasible; j_max from the limits, else
//    a_max / `jerk_ramp_s` on each axis.
//  - Deposition coupling (corner_choice.hpp): per corner, a constant-speed blend, a slowed
//    corner, a loop (aerosol: the shutter closed at print speed; extrusion: rest to rest with
//    the flow off) or a stop (extrusion), by the predicted thickness
//    error over the target region plus `time_weight` times the time; an aerosol chain whose
//    corners cannot all keep the print speed is also weighed whole at one constant speed
//    (constant_speed_chain), an even, thicker line, by the same cost; extrusion's commanded flow
//    leads the planned speed by the flow lag (pressure advance), and its decelerations stay
//    within what the lagging flow can follow (line_profile.hpp).
//  - Transitions between print paths: jerk-limited synchronised minimum-time moves with the
//    material off; aerosol paths are entered and left at print speed (the stream cannot be
//    modulated, so a path's start ramp would thicken it), extrusion paths at rest.
//  - On a machine whose joints turn the tool (an arm), in a job that turns it, each print path
//    is timed on the joints instead, by `conformal`'s TOPP-RA law, its flow following the speed
//    or its speed held constant by the same cost (aerosol: the constant speed, the ramps on a
//    lead-in and a lead-out with the shutter closed; plan_on_joints in uniform_planner.cpp).
// Joined paths (a path starting where the previous one ended) are printed in one go, their
// joint a corner like any other. Arcs (PrintPath::arcs) are chorded within a tenth of the
// tolerance first; then every chain's fine edges (those chords, or a slicer's) are merged within
// half the tolerance (merge_fine_edges in path_plan.hpp) and the merged corners blended within
// the rest.
//
// Without a PlanningContext (Planner::plan) the process is the aerosol default.
#pragma once

#include <memory>
#include <vector>

#include "planners/motion/uniform/corner_choice.hpp"
#include "planners/planner.hpp"

namespace depotwin {

struct UniformSettings {
  double tolerance_mm = 0.05;  // the blended path stays this close to the polyline
  // a second of extra time is worth this many mm of misplaced line (README, "Beyond the papers":
  // the default from a sweep over the comparison scenarios)
  double time_weight_mm_s = 0.2;
  double jerk_ramp_s = 0.01;  // without j_max: the acceleration ramps up in this time
  double period_s = 0.001;    // longest sample period of a blend
  // a corner equal to one already decided in the same planning takes its decision
  // (CornerDecisionCache; not a scenario parameter: off, every corner is predicted, as the
  // tests compare)
  bool reuse_corner_decisions = true;
  // runs of corners along a chorded circle taken as one curve where they cannot keep the print
  // speed one by one (find_arc_runs; not a scenario parameter: off, every corner is its own, as
  // the tests compare)
  bool arc_runs = true;
  // speed changes from and to rest (or a held corner) across blended corners planned as one
  // curve (plan_chain's curved ramps; not a scenario parameter: off, they change on the lines
  // only, as the tests compare)
  bool curved_ramps = true;
};

class UniformPlanner : public Planner {
 public:
  explicit UniformPlanner(UniformSettings settings) : settings_(settings) {}
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
  Trajectory plan_in_context(const Toolpath& toolpath, const TcpLimits& limits,
                             const PlanningContext& context) const override;
  const UniformSettings& settings() const { return settings_; }

 private:
  UniformSettings settings_;
};

std::vector<PlannerParameter> uniform_parameters();
UniformSettings uniform_settings(const PlannerSpec& spec);
std::unique_ptr<Planner> make_uniform_planner(const PlannerSpec& spec);

}  // namespace depotwin
