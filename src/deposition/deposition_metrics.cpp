#include "deposition/deposition_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kUmPerMm = 1000.0;

struct Interval {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return lo > hi; }
  void cover(double a, double b) {
    lo = std::min(lo, a);
    hi = std::max(hi, b);
  }
};

// x-range where c * x + d lies in [m, M]; false when no x qualifies
bool linear_range(double c, double d, double m, double big_m, double& lo, double& hi) {
  if (std::abs(c) < 1e-12) {
    if (d < m || d > big_m) return false;
    return true;  // no constraint on x
  }
  double a = (m - d) / c, b = (big_m - d) / c;
  if (a > b) std::swap(a, b);
  lo = std::max(lo, a);
  hi = std::min(hi, b);
  return lo <= hi;
}

// x-interval of row y inside the capsule of radius r around segment A -> B (convex, so the
// union of the two end disks and the band rectangle is one interval)
Interval capsule_row(double ax, double ay, double bx, double by, double ex, double ey,
                     double length, double r, double y) {
  Interval row;
  auto cover_disk = [&](double px, double py) {
    const double dy = y - py;
    if (std::abs(dy) > r) return;
    const double half = std::sqrt(r * r - dy * dy);
    row.cover(px - half, px + half);
  };
  cover_disk(ax, ay);
  cover_disk(bx, by);
  if (length > 0.0) {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    // along the segment: 0 <= (x - ax) ex + (y - ay) ey <= length
    const bool along = linear_range(ex, -ax * ex + (y - ay) * ey, 0.0, length, lo, hi);
    // across: -r <= -(x - ax) ey + (y - ay) ex <= r
    const bool across = along && linear_range(-ey, ax * ey + (y - ay) * ex, -r, r, lo, hi);
    if (along && across && std::isfinite(lo) && std::isfinite(hi)) row.cover(lo, hi);
  }
  return row;
}

// the cell centred on (x, y), side h: a bit per sub-point of its 8 x 8 grid (centres of
// h/8 squares) that lies within r of the segment from (ax, ay) along the unit (ex, ey)
uint64_t sub_points_within(double x, double y, double ax, double ay, double ex, double ey,
                           double length, double r, double h) {
  uint64_t mask = 0;
  const double r2 = r * r * (1.0 + 1e-9);
  for (int j = 0; j < 8; ++j) {
    const double py = y + (j - 3.5) * h / 8.0 - ay;
    for (int i = 0; i < 8; ++i) {
      const double px = x + (i - 3.5) * h / 8.0 - ax;
      const double t = std::min(length, std::max(0.0, px * ex + py * ey));
      const double dx = px - t * ex, dy = py - t * ey;
      if (dx * dx + dy * dy <= r2) mask |= uint64_t{1} << (8 * j + i);
    }
  }
  return mask;
}

// A cell the band's edge crosses (0 < share < 1), read at its 8 x 8 sub-points from the field
// interpolated between cell centres: the mean thickness of its part inside the band, and the
// share of its material there (a cell's inner side holds more than its outer one where the
// deposit falls off across the edge). A cell with nothing around it: its value, by area.
struct EdgeCell {
  double inside_mean_mm = 0.0;
  double material_share = 0.0;
};
EdgeCell read_edge_cell(const ThicknessField& field, int ix, int iy, uint64_t inside_mask,
                        double value_mm) {
  // the cell and its eight neighbours, read once: every sub-point lies between their centres
  double around[3][3];
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      around[dy + 1][dx + 1] =
          dx == 0 && dy == 0 ? value_mm : field.cell_thickness_mm(ix + dx, iy + dy);
  // a sub-point's offset from the centre, in cells: the neighbour it leans to and its weight
  // (bilinear_between_cells' rule, thickness_mm_at's, at (ix + offset) h)
  BilinearPoint at[8];
  for (int i = 0; i < 8; ++i) {
    const double offset = (i - 3.5) / 8.0;
    at[i].ix0 = offset < 0.0 ? 0 : 1;  // index into around: the lower of the two
    at[i].wx = offset < 0.0 ? 1.0 + offset : offset;
  }
  double inside = 0.0, all = 0.0;
  int inside_count = 0;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      BilinearPoint p;
      p.ix0 = at[i].ix0;
      p.wx = at[i].wx;
      p.iy0 = at[j].ix0;
      p.wy = at[j].wx;
      const double t = bilinear_between_cells(p, [&](int cx, int cy) { return around[cy][cx]; });
      all += t;
      if (inside_mask >> (8 * j + i) & 1) {
        inside += t;
        ++inside_count;
      }
    }
  EdgeCell cell;
  if (all > 0.0 && inside_count > 0) {
    cell.inside_mean_mm = inside / inside_count;
    cell.material_share = inside / all;
  } else {
    cell.inside_mean_mm = value_mm;
    cell.material_share = inside_count / 64.0;
  }
  return cell;
}

