#include "plots/plot_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "core/number_text.hpp"

namespace depotwin::plots {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// a number in %.9g form, independent of the C locale (core/number_text.hpp)
void append_number(std::string& out, double value) {
  depotwin::append_number(out, value, 9);
}

}  // namespace

bool operator==(const TimeInterval& a, const TimeInterval& b) {
  return a.begin_s == b.begin_s && a.end_s == b.end_s;
}

std::vector<TimeInterval> transition_intervals(const Trajectory& trajectory) {
  std::vector<TimeInterval> bands;
  bool open = false;
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (piece.depositing) {
      open = false;
      continue;
    }
    // consecutive non-depositing pieces are one band
    if (open)
      bands.back().end_s = piece.t_end_s;
    else
      bands.push_back({piece.t_begin_s, piece.t_end_s});
    open = true;
  }
  // a zero-length band shades nothing
  bands.erase(std::remove_if(bands.begin(), bands.end(),
                             [](const TimeInterval& b) { return !(b.end_s > b.begin_s); }),
              bands.end());
  return bands;
}

std::vector<TimeInterval> transition_intervals(const MotionSamples& samples) {
  std::vector<TimeInterval> bands;
  const size_t n = samples.size();
  size_t k = 0;
  while (k < n) {
    if (samples.depositing[k]) {
      ++k;
      continue;
    }
    const size_t first = k;
    while (k < n && !samples.depositing[k]) ++k;
    const double end_s = k < n ? samples.t_s[k] : samples.t_s[n - 1];
    if (end_s > samples.t_s[first]) bands.push_back({samples.t_s[first], end_s});
  }
  return bands;
}

std::vector<PathLabel> halfway_path_labels(const Toolpath& toolpath) {
  std::vector<PathLabel> labels;
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    const PrintPath& path = toolpath.paths[i];
    // the edge the half length falls on, and where on it
    const double half_mm = 0.5 * path.length_mm();
    double walked_mm = 0.0;
    Vec3 halfway = path.points.back();
    for (size_t edge = 0; edge + 1 < path.points.size(); ++edge) {
      const double length = path.edge_length(edge);
      if (walked_mm + length >= half_mm && length > 0.0) {
        halfway = path.edge_point(edge, (half_mm - walked_mm) / length);
        break;
      }
      walked_mm += length;
    }
    labels.push_back({halfway.x(), halfway.y(), static_cast<int>(i)});
  }
  return labels;
}

namespace {

// "0", "0, 1" or "0–3, 7": the distinct numbers ascending, runs of three or more as ranges
std::string number_list(std::vector<int> numbers) {
  std::sort(numbers.begin(), numbers.end());
  numbers.erase(std::unique(numbers.begin(), numbers.end()), numbers.end());
  std::string text;
  for (size_t i = 0; i < numbers.size();) {
    size_t last = i;
    while (last + 1 < numbers.size() && numbers[last + 1] == numbers[last] + 1) ++last;
    if (!text.empty()) text += ", ";
    text += std::to_string(numbers[i]);
    if (last > i) text += (last == i + 1 ? ", " : "–") + std::to_string(numbers[last]);
    i = last + 1;
  }
  return text;
}

}  // namespace

std::vector<DrawnLabel> drawn_path_labels(const std::vector<PathLabel>& labels,
                                          double merge_within_mm, size_t max_drawn) {
  // (each label costs at most max_drawn distances: the search stops past max_drawn)
  std::vector<DrawnLabel> drawn;
  std::vector<std::vector<int>> numbers;
  for (const PathLabel& label : labels) {
    size_t joins = 0;
    while (joins < drawn.size() && std::hypot(drawn[joins].x_mm - label.x_mm,
                                              drawn[joins].y_mm - label.y_mm) > merge_within_mm)
      ++joins;
    if (joins == drawn.size()) {
      if (drawn.size() == max_drawn) return {};
      drawn.push_back({"", label.x_mm, label.y_mm});
      numbers.emplace_back();
    }
    numbers[joins].push_back(label.path);
  }
  for (size_t i = 0; i < drawn.size(); ++i) drawn[i].text = number_list(numbers[i]);
  return drawn;
}

