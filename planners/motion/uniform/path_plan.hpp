// One print path planned by `uniform`, once each corner's treatment is chosen
// (corner_choice.hpp chooses it): its geometry, its jerk-limited time law and its trajectory
// pieces.
//
// Geometry. The polyline's edges, trimmed at each corner by the corner's treatment:
//   straight  collinear edges: no corner;
//   blend     a clothoid pair (clothoid_blend.hpp) traversed at constant speed; the edges lose
//             its tangent length;
//   loop      (aerosol) the shutter closes `trim_in` before the corner, the nozzle loops with
//             the shutter closed (a jerk-limited synchronised move, motion/sync.hpp, leaving
//             and entering at the lines' velocities) and printing resumes `trim_out` after the
//             corner;
//   stop      the path comes to rest at the corner (a reversal an extruder cannot loop);
//   arc       one of a run of corners along a circle taken as one clothoid-arc-clothoid curve
//             at constant speed (arc_run.hpp): the run's end edges lose what it takes of them,
//             its inner edges are taken whole. A run from rest to rest (the whole chain, a
//             slicer's hole) changes speed on the curve itself (see path_plan.cpp,
//             plan_run_from_rest).
//
// Time law. Speed changes happen on the straight lines only (but on a run from rest to rest);
// every curved section (blend, arc run) is traversed at one constant speed, its "node" speed.
// Between two nodes a line runs the time-optimal jerk-limited profile of line_profile.hpp (zero
// acceleration at both ends), so the acceleration is continuous everywhere: a line meets a blend
// where the blend's curvature (and so its acceleration) is 0. Each node's speed is capped by its
// section's limits (blend_speed_bound over the blend's box), the print speed and the adjacent
// lines' caps; a backward and a forward pass (the classic look-ahead) lower the caps to what the
// lines can reach (reachable_speed), which makes every line's profile feasible and the whole law
// the fastest jerk-limited one of this family. Per-axis limits map exactly onto a line: v <= v_k /
// |u_k|, a <= a_k / |u_k|, j <= j_k / |u_k| for its direction u, over the line's box
// (TcpLimits::along: a machine's joint limits mapped where the line is).
//
// Pieces. A line is a PhaseMotion (per axis p0_k + u_k s(t): constant-jerk phases, exact); a
// blend is a SampledMotion at constant speed (samples of the exact clothoid; an even number of
// equal periods no longer than period_s, so the apex, where the curvature rate flips, falls
// on a sample); a loop is a transition piece (not depositing). With a flow lag (extrusion) the
// pieces' commanded flow leads the planned speed (TrajectoryPiece::flow_lead_s).
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"
#include "planners/motion/uniform/clothoid_blend.hpp"
#include "planners/motion/uniform/line_profile.hpp"

namespace depotwin {

class ArcRun;

enum class CornerTreatment { straight, blend, loop, stop, arc };
const char* corner_treatment_name(CornerTreatment treatment);

// How one interior point of a path is taken.
struct CornerPlan {
  CornerTreatment treatment = CornerTreatment::straight;
  double half_length_mm = 0.0;        // blend: the clothoids' half-length
  double trim_in_mm = 0.0;            // loop: printing stops this far before the corner
  double trim_out_mm = 0.0;           // loop: and resumes this far after it
  std::shared_ptr<const ArcRun> arc;  // arc: the run the corner is in
};

// What is printed in one go: consecutive print paths joined end to start (one path, or several
// whose ends touch, e.g. a polyline given as separate segments), as one polyline whose edges
// keep their own path's index and speed.
struct PrintChain {
  std::vector<Vec3> points;
  std::vector<ToolOrientation> orientations;  // per point
  std::vector<double> edge_speed_mm_s;        // per edge: its path's print speed
  std::vector<int> edge_path;                 // per edge: index into Toolpath::paths
  std::vector<int> edge_source;               // per edge: the path's source index (messages)
  // per point: the print path and the point index within it where the point ends an edge
  // (the first point: the first path's point 0)
  std::vector<int> point_path, point_index;
  bool oriented = false;  // some path has normals or rolls: the tool axis is carried

