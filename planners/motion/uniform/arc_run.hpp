// A run of corners along a circle taken as one curve: a clothoid from the run's entry line up to
// the circle's curvature, an arc, and a clothoid back down to its exit line, at one constant
// speed (a run from rest to rest, the whole chain, changes speed on it: path_plan.cpp). A circle
// given as fine chords (a G-code arc, a slicer's hole) merges into edges whose corners each need a
// clothoid pair of their own (clothoid_blend.hpp): each pair takes the curvature from 0 up to twice
// the circle's and back within about one chord, and its curvature rate, v^3 kappa' of jerk, caps
// the speed (a 4 mm circle at 50 mm/s on a 1000 mm/s^2 stage: 42.5 mm/s at the most, with 0.9 mm
// chords). On the arc the curvature is constant (jerk v^3 / R^2, acceleration v^2 / R) and it
// changes only on the two transitions, whose length is chosen for the speed.
//
// Geometry (in the run's plane, turning left about its normal e3): the circle (centre c, the
// vertices' least-squares circle; radius R) lies p_in inside the entry line's offset at R and
// p_out inside the exit line's, where a clothoid of length Lc ending at curvature 1 / R is
// shifted by
//   p(Lc) = Lc Y(1) - R (1 - cos tau),  tau = Lc / (2 R)   (its turn),
// and starts k(Lc) = Lc X(1) - R sin tau before the foot of c on its line (X, Y of
// clothoid_integrals at phi = tau). R is the nearer line's distance from c less the shift of
// the transition the run's speed needs (the print speed, or below it: find_arc_runs); each
// transition is then the length whose shift takes its line to the circle. The arc turns the
// run's total turn less tau_in + tau_out.
//
// Bounds at constant speed v (per axis k, m_k the plane's extent along axis k, sqrt(e1_k^2 +
// e2_k^2), the most any in-plane unit vector has on it): v m_k <= v_max, v^2 m_k / R <= a_max,
// v^3 m_k sqrt((1 / (R Lc))^2 + 1 / R^4) <= j_max (p''' = kappa' N - kappa^2 t, largest where a
// transition meets the arc), under blend_limits over the run's box.
#pragma once

#include <memory>
#include <vector>

#include "core/limits.hpp"
#include "core/types.hpp"
#include "planners/motion/uniform/path_plan.hpp"

namespace depotwin {

class ArcRun {
 public:
  // (built by find_arc_runs)
  ArcRun(size_t first_corner, size_t last_corner, const Vec3& centre, double radius_mm,
         const Vec3& d_in, const Vec3& d_out, const Vec3& normal, double total_turn_rad,
         double transition_in_mm, double transition_out_mm, const Vec3& start_mm,
         const Vec3& end_mm);

  size_t first_corner() const { return first_corner_; }
  size_t last_corner() const { return last_corner_; }
  bool covers(size_t corner) const { return corner >= first_corner_ && corner <= last_corner_; }
  double radius_mm() const { return radius_; }
  const Vec3& centre_mm() const { return centre_; }
  // the sections: 0 the entry transition, 1 the arc, 2 the exit transition
  double section_length_mm(int section) const;
  // the chain's edge a section's piece belongs to: the transitions the end edges, the arc the
  // first inner edge (the inner edges are of one path)
  size_t section_edge(int section) const;
  double length_mm() const { return transition_in_ + arc_length_ + transition_out_; }
  const Vec3& start_mm() const { return start_; }
  const Vec3& end_mm() const { return end_; }
  // the tangent at its start and end (the end edges' directions, or at a free end, see
  // find_arc_runs, the transition's own)
  const Vec3& start_direction() const { return d_in_; }
  const Vec3& end_direction() const { return d_out_; }
  double transition_in_mm() const { return transition_in_; }
  double transition_out_mm() const { return transition_out_; }
  // the unit normal of its plane (it turns left about it)
  Vec3 normal() const;

  // position and the arc-length derivatives p', p'', p''' at arc length s in [0, length]
  void at(double s_mm, Vec3& position_mm, Vec3& d1, Vec3& d2, Vec3& d3) const;
  Vec3 position(double s_mm) const;

  // set by find_arc_runs: how far the curve starts before the first corner on the entry edge
  // and ends past the last on the exit edge, its largest distance from the polyline, and the
  // constant speed it keeps the limits at
  double entry_trim_mm = 0.0, exit_trim_mm = 0.0;
  double deviation_mm = 0.0;
  double speed_bound_mm_s = 0.0;
  // the run is its whole chain, which starts and ends at rest (an extrusion path along one
  // chorded circle, a slicer's hole): its speed changes on the curve itself (plan_chain)
  bool from_rest_to_rest = false;

 private:
  size_t first_corner_, last_corner_;
  Vec3 centre_;
  double radius_;
  Vec3 d_in_, n_in_, d_out_, n_out_;  // the lines' directions and their left normals
  double transition_in_, transition_out_, arc_length_;
  double tau_in_, tau_out_;  // the transitions' turns
  Vec3 start_, end_;
};

// The runs of a chain's corners taken as arcs: runs of at least kMinArcRunCorners consecutive
// corners that turn one way in one plane, each by less than 90 deg, at one print speed, their
// inner edges of one print path (the end edges may be of the paths joined to it), at least one
// of which cannot keep the print speed on its own largest blend, where one such curve keeps
// the print speed under the limits over the run's box (where its arc alone cannot, 0.9 of the
// speed the arc allows; where its transitions at the print speed do not fit its end edges, 0.9,
// 0.75 or 0.6 of it, for shorter ones; the planner weighs a slower run against the corners' own
// choices), stays
// within tolerance_mm of the polyline as given (before merge_fine_edges: `given`, checked on
// its samples both ways) and starts and ends on the run's end edges, leaving each at least
// half for its other end (the whole edge at an end of the chain the path enters or leaves at
// speed). There, where the edge is too short for that (a chorded circle's closing chords), the
// curve may start or end at the chain's end point itself, free: its transition's line turned
// to pass through that point (the transition move to or from the chain takes its direction).
// A chain entered and left at rest may be one run with both ends free (from_rest_to_rest),
// tried first there and with no slow corner needed: its speed changes on the curve, where the
// corners one by one ramp on the lines between their blends only.
// Longest first, from each corner on. Chains carrying the tool's orientation have none.
constexpr size_t kMinArcRunCorners = 3;
std::vector<std::shared_ptr<const ArcRun>> find_arc_runs(
    const MergedChain& merged, const PrintChain& given, const std::vector<CornerGeometry>& geometry,
    double tolerance_mm, const TcpLimits& limits, const PathMotionOptions& options);

}  // namespace depotwin