bool paths_crowd_window(const Toolpath& toolpath, double x_lo, double x_hi, double y_lo,
                        double y_hi) {
  // (a clipped straight edge needs at most about 3 kCrowdGrid samples)
  constexpr double kMaxArcSamples = 4096, kMaxStraightSamples = 1 << 20;
  const double cell_mm = std::max(x_hi - x_lo, y_hi - y_lo) / kCrowdGrid;
  if (!(cell_mm > 0.0)) return false;
  const int nx = std::max(1, static_cast<int>(std::ceil((x_hi - x_lo) / cell_mm)));
  const int ny = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo) / cell_mm)));
  // the share is of the cells the paths' bounds cover in the window (a map has margins)
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const PrintPath& path : toolpath.paths) {
    Vec3 path_lo, path_hi;
    path.bounds(path_lo, path_hi);
    lo = lo.cwiseMin(path_lo), hi = hi.cwiseMax(path_hi);
  }
  // (no paths, or none in the window)
  if (!(lo.x() <= x_hi && hi.x() >= x_lo && lo.y() <= y_hi && hi.y() >= y_lo)) return false;
  const auto cell_span = [&](double from, double to, double origin, int n) {
    const int first = std::max(0, static_cast<int>(std::floor((from - origin) / cell_mm)));
    const int last = std::min(n - 1, static_cast<int>(std::floor((to - origin) / cell_mm)));
    return std::max(0, last - first + 1);
  };
  const double bounded_cells =
      static_cast<double>(cell_span(std::max(lo.x(), x_lo), std::min(hi.x(), x_hi), x_lo, nx)) *
      cell_span(std::max(lo.y(), y_lo), std::min(hi.y(), y_hi), y_lo, ny);
  if (bounded_cells == 0.0) return false;
  const size_t crowded_above = static_cast<size_t>(kCrowdedShare * bounded_cells);
  std::vector<char> crossed(static_cast<size_t>(nx) * ny, 0);
  size_t n_crossed = 0;
  for (const PrintPath& path : toolpath.paths)
    for (size_t edge = 0; edge + 1 < path.points.size(); ++edge) {
      // the part of the edge to sample: a straight edge's within the window (Liang-Barsky), an
      // arc whole (at most kMaxArcSamples points: this is an estimate for the eye)
      double s0 = 0.0, s1 = 1.0;
      const bool straight = path.arcs.empty() || !path.arcs[edge].is_arc();
      if (straight) {
        const Vec3 &a = path.points[edge], d = path.points[edge + 1] - a;
        // (per side: how fast the edge heads out through it, and the room it has there)
        const double outward[4] = {-d.x(), d.x(), -d.y(), d.y()};
        const double room[4] = {a.x() - x_lo, x_hi - a.x(), a.y() - y_lo, y_hi - a.y()};
        for (int side = 0; side < 4 && s0 <= s1; ++side) {
          if (outward[side] == 0.0) {
            if (room[side] < 0.0) s0 = 2.0;  // parallel to the side, outside it
          } else if (outward[side] < 0.0) {
            s0 = std::max(s0, room[side] / outward[side]);
          } else {
            s1 = std::min(s1, room[side] / outward[side]);
          }
        }
        if (s0 > s1) continue;
      }
      // the cells of points half a cell apart along it
      const double length_mm = (s1 - s0) * path.edge_length(edge);
      const int samples = static_cast<int>(std::min(straight ? kMaxStraightSamples : kMaxArcSamples,
                                                    1.0 + std::ceil(length_mm / (0.5 * cell_mm))));
      for (int k = 0; k <= samples; ++k) {
        const Vec3 p = path.edge_point(edge, s0 + (s1 - s0) * k / samples);
        const int ix = static_cast<int>(std::floor((p.x() - x_lo) / cell_mm));
        const int iy = static_cast<int>(std::floor((p.y() - y_lo) / cell_mm));
        if (ix < 0 || ix >= nx || iy < 0 || iy >= ny) continue;
        char& cell = crossed[static_cast<size_t>(iy) * nx + ix];
        if (cell == 0 && ++n_crossed > crowded_above) return true;
        cell = 1;
      }
    }
  return false;
}

void Curve::add(double px, double py) {
  x.push_back(px);
  y.push_back(py);
}