// the cell of tile (tx, ty) at local index k: its lattice indices
void cell_indices(int tx, int ty, int k, int& ix, int& iy) {
  using Tiles = TargetRegion::Tiles;
  ix = tx * Tiles::kSize + k % Tiles::kSize;
  iy = ty * Tiles::kSize + k / Tiles::kSize;
}

// point at arc length s along a polyline (xy), advancing a segment cursor (s increasing)
void point_at_arc(const PrintPath& path, double s, size_t& segment, double& segment_start,
                  double& x, double& y) {
  const size_t last = path.points.size() - 2;
  while (segment < last) {
    const double len = (path.points[segment + 1] - path.points[segment]).head<2>().norm();
    if (s <= segment_start + len) break;
    segment_start += len;
    ++segment;
  }
  const Eigen::Vector2d a = path.points[segment].head<2>();
  const Eigen::Vector2d b = path.points[segment + 1].head<2>();
  const double len = (b - a).norm();
  const double t = len > 0.0 ? std::min(1.0, std::max(0.0, (s - segment_start) / len)) : 0.0;
  x = a.x() + t * (b.x() - a.x());
  y = a.y() + t * (b.y() - a.y());
}

double planar_length_mm(const PrintPath& path) {
  double length = 0.0;
  for (size_t k = 0; k + 1 < path.points.size(); ++k)
    length += (path.points[k + 1] - path.points[k]).head<2>().norm();
  return length;
}

}  // namespace

TargetRegion::TargetRegion(const Toolpath& toolpath, double line_width_mm, double cell_mm)
    : cell_mm_(cell_mm), half_width_mm_(0.5 * line_width_mm) {
  if (!(line_width_mm > 0.0) || !(cell_mm > 0.0))
    throw InputError("process.line_width_mm", "line width and cell size must be > 0");
  const double h = cell_mm_;
  const double r = half_width_mm_;
  // "within r": a relative tolerance keeps cells exactly at r in, whatever the rounding
  const double r2 = r * r * (1.0 + 1e-9);
  // a cell's share of the band: which of its 8 x 8 sub-points lie within r of a centreline
  // (a mask, or-ed over every segment of every path: the band's union, each cell once).
  // Cells whose centre lies within r - h/sqrt(2) are whole, those beyond r + h/sqrt(2) out.
  const double half_diagonal = h * std::sqrt(0.5);
  const double reach = r + half_diagonal;
  const double reach2 = reach * reach;
  const double whole = r - half_diagonal;
  const double whole2 = whole > 0.0 ? whole * whole : -1.0;

  for (size_t p = 0; p < toolpath.paths.size(); ++p) {
    const PrintPath& path = toolpath.paths[p];
    path_length_mm_.push_back(planar_length_mm(path));
    double arc_start = 0.0;
    for (size_t k = 0; k + 1 < path.points.size(); ++k) {
      const double ax = path.points[k].x(), ay = path.points[k].y();
      const double bx = path.points[k + 1].x(), by = path.points[k + 1].y();
      const double length = std::hypot(bx - ax, by - ay);
      const double ex = length > 0.0 ? (bx - ax) / length : 1.0;
      const double ey = length > 0.0 ? (by - ay) / length : 0.0;

      // rasterise the capsule row by row (one cell of slack, then the exact test)
      const int iy_lo = static_cast<int>(std::floor((std::min(ay, by) - r) / h));
      const int iy_hi = static_cast<int>(std::ceil((std::max(ay, by) + r) / h));
      for (int iy = iy_lo; iy <= iy_hi; ++iy) {
        const double y = iy * h;
        // (the row's interval with the same tolerance as the test below: a row exactly r
        // from the centreline, rounded a hair beyond it, keeps its cells)
        const Interval row = capsule_row(ax, ay, bx, by, ex, ey, length, reach, y);
        if (row.empty()) continue;
        const int ix_lo = static_cast<int>(std::floor(row.lo / h)) - 1;
        const int ix_hi = static_cast<int>(std::ceil(row.hi / h)) + 1;
        for (int ix = ix_lo; ix <= ix_hi; ++ix) {
          const double x = ix * h;
          const double t = std::min(length, std::max(0.0, (x - ax) * ex + (y - ay) * ey));
          const double dx = x - (ax + t * ex), dy = y - (ay + t * ey);
          const double d2 = dx * dx + dy * dy;
          if (d2 >= reach2) continue;
          // keep, per path, the nearest centreline point; settle the previous path's cell first
          Cell& cell = tiles_.get_or_create(Tiles::tile_of(ix),
                                            Tiles::tile_of(iy))[Tiles::local_index(ix, iy)];
          if (d2 <= whole2) {
            cell.inside_mask = kWholeCell;
          } else if (cell.inside_mask != kWholeCell) {
            cell.inside_mask |= sub_points_within(x, y, ax, ay, ex, ey, length, r, h);
          }
          if (d2 <= r2) cell.flags |= kCentreInside;
          if (cell.path != static_cast<int32_t>(p)) {
            finish_cell(cell);
            cell.path = static_cast<int32_t>(p);
            cell.best_distance2_mm2 = static_cast<float>(d2);
            cell.best_arc_mm = arc_start + t;
          } else if (d2 < cell.best_distance2_mm2) {
            cell.best_distance2_mm2 = static_cast<float>(d2);
            cell.best_arc_mm = arc_start + t;
          }
          cell.flags |= kTarget;
        }
      }
      arc_start += length;
    }
  }
  // settle the last path of every cell; one with no sub-point in the band is not a target
  for (const auto& [tx, ty] : tiles_.sorted_tiles()) {
    Cell* tile = tiles_.find(tx, ty);
    for (int k = 0; k < Tiles::kCells; ++k) {
      finish_cell(tile[k]);
      tile[k].path = -1;
      if (tile[k].inside_mask == 0) tile[k].flags &= static_cast<uint8_t>(~kTarget);
    }
  }
}

