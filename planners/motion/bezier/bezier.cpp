#include "planners/motion/bezier/bezier.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>  // cross products of arcs

#include "core/error.hpp"
#include "motion/jerk.hpp"
#include "planners/motion/bezier/bezier_curve.hpp"
#include "planners/motion/bezier/bezier_profile.hpp"
#include "planners/motion/fine_edges.hpp"
#include "planners/motion/print_segments.hpp"
#include "planners/motion/sampled_jerk.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

constexpr const char* kAxisName[3] = {"x", "y", "z"};
// detailed warnings per plan; the rest are counted in one summary line
constexpr size_t kMaxDetailedWarnings = 20;
// rounds of slowing blends whose interpolated samples exceed a limit
constexpr int kMaxSlowDownRounds = 12;

// ---------------------------------------------------------------------------------------
// geometry: a print path as lines between nodes; a node is the path's start or end, a
// blended corner, a corner where the path stops, or a straight pass-through (lead-in/out)

struct PathLine {
  Vec3 from_mm = Vec3::Zero(), to_mm = Vec3::Zero();
  Vec3 dir = Vec3::UnitX();  // the polyline edge's direction (also when length is 0)
  double length_mm = 0.0;
  double accel_mm_s2 = 0.0;             // along-line acceleration every axis allows
  double cap_mm_s = 0.0;                // print speed
  std::optional<GridProfile> prebuilt;  // the lead-in ramp, built to end exactly at P_0
  // under a jerk limit: the along-line jerk every axis allows (infinity where no axis has a
  // j_max; 0: the path is not jerk-limited) and the lead-in's S-curve
  double jerk_mm_s3 = 0.0;
  std::optional<JerkGridProfile> prebuilt_jerk;
};

struct PathNode {
  std::optional<BezierBlend> blend;
  double blend_length_mm = 0.0;
  double speed_mm_s = 0.0;  // after the passes: the speed through the node
  double cap_mm_s = 0.0;    // before the passes
  bool exact = false;       // the line before ends on a sample here (rest, or lead-in end)
  int corner = -1;          // corner number within the polyline (1-based), -1 if none
  bool arc = false;         // the blend is one of the path's exact arcs (its corner: the start)
  std::string cap_reason;   // what limits the blend speed, for the warning
};

struct PathGeometry {
  std::vector<PathLine> lines;  // line k runs from node k to node k + 1
  std::vector<PathNode> nodes;
  bool lead = false;  // lines.front() / lines.back() are lead-in / lead-out
};

// along-line acceleration every axis allows on direction `dir`
double line_accel(const Vec3& dir, const MachineLimits& limits) {
  double a = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis)
    if (std::abs(dir[axis]) > 1e-12)
      a = std::min(a, limits.axes[axis].a_max_mm_s2 / std::abs(dir[axis]));
  return a;
}

// under a jerk limit, the share of j_max a blend's constant-speed crossing plans with (the
// Taylor update, the joint corrections and the cubic interpolation of the samples take a
// little; what they take is checked after sampling and the blend slowed if needed)
constexpr double kBlendJerkShare = 0.9;

// along-line jerk every axis allows (infinity where no axis has a j_max)
double line_jerk(const Vec3& dir, const MachineLimits& limits) {
  double j = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis)
    if (std::abs(dir[axis]) > 1e-12 && limits.axes[axis].j_max_mm_s3 > 0.0)
      j = std::min(j, limits.axes[axis].j_max_mm_s3 / std::abs(dir[axis]));
  return j;
}

// The highest constant speed through a blend that keeps every axis within its limits:
// |v T_axis| <= v_max and |v^2 kappa N_axis| <= a_max along the curve; at u = 0 and 1
// the acceleration jumps between two samples, where cubic Hermite interpolation of the
// samples overshoots a step by up to 4/3, so the ends count 4/3.
//
// Under a jerk limit (the curvature-continuous blend: no jump at its ends) also
// |v^3 d3p/ds3| <= kBlendJerkShare j_max per axis, the jerk of a constant-speed crossing.
double blend_speed_cap(const BezierBlend& blend, const MachineLimits& limits, std::string& reason,
                       bool jump_at_start = true, bool jump_at_end = true) {
  constexpr int kIntervals = 256;
  double cap = std::numeric_limits<double>::infinity();
  Vec3 p, d1, d2;
  if (blend.degree == 4) jump_at_start = jump_at_end = false;
  for (int i = 0; i <= kIntervals; ++i) {
    const double u = double(i) / kIntervals;
    blend.derivatives(u, p, d1, d2);
    if (blend.degree == 4) {
      const Vec3 third = blend.third_arc_derivative(u);
      for (int axis = 0; axis < 3; ++axis) {
        const double j_max = limits.axes[axis].j_max_mm_s3;
        if (!(j_max > 0.0) || std::abs(third[axis]) < 1e-12) continue;
        const double v = std::cbrt(kBlendJerkShare * j_max / std::abs(third[axis]));
        if (v < cap) {
          cap = v;
          reason = std::string("j_max of axis ") + kAxisName[axis];
        }
      }
    }
    const double speed_u = d1.norm();
    const Vec3 tangent = d1 / speed_u;
    // curvature vector: the normal part of d2p/du2 over |dp/du|^2
    const Vec3 curvature = (d2 - d2.dot(tangent) * tangent) / (speed_u * speed_u);
    const bool jump = (i == 0 && jump_at_start) || (i == kIntervals && jump_at_end);
    const double hermite_factor = jump ? 4.0 / 3.0 : 1.0;
    for (int axis = 0; axis < 3; ++axis) {
      const AxisLimits& lim = limits.axes[axis];
      if (std::abs(tangent[axis]) > 1e-12 && lim.v_max_mm_s / std::abs(tangent[axis]) < cap) {
        cap = lim.v_max_mm_s / std::abs(tangent[axis]);
        reason = std::string("v_max of axis ") + kAxisName[axis];
      }
      const double k = hermite_factor * std::abs(curvature[axis]);
      if (k > 1e-12 && std::sqrt(lim.a_max_mm_s2 / k) < cap) {
        cap = std::sqrt(lim.a_max_mm_s2 / k);
        reason = std::string("a_max of axis ") + kAxisName[axis];
      }
    }
  }
  return cap;
}

std::string corner_name(const PrintPath& path, int corner) {
  return "path " + std::to_string(path.source_index) + " corner " + std::to_string(corner);
}

std::string node_name(const PrintPath& path, const PathNode& node) {
  return node.arc ? "path " + std::to_string(path.source_index) + " arc from point " +
                        std::to_string(node.corner)
                  : corner_name(path, node.corner);
}

// ---------------------------------------------------------------------------------------
// exact arcs (G-code G2/G3): a circular arc of sweep phi is the rational quadratic Bezier with
// its ends as end points, the tangents' intersection as middle point and weight cos(phi / 2)
// (Piegl & Tiller, The NURBS Book, sec. 7.3), so the blend machinery of eq. (18) traverses it
// exactly, at constant speed, pieces of at most 90 degrees

