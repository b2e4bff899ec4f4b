#include "plots/plot_data.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>

namespace depotwin::plots {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// a number in %.9g form, independent of the C locale
void append_number(std::string& out, double value) {
  char buffer[32];
  const auto result =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 9);
  out.append(buffer, result.ptr);
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
  std::vector<double> error(samples.size(), kNaN);
  const int path_count = static_cast<int>(toolpath.paths.size());
  for (size_t k = 0; k < samples.size(); ++k) {
    const int path = samples.path_index[k];
    if (!samples.depositing[k] || path < 0 || path >= path_count) continue;
    error[k] =
        distance_to_polyline(samples.position_mm[k], toolpath.paths[path].points) / feature_mm;
  }
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
  // block means (double sums: the order is fixed, so the result is deterministic)
  for (int by = 0; by < out.ny; ++by) {
    for (int bx = 0; bx < out.nx; ++bx) {
      double sum = 0.0;
      int cells = 0;
      for (int iy = by * factor; iy < std::min(map.ny, (by + 1) * factor); ++iy)
        for (int ix = bx * factor; ix < std::min(map.nx, (bx + 1) * factor); ++ix) {
          sum += map.at(ix, iy);
          ++cells;
        }
      out.thickness_um[static_cast<size_t>(by) * out.nx + bx] =
          static_cast<float>(sum / std::max(cells, 1));
    }
  }
  return out;
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