void Curve::add_break() {
  if (x.empty() || std::isnan(x.back())) return;  // no leading or doubled breaks
  x.push_back(kNaN);
  y.push_back(kNaN);
}

size_t Curve::point_count() const {
  return static_cast<size_t>(
      std::count_if(x.begin(), x.end(), [](double v) { return !std::isnan(v); }));
}

void Curve3::add(const Vec3& p) {
  x.push_back(p.x());
  y.push_back(p.y());
  z.push_back(p.z());
}

void Curve3::add_break() {
  if (x.empty() || std::isnan(x.back())) return;
  x.push_back(kNaN);
  y.push_back(kNaN);
  z.push_back(kNaN);
}

size_t Curve3::point_count() const {
  return static_cast<size_t>(
      std::count_if(x.begin(), x.end(), [](double v) { return !std::isnan(v); }));
}

std::vector<size_t> decimate_min_max(const std::vector<double>& values, size_t begin, size_t end,
                                     size_t max_points) {
  std::vector<size_t> kept;
  if (end <= begin) return kept;
  max_points = std::max<size_t>(max_points, 4);
  const size_t count = end - begin;
  if (count <= max_points) {
    for (size_t k = begin; k < end; ++k) kept.push_back(k);
    return kept;
  }
  // first and last sample, and min + max of each bucket of the interior
  kept.reserve(max_points);
  kept.push_back(begin);
  const size_t interior_begin = begin + 1, interior = count - 2;
  const size_t buckets = (max_points - 2) / 2;
  for (size_t b = 0; b < buckets; ++b) {
    const size_t lo = interior_begin + b * interior / buckets;
    const size_t hi = interior_begin + (b + 1) * interior / buckets;
    if (hi <= lo) continue;
    size_t at_min = lo, at_max = lo;
    for (size_t k = lo + 1; k < hi; ++k) {
      if (values[k] < values[at_min]) at_min = k;
      if (values[k] > values[at_max]) at_max = k;
    }
    kept.push_back(std::min(at_min, at_max));
    if (at_max != at_min) kept.push_back(std::max(at_min, at_max));
  }
  kept.push_back(end - 1);
  return kept;
}

Curve time_curve(const std::vector<double>& t_s, const std::vector<double>& y, size_t max_points) {
  // the finite runs of y
  std::vector<std::pair<size_t, size_t>> runs;
  size_t finite = 0;
  for (size_t k = 0; k < y.size();) {
    if (!std::isfinite(y[k])) {
      ++k;
      continue;
    }
    const size_t first = k;
    while (k < y.size() && std::isfinite(y[k])) ++k;
    runs.push_back({first, k});
    finite += k - first;
  }
  Curve curve;
  for (const auto& [first, last] : runs) {
    // the budget shared in proportion to the run's samples, at least its ends
    const size_t count = last - first;
    const size_t budget =
        finite <= max_points
            ? count
            : std::max<size_t>(4, max_points * count / std::max<size_t>(finite, 1));
    for (size_t k : decimate_min_max(y, first, last, budget)) curve.add(t_s[k], y[k]);
    curve.add_break();
  }
  return curve;
}

namespace {

bool in_part(const MotionSamples& samples, size_t k, PathPart part) {
  if (part == PathPart::all) return true;
  return (samples.depositing[k] != 0) == (part == PathPart::printing);
}

// one thinning pass at the given spacing
Curve thin_path(const MotionSamples& samples, PathPart part, double spacing_mm) {
  Curve curve;
  const size_t n = samples.size();
  size_t k = 0;
  while (k < n) {
    if (!in_part(samples, k, part)) {
      ++k;
      continue;
    }
    size_t first = k;
    while (k < n && in_part(samples, k, part)) ++k;
    size_t last = k;  // one past the run
    // a transition reaches the print samples on both sides, so the lines join up
    if (part == PathPart::transition) {
      if (first > 0) --first;
      if (last < n) ++last;
    }
    const auto& p = samples.position_mm;
    size_t previous = first;
    curve.add(p[first].x(), p[first].y());
    for (size_t j = first + 1; j + 1 < last; ++j) {
      if ((p[j] - p[previous]).head<2>().norm() < spacing_mm) continue;
      curve.add(p[j].x(), p[j].y());
      previous = j;
    }
    if (last - 1 > first) curve.add(p[last - 1].x(), p[last - 1].y());
    curve.add_break();
  }
  return curve;
}

}  // namespace