void TargetRegion::finish_cell(Cell& cell) const {
  if (cell.path < 0) return;
  // a cell exactly r from an end stays in (rounding tolerance well below a cell)
  const double arc = cell.best_arc_mm;
  const double length = path_length_mm_[static_cast<size_t>(cell.path)];
  const double tolerance = 1e-9 * (1.0 + length);
  if (arc < half_width_mm_ - tolerance || arc > length - half_width_mm_ + tolerance)
    cell.flags |= kEndZone;
}

uint8_t TargetRegion::flags(int ix, int iy) const {
  const Cell* tile = tiles_.find(Tiles::tile_of(ix), Tiles::tile_of(iy));
  return tile ? tile[Tiles::local_index(ix, iy)].flags : 0;
}

double TargetRegion::weight(int ix, int iy) const {
  const Cell* tile = tiles_.find(Tiles::tile_of(ix), Tiles::tile_of(iy));
  return tile ? tile[Tiles::local_index(ix, iy)].weight() : 0.0;
}

size_t TargetRegion::target_cells() const {
  size_t count = 0;
  for (const auto& [tx, ty] : tiles_.sorted_tiles()) {
    const Cell* tile = tiles_.find(tx, ty);
    for (int k = 0; k < Tiles::kCells; ++k) count += (tile[k].flags & kCentreInside) ? 1 : 0;
  }
  return count;
}