// an arc meets its neighbour tangentially when their directions differ by at most this (rad)
constexpr double kTangentJoin_rad = 2e-3;
// a vertex whose edges turn by at most this (rad) is straight on: no corner, one line
constexpr double kStraightTurnRad = 1e-10;

// the arc edge's radius vector at its start, in its plane (from the centre at the start's level)
Vec3 arc_radius(const PrintPath& path, size_t edge) {
  const EdgeArc& arc = path.arcs[edge];
  const Vec3 r = path.points[edge] - arc.center_mm;
  return r - r.dot(arc.axis) * arc.axis;
}

bool is_arc_edge(const PrintPath& path, size_t edge) {
  return !path.arcs.empty() && path.arcs[edge].is_arc();
}

// the unit direction of travel at the start (s = 0) or end (s = 1) of an edge
Vec3 edge_direction(const PrintPath& path, size_t edge, double s) {
  if (!is_arc_edge(path, edge)) return (path.points[edge + 1] - path.points[edge]).normalized();
  const EdgeArc& arc = path.arcs[edge];
  const Vec3 r = arc_radius(path, edge);
  const double phi = s * arc.sweep_rad;
  const Vec3 rise = (path.points[edge + 1] - path.points[edge]).dot(arc.axis) / arc.sweep_rad *
                    arc.axis;  // a helix climbs along the axis
  return (-std::sin(phi) * r + std::cos(phi) * arc.axis.cross(r) + rise).normalized();
}

// the arc edge as blends of at most 90 degrees each (planar arcs only)
std::vector<BezierBlend> arc_pieces(const PrintPath& path, size_t edge) {
  const EdgeArc& arc = path.arcs[edge];
  const Vec3 r = arc_radius(path, edge);
  const Vec3 centre = path.points[edge] - r;
  const Vec3 side = arc.axis.cross(r);
  const int n = std::max(1, static_cast<int>(std::ceil(arc.sweep_rad / (kPi / 2.0) - 1e-9)));
  const double piece_rad = arc.sweep_rad / n;
  const auto at = [&](double phi) { return centre + std::cos(phi) * r + std::sin(phi) * side; };
  std::vector<BezierBlend> pieces;
  for (int k = 0; k < n; ++k) {
    const double from = k * piece_rad, mid = (k + 0.5) * piece_rad;
    BezierBlend piece;
    piece.entry_mm = k == 0 ? path.points[edge] : at(from);
    piece.exit_mm = k + 1 == n ? path.points[edge + 1] : at(from + piece_rad);
    piece.corner_mm =
        centre + (std::cos(mid) * r + std::sin(mid) * side) / std::cos(0.5 * piece_rad);
    piece.weight = std::cos(0.5 * piece_rad);
    pieces.push_back(piece);
  }
  return pieces;
}

// The path as bezier traverses it. An arc stays exact when it is planar, lies inside the path
// (the path starts and ends at rest on a line: blends keep a constant speed) and meets both
// neighbours tangentially; every other arc becomes chords within `tolerance_mm`, as for the
// planners that need polylines. `original_vertex` gets each vertex's index in `path`, -1 for
// a vertex between chords.
//
// Under a jerk limit every arc becomes chords (keep_arcs false): a circle entered from its
// tangent line steps the curvature from 0 to 1 / R, which no finite jerk crosses at speed; the
// chords' corners get curvature-continuous blends like every other corner.
PrintPath with_traversable_arcs(const PrintPath& path, double tolerance_mm,
                                std::vector<int>& original_vertex, bool keep_arcs = true) {
  const size_t edges = path.points.size() - 1;
  std::vector<bool> exact(edges, false);
  if (keep_arcs && path.has_arcs() && path.normals.empty() && path.rolls.empty())
    for (size_t e = 1; e + 1 < edges; ++e)
      exact[e] = is_arc_edge(path, e) &&
                 std::abs((path.points[e + 1] - path.points[e]).dot(path.arcs[e].axis)) <= 1e-9;
  // an edge's direction at a join: an arc kept exact its tangent, a chorded one its chord's
  const auto chord_direction = [&](size_t edge, bool at_end) {
    PrintPath single;
    single.points = {path.points[edge], path.points[edge + 1]};
    single.arcs = {path.arcs[edge]};
    const std::vector<Vec3> chords = single.chorded(tolerance_mm).points;
    return at_end ? (chords.back() - chords[chords.size() - 2]).normalized()
                  : (chords[1] - chords[0]).normalized();
  };
  const auto direction = [&](size_t edge, bool at_end) {
    if (is_arc_edge(path, edge) && !exact[edge]) return chord_direction(edge, at_end);
    return edge_direction(path, edge, at_end ? 1.0 : 0.0);
  };
  // tangency, until no arc changes (an arc chorded may break its neighbour's tangency)
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t e = 1; e + 1 < edges; ++e) {
      if (!exact[e]) continue;
      const double in =
          std::acos(std::clamp(direction(e - 1, true).dot(direction(e, false)), -1.0, 1.0));
      const double out =
          std::acos(std::clamp(direction(e, true).dot(direction(e + 1, false)), -1.0, 1.0));
      if (in > kTangentJoin_rad || out > kTangentJoin_rad) exact[e] = false, changed = true;
    }
  }
  // the path with the other arcs' chords
  PrintPath out = path;
  out.points.assign(1, path.points.front());
  out.arcs.clear();
  original_vertex.assign(1, 0);
  for (size_t e = 0; e < edges; ++e) {
    if (is_arc_edge(path, e) && !exact[e]) {
      PrintPath single;
      single.points = {path.points[e], path.points[e + 1]};
      single.arcs = {path.arcs[e]};
      const std::vector<Vec3> chords = single.chorded(tolerance_mm).points;
      for (size_t c = 1; c + 1 < chords.size(); ++c) {
        out.points.push_back(chords[c]);
        out.arcs.push_back(EdgeArc{});
        original_vertex.push_back(-1);
      }
      out.arcs.push_back(EdgeArc{});
    } else {
      out.arcs.push_back(exact[e] ? path.arcs[e] : EdgeArc{});
    }
    out.points.push_back(path.points[e + 1]);
    original_vertex.push_back(static_cast<int>(e + 1));
  }
  if (!out.has_arcs()) out.arcs.clear();
  return out;
}

