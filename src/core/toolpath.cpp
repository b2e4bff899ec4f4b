#include "core/toolpath.hpp"

#include <algorithm>

namespace depotwin {

double PrintPath::length_mm() const {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) length += (points[i] - points[i - 1]).norm();
  return length;
}

PrintPath PrintPath::reversed() const {
  PrintPath out = *this;
  std::reverse(out.points.begin(), out.points.end());
  std::reverse(out.normals.begin(), out.normals.end());
  std::reverse(out.rolls.begin(), out.rolls.end());
  return out;
}

void PrintPath::bounds(Vec3& lo, Vec3& hi) const {
  lo = hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
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