ThicknessStats thickness_stats(const ThicknessField& field, const TargetRegion& region,
                               const Toolpath& toolpath) {
  if (field.cell_mm() != region.cell_mm())
    throw InternalError("thickness_stats: region and field have different cells");
  ThicknessStats stats;
  const auto region_tiles = region.tiles().sorted_tiles();

  // cells of the stats region, each by its share of the band (a cell the band's edge crosses
  // by the mean thickness of its part inside): two passes (mean, min, max; then the spread).
  // min and max are over the cells whose centre lies within r (every cell with a share when
  // no centre does: a line narrower than a cell)
  double sum = 0.0, weights = 0.0;
  double min_value = std::numeric_limits<double>::infinity();
  double max_value = -std::numeric_limits<double>::infinity();
  double min_any = min_value, max_any = max_value;
  bool any_centre = false;
  auto for_each_stats_cell = [&](auto&& visit) {
    for (const auto& [tx, ty] : region_tiles) {
      const TargetRegion::Cell* cells = region.tiles().find(tx, ty);
      const double* values = field.tiles().find(tx, ty);
      for (int k = 0; k < TargetRegion::Tiles::kCells; ++k) {
        const TargetRegion::Cell& cell = cells[k];
        if (!(cell.flags & TargetRegion::kTarget) || (cell.flags & TargetRegion::kEndZone))
          continue;
        double value = values ? values[k] : 0.0;
        if (cell.inside_mask != TargetRegion::kWholeCell) {
          int ix = 0, iy = 0;
          cell_indices(tx, ty, k, ix, iy);
          value = read_edge_cell(field, ix, iy, cell.inside_mask, value).inside_mean_mm;
        }
        visit(value, cell);
      }
    }
  };
  for_each_stats_cell([&](double v, const TargetRegion::Cell& cell) {
    sum += cell.weight() * v;
    weights += cell.weight();
    ++stats.cells;
    min_any = std::min(min_any, v);
    max_any = std::max(max_any, v);
    if (!(cell.flags & TargetRegion::kCentreInside)) return;
    any_centre = true;
    min_value = std::min(min_value, v);
    max_value = std::max(max_value, v);
  });
  if (!any_centre) min_value = min_any, max_value = max_any;
  if (stats.cells > 0 && sum > 0.0) {
    const double mean = sum / weights;
    double squares = 0.0;
    // (relative to the mean: a tiny flow's squares would underflow to a cv of 0)
    for_each_stats_cell([&](double v, const TargetRegion::Cell& cell) {
      squares += cell.weight() * ((v - mean) / mean) * ((v - mean) / mean);
    });
    stats.mean_um = mean * kUmPerMm;
    stats.cv = std::sqrt(squares / weights);
    stats.min_rel = min_value / mean;
    stats.max_rel = max_value / mean;
  }

  // centreline samples every cell length, ends excluded by r
  std::vector<double> samples;
  const double r = region.half_width_mm();
  const double h = field.cell_mm();
  for (const PrintPath& path : toolpath.paths) {
    if (path.points.size() < 2) continue;
    const double length = planar_length_mm(path);
    size_t segment = 0;
    double segment_start = 0.0;
    for (long long k = 0;; ++k) {
      const double s = r + static_cast<double>(k) * h;
      if (s > length - r + 1e-12) break;
      double x = 0.0, y = 0.0;
      point_at_arc(path, s, segment, segment_start, x, y);
      samples.push_back(field.thickness_mm_at(x, y));
    }
  }
  stats.line_samples = samples.size();
  if (!samples.empty()) {
    double line_sum = 0.0;
    for (double v : samples) line_sum += v;
    const double line_mean = line_sum / static_cast<double>(samples.size());
    if (line_mean > 0.0) {
      double squares = 0.0;
      for (double v : samples)
        squares += ((v - line_mean) / line_mean) * ((v - line_mean) / line_mean);
      stats.line_cv = std::sqrt(squares / static_cast<double>(samples.size()));
    }
  }
  return stats;
}

MaterialSplit split_material(const ThicknessField& field, const TargetRegion& region,
                             const MaterialAccount& account) {
  if (field.cell_mm() != region.cell_mm())
    throw InternalError("split_material: region and field have different cells");
  // every landed cell is on target by the share of its material inside the band (a whole
  // cell: all of it; one the band's edge crosses: read at its sub-points), overspray by the
  // rest, summed in sorted tile order
  double on_target_mm = 0.0, outside_mm = 0.0;
  for (const auto& [tx, ty] : field.tiles().sorted_tiles()) {
    const double* values = field.tiles().find(tx, ty);
    const TargetRegion::Cell* cells = region.tiles().find(tx, ty);
    for (int k = 0; k < ThicknessField::Tiles::kCells; ++k) {
      double share = 0.0;
      if (cells && cells[k].inside_mask == TargetRegion::kWholeCell) {
        share = 1.0;
      } else if (cells && cells[k].inside_mask != 0 && values[k] != 0.0) {
        int ix = 0, iy = 0;
        cell_indices(tx, ty, k, ix, iy);
        share = read_edge_cell(field, ix, iy, cells[k].inside_mask, values[k]).material_share;
      }
      on_target_mm += share * values[k];
      outside_mm += (1.0 - share) * values[k];
    }
  }
  const double area_mm2 = field.cell_mm() * field.cell_mm();
  MaterialSplit split;
  split.emitted_mm3 = account.emitted_mm3;
  split.on_target_mm3 = on_target_mm * area_mm2;
  split.overspray_mm3 = outside_mm * area_mm2;
  split.captured_mm3 = account.captured_mm3;
  split.closed_time_s = account.closed_time_s;
  if (account.emitted_mm3 > 0.0)
    split.fraction = (split.overspray_mm3 + split.captured_mm3) / account.emitted_mm3;
  return split;
}

DepositionMetrics evaluate_deposition(const ThicknessField& field, const Toolpath& toolpath,
                                      double line_width_mm, const MaterialAccount& account) {
  const TargetRegion region(toolpath, line_width_mm, field.cell_mm());
  DepositionMetrics metrics;
  metrics.thickness = thickness_stats(field, region, toolpath);
  metrics.material = split_material(field, region, account);
  return metrics;
}

}  // namespace depotwin