// Fine chords merged (BezierSettings::merge_mm): consecutive straight edges become one where
// every point dropped stays within max_error_mm of it, so a curve given as many short chords
// gets corners with room for their fillets. Clipped to half of 0.05 mm chords, the blends
// left lines of 0 mm between them, where no ramp fits: a circle of radius 10 mm in 0.05 mm
// chords was printed at a third of its speed. Arcs kept exact are not merged; `original_vertex`
// keeps the index of each point kept.
PrintPath with_fine_chords_merged(const PrintPath& path, std::vector<int>& original_vertex,
                                  double max_error_mm) {
  constexpr size_t kMaxMergedEdges = 256;  // bounds the work per merged edge
  const FineEdgeMerge merged = merge_polyline_edges(
      path.points, max_error_mm, kMaxMergedEdges, [&](size_t anchor, size_t edge) {
        return !is_arc_edge(path, anchor) && !is_arc_edge(path, edge);
      });
  if (merged.kept.size() == path.points.size()) return path;
  PrintPath out = path;
  out.points.clear();
  out.arcs.clear();
  std::vector<int> kept_vertex;
  for (size_t k = 0; k < merged.kept.size(); ++k) {
    const size_t i = merged.kept[k];
    out.points.push_back(path.points[i]);
    kept_vertex.push_back(original_vertex[i]);
    // an edge kept alone keeps its arc; a merged one is straight
    if (k > 0 && path.has_arcs()) out.arcs.push_back(path.arcs[merged.kept[k - 1]]);
  }
  original_vertex = std::move(kept_vertex);
  return out;
}

PathGeometry build_geometry(const PrintPath& path, const std::vector<int>& original_vertex,
                            const BezierSettings& settings, const MachineLimits& limits,
                            size_t first_weight, std::vector<std::string>& warnings,
                            bool jerk_limited) {
  const std::vector<Vec3>& points = path.points;
  const size_t edges = points.size() - 1;
  const double print_speed = path.speed_mm_s;
  std::vector<Vec3> dirs(edges);
  std::vector<double> lengths(edges);
  for (size_t i = 0; i < edges; ++i) {
    lengths[i] = (points[i + 1] - points[i]).norm();
    dirs[i] = (points[i + 1] - points[i]) / lengths[i];
  }
  // a vertex between two straight edges that turns by at most kStraightTurnRad is no corner:
  // its edges are one line (no blend: a blend of a 0-degree turn is a piece of the line at
  // constant speed, and clipped to half of short edges it leaves lines of length 0 between
  // blends, where no ramp fits); `run` is the length of the merged line each edge is part of
  std::vector<bool> straight(points.size(), false);
  for (size_t j = 1; j < edges; ++j)
    straight[j] = !is_arc_edge(path, j - 1) && !is_arc_edge(path, j) &&
                  dirs[j - 1].dot(dirs[j]) > 0.0 &&
                  dirs[j - 1].cross(dirs[j]).norm() <= kStraightTurnRad;
  std::vector<double> run = lengths;
  for (size_t e = 1; e < edges; ++e)
    if (straight[e]) run[e] += run[e - 1];
  for (size_t e = edges - 1; e-- > 0;)
    if (straight[e + 1]) run[e] = run[e + 1];

  // a straight line from a to b along dir (trimmed by the blends below)
  const auto line_between = [&](const Vec3& a, const Vec3& b, const Vec3& dir) {
    PathLine line;
    line.from_mm = a;
    line.to_mm = b;
    line.dir = dir;
    line.accel_mm_s2 = line_accel(dir, limits);
    line.cap_mm_s = print_speed;
    if (jerk_limited) line.jerk_mm_s3 = line_jerk(dir, limits);
    return line;
  };

  // the blended corner at vertex j between straight edges j - 1 and j
  const auto corner_node = [&](size_t j) {
    PathNode node;
    node.corner = original_vertex[j] >= 0 ? original_vertex[j] : static_cast<int>(j);
    const double weight = settings.weights.size() == 1 ? settings.weights.front()
                          : original_vertex[j] > 0
                              ? settings.weights[first_weight + original_vertex[j] - 1]
                              : 1.0;  // a corner between an arc's chords
    const Vec3& in_dir = dirs[j - 1];
    const Vec3& out_dir = dirs[j];
    // an exact reversal has no blend (its parabola degenerates to a cusp): stop there
    if ((in_dir + out_dir).norm() < 1e-9) {
      node.exact = true;
      warnings.push_back(corner_name(path, node.corner) +
                         ": reverses direction; stopping at the corner");
      return node;
    }
    // fillet distance, clipped to half the shorter adjacent line
    const double room = 0.5 * std::min(run[j - 1], run[j]);
    double delta = settings.delta_mm;
    if (delta > room) {
      delta = room;
      std::ostringstream msg;
      msg << corner_name(path, node.corner) << ": fillet distance clipped from "
          << settings.delta_mm << " to " << delta << " mm (half the shorter adjacent line)";
      warnings.push_back(msg.str());
    }
    // under a jerk limit the curvature-continuous quartic (see bezier_curve.hpp)
    BezierBlend blend =
        jerk_limited
            ? BezierBlend::curvature_continuous_at_corner(points[j], in_dir, out_dir, delta, weight)
            : BezierBlend::at_corner(points[j], in_dir, out_dir, delta, weight);
    const double blend_length = blend.arc_length_mm();
    std::string reason;
    const double cap = std::min(print_speed, blend_speed_cap(blend, limits, reason));
    // A very sharp corner crossed slowly can take longer than stopping at it. Compare the
    // extra time over cruising at print speed: blend = the slow blend plus the ramps down
    // to its speed and back, stop = the legs of 2 delta plus ramping to rest and back.
    const double a = std::min(line_accel(in_dir, limits), line_accel(out_dir, limits));
    double blend_extra = blend_length / cap - blend_length / print_speed +
                         (print_speed - cap) * (print_speed - cap) / (a * print_speed);
    double stop_extra = (2.0 * delta - blend_length) / print_speed + print_speed / a;
    if (jerk_limited) {
      // the same with S-curves: a ramp by dv takes tau(dv) and loses tau (dv / 2) / v_print
      const double j = std::min(line_jerk(in_dir, limits), line_jerk(out_dir, limits));
      const auto ramp_s = [&](double dv) {
        return std::isfinite(j) ? s_curve_duration(dv, a, j) : dv / a;
      };
      blend_extra = blend_length / cap - blend_length / print_speed +
                    ramp_s(print_speed - cap) * (print_speed - cap) / print_speed;
      stop_extra = (2.0 * delta - blend_length) / print_speed + ramp_s(print_speed);
    }
    if (blend_extra > stop_extra) {
      node.exact = true;
      std::ostringstream msg;
      msg << corner_name(path, node.corner) << ": blend would need " << cap << " mm/s (" << reason
          << "); stopping at the corner is faster";
      warnings.push_back(msg.str());
      return node;
    }
    node.blend = blend;
    node.blend_length_mm = blend_length;
    node.cap_mm_s = cap;
    node.cap_reason = cap < print_speed ? reason : "";
    return node;
  };

  // nodes and lines alternate: a straight edge is a line, a corner between two straight edges
  // a node (blend or stop), an exact arc one node per piece (zero-length lines between
  // pieces and between consecutive arcs); the path starts and ends at rest on a line
  PathGeometry g;
  g.nodes.emplace_back();
  g.nodes.back().exact = true;
  for (size_t e = 0; e < edges; ++e) {
    if (!is_arc_edge(path, e)) {
      if (e > 0 && straight[e]) {  // straight on: the line before runs on to this edge's end
        const Vec3 from = g.lines.back().from_mm;
        g.lines.back() = line_between(from, points[e + 1], (points[e + 1] - from).normalized());
        continue;
      }
      if (e > 0 && !is_arc_edge(path, e - 1)) g.nodes.push_back(corner_node(e));
      g.lines.push_back(line_between(points[e], points[e + 1], dirs[e]));
      continue;
    }
    const std::vector<BezierBlend> pieces = arc_pieces(path, e);
    for (size_t k = 0; k < pieces.size(); ++k) {
      const BezierBlend& piece = pieces[k];
      if (k > 0 || is_arc_edge(path, e - 1))
        g.lines.push_back(line_between(
            piece.entry_mm, piece.entry_mm,
            edge_direction(path, e, static_cast<double>(k) / static_cast<double>(pieces.size()))));
      PathNode node;
      node.arc = true;
      node.corner = original_vertex[e];
      node.blend = piece;
      node.blend_length_mm = piece.arc_length_mm();
      // the curvature jumps where the arc meets another curve or a line, not between pieces
      std::string reason;
      node.cap_mm_s = std::min(
          print_speed, blend_speed_cap(piece, limits, reason, k == 0, k + 1 == pieces.size()));
      node.cap_reason = node.cap_mm_s < print_speed ? reason : "";
      g.nodes.push_back(node);
    }
  }
  g.nodes.emplace_back();
  g.nodes.back().exact = true;

  // lines between the nodes: trimmed by the blends (an arc's ends are its lines' ends)
  for (size_t i = 0; i < g.lines.size(); ++i) {
    PathLine& line = g.lines[i];
    if (g.nodes[i].blend) line.from_mm = g.nodes[i].blend->exit_mm;
    if (g.nodes[i + 1].blend) line.to_mm = g.nodes[i + 1].blend->entry_mm;
    line.length_mm = std::max(0.0, (line.to_mm - line.from_mm).dot(line.dir));
  }

  // lead-in/out: straight extensions of the first and last line, material off; the
  // path's own ends become pass-through nodes at print speed
  if (settings.lead_in) {
    g.lead = true;
    PathNode first = g.nodes.front(), last = g.nodes.back();
    first.exact = true;  // the lead-in ramp ends exactly at P_0, on a sample
    last.exact = false;  // printing runs on through P_n
    first.cap_mm_s = last.cap_mm_s = print_speed;
    PathLine lead_in_line = g.lines.front(), lead_out_line = g.lines.back();
    lead_out_line.from_mm = points.back();
    // long enough for the final knee and ramp of an exact end plus the entry margin
    const double a_out = lead_out_line.accel_mm_s2, period = settings.period_s;
    lead_out_line.length_mm =
        print_speed * print_speed / (2.0 * a_out) + 5.0 * print_speed * period;
    if (jerk_limited && std::isfinite(lead_out_line.jerk_mm_s3))
      lead_out_line.length_mm =
          jerk_grid_room(print_speed, 0.0, a_out, lead_out_line.jerk_mm_s3, period) +
          2.0 * print_speed * period;
    lead_out_line.to_mm = lead_out_line.from_mm + lead_out_line.length_mm * lead_out_line.dir;
    // the lead-in's length is set once its end speed is known (after the passes)
    lead_in_line.to_mm = points.front();
    g.nodes.front() = first;
    g.nodes.back() = last;
    g.nodes.insert(g.nodes.begin(), PathNode{});
    g.nodes.front().exact = true;
    g.nodes.push_back(PathNode{});
    g.nodes.back().exact = true;
    g.lines.insert(g.lines.begin(), lead_in_line);
    g.lines.push_back(lead_out_line);
  }
  return g;
}