Curve xy_path_curve(const MotionSamples& samples, PathPart part, size_t max_points) {
  if (samples.size() == 0) return {};
  // start at 1/1500 of the motion's extent (below a pixel) and coarsen until it fits
  Eigen::Vector2d lo = samples.position_mm[0].head<2>(), hi = lo;
  for (const Vec3& p : samples.position_mm) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  double spacing_mm = std::max((hi - lo).maxCoeff(), 1e-6) / 1500.0;
  Curve curve = thin_path(samples, part, spacing_mm);
  for (int attempt = 0; attempt < 30 && curve.point_count() > max_points; ++attempt) {
    spacing_mm *= 1.5;
    curve = thin_path(samples, part, spacing_mm);
  }
  return curve;
}

namespace {

// the runs of samples in `part` as index ranges [first, last) (a transition run widened by one
// sample on each side, so that it meets the print samples)
std::vector<std::pair<size_t, size_t>> part_runs(const MotionSamples& samples, PathPart part) {
  std::vector<std::pair<size_t, size_t>> runs;
  const size_t n = samples.size();
  size_t k = 0;
  while (k < n) {
    if (!in_part(samples, k, part)) {
      ++k;
      continue;
    }
    size_t first = k;
    while (k < n && in_part(samples, k, part)) ++k;
    size_t last = k;
    if (part == PathPart::transition) {
      if (first > 0) --first;
      if (last < n) ++last;
    }
    runs.push_back({first, last});
  }
  return runs;
}

// one thinning pass over polylines given as point accessors
template <typename Lines>
Curve3 thin_3d(const Lines& lines, size_t count, double spacing_mm) {
  Curve3 curve;
  for (size_t line = 0; line < count; ++line) {
    const auto [begin, end] = lines.range(line);
    if (end <= begin) continue;
    Vec3 previous = lines.point(begin);
    curve.add(previous);
    for (size_t j = begin + 1; j + 1 < end; ++j) {
      const Vec3 p = lines.point(j);
      if ((p - previous).norm() < spacing_mm) continue;
      curve.add(p);
      previous = p;
    }
    if (end - 1 > begin) curve.add(lines.point(end - 1));
    curve.add_break();
  }
  return curve;
}

// spacing from extent / 1500 upwards until at most max_points remain
template <typename Lines>
Curve3 thin_to_budget(const Lines& lines, size_t count, size_t max_points) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (size_t line = 0; line < count; ++line) {
    const auto [begin, end] = lines.range(line);
    for (size_t j = begin; j < end; ++j) {
      lo = lo.cwiseMin(lines.point(j));
      hi = hi.cwiseMax(lines.point(j));
    }
  }
  if (!(hi.x() >= lo.x())) return {};
  double spacing_mm = std::max((hi - lo).maxCoeff(), 1e-6) / 1500.0;
  Curve3 curve = thin_3d(lines, count, spacing_mm);
  for (int attempt = 0; attempt < 30 && curve.point_count() > max_points; ++attempt) {
    spacing_mm *= 1.5;
    curve = thin_3d(lines, count, spacing_mm);
  }
  return curve;
}

}  // namespace

Curve3 path_curve_3d(const MotionSamples& samples, PathPart part, size_t max_points) {
  struct Runs {
    const MotionSamples& samples;
    std::vector<std::pair<size_t, size_t>> runs;
    std::pair<size_t, size_t> range(size_t i) const { return runs[i]; }
    Vec3 point(size_t j) const { return samples.position_mm[j]; }
  } lines{samples, part_runs(samples, part)};
  return thin_to_budget(lines, lines.runs.size(), max_points);
}

Curve3 polylines_3d(const std::vector<const std::vector<Vec3>*>& polylines, size_t max_points) {
  // the points of all lines in one array, each line a range of it
  struct Lines {
    std::vector<Vec3> points;
    std::vector<std::pair<size_t, size_t>> ranges;
    std::pair<size_t, size_t> range(size_t i) const { return ranges[i]; }
    Vec3 point(size_t j) const { return points[j]; }
  } lines;
  for (const std::vector<Vec3>* line : polylines) {
    const size_t begin = lines.points.size();
    lines.points.insert(lines.points.end(), line->begin(), line->end());
    lines.ranges.push_back({begin, lines.points.size()});
  }
  return thin_to_budget(lines, lines.ranges.size(), max_points);
}

