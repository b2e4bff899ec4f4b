#include "planners/ordering/point_grid.hpp"

namespace depotwin {

PointGrid::PointGrid(const std::vector<Vec3>& points, double points_per_cell) {
  const int count = static_cast<int>(points.size());
  cell_of_.assign(count, 0);
  slot_.assign(count, -1);
  if (count == 0) {
    cells_.resize(1);
    return;
  }
  // bounding box of the points, split into square cells
  double x_lo = points[0].x(), x_hi = x_lo, y_lo = points[0].y(), y_hi = y_lo;
  for (const Vec3& p : points) {
    x_lo = std::min(x_lo, p.x()), x_hi = std::max(x_hi, p.x());
    y_lo = std::min(y_lo, p.y()), y_hi = std::max(y_hi, p.y());
  }
  const double width_mm = std::max(x_hi - x_lo, 1e-9), height_mm = std::max(y_hi - y_lo, 1e-9);
  const double cells_wanted = std::max(1.0, count / points_per_cell);
  cell_mm_ = std::max(std::sqrt(width_mm * height_mm / cells_wanted),
                      std::max(width_mm, height_mm) / 4096.0);
  origin_x_ = x_lo, origin_y_ = y_lo;
  columns_ = std::max(1, static_cast<int>(std::ceil(width_mm / cell_mm_)));
  rows_ = std::max(1, static_cast<int>(std::ceil(height_mm / cell_mm_)));
  cells_.assign(static_cast<size_t>(columns_) * rows_, {});
  for (int id = 0; id < count; ++id) {
    const int cell = row(points[id].y()) * columns_ + column(points[id].x());
    cell_of_[id] = cell;
    slot_[id] = static_cast<int>(cells_[cell].size());
    cells_[cell].push_back(id);
  }
  alive_ = count;
}

void PointGrid::remove(int id) {
  if (slot_[id] < 0) return;
  // swap with the last point of the cell, then pop
  std::vector<int>& cell = cells_[cell_of_[id]];
  const int moved = cell.back();
  cell[slot_[id]] = moved;
  slot_[moved] = slot_[id];
  cell.pop_back();
  slot_[id] = -1;
  --alive_;
}

}  // namespace depotwin