// forward/backward passes: node speeds as high as their caps allow while every line
// can hold the ramps between its end speeds on the sample grid
//
// Under a jerk limit a line holds its S-curve when jerk_grid_room fits in it. That room is not
// monotone in the lower end speed (a faster start can need more room), so instead of one
// forward and one backward pass the sweeps repeat until nothing changes; each change lowers the
// higher end speed of a line that cannot hold its S-curve, which only shortens that S-curve.
void assign_jerk_node_speeds(PathGeometry& g, double period_s, size_t first) {
  const auto fits = [&](size_t k, double v_a, double v_b) {
    const PathLine& line = g.lines[k];
    return jerk_grid_room(v_a, v_b, line.accel_mm_s2, line.jerk_mm_s3, period_s) <=
           line.length_mm * (1 + 1e-12);
  };
  const auto settle = [&](size_t k) {
    double& v_a = g.nodes[k].speed_mm_s;
    double& v_b = g.nodes[k + 1].speed_mm_s;
    if (fits(k, v_a, v_b)) return false;
    double& high = v_a > v_b ? v_a : v_b;
    const double low = std::min(v_a, v_b);
    double lo = low, hi = high;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      (fits(k, low, mid) ? lo : hi) = mid;
    }
    high = lo;
    return true;
  };
  for (int sweep = 0; sweep < 10000; ++sweep) {
    bool changed = false;
    for (size_t k = first; k < g.lines.size(); ++k) changed = settle(k) || changed;
    for (size_t k = g.lines.size(); k-- > first;) changed = settle(k) || changed;
    if (!changed) return;
  }
  throw InternalError("bezier: jerk-limited node speeds did not settle");
}

void assign_node_speeds(PathGeometry& g, double period_s) {
  const size_t first = g.lead ? 1 : 0;  // the lead-in line is built to fit afterwards
  for (PathNode& node : g.nodes)
    node.speed_mm_s = node.blend || (!node.exact && node.cap_mm_s > 0.0) ? node.cap_mm_s : 0.0;
  if (g.lead) g.nodes[1].speed_mm_s = g.nodes[1].cap_mm_s;
  const bool jerk_limited = !g.lines.empty() && g.lines.front().jerk_mm_s3 > 0.0;
  if (jerk_limited) {
    assign_jerk_node_speeds(g, period_s, first);
    // the lead-in: one grid S-curve from rest to the speed at P_0, its length made to fit
    if (g.lead) {
      PathLine& lead_in = g.lines.front();
      const double v = g.nodes[1].speed_mm_s;
      JerkGridProfile ramp;
      ramp.append_s_curve(grid_s_curve(v, lead_in.accel_mm_s2, lead_in.jerk_mm_s3, period_s), v,
                          period_s);
      ramp.v_after_mm_s = v;
      lead_in.length_mm = ramp.distance_mm(period_s);
      lead_in.from_mm = lead_in.to_mm - lead_in.length_mm * lead_in.dir;
      lead_in.prebuilt_jerk = ramp;
    }
    return;
  }
  for (size_t k = first; k < g.lines.size(); ++k) {
    const PathLine& line = g.lines[k];
    g.nodes[k + 1].speed_mm_s = std::min(
        g.nodes[k + 1].speed_mm_s,
        reachable_speed(g.nodes[k].speed_mm_s, line.length_mm, line.accel_mm_s2, period_s));
  }
  for (size_t k = g.lines.size(); k-- > first;) {
    const PathLine& line = g.lines[k];
    g.nodes[k].speed_mm_s = std::min(
        g.nodes[k].speed_mm_s,
        reachable_speed(g.nodes[k + 1].speed_mm_s, line.length_mm, line.accel_mm_s2, period_s));
  }
  // the lead-in: one grid ramp from rest to the speed at P_0, its length made to fit
  if (g.lead) {
    PathLine& lead_in = g.lines.front();
    const double v = g.nodes[1].speed_mm_s;
    const double ramp_steps = std::ceil(v / (lead_in.accel_mm_s2 * period_s) - 1e-9);
    if (!(ramp_steps <= 1e9))
      throw InputError("limits.a_max",
                       "bezier: the lead-in ramp takes more than 1e9 samples of its period; "
                       "raise a_max or the period_s");
    const int steps = std::max(1, static_cast<int>(ramp_steps));
    GridProfile ramp;
    ramp.v_start_mm_s = 0.0;
    ramp.phases[0] = {steps, v / (steps * period_s)};
    ramp.v_after_mm_s = v;
    lead_in.length_mm = ramp.distance_mm(period_s);
    lead_in.from_mm = lead_in.to_mm - lead_in.length_mm * lead_in.dir;
    lead_in.prebuilt = ramp;
  }
}