namespace {

// The triangles seen from above: those facing up (facet normal z > 0.05), and those facing down
// (z < -0.05) with no triangle of the mesh above their centre, turned over. The second kind is
// an open surface seen from its back (a band that turns over along its length, a patch wound
// facing down), which the hatch prints on the side seen from above; a closed solid's underside
// lies under its top and stays out, as does a patch under an overhang.
std::vector<std::array<int, 3>> faces_seen_from_above(const TriangleMesh& mesh) {
  std::vector<std::array<int, 3>> seen;
  std::vector<size_t> facing_down;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const double n_z = mesh.facet_normal(t).z();
    if (n_z > 0.05) seen.push_back(mesh.triangles[t]);
    if (n_z < -0.05) facing_down.push_back(t);
  }
  if (facing_down.empty()) return seen;

  // every triangle with an x-y footprint, bucketed by the grid cells its footprint's box meets
  // (at most 256 x 256 cells, so a fan of slivers across the part costs 256 cells each)
  Vec3 lo, hi;
  mesh.bounds(lo, hi);
  const double size_mm = std::max((hi - lo).maxCoeff(), 1e-9);
  const int cells = std::clamp(
      static_cast<int>(std::ceil(std::sqrt(0.5 * static_cast<double>(mesh.triangle_count())))), 1,
      256);
  const Eigen::Vector2d cell_mm = (hi - lo).head<2>().cwiseMax(1e-9) / cells;
  const auto cell_index = [&](double v, int axis) {
    return std::clamp(static_cast<int>(std::floor((v - lo[axis]) / cell_mm[axis])), 0, cells - 1);
  };
  std::vector<std::vector<int>> bucket(static_cast<size_t>(cells) * cells);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (std::abs(mesh.facet_normal(t).z()) < 1e-9) continue;  // a wall: no footprint
    Vec3 t_lo = mesh.vertices[mesh.triangles[t][0]], t_hi = t_lo;
    for (int c = 1; c < 3; ++c) {
      t_lo = t_lo.cwiseMin(mesh.vertices[mesh.triangles[t][c]]);
      t_hi = t_hi.cwiseMax(mesh.vertices[mesh.triangles[t][c]]);
    }
    for (int i = cell_index(t_lo.x(), 0); i <= cell_index(t_hi.x(), 0); ++i)
      for (int j = cell_index(t_lo.y(), 1); j <= cell_index(t_hi.y(), 1); ++j)
        bucket[static_cast<size_t>(i) * cells + j].push_back(static_cast<int>(t));
  }

  // the height of triangle t above (x, y) where its footprint holds the point (its edges
  // included, to a hair of the part's size), else nothing
  const double hair_mm = 1e-9 * size_mm;
  const auto height_over = [&](int t, const Vec3& p) -> std::optional<double> {
    const Vec3& a = mesh.vertices[mesh.triangles[t][0]];
    const Vec3& b = mesh.vertices[mesh.triangles[t][1]];
    const Vec3& c = mesh.vertices[mesh.triangles[t][2]];
    const auto cross = [](const Vec3& u, const Vec3& v, const Vec3& w) {
      return (v.x() - u.x()) * (w.y() - u.y()) - (v.y() - u.y()) * (w.x() - u.x());
    };
    const double area = cross(a, b, c);
    const double wa = cross(p, b, c) / area, wb = cross(a, p, c) / area, wc = cross(a, b, p) / area;
    const double slack = hair_mm / std::max((b - a).norm() + (c - b).norm(), 1e-300);
    if (wa < -slack || wb < -slack || wc < -slack) return std::nullopt;
    return wa * a.z() + wb * b.z() + wc * c.z();
  };
  for (size_t t : facing_down) {
    const std::array<int, 3>& triangle = mesh.triangles[t];
    const Vec3 centre =
        (mesh.vertices[triangle[0]] + mesh.vertices[triangle[1]] + mesh.vertices[triangle[2]]) /
        3.0;
    bool covered = false;
    for (int other : bucket[static_cast<size_t>(cell_index(centre.x(), 0)) * cells +
                            cell_index(centre.y(), 1)]) {
      if (other == static_cast<int>(t)) continue;
      const std::optional<double> z = height_over(other, centre);
      if (z && *z > centre.z() + hair_mm) {
        covered = true;
        break;
      }
    }
    if (!covered) seen.push_back({triangle[0], triangle[2], triangle[1]});  // turned to face up
  }
  return seen;
}

}  // namespace

