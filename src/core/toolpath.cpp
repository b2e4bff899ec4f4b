#include "core/toolpath.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace depotwin {

namespace {

// the arc's start radius vector, made exactly perpendicular to its axis
Vec3 arc_radius_vector(const Vec3& start, const EdgeArc& arc) {
  const Vec3 r = start - arc.center_mm;
  return r - r.dot(arc.axis) * arc.axis;
}

// the point at angle phi (rad, 0..sweep) of an arc edge from start to end
Vec3 arc_point_at(const Vec3& start, const Vec3& end, const EdgeArc& arc, double phi) {
  const Vec3 radius = arc_radius_vector(start, arc);
  const double rise = (end - start).dot(arc.axis);
  const Vec3 centre = start - radius;  // on the axis at the start's level
  return centre + std::cos(phi) * radius + std::sin(phi) * arc.axis.cross(radius) +
         (phi / arc.sweep_rad) * rise * arc.axis;
}

}  // namespace

int arc_chord_count(double radius_mm, double sweep_rad, double tolerance_mm) {
  if (!(sweep_rad > 0.0) || !(radius_mm > 0.0)) return 1;
  // sagitta r (1 - cos(a/2)) <= tolerance for a chord turning a; at most 90 degrees a chord
  const double cosine = 1.0 - std::max(tolerance_mm, 1e-12) / radius_mm;
  const double per_chord = std::min(kPi / 2.0, 2.0 * std::acos(std::max(-1.0, cosine)));
  return std::max(1, static_cast<int>(std::ceil(sweep_rad / per_chord - 1e-9)));
}

void grow_arc_bounds(const Vec3& start, const Vec3& end, const EdgeArc& arc, Vec3& lo, Vec3& hi) {
  lo = lo.cwiseMin(start).cwiseMin(end);
  hi = hi.cwiseMax(start).cwiseMax(end);
  if (!arc.is_arc()) return;
  // per coordinate k, the extremes where d/dphi of c_k + u_k cos + w_k sin + (h/sweep) phi a_k
  // vanishes: w_k cos(phi) - u_k sin(phi) = -(h / sweep) a_k
  const Vec3 u = arc_radius_vector(start, arc);
  const Vec3 w = arc.axis.cross(u);
  const double rise_rate = (end - start).dot(arc.axis) / arc.sweep_rad;
  for (int k = 0; k < 3; ++k) {
    const double amplitude = std::hypot(w[k], u[k]);
    const double rhs = -rise_rate * arc.axis[k];
    if (amplitude < 1e-15 || std::abs(rhs) > amplitude) continue;
    const double phase = std::atan2(-u[k], w[k]);
    const double spread = std::acos(std::clamp(rhs / amplitude, -1.0, 1.0));
    for (const double base : {phase + spread, phase - spread})
      for (const double turn : {-2.0 * kPi, 0.0, 2.0 * kPi}) {
        const double phi = base + turn;
        if (phi <= 0.0 || phi >= arc.sweep_rad) continue;
        const Vec3 p = arc_point_at(start, end, arc, phi);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
  }
}

Vec3 arc_tangent_extent(const Vec3& start, const Vec3& end, const EdgeArc& arc, double phi0,
                        double phi1) {
  // the tangent d/dphi = -sin(phi) u + cos(phi) w + (h / sweep) a has the constant length
  // sqrt(r^2 + (h / sweep)^2); its coordinate k peaks where u_k cos(phi) + w_k sin(phi) = 0
  const Vec3 u = arc_radius_vector(start, arc);
  const Vec3 w = arc.axis.cross(u);
  const Vec3 rise_rate = ((end - start).dot(arc.axis) / arc.sweep_rad) * arc.axis;
  const double length = std::hypot(u.norm(), rise_rate.norm());
  Vec3 extent = Vec3::Zero();
  if (!(length > 0.0)) return extent;
  const auto take = [&](double phi) {
    extent =
        extent.cwiseMax((-std::sin(phi) * u + std::cos(phi) * w + rise_rate).cwiseAbs() / length);
  };
  take(phi0);
  take(phi1);
  for (int k = 0; k < 3; ++k) {
    const double phase = std::atan2(-u[k], w[k]);
    for (const double turn : {-2.0, -1.0, 0.0, 1.0, 2.0, 3.0}) {
      const double phi = phase + turn * kPi;
      if (phi > phi0 && phi < phi1) take(phi);
    }
  }
  return extent.cwiseMin(Vec3::Ones());
}

bool PrintPath::has_arcs() const {
  for (const EdgeArc& arc : arcs)
    if (arc.is_arc()) return true;
  return false;
}

double PrintPath::edge_length(size_t edge) const {
  const Vec3 chord = points[edge + 1] - points[edge];
  if (arcs.empty() || !arcs[edge].is_arc()) return chord.norm();
  const EdgeArc& arc = arcs[edge];
  const double radius = arc_radius_vector(points[edge], arc).norm();
  return std::hypot(radius * arc.sweep_rad, chord.dot(arc.axis));
}

Vec3 PrintPath::edge_point(size_t edge, double s) const {
  if (arcs.empty() || !arcs[edge].is_arc())
    return points[edge] + s * (points[edge + 1] - points[edge]);
  if (s >= 1.0) return points[edge + 1];
  return arc_point_at(points[edge], points[edge + 1], arcs[edge], s * arcs[edge].sweep_rad);
}

PrintPath PrintPath::chorded(double tolerance_mm, std::vector<size_t>* source_point) const {
  PrintPath out = *this;
  out.arcs.clear();
  if (source_point) {
    source_point->resize(points.size());
    for (size_t i = 0; i < points.size(); ++i) (*source_point)[i] = i;
  }
  if (!has_arcs()) return out;
  out.points.assign(1, points.front());
  out.normals.clear();
  out.rolls.clear();
  if (!normals.empty()) out.normals.push_back(normals.front());
  if (!rolls.empty()) out.rolls.push_back(rolls.front());
  if (source_point) source_point->assign(1, 0);
  for (size_t edge = 0; edge + 1 < points.size(); ++edge) {
    // the edge's chords: one for a straight edge
    int chords = 1;
    if (arcs[edge].is_arc())
      chords = arc_chord_count(arc_radius_vector(points[edge], arcs[edge]).norm(),
                               arcs[edge].sweep_rad, tolerance_mm);
    for (int j = 1; j <= chords; ++j) {
      const double s = static_cast<double>(j) / chords;
      out.points.push_back(j == chords ? points[edge + 1] : edge_point(edge, s));
      if (!normals.empty()) out.normals.push_back(slerp_axis(normals[edge], normals[edge + 1], s));
      if (!rolls.empty()) out.rolls.push_back(rolls[edge] + s * (rolls[edge + 1] - rolls[edge]));
      if (source_point) source_point->push_back(edge + 1);
    }
  }
  return out;
}

double PrintPath::length_mm() const {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) length += edge_length(i - 1);
  return length;
}