// ---------------------------------------------------------------------------------------
// sampling: the Taylor update of the curve parameter along the pieces of one path

class PathSampler {
 public:
  PathSampler(const PathGeometry& geometry, double period_s, std::vector<Vec3>& positions,
              std::vector<Vec3>& velocities, std::vector<int>& nodes)
      : g_(geometry),
        period_(period_s),
        positions_(positions),
        velocities_(velocities),
        nodes_(nodes) {}

  // samples from the path's start to its end, both at rest; returns the sample indices
  // where printing starts and stops (P_0 reached, first sample past P_n) in lead mode
  void run(size_t& print_begin, size_t& print_end) {
    print_begin = 0;
    print_end = 0;
    enter_line(0, 0.0, g_.nodes[0].speed_mm_s, true);
    while (true) {
      if (piece_ % 2 == 0) {
        if (!step_line()) break;
      } else {
        step_blend();
      }
    }
    print_end = g_.lead ? lead_out_begin_ : positions_.size() - 1;
    print_begin = g_.lead ? lead_in_end_ : 0;
  }
  // the largest distance a line's last sample was moved to put it exactly on the line's end
  // (the closed-form profile's own rounding)
  double largest_end_snap_mm() const { return largest_end_snap_mm_; }

 private:
  // pieces: 2k = line k, 2k + 1 = node k + 1
  int line_of(size_t piece) const { return static_cast<int>(piece / 2); }
  int node_of(size_t piece) const { return static_cast<int>((piece + 1) / 2); }

  void push(const Vec3& position, const Vec3& velocity) {
    positions_.push_back(position);
    velocities_.push_back(velocity);
    nodes_.push_back(piece_ % 2 == 1 ? node_of(piece_) : -1 - line_of(piece_));
  }

  // start line k at distance s0 from its start with speed v_in: plan its grid profile
  void enter_line(int k, double s0_mm, double v_in, bool push_sample) {
    const PathLine& line = g_.lines[k];
    const PathNode& end = g_.nodes[k + 1];
    piece_ = 2 * size_t(k);
    step_ = 0;
    line_u_ = line.length_mm > 0.0 ? s0_mm / line.length_mm : 0.0;  // eq. (13)
    entry_mm_ = s0_mm;
    jerk_ = line.jerk_mm_s3 > 0.0;
    if (jerk_) {
      // under a jerk limit: S-curves on the grid (bezier_profile.hpp)
      std::optional<JerkGridProfile> profile =
          line.prebuilt_jerk
              ? line.prebuilt_jerk
              : plan_jerk_grid_profile(line.length_mm - s0_mm, v_in, end.speed_mm_s, line.cap_mm_s,
                                       line.accel_mm_s2, line.jerk_mm_s3, period_, end.exact);
      if (!profile) {
        std::ostringstream msg;
        msg << "bezier: no jerk-limited grid profile on a line of " << line.length_mm - s0_mm
            << " mm from " << v_in << " to " << end.speed_mm_s << " mm/s";
        throw InternalError(msg.str());
      }
      jerk_profile_ = std::move(*profile);
      if (push_sample) push(line.from_mm + s0_mm * line.dir, v_in * line.dir);
      if (g_.lead && size_t(k) + 1 == g_.lines.size()) lead_out_begin_ = positions_.size() - 1;
      return;
    }
    std::optional<GridProfile> profile =
        line.prebuilt ? line.prebuilt
                      : plan_grid_profile(line.length_mm - s0_mm, v_in, end.speed_mm_s,
                                          line.cap_mm_s, line.accel_mm_s2, period_, end.exact);
    if (!profile) {
      std::ostringstream msg;
      msg << "bezier: no grid profile on a line of " << line.length_mm - s0_mm << " mm from "
          << v_in << " to " << end.speed_mm_s << " mm/s";
      throw InternalError(msg.str());
    }
    profile_ = *profile;
    if (push_sample) push(line.from_mm + s0_mm * line.dir, v_in * line.dir);
    // printing stops at the first sample on the lead-out (past P_n by less than v T)
    if (g_.lead && size_t(k) + 1 == g_.lines.size()) lead_out_begin_ = positions_.size() - 1;
  }

  // one sample period on a line; false once the path's end is reached
  bool step_line() {
    const int k = line_of(piece_);
    const PathLine& line = g_.lines[k];
    const PathNode& end = g_.nodes[k + 1];
    const int total_steps = jerk_ ? jerk_profile_.total_steps() : profile_.total_steps();
    if (end.exact && step_ == total_steps) {
      // the profile ends exactly at the line's end, on this sample
      largest_end_snap_mm_ =
          std::max(largest_end_snap_mm_, (positions_.back() - line.to_mm).cwiseAbs().maxCoeff());
      positions_.back() = line.to_mm;
      velocities_.back() = end.speed_mm_s * line.dir;
      if (g_.lead && k == 0) lead_in_end_ = positions_.size() - 1;
      if (size_t(k) + 1 == g_.lines.size()) return false;
      // a stop or the lead-in's end: the next line starts here, from this sample
      enter_line(k + 1, 0.0, end.speed_mm_s, false);
      return true;
    }
    double v = 0.0, a = 0.0, j = 0.0;
    if (jerk_)
      jerk_profile_.at_step(step_, period_, v, a, j);
    else
      profile_.at_step(step_, period_, v, a);
    if (!end.exact && v <= 0.0 && a <= 0.0 && j <= 0.0)
      throw InternalError("bezier: stalled on a line before a moving joint");
    // eq. (5) on a line: |dp/du| = L and d2p/du2 = 0, so u advances by (v T + a T^2 / 2) / L
    // exactly (the acceleration changes only at samples; under a jerk limit the jerk, and the
    // step adds j T^3 / 6). The sum of these steps is taken in closed form from the line's
    // entry, which keeps rounding from piling up over long lines.
    const double step_mm = jerk_ ? period_ * (v + period_ * (0.5 * a + j * period_ / 6.0))
                                 : v * period_ + 0.5 * a * period_ * period_;
    const double remaining_mm = line.length_mm * (1.0 - line_u_);
    if (end.exact || step_mm < remaining_mm) {
      ++step_;
      const double s_mm = entry_mm_ + (jerk_ ? jerk_profile_.distance_after(step_, period_)
                                             : profile_.distance_after(step_, period_));
      line_u_ = s_mm / line.length_mm;
      double v_next = 0.0, a_next = 0.0, j_next = 0.0;
      if (jerk_)
        jerk_profile_.at_step(step_, period_, v_next, a_next, j_next);
      else
        profile_.at_step(step_, period_, v_next, a_next);
      push(line.from_mm + s_mm * line.dir, v_next * line.dir);
      return true;
    }
    // the joint falls inside this period: carry the rest of the step into the next pieces
    const double v_end = jerk_ ? v + period_ * (a + 0.5 * j * period_) : v + a * period_;
    cross_joint(piece_ + 1, step_mm - remaining_mm, v_end);
    return true;
  }

