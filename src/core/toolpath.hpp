// The toolpath: what is to be printed, before any timing.
#pragma once

#include <string>
#include <vector>

#include "core/pose.hpp"
#include "core/types.hpp"

namespace depotwin {

// One edge of a print path as an exact circular or helical arc (G2/G3): the centre at the
// level of the edge's start along `axis` (unit), the arc turning positively (right hand) about
// the axis by `sweep_rad` (0 < sweep <= 2 pi; a full circle ends where it started, plus the
// rise). With r = |start - centre| and the rise h = (end - start) . axis, the point at s in
// [0, 1] is centre + Rot(axis, s sweep)(start - centre) + s h axis, and the length is
// sqrt((r sweep)^2 + h^2). A sweep of 0 is a straight edge.
struct EdgeArc {
  Vec3 center_mm = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double sweep_rad = 0.0;

  bool is_arc() const { return sweep_rad > 0.0; }
};

// One print path: a polyline (mm) printed at one desired speed with material on; edges may be
// exact arcs (`arcs`), which planners that need polylines chord first (`chorded`).
struct PrintPath {
  std::vector<Vec3> points;   // at least two, consecutive points distinct
  std::vector<Vec3> normals;  // optional unit surface normals per point (conformal work): the
                              // tool axes the path asks for; none: a vertical nozzle
  std::vector<double> rolls;  // optional roll about the tool axis per point (rad, Pose), chosen
                              // by a machine with a wrist; none: roll 0 everywhere
  double speed_mm_s = 0.0;    // desired TCP speed while printing
  int source_index = 0;       // index in the scenario's list, for messages and reports
  int layer = 0;              // the layer it belongs to (surface toolpaths, G-code; 0 otherwise)
  std::vector<EdgeArc> arcs;  // empty: every edge straight; else one per edge (sweep 0: straight)

  // true when some edge is an arc
  bool has_arcs() const;
  // the length of edge i (points i to i + 1): helical for an arc
  double edge_length(size_t edge) const;
  // the point at s in [0, 1] along edge i
  Vec3 edge_point(size_t edge, double s) const;
  // The path with its arcs replaced by chords whose sagitta is at most `tolerance_mm` (and that
  // turn at most 90 degrees each); no arcs left. Normals are slerped and rolls interpolated
  // along an arc. `source_point` (optional, out): for each new point, the index of the original
  // point that ends the edge it lies on (0 for the first), to carry per-point data over.
  PrintPath chorded(double tolerance_mm, std::vector<size_t>* source_point = nullptr) const;

  double length_mm() const;
  const Vec3& front() const { return points.front(); }
  const Vec3& back() const { return points.back(); }
  // the same path printed the other way round
  PrintPath reversed() const;
  // axis-aligned bounds of the path (its points and the exact extent of its arcs)
  void bounds(Vec3& lo, Vec3& hi) const;
  // the tool axis at point i (its normal, or vertical without normals)
  Vec3 tool_axis(size_t i) const;
  // the roll at point i (0 without rolls)
  double roll(size_t i) const;
  // axis and roll at point i
  ToolOrientation orientation(size_t i) const { return ToolOrientation{tool_axis(i), roll(i)}; }
  // the tool axis at the point of the path nearest to p: the normals of the nearest edge
  // slerped by where p projects onto it. `edge_hint` (in/out) is the edge of the previous
  // query; the search goes forwards from it a few edges, so points that move along the path
  // cost constant time.
  Vec3 tool_axis_near(const Vec3& p, size_t& edge_hint) const;
  // axis and roll (linear along the edge) at the point of the path nearest to p, as above
  ToolOrientation orientation_near(const Vec3& p, size_t& edge_hint) const;
};

// Start and end of the job (at rest) and the print paths in print order.
struct Toolpath {
  Vec3 start_mm = Vec3::Zero();
  Vec3 end_mm = Vec3::Zero();
  // the roll at start and end (the tool axis there is vertical)
  double start_roll_rad = 0.0;
  double end_roll_rad = 0.0;
  std::vector<PrintPath> paths;
  // the sagitta within which a planner that needs polylines chords the paths' arcs (mm): a
  // G-code toolpath's `chord_tolerance_mm`
  double chord_tolerance_mm = 0.01;

  ToolOrientation start_orientation() const { return {vertical_tool_axis(), start_roll_rad}; }
  ToolOrientation end_orientation() const { return {vertical_tool_axis(), end_roll_rad}; }
  // the number of layers (1 + the largest PrintPath::layer; 1 for an empty toolpath)
  int layer_count() const;

  double print_length_mm() const;
  // every path chorded (PrintPath::chorded)
  Toolpath chorded(double tolerance_mm) const;
  // axis-aligned bounds over start, end and every path point
  void bounds(Vec3& lo, Vec3& hi) const;
};

// Shembekar et al.'s offset-point gap test (sec. 4.1) for consecutive points p0, p1 with unit
// normals n0, n1 and offset distance d: |(p1 + d n1) - (p0 + d n0)| / |p1 - p0|. Above 1 the
// surface is convex between them, below 1 concave, 1 flat (1 for coincident points). For
// points on a curve of normal curvature k it is 1 + d k (exactly, on a circle).
double gap_ratio(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1, double d);

// The number of chords that follow an arc of radius r and sweep within a sagitta tolerance,
// each turning at most 90 degrees: the smallest n with r (1 - cos(sweep / 2n)) <= tolerance.
int arc_chord_count(double radius_mm, double sweep_rad, double tolerance_mm);

// The exact axis-aligned bounds of an arc edge from `start` (EdgeArc above), grown into lo/hi.
void grow_arc_bounds(const Vec3& start, const Vec3& end, const EdgeArc& arc, Vec3& lo, Vec3& hi);

// The largest magnitude of each coordinate of an arc edge's unit tangent over the angles
// [phi0, phi1] of its sweep (0 <= phi0 <= phi1 <= sweep): at both ends, and where a coordinate
// peaks between them. A speed v along the arc needs at most v times it on each axis.
Vec3 arc_tangent_extent(const Vec3& start, const Vec3& end, const EdgeArc& arc, double phi0,
                        double phi1);

// Two path ends closer than this (mm) are one point: printing continues through them.
constexpr double kJoinTolerance_mm = 1e-6;

// The work frame's z = 0 is the top of the table, bed or plate the part stands on; a print
// point this far (mm) below it still counts as on it (rounding in a part's file)
constexpr double kWorkSurfaceTolerance_mm = 1e-3;

// The toolpath with each run of consecutive paths that join end to start (printing goes on
// through the joint) merged into one polyline: what is printed in one go. The merged path
// keeps the first path's speed and source index. Used where "a path's ends" matter (the
// thickness metrics exclude path ends, not joints inside a continuous print).
Toolpath merge_joined_paths(const Toolpath& toolpath);

}  // namespace depotwin
