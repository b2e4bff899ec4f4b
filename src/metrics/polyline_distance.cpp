#include "metrics/polyline_distance.hpp"

#include <cmath>
#include <limits>

#include "metrics/motion_metrics.hpp"

namespace depotwin {

namespace {

// below this many segments every query visits them all
constexpr std::size_t kMinBinnedSegments = 32;
// the grid has at most this many cells per segment (its cell grows to keep to it)
constexpr double kMaxCellsPerSegment = 4.0;
// a point this many cells or more from the grid is measured against every segment (no index
// arithmetic near the integers' limits)
constexpr double kFarCells = 1e9;
// slack on the cells a segment is listed in, and on the search's bound, in cells: both
// only ever add work, never drop a segment
constexpr double kCellSlack = 1e-6;

}  // namespace

PolylineDistance::PolylineDistance(const std::vector<Vec3>& polyline) : points_(polyline) {
  const std::size_t segments = polyline.size() > 1 ? polyline.size() - 1 : 0;
  if (segments < kMinBinnedSegments) return;
  // the box of the points in (x, y)
  double lo_x = polyline[0].x(), hi_x = lo_x, lo_y = polyline[0].y(), hi_y = lo_y;
  for (std::size_t k = 0; k < polyline.size(); ++k) {
    const Vec3& p = polyline[k];
    if (!p.allFinite()) return;
    lo_x = std::min(lo_x, p.x());
    hi_x = std::max(hi_x, p.x());
    lo_y = std::min(lo_y, p.y());
    hi_y = std::max(hi_y, p.y());
  }
  const double width = hi_x - lo_x, height = hi_y - lo_y;
  // a box of no extent (a vertical column, one point repeated): every segment is visited
  if (!(std::max(width, height) > 0.0) || !std::isfinite(width) || !std::isfinite(height)) return;
  // about two cells per segment over the box (a thin box: its length in 2 n cells), so that a
  // cell holds a few segments whatever their lengths; at most kMaxCellsPerSegment per segment
  const double count = static_cast<double>(segments);
  const auto cells_for = [&](double side) {
    return (std::floor(width / side) + 1.0) * (std::floor(height / side) + 1.0);
  };
  double cell =
      std::max(std::sqrt(width * height / (2.0 * count)), std::max(width, height) / (2.0 * count));
  if (!(cell > 0.0) || !std::isfinite(cell)) return;  // a box too small to divide
  while (cells_for(cell) > kMaxCellsPerSegment * count) cell *= 1.25;
  cell_ = cell;
  origin_x_ = lo_x;
  origin_y_ = lo_y;
  nx_ = static_cast<long>(std::floor(width / cell)) + 1;
  ny_ = static_cast<long>(std::floor(height / cell)) + 1;

  // the segments of each cell, compressed rows: counted, then filled
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  cell_start_.assign(cells + 1, 0);
  for (std::size_t k = 0; k < segments; ++k)
    for_each_cell_of_segment(k, [&](long i, long j) { ++cell_start_[j * nx_ + i + 1]; });
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(cell_start_[cells]);
  std::vector<std::uint32_t> filled(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t k = 0; k < segments; ++k)
    for_each_cell_of_segment(k, [&](long i, long j) {
      cell_items_[filled[j * nx_ + i]++] = static_cast<std::uint32_t>(k);
    });
  binned_ = true;
}

template <typename Visit>
void PolylineDistance::for_each_cell_of_segment(std::size_t k, Visit&& visit) const {
  // column by column, the cells the segment's (x, y) span crosses in that column's x range,
  // widened by kCellSlack of a cell on every side
  const Vec3& a = points_[k];
  const Vec3& b = points_[k + 1];
  const auto index = [&](double value, double origin, long size) {
    const double f = std::floor((value - origin) / cell_);
    return static_cast<long>(std::clamp(f, 0.0, static_cast<double>(size - 1)));
  };
  const double slack = kCellSlack * cell_;
  const double x0 = std::min(a.x(), b.x()), x1 = std::max(a.x(), b.x());
  const long i0 = index(x0 - slack, origin_x_, nx_), i1 = index(x1 + slack, origin_x_, nx_);
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  for (long i = i0; i <= i1; ++i) {
    // the part of the segment over this column, as its y span
    double y_lo = std::min(a.y(), b.y()), y_hi = std::max(a.y(), b.y());
    if (dx != 0.0) {
      const double column_lo = std::max(x0, origin_x_ + static_cast<double>(i) * cell_);
      const double column_hi = std::min(x1, origin_x_ + static_cast<double>(i + 1) * cell_);
      const double ya = a.y() + (std::clamp(column_lo, x0, x1) - a.x()) / dx * dy;
      const double yb = a.y() + (std::clamp(column_hi, x0, x1) - a.x()) / dx * dy;
      y_lo = std::max(y_lo, std::min(ya, yb));
      y_hi = std::min(y_hi, std::max(ya, yb));
    }
    const long j0 = index(y_lo - slack, origin_y_, ny_), j1 = index(y_hi + slack, origin_y_, ny_);
    for (long j = j0; j <= j1; ++j) visit(i, j);
  }
}

double PolylineDistance::scan_all(const Vec3& point) const {
  return distance_to_polyline(point, points_);
}

double PolylineDistance::operator()(const Vec3& point) const {
  if (!binned_ || !point.allFinite()) return scan_all(point);
  const double fi = std::floor((point.x() - origin_x_) / cell_);
  const double fj = std::floor((point.y() - origin_y_) / cell_);
  if (!(std::abs(fi) < kFarCells && std::abs(fj) < kFarCells)) return scan_all(point);
  const long pi = static_cast<long>(fi), pj = static_cast<long>(fj);
  // the rings of cells around the point's cell that meet the grid, nearest first
  const long first_ring = std::max({0L, -pi, pi - (nx_ - 1), -pj, pj - (ny_ - 1)});
  const long last_ring = std::max({pi, nx_ - 1 - pi, pj, ny_ - 1 - pj});
  // how far the point is inside its own cell: the square of rings 0..r reaches r cells
  // further on every side
  const double inside = std::max(
      0.0,
      std::min({point.x() - (origin_x_ + fi * cell_), origin_x_ + (fi + 1.0) * cell_ - point.x(),
                point.y() - (origin_y_ + fj * cell_), origin_y_ + (fj + 1.0) * cell_ - point.y()}));
  double best = std::numeric_limits<double>::infinity();
  const auto visit_cell = [&](long i, long j) {
    const std::size_t c = static_cast<std::size_t>(j * nx_ + i);
    for (std::uint32_t n = cell_start_[c]; n < cell_start_[c + 1]; ++n) {
      const std::uint32_t k = cell_items_[n];
      best = std::min(best, point_segment_distance(point, points_[k], points_[k + 1]));
    }
  };
  for (long r = first_ring; r <= last_ring; ++r) {
    // the ring's cells on the grid: its bottom and top rows, then its two columns between
    const long i_lo = std::max(pi - r, 0L), i_hi = std::min(pi + r, nx_ - 1);
    const long j_lo = std::max(pj - r + 1, 0L), j_hi = std::min(pj + r - 1, ny_ - 1);
    for (const long j : {pj - r, pj + r}) {
      if (j >= 0 && j < ny_)
        for (long i = i_lo; i <= i_hi; ++i) visit_cell(i, j);
      if (r == 0) break;  // one row
    }
    for (const long i : {pi - r, pi + r}) {
      if (r == 0 || i < 0 || i >= nx_) continue;
      for (long j = j_lo; j <= j_hi; ++j) visit_cell(i, j);
    }
    // every segment not seen yet lies, in (x, y), outside the square of rings 0..r, at least
    // `inside` + r cells from the point on every side
    if (best <= inside + (static_cast<double>(r) - kCellSlack) * cell_) break;
  }
  return best;
}

}  // namespace depotwin