  // one sample period on a blend at constant speed, eq. (4)
  void step_blend() {
    const PathNode& node = g_.nodes[node_of(piece_)];
    const BezierBlend& blend = *node.blend;
    const double v = node.speed_mm_s;
    Vec3 p, d1, d2;
    blend.derivatives(blend_u_, p, d1, d2);
    const double next_u = blend_u_ + taylor_parameter_step(d1, d2, v, 0.0, period_);
    if (next_u < 1.0) {
      blend_u_ = next_u;
      blend.derivatives(blend_u_, p, d1, d2);
      // velocity from the analytic derivative: p'(u) du/dt with du/dt = v / |p'(u)|, eq. (3).
      // (Eq. (10) prints the middle coefficient of db/dt as 2 u'(1 - u) - 2 u u''; the
      // derivative of eq. (8) is 2 u' (1 - 2u), which is what p'(u) u' gives.)
      push(p, (v / d1.norm()) * d1);
      return;
    }
    // eq. (12): what is left of the blend; the rest of the step continues past it
    const double left_mm = distance_to_end(d1, d2, blend_u_);
    cross_joint(piece_ + 1, std::max(0.0, v * period_ - left_mm), v);
  }

  // Continue `distance_mm` into the pieces from `piece` on at constant speed v and place the
  // sample there (eqs. (11), (13)); pieces shorter than the distance are passed over.
  void cross_joint(size_t piece, double distance_mm, double v) {
    while (true) {
      if (piece % 2 == 0) {
        const int k = line_of(piece);
        const PathLine& line = g_.lines[k];
        if (distance_mm < line.length_mm || g_.nodes[k + 1].exact) {
          enter_line(k, std::min(distance_mm, line.length_mm), v, true);
          return;
        }
        distance_mm -= line.length_mm;
        ++piece;
        continue;
      }
      const PathNode& node = g_.nodes[node_of(piece)];
      if (node.blend && distance_mm < node.blend_length_mm) {
        Vec3 p, d1, d2;
        node.blend->derivatives(0.0, p, d1, d2);
        blend_u_ = std::clamp(parameter_at_distance_from_start(d1, d2, distance_mm), 0.0, 1.0);
        node.blend->derivatives(blend_u_, p, d1, d2);
        piece_ = piece;
        push(p, (v / d1.norm()) * d1);
        return;
      }
      if (node.blend) distance_mm -= node.blend_length_mm;
      ++piece;
    }
  }

  const PathGeometry& g_;
  const double period_;
  std::vector<Vec3>& positions_;
  std::vector<Vec3>& velocities_;
  std::vector<int>& nodes_;  // per sample: the blend's node, or -1 - line index on a line
  size_t piece_ = 0;
  // line state
  GridProfile profile_;
  JerkGridProfile jerk_profile_;  // under a jerk limit (jerk_), instead of profile_
  bool jerk_ = false;
  int step_ = 0;
  double line_u_ = 0.0;
  double entry_mm_ = 0.0;  // where on the line the profile started
  // blend state
  double blend_u_ = 0.0;
  size_t lead_in_end_ = 0, lead_out_begin_ = 0;
  double largest_end_snap_mm_ = 0.0;
};

// How far the interpolated samples go beyond the limits, per blend: cubic Hermite between
// two samples has a linear acceleration (extremes at the samples) and a quadratic velocity
// (extreme where the acceleration crosses zero). A blend whose curvature changes a lot within
// one sample period can overshoot there; `slow_down[j]` < 1 is the factor by which blend j's
// speed must shrink. Returns false when an excess is not on a blend (not expected: lines
// carry exact quadratics).
bool check_sampled_limits(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                          const std::vector<int>& nodes, const PathGeometry& g, double period_s,
                          const MachineLimits& limits, double end_snap_mm,
                          std::vector<double>& slow_down) {
  // rounding (a ramp at exactly a_max): a share of the limit; and the acceleration that a
  // position's rounding makes over one period, 6 dp / h^2, for a few ulps of the largest
  // coordinate and the largest move of a line's last sample onto its end (at a_max 0.1 mm/s^2
  // a 9e-12 mm move alone read 0.03 % over the limit; at 0.01, the ulps 1e-6 of it)
  constexpr double kTolerance = 1e-6;
  bool owned = true;
  slow_down.assign(g.nodes.size(), 1.0);
  const double h = period_s;
  const double a_rounding = 6.0 * sample_position_rounding_mm(positions, end_snap_mm) / (h * h);
  const bool jerk_limited = !g.lines.empty() && g.lines.front().jerk_mm_s3 > 0.0;
  // the blend interval k belongs to (either end on it, or the joint between two lines)
  const auto owner = [&](size_t k) {
    int node = nodes[k] >= 0 ? nodes[k] : nodes[k + 1];
    if (node < 0 && nodes[k] != nodes[k + 1]) node = -1 - nodes[k] + 1;
    return node;
  };
  for (size_t k = 0; k + 1 < positions.size(); ++k) {
    const int node = owner(k);
    double factor = 1.0;
    for (int axis = 0; axis < 3; ++axis) {
      const double dp = positions[k + 1][axis] - positions[k][axis];
      const double v0 = velocities[k][axis], v1 = velocities[k + 1][axis];
      const double a0 = 6.0 * dp / (h * h) - (4.0 * v0 + 2.0 * v1) / h;
      const double a1 = -6.0 * dp / (h * h) + (2.0 * v0 + 4.0 * v1) / h;
      double v_peak = std::max(std::abs(v0), std::abs(v1));
      if ((a0 > 0.0) != (a1 > 0.0) && a0 != a1) {
        const double s = a0 / (a0 - a1);
        v_peak = std::max(v_peak, std::abs(v0 + h * (a0 * s + 0.5 * (a1 - a0) * s * s)));
      }
      const double a_ratio = std::max(0.0, std::max(std::abs(a0), std::abs(a1)) - a_rounding) /
                             limits.axes[axis].a_max_mm_s2;
      const double v_ratio = v_peak / limits.axes[axis].v_max_mm_s;
      if (a_ratio > 1.0 + kTolerance) factor = std::min(factor, std::sqrt(1.0 / a_ratio));
      if (v_ratio > 1.0 + kTolerance) factor = std::min(factor, 1.0 / v_ratio);
    }
    if (factor >= 1.0) continue;
    if (node < 0 || !g.nodes[node].blend) {
      owned = false;
      continue;
    }
    slow_down[node] = std::min(slow_down[node], factor);
  }
  if (!jerk_limited || positions.size() < 2) return owned;

  // the jerk the plan's 1 ms finite differences see on the interpolated samples (see
  // sampled_jerk.hpp); a period over j_max slows the blends it touches (the jerk goes with v^3)
  constexpr double kJerkTolerance = 1e-3;
  const Vec3 j_max(limits.axes[0].j_max_mm_s3, limits.axes[1].j_max_mm_s3,
                   limits.axes[2].j_max_mm_s3);
  std::vector<double> ratio;
  if (sampled_jerk_ratio(positions, velocities, h, j_max, &ratio, 0.001, end_snap_mm) <=
      1.0 + kJerkTolerance)
    return owned;
  for (size_t k = 0; k < ratio.size(); ++k) {
    if (ratio[k] <= 1.0 + kJerkTolerance) continue;
    // the blends within a few periods of it (a window spans three fd periods)
    bool found = false;
    const size_t reach = static_cast<size_t>(std::ceil(0.003 / h)) + 1;
    for (size_t i = k >= reach ? k - reach : 0; i <= std::min(ratio.size() - 1, k + reach); ++i) {
      const int node = owner(i);
      if (node < 0 || !g.nodes[node].blend) continue;
      slow_down[node] = std::min(slow_down[node], std::cbrt(1.0 / ratio[k]));
      found = true;
    }
    owned = owned && found;
  }
  return owned;
}