  size_t edges() const { return points.empty() ? 0 : points.size() - 1; }
  // the print speed at interior point `corner`: the lower of its two edges'
  double corner_print_speed_mm_s(size_t corner) const {
    return std::min(edge_speed_mm_s[corner - 1], edge_speed_mm_s[corner]);
  }
  // the orientation at a fraction of edge e (slerp of the axes, rolls linear)
  ToolOrientation edge_orientation(size_t e, double fraction) const;
  // the orientation at the point of edges e and e + 1 nearest to p (a blend's sample)
  ToolOrientation orientation_near_corner(size_t corner, const Vec3& p) const;
};
// the chains of a toolpath: runs of consecutive paths whose ends join (kJoinTolerance_mm);
// InputError for a path with fewer than two points, a zero-length edge, a bad speed or
// non-finite points
std::vector<PrintChain> print_chains(const Toolpath& toolpath);

// How the path's ends are taken and how the flow is commanded.
struct PathMotionOptions {
  bool enter_at_speed = false;      // starts at print speed (aerosol: a transition brings it)
  bool leave_at_speed = false;      // ends at print speed
  double lag_s = 0.0;               // extruder flow lag: the deceleration rule and the flow lead
  bool flow_follows_speed = false;  // pieces carry flow_lead_s = lag_s
  // the led flow may go below 0 (process.retract: the extruder pulls the filament back), so
  // decelerations are bounded by a_max alone, not by |v| / lag_s
  bool flow_may_retract = false;
  // the lag the deceleration rule keeps to (LineLimits::lag_s): lag_s, or 0 when the flow may
  // retract
  double deceleration_lag_s() const { return flow_may_retract ? 0.0 : lag_s; }
  double period_s = 0.001;  // longest sample period of a blend
  // loops leave and re-enter their lines at rest (extrusion: the line ends at rest, the nozzle
  // travels with the flow off, the next line starts from rest); else at the lines' speeds
  bool loops_at_rest = false;
  // corners may be looped (choose_corner's loop candidates); false where a loop's excursion
  // past the corner would leave the machine's travel (the uniform planner finds that)
  bool loops_allowed = true;
  // a speed change from or to rest (or a corner held at its cap) across blended corners whose
  // lines are too short for it is planned as one curve (the look-ahead changes speed on the
  // lines only)
  bool curved_ramps = true;
};

// A chain with its runs of fine edges merged (a block compressor, LinuxCNC's naive-CAM
// tolerance `G64 Q`): slicers and CAM systems give curves as chords, often shorter than the
// blend a corner needs at print speed under the jerk limit (0.3 mm chords of a 10 mm circle at
// 50 mm/s: each corner's clothoid pair would need 0.2 mm of each chord). Blended one corner
// at a time within half a chord, such a curve is a string of curvature spikes: every corner
// slowed or looped. Here consecutive edges of one path (same print speed) become one edge
// wherever every point dropped lies within max_error_mm of it (greedily, from each kept
// point as far as the next edge would still hold), so the curve keeps points every
// 2 sqrt(2 r max_error_mm) or so and their corners fit their blends. A point farther from the
// chord is kept: the sharp corners the deposit decides stay as given. On chains that carry the
// tool's orientation, only points where it stays the same are dropped. edge_error_mm: per
// merged edge, the largest distance of a dropped point from it (0 where nothing was dropped);
// the original polyline stays within that of the edge, so a corner's blend keeps to the
// tolerance less its edges' errors (corner_geometry).
struct MergedChain {
  PrintChain chain;
  std::vector<double> edge_error_mm;
  std::vector<size_t> source_point;  // per kept point, its index in the given chain
};
// With `limits`, an edge is merged only where the print speed keeps within every axis's v_max
// along the merged edge (plan_chain's check), whose direction differs from each edge's.
MergedChain merge_fine_edges(const PrintChain& chain, double max_error_mm,
                             const TcpLimits* limits = nullptr);

// A corner's geometry (interior points only): its directions, turn and blend shape.
struct CornerGeometry {
  Vec3 point = Vec3::Zero();
  Vec3 d_in = Vec3::UnitX(), d_out = Vec3::UnitX();
  double turn_rad = 0.0;              // 0: straight on, pi: a reversal
  double interior_deg = 180.0;        // the joint angle: 180 - turn
  double tangent_per_length = 0.0;    // T / L of a clothoid pair at this turn
  double deviation_per_length = 0.0;  // deviation / L
  BlendShape shape;                   // per-axis maxima at half-length 1
  double max_half_length_mm = 0.0;    // tolerance and room on the adjacent edges
};
// whether the planner takes corner g straight on (no treatment): no turn, or a turn below
// 90 deg with no room for a blend (a kink within rounding of straight)
inline bool taken_straight_on(const CornerGeometry& g) {
  return g.turn_rad <= 0.0 || (g.max_half_length_mm <= 0.0 && g.turn_rad < 0.5 * kPi);
}
// every point's corner geometry (index = point index; ends are straight placeholders),
// with the largest blend within tolerance_mm that leaves each adjacent edge at least half for
// its other end; with edge_error_mm (per edge, merge_fine_edges), within tolerance_mm less the
// larger error of the corner's two edges
std::vector<CornerGeometry> corner_geometry(const std::vector<Vec3>& points, double tolerance_mm,
                                            const std::vector<double>& edge_error_mm = {});
// the tolerance a corner's blend keeps to: tolerance_mm less the larger merge error of its two
// edges (none without edge errors)
double corner_tolerance_mm(double tolerance_mm, const std::vector<double>& edge_error_mm,
                           size_t corner);
// that largest blend at corner g (its turn set: tangent and deviation per length) between
// edges of the given lengths; 0 for a corner taken straight or as a reversal
double max_blend_half_length(const CornerGeometry& g, double edge_in_mm, double edge_out_mm,
                             double tolerance_mm);

// A planned print path: pieces from t_begin, and its boundary velocities.
struct PlannedPath {
  std::vector<TrajectoryPiece> pieces;
  Vec3 start_velocity = Vec3::Zero(), end_velocity = Vec3::Zero();
  double t_end_s = 0.0;
  // per corner (point index), the constant speed it was taken at (blends), or the line speeds
  // into and out of it (loops, straights, stops: the lower)
  std::vector<double> corner_speed_mm_s;
  // on the arc runs and the lines next to them, the integral of (print speed - speed) dt: how
  // much longer a line laid at the print speed would be (what a stream that cannot follow the
  // speed lays thicker there)
  double run_speed_deficit_mm = 0.0;
  // the corners' speeds as the look-ahead gave them, speeds changing on the lines only (before
  // any curved ramp): what tells a blend that holds its lines back (resize_held_blends)
  std::vector<double> lookahead_corner_speed_mm_s;
};

// The limits a planner needs with a jerk limit on every axis: the user's where given, else
// a_max / jerk_ramp_s (the acceleration ramps up in jerk_ramp_s); the machine's joint map kept.
TcpLimits with_jerk_limits(const TcpLimits& limits, double jerk_ramp_s);

// Plans a chain from t_begin with the corners as given (one per point; ends ignored). `limits`
// must carry jerk limits (with_jerk_limits). InputError when a print speed exceeds an axis'
// limit along its edge. Speeds change on the lines (a backward and a forward look-ahead), on a
// run from rest to rest, and (options.curved_ramps) on a curved ramp: a stretch from or to a
// rest or a corner held at its cap across blended corners the look-ahead leaves below their
// caps, planned as one curve where that is quicker.
PlannedPath plan_chain(const PrintChain& chain, const std::vector<CornerGeometry>& geometry,
                       const std::vector<CornerPlan>& corners, const TcpLimits& limits,
                       const PathMotionOptions& options, double t_begin_s);

// the limits blends are held to: kBlendLimitShare of the acceleration and jerk limits (the
// slack the cubic interpolation of a blend's samples needs)
MachineLimits blend_limits(MachineLimits limits);
// the limits a blend of the given half-length at corner g is held to: blend_limits over the
// box of its two tangent points and the corner (the triangle it lies in)
MachineLimits corner_blend_limits(const CornerGeometry& g, double half_length_mm,
                                  const TcpLimits& limits);

// the straight line's limits along direction u (unit) under per-axis limits, capped at speed
LineLimits line_limits(const Vec3& u, const MachineLimits& limits, double speed_cap_mm_s,
                       double lag_s);

}  // namespace depotwin