TriangleMesh display_surface(const TriangleMesh& mesh, size_t max_triangles) {
  // the triangles seen from above and the vertices they use
  const std::vector<std::array<int, 3>> up = faces_seen_from_above(mesh);
  TriangleMesh out;
  if (up.empty()) return out;
  Eigen::Vector2d lo = mesh.vertices[up[0][0]].head<2>(), hi = lo;
  for (const auto& triangle : up)
    for (int v : triangle) {
      lo = lo.cwiseMin(mesh.vertices[v].head<2>());
      hi = hi.cwiseMax(mesh.vertices[v].head<2>());
    }
  // the triangles with the vertices they use, renumbered in order of first use
  auto compact = [&](const std::vector<std::array<int, 3>>& triangles) {
    std::map<int, int> renumbered;
    for (const auto& triangle : triangles) {
      std::array<int, 3> t{};
      for (int c = 0; c < 3; ++c) {
        const auto [it, added] =
            renumbered.emplace(triangle[c], static_cast<int>(out.vertices.size()));
        if (added) out.vertices.push_back(mesh.vertices[triangle[c]]);
        t[c] = it->second;
      }
      out.triangles.push_back(t);
    }
    return out;
  };
  if (up.size() <= max_triangles) return compact(up);
  // vertex clustering on an x-y grid: start where the grid has about max_triangles / 2 cells
  // (two triangles per cell of a regular tessellation) and coarsen until the result fits
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-9);
  double cell_mm = std::sqrt(extent.x() * extent.y() / std::max<size_t>(max_triangles / 2, 1));
  for (int attempt = 0; attempt < 40; ++attempt, cell_mm *= 1.15) {
    // each vertex's cell, and each cell's representative: its vertex nearest the cell centre
    auto cell_of = [&](const Vec3& p) {
      return std::make_pair(static_cast<long>(std::floor((p.x() - lo.x()) / cell_mm)),
                            static_cast<long>(std::floor((p.y() - lo.y()) / cell_mm)));
    };
    std::map<std::pair<long, long>, int> representative;  // cell -> vertex index in `mesh`
    for (const auto& triangle : up)
      for (int v : triangle) {
        const Vec3& p = mesh.vertices[v];
        const auto cell = cell_of(p);
        const Eigen::Vector2d centre =
            lo + cell_mm * Eigen::Vector2d(cell.first + 0.5, cell.second + 0.5);
        auto [it, added] = representative.emplace(cell, v);
        if (!added && v != it->second) {
          const double d = (p.head<2>() - centre).squaredNorm();
          const double best = (mesh.vertices[it->second].head<2>() - centre).squaredNorm();
          if (d < best || (d == best && v < it->second)) it->second = v;
        }
      }
    std::set<std::array<int, 3>> seen;
    std::vector<std::array<int, 3>> kept;
    for (const auto& triangle : up) {
      std::array<int, 3> t{};
      for (int c = 0; c < 3; ++c) t[c] = representative.at(cell_of(mesh.vertices[triangle[c]]));
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
      std::array<int, 3> key = t;
      std::sort(key.begin(), key.end());
      if (!seen.insert(key).second) continue;
      kept.push_back(t);
    }
    if (kept.size() <= max_triangles) return compact(kept);
  }
  return out;  // a grid 270 times coarser still too fine: not for any real mesh; nothing drawn
}

double feature_size_mm(const Toolpath& toolpath) {
  Vec3 lo, hi;
  bool any = false;
  for (const PrintPath& path : toolpath.paths) {
    for (const Vec3& p : path.points) {
      if (!any) lo = hi = p;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
      any = true;
    }
  }
  if (!any) toolpath.bounds(lo, hi);
  const double extent_mm = (hi - lo).maxCoeff();
  return extent_mm > 0.0 ? extent_mm : 1.0;
}