TrajectoryPiece sampled_piece(double t_begin_s, double period_s, std::vector<Vec3> positions,
                              std::vector<Vec3> velocities, int path_index, bool depositing,
                              double desired_speed_mm_s, const PrintPath& path) {
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  piece.t_end_s = t_begin_s + period_s * double(positions.size() - 1);
  piece.path_index = path_index;
  piece.depositing = depositing;
  piece.desired_speed_mm_s = desired_speed_mm_s;
  SampledMotion motion;
  motion.period_s = period_s;
  motion.position_mm = std::move(positions);
  motion.velocity_mm_s = std::move(velocities);
  // the tool axis (and roll) of a path with normals or rolls: at every sample, the path's
  // where it is nearest
  if (!path.normals.empty() || !path.rolls.empty()) {
    size_t edge_hint = 0;
    motion.tool_axis.reserve(motion.position_mm.size());
    if (!path.rolls.empty()) motion.roll_rad.reserve(motion.position_mm.size());
    for (const Vec3& p : motion.position_mm) {
      const ToolOrientation tool = path.orientation_near(p, edge_hint);
      motion.tool_axis.push_back(tool.axis);
      if (!path.rolls.empty()) motion.roll_rad.push_back(tool.roll_rad);
    }
  }
  piece.motion = std::move(motion);
  return piece;
}

// The limits over the box a path sweeps: its points, and with a lead-in its extensions of
// up to v^2 / (2 a) and a few samples beyond either end (the padding follows the limits over
// the padded box, which are tighter)
MachineLimits path_limits(const PrintPath& path, const TcpLimits& limits, bool lead_in,
                          double period_s) {
  Vec3 lo, hi;
  path.bounds(lo, hi);
  MachineLimits over = limits.over(lo, hi);
  if (!lead_in) return over;
  for (int round = 0; round < 3; ++round) {
    double a_min = std::numeric_limits<double>::infinity();
    for (const AxisLimits& axis : over.axes) a_min = std::min(a_min, axis.a_max_mm_s2);
    const double v = path.speed_mm_s;
    const double pad_mm = v * v / (2.0 * a_min) + 4.0 * v * period_s;
    over = limits.over((lo.array() - pad_mm).matrix(), (hi.array() + pad_mm).matrix());
  }
  return over;
}

}  // namespace

std::vector<PlannerParameter> bezier_parameters() {
  return {
      {"delta",
       0.5,
       1e-6,
       100.0,
       "fillet distance: the blend starts and ends this far from the corner",
       false,
       {},
       "mm"},
      {"weight", 1.0, 0.01, 100.0,
       "rational weight of each corner (one value, or one per corner of the toolpath in order); "
       "larger pulls the blend towards the corner, 1 is the parabola",
       true},
      {"period_s", 0.001, 1e-5, 0.1, "sample period T_s of the Taylor update of u", false, {}, "s"},
      {"lead_in",
       0.0,
       0.0,
       1.0,
       "1: ramp up and down on extensions of the first and last line with material off; 0: on "
       "the lines",
       false,
       {},
       "",
       true},
      {"merge",
       0.01,
       0.0,
       1.0,
       "fine chords: consecutive straight edges whose dropped points stay within this of one "
       "line are merged into it before the corners are blended (0: every point kept; a "
       "per-corner weight list or a path with tool orientations keeps every point)",
       false,
       {},
       "mm"},
  };
}

BezierSettings bezier_settings(const PlannerSpec& spec) {
  BezierSettings settings;
  settings.delta_mm = spec.get("delta", settings.delta_mm);
  auto weights = spec.params.find("weight");
  if (weights != spec.params.end() && !weights->second.empty()) settings.weights = weights->second;
  settings.period_s = spec.get("period_s", settings.period_s);
  settings.merge_mm = spec.get("merge", settings.merge_mm);
  settings.lead_in = spec.get_switch("lead_in", settings.lead_in);
  return settings;
}

std::unique_ptr<Planner> make_bezier_planner(const PlannerSpec& spec) {
  return std::make_unique<BezierPlanner>(bezier_settings(spec));
}