PrintPath PrintPath::reversed() const {
  PrintPath out = *this;
  std::reverse(out.points.begin(), out.points.end());
  std::reverse(out.normals.begin(), out.normals.end());
  std::reverse(out.rolls.begin(), out.rolls.end());
  // an arc run backwards: the centre at the old end's level, the axis flipped, the same sweep
  for (size_t edge = 0; edge < arcs.size(); ++edge) {
    EdgeArc& arc = out.arcs[arcs.size() - 1 - edge];
    arc = arcs[edge];
    if (!arc.is_arc()) continue;
    arc.center_mm += (points[edge + 1] - points[edge]).dot(arc.axis) * arc.axis;
    arc.axis = -arc.axis;
  }
  return out;
}

void PrintPath::bounds(Vec3& lo, Vec3& hi) const {
  lo = hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (size_t edge = 0; edge < arcs.size(); ++edge)
    if (arcs[edge].is_arc()) grow_arc_bounds(points[edge], points[edge + 1], arcs[edge], lo, hi);
}

Vec3 PrintPath::tool_axis(size_t i) const {
  return normals.empty() ? vertical_tool_axis() : normals[i];
}

double PrintPath::roll(size_t i) const {
  return rolls.empty() ? 0.0 : rolls[i];
}

Vec3 PrintPath::tool_axis_near(const Vec3& p, size_t& edge_hint) const {
  if (normals.empty() || points.size() < 2) return vertical_tool_axis();
  return orientation_near(p, edge_hint).axis;
}