std::vector<double> speed_error_with_gaps(const MotionSamples& samples) {
  std::vector<double> error = relative_speed_error(samples);
  for (size_t k = 0; k < samples.size(); ++k)
    if (!samples.depositing[k] || !(samples.desired_speed_mm_s[k] > 0.0)) error[k] = kNaN;
  return error;
}

std::vector<double> relative_position_error(const MotionSamples& samples, const Toolpath& toolpath,
                                            double feature_mm) {
  // path_error's distances (NaN stays NaN)
  std::vector<double> error = path_distances(samples, toolpath);
  for (double& e : error) e /= feature_mm;
  return error;
}

HeightMap downsample_for_display(const HeightMap& map, int max_cells_per_side) {
  const int longest = std::max(map.nx, map.ny);
  const int factor = longest <= max_cells_per_side
                         ? 1
                         : (longest + max_cells_per_side - 1) / std::max(max_cells_per_side, 1);
  if (factor <= 1) return map;
  HeightMap out;
  out.nx = (map.nx + factor - 1) / factor;
  out.ny = (map.ny + factor - 1) / factor;
  out.cell_mm = map.cell_mm * factor;
  out.origin_x_mm = map.origin_x_mm + 0.5 * (factor - 1) * map.cell_mm;
  out.origin_y_mm = map.origin_y_mm + 0.5 * (factor - 1) * map.cell_mm;
  out.thickness_um.assign(static_cast<size_t>(out.nx) * out.ny, 0.0f);
  // block maxima: a bead narrower than a block keeps its peak colour instead of being averaged
  // into the empty cells around it
  for (int by = 0; by < out.ny; ++by) {
    for (int bx = 0; bx < out.nx; ++bx) {
      float block_max = 0.0f;
      for (int iy = by * factor; iy < std::min(map.ny, (by + 1) * factor); ++iy)
        for (int ix = bx * factor; ix < std::min(map.nx, (bx + 1) * factor); ++ix)
          block_max = std::max(block_max, map.at(ix, iy));
      out.thickness_um[static_cast<size_t>(by) * out.nx + bx] = block_max;
    }
  }
  return out;
}

HeightMap pad_to_extent(const HeightMap& map, double x_lo, double x_hi, double y_lo, double y_hi) {
  if (map.nx <= 0 || map.ny <= 0 || !(map.cell_mm > 0.0)) return map;
  // whole cells to add on each side (a hair's overlap of an edge adds none)
  const auto cells_beyond = [&](double gap_mm) {
    return std::max(0, static_cast<int>(std::ceil(gap_mm / map.cell_mm - 1e-6)));
  };
  const int left = cells_beyond(map.x_lo_mm() - x_lo);
  const int right = cells_beyond(x_hi - map.x_hi_mm());
  const int bottom = cells_beyond(map.y_lo_mm() - y_lo);
  const int top = cells_beyond(y_hi - map.y_hi_mm());
  if (left + right + bottom + top == 0) return map;
  HeightMap out;
  out.cell_mm = map.cell_mm;
  out.nx = map.nx + left + right;
  out.ny = map.ny + bottom + top;
  out.origin_x_mm = map.origin_x_mm - left * map.cell_mm;
  out.origin_y_mm = map.origin_y_mm - bottom * map.cell_mm;
  out.thickness_um.assign(static_cast<size_t>(out.nx) * out.ny, 0.0f);
  for (int iy = 0; iy < map.ny; ++iy)
    std::copy_n(map.thickness_um.begin() + static_cast<size_t>(iy) * map.nx, map.nx,
                out.thickness_um.begin() + static_cast<size_t>(iy + bottom) * out.nx + left);
  return out;
}

std::string fixed_text(double value, double largest) {
  const double magnitude =
      std::abs(largest) > 0.0 ? std::floor(std::log10(std::abs(largest))) : 0.0;
  const int decimals = static_cast<int>(std::clamp(2.0 - magnitude, 0.0, 6.0));
  return format("%.*f", decimals, value);
}