Trajectory BezierPlanner::plan(const Toolpath& toolpath, const TcpLimits& tcp_limits) const {
  const std::string limits_problem = tcp_limits.requested().validate();
  if (!limits_problem.empty()) throw InputError("limits", limits_problem);
  // degenerate edges, bad speeds and lines too fast for an axis: as for every planner (arcs as
  // the chords the others get)
  split_into_segments(toolpath.chorded(toolpath.chord_tolerance_mm), tcp_limits);

  // one weight for all corners, or exactly one per corner
  size_t corners = 0;
  for (const PrintPath& path : toolpath.paths) {
    if (path.points.size() < 2)
      throw InputError("toolpath path " + std::to_string(path.source_index),
                       "needs at least two points");
    corners += path.points.size() - 2;
  }
  if (settings_.weights.empty() ||
      (settings_.weights.size() != 1 && settings_.weights.size() != corners)) {
    std::ostringstream msg;
    msg << "has " << settings_.weights.size() << " values; ";
    if (corners == 0)
      msg << "the toolpath has no corners (every path is a single line): give one value";
    else
      msg << "the toolpath has " << corners << (corners == 1 ? " corner" : " corners")
          << " (give one value for all, or one per corner in order)";
    throw InputError("planners.bezier.weight", msg.str());
  }

  // a jerk limit in force anywhere on the job: S-curves on the lines, curvature-continuous
  // blends, arcs as chords (see bezier.hpp)
  Vec3 job_lo = toolpath.start_mm.cwiseMin(toolpath.end_mm);
  Vec3 job_hi = toolpath.start_mm.cwiseMax(toolpath.end_mm);
  for (const PrintPath& path : toolpath.paths) {
    Vec3 lo, hi;
    path.bounds(lo, hi);
    job_lo = job_lo.cwiseMin(lo);
    job_hi = job_hi.cwiseMax(hi);
  }
  const bool jerk_limited =
      tcp_limits.requested().jerk_limited() || tcp_limits.over(job_lo, job_hi).jerk_limited();

  std::vector<TrajectoryPiece> pieces;
  std::vector<std::string> warnings;
  double t = 0.0;
  Vec3 position = toolpath.start_mm;
  ToolOrientation tool = toolpath.start_orientation();
  size_t next_weight = 0;
  std::vector<Vec3> positions, velocities;
  std::vector<int> owners;
  std::vector<double> slow_down;
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    // the path with the arcs it can traverse exactly, the others as chords
    std::vector<int> original_vertex;
    PrintPath path = with_traversable_arcs(toolpath.paths[i], toolpath.chord_tolerance_mm,
                                           original_vertex, !jerk_limited);
    // fine chords merged, unless each corner has its own weight or each point its orientation
    if (settings_.merge_mm > 0.0 && settings_.weights.size() == 1 && path.normals.empty() &&
        path.rolls.empty())
      path = with_fine_chords_merged(path, original_vertex, settings_.merge_mm);
    // the limits over the path's own box (per path: its blends and ramps are planned together)
    const MachineLimits limits =
        path_limits(path, tcp_limits, settings_.lead_in, settings_.period_s);
    PathGeometry geometry = build_geometry(path, original_vertex, settings_, limits, next_weight,
                                           warnings, jerk_limited);
    next_weight += toolpath.paths[i].points.size() - 2;

    // the samples: Taylor update along the path; blends whose samples, interpolated,
    // exceed a limit are slowed and the path sampled again
    const double estimate = path.length_mm() / path.speed_mm_s / settings_.period_s;
    positions.reserve(static_cast<size_t>(1.2 * estimate) + 64);
    velocities.reserve(positions.capacity());
    owners.reserve(positions.capacity());
    size_t print_begin = 0, print_end = 0;
    for (int attempt = 0;; ++attempt) {
      assign_node_speeds(geometry, settings_.period_s);
      positions.clear();
      velocities.clear();
      owners.clear();
      PathSampler sampler(geometry, settings_.period_s, positions, velocities, owners);
      sampler.run(print_begin, print_end);
      const bool owned =
          check_sampled_limits(positions, velocities, owners, geometry, settings_.period_s, limits,
                               sampler.largest_end_snap_mm(), slow_down);
      const bool within =
          std::all_of(slow_down.begin(), slow_down.end(), [](double f) { return f >= 1.0; });
      if (owned && within) break;
      if (!owned || attempt == kMaxSlowDownRounds)
        throw InternalError("bezier: sampled motion of path " + std::to_string(path.source_index) +
                            " exceeds the limits");
      // the samples fall differently at the new speed: take a growing extra margin so the
      // rounds settle (1e-4, 1e-3, 1e-2, then 10 %)
      const double margin = std::pow(10.0, std::min(-1, attempt - 4));
      for (size_t j = 0; j < slow_down.size(); ++j) {
        if (slow_down[j] >= 1.0) continue;
        PathNode& node = geometry.nodes[j];
        node.cap_mm_s = std::min(node.cap_mm_s, node.speed_mm_s) * slow_down[j] * (1.0 - margin);
        if (node.cap_reason.empty()) node.cap_reason = "limits between samples on a sharp blend";
      }
    }
    for (const PathNode& node : geometry.nodes) {
      if (!node.blend || node.speed_mm_s >= path.speed_mm_s * (1.0 - 1e-9)) continue;
      std::ostringstream msg;
      msg << node_name(path, node) << ": blend slowed to " << node.speed_mm_s
          << " mm/s (print speed " << path.speed_mm_s << " mm/s; "
          << (node.cap_reason.empty() ? std::string("adjacent lines too short to ramp")
                                      : node.cap_reason)
          << ")";
      warnings.push_back(msg.str());
    }

    // shutter closed: to the path's first sample, at rest
    pieces.push_back(transition_piece(t, position, Vec3::Zero(), positions.front(), Vec3::Zero(),
                                      tcp_limits, tool, path.orientation(0)));
    t = pieces.back().t_end_s;
    const int path_index = static_cast<int>(i);
    auto slice = [&](size_t begin, size_t end) {
      return std::vector<Vec3>(positions.begin() + begin, positions.begin() + end + 1);
    };
    auto slice_v = [&](size_t begin, size_t end) {
      return std::vector<Vec3>(velocities.begin() + begin, velocities.begin() + end + 1);
    };
    if (geometry.lead) {
      pieces.push_back(sampled_piece(t, settings_.period_s, slice(0, print_begin),
                                     slice_v(0, print_begin), -1, false, 0.0, path));
      t = pieces.back().t_end_s;
    }
    pieces.push_back(sampled_piece(t, settings_.period_s, slice(print_begin, print_end),
                                   slice_v(print_begin, print_end), path_index, true,
                                   path.speed_mm_s, path));
    t = pieces.back().t_end_s;
    if (geometry.lead) {
      const size_t last = positions.size() - 1;
      pieces.push_back(sampled_piece(t, settings_.period_s, slice(print_end, last),
                                     slice_v(print_end, last), -1, false, 0.0, path));
      t = pieces.back().t_end_s;
    }
    position = positions.back();
    tool = path.orientation(path.points.size() - 1);
  }
  pieces.push_back(transition_piece(t, position, Vec3::Zero(), toolpath.end_mm, Vec3::Zero(),
                                    tcp_limits, tool, toolpath.end_orientation()));

  // keep the warnings readable on long toolpaths
  if (warnings.size() > kMaxDetailedWarnings) {
    const size_t more = warnings.size() - kMaxDetailedWarnings;
    warnings.resize(kMaxDetailedWarnings);
    warnings.push_back("... and " + std::to_string(more) + " more corner warnings");
  }
  return Trajectory("bezier", std::move(pieces), std::move(warnings));
}

}  // namespace depotwin