ToolOrientation PrintPath::orientation_near(const Vec3& p, size_t& edge_hint) const {
  if ((normals.empty() && rolls.empty()) || points.size() < 2) return orientation(0);
  const size_t edges = points.size() - 1;
  // the nearest edge from the hint onwards, stopping once the distance grows again
  const auto projection = [&](size_t edge, double& fraction) {
    const Vec3 chord = points[edge + 1] - points[edge];
    fraction = std::clamp((p - points[edge]).dot(chord) / chord.squaredNorm(), 0.0, 1.0);
    return (points[edge] + fraction * chord - p).squaredNorm();
  };
  size_t best = std::min(edge_hint, edges - 1);
  double best_fraction = 0.0;
  double best_distance2 = projection(best, best_fraction);
  for (size_t edge = best + 1; edge < edges; ++edge) {
    double fraction = 0.0;
    const double distance2 = projection(edge, fraction);
    if (distance2 > best_distance2 + 1e-9 && edge > best + 2) break;
    if (distance2 < best_distance2) {
      best = edge;
      best_fraction = fraction;
      best_distance2 = distance2;
    }
  }
  edge_hint = best;
  ToolOrientation near;
  near.axis = normals.empty() ? vertical_tool_axis()
                              : slerp_axis(normals[best], normals[best + 1], best_fraction);
  near.roll_rad =
      rolls.empty() ? 0.0 : rolls[best] + best_fraction * (rolls[best + 1] - rolls[best]);
  return near;
}

double gap_ratio(const Vec3& p0, const Vec3& n0, const Vec3& p1, const Vec3& n1, double d) {
  const double gap = (p1 - p0).norm();
  if (gap == 0.0) return 1.0;
  return ((p1 + d * n1) - (p0 + d * n0)).norm() / gap;
}

Toolpath Toolpath::chorded(double tolerance_mm) const {
  Toolpath out = *this;
  for (PrintPath& path : out.paths) path = path.chorded(tolerance_mm);
  return out;
}

double Toolpath::print_length_mm() const {
  double length = 0.0;
  for (const PrintPath& path : paths) length += path.length_mm();
  return length;
}

Toolpath merge_joined_paths(const Toolpath& toolpath) {
  Toolpath merged;
  merged.start_mm = toolpath.start_mm;
  merged.end_mm = toolpath.end_mm;
  for (const PrintPath& path : toolpath.paths) {
    const bool joins = !merged.paths.empty() && merged.paths.back().layer == path.layer &&
                       (merged.paths.back().back() - path.front()).norm() <= kJoinTolerance_mm;
    if (!joins) {
      merged.paths.push_back(path);
      continue;
    }
    // append without repeating the joint (normals and rolls only when both paths carry them)
    PrintPath& last = merged.paths.back();
    const bool with_normals = !last.normals.empty() && !path.normals.empty();
    const bool with_rolls = !last.rolls.empty() && !path.rolls.empty();
    // arcs: both paths' edges, straight where a path has none
    if (!last.arcs.empty() || !path.arcs.empty()) {
      last.arcs.resize(last.points.size() - 1);
      if (path.arcs.empty())
        last.arcs.resize(last.arcs.size() + path.points.size() - 1);
      else
        last.arcs.insert(last.arcs.end(), path.arcs.begin(), path.arcs.end());
    }
    last.points.insert(last.points.end(), path.points.begin() + 1, path.points.end());
    if (with_normals)
      last.normals.insert(last.normals.end(), path.normals.begin() + 1, path.normals.end());
    else
      last.normals.clear();
    if (with_rolls)
      last.rolls.insert(last.rolls.end(), path.rolls.begin() + 1, path.rolls.end());
    else
      last.rolls.clear();
  }
  return merged;
}

int Toolpath::layer_count() const {
  int layers = 1;
  for (const PrintPath& path : paths) layers = std::max(layers, path.layer + 1);
  return layers;
}

void Toolpath::bounds(Vec3& lo, Vec3& hi) const {
  lo = start_mm.cwiseMin(end_mm);
  hi = start_mm.cwiseMax(end_mm);
  for (const PrintPath& path : paths) {
    if (path.points.empty()) continue;
    Vec3 path_lo, path_hi;
    path.bounds(path_lo, path_hi);
    lo = lo.cwiseMin(path_lo);
    hi = hi.cwiseMax(path_hi);
  }
}

}  // namespace depotwin