std::vector<std::string> wrap_text(const std::string& text, size_t max_chars) {
  // characters, not bytes: a UTF-8 continuation byte starts none
  const auto length = [](const std::string& s) {
    return static_cast<size_t>(
        std::count_if(s.begin(), s.end(), [](char c) { return (c & 0xC0) != 0x80; }));
  };
  std::vector<std::string> lines;
  std::string line;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    start = end + 1;
    if (word.empty()) continue;
    if (!line.empty() && length(line) + 1 + length(word) > max_chars) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

double round_step_up(double rough) {
  if (!(rough > 0.0) || !std::isfinite(rough)) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(rough)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * decade >= rough) return m * decade;
  return 10.0 * decade;
}

size_t widest_tick_label(double lo, double hi, double step) {
  size_t widest = 0;
  if (!(step > 0.0) || !(hi >= lo)) return widest;
  const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last && k - first < 1000; k += 1.0) {
    // a tick that should be 0 prints as 0, not as a rounding remainder
    const double value = std::abs(k) < 0.5 ? 0.0 : k * step;
    widest = std::max(widest, format("%g", value).size());
  }
  return widest;
}

int tick_count(double lo, double hi, double step) {
  if (!(step > 0.0) || !(hi >= lo)) return 0;
  // (a tick on an end, within rounding, counts)
  const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
  return std::max(0, static_cast<int>(last - first) + 1);
}

double axis_tick_step(double lo, double hi, double preferred_step, int min_ticks) {
  const double span = hi - lo;
  if (!(span > 0.0) || !std::isfinite(span)) return 1.0;
  const double step = preferred_step > 0.0 ? preferred_step : span;
  if (tick_count(lo, hi, step) >= min_ticks) return step;
  // down the 1-2-5 ladder from the first rung below the preferred step
  double decade = std::pow(10.0, std::floor(std::log10(step)));
  const double mantissas[3] = {5.0, 2.0, 1.0};
  for (int rung = 0; rung < 60; ++rung) {
    for (double m : mantissas) {
      const double candidate = m * decade;
      if (candidate >= step * (1.0 - 1e-9)) continue;
      if (tick_count(lo, hi, candidate) >= min_ticks) return candidate;
    }
    decade /= 10.0;
  }
  return step;
}

std::string format_curve(const Curve& curve) {
  std::string out;
  out.reserve(curve.size() * 24);
  for (size_t k = 0; k < curve.size(); ++k) {
    if (std::isnan(curve.x[k])) {
      out += '\n';
      continue;
    }
    append_number(out, curve.x[k]);
    out += ' ';
    append_number(out, curve.y[k]);
    out += '\n';
  }
  return out;
}

std::string format_curve3(const Curve3& curve) {
  std::string out;
  out.reserve(curve.size() * 36);
  for (size_t k = 0; k < curve.size(); ++k) {
    if (std::isnan(curve.x[k])) {
      out += "\n\n";
      continue;
    }
    append_number(out, curve.x[k]);
    out += ' ';
    append_number(out, curve.y[k]);
    out += ' ';
    append_number(out, curve.z[k]);
    out += '\n';
  }
  return out;
}

std::string format_triangles(const TriangleMesh& mesh) {
  std::string out;
  out.reserve(mesh.triangle_count() * 110);
  for (const auto& triangle : mesh.triangles) {
    for (int v : triangle) {
      const Vec3& p = mesh.vertices[v];
      append_number(out, p.x());
      out += ' ';
      append_number(out, p.y());
      out += ' ';
      append_number(out, p.z());
      out += '\n';
    }
    out += '\n';
  }
  return out;
}

std::string format_binary_map(const HeightMap& map) {
  std::string out(map.thickness_um.size() * sizeof(float), '\0');
  if (!out.empty()) std::memcpy(out.data(), map.thickness_um.data(), out.size());
  return out;
}

std::string format(const char* pattern, ...) {
  va_list arguments;
  va_start(arguments, pattern);
  va_list copy;
  va_copy(copy, arguments);
  const int length = std::vsnprintf(nullptr, 0, pattern, copy);
  va_end(copy);
  std::string out(length > 0 ? static_cast<size_t>(length) : 0, '\0');
  if (length > 0) std::vsnprintf(out.data(), out.size() + 1, pattern, arguments);
  va_end(arguments);
  return out;
}

}  // namespace depotwin::plots
