// A uniform x-y bucket grid over the path ends, searched ring by ring around a query
// point. Used for neighbour lists, the exact nearest-neighbour sequencer and the cheap
// lower bound. Points can be removed (the nearest-neighbour tour consumes them).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/types.hpp"

namespace depotwin {

class PointGrid {
 public:
  // buckets sized for about `points_per_cell` points each
  explicit PointGrid(const std::vector<Vec3>& points, double points_per_cell = 2.0);

  void remove(int id);
  bool contains(int id) const { return slot_[id] >= 0; }
  int size() const { return alive_; }

  // Visits the points around `p` ring by ring (the query cell first). After each ring
  // calls stop(distance_mm): every point not yet visited is at least that far from p in
  // x-y Chebyshev distance; the search ends when stop() returns true or the grid is
  // exhausted. visit(id) sees each remaining point at most once.
  template <class Visit, class Stop>
  void search(const Vec3& p, Visit visit, Stop stop) const {
    const int cx = column(p.x()), cy = row(p.y());
    for (int ring = 0;; ++ring) {
      const int x0 = cx - ring, x1 = cx + ring, y0 = cy - ring, y1 = cy + ring;
      for (int y = std::max(y0, 0); y <= std::min(y1, rows_ - 1); ++y) {
        if (y == y0 || y == y1) {
          for (int x = std::max(x0, 0); x <= std::min(x1, columns_ - 1); ++x)
            visit_cell(x, y, visit);
        } else {
          if (x0 >= 0) visit_cell(x0, y, visit);
          if (x1 < columns_) visit_cell(x1, y, visit);
        }
      }
      if (x0 <= 0 && y0 <= 0 && x1 >= columns_ - 1 && y1 >= rows_ - 1) return;  // all seen
      // distance from p to the border of the square of cells searched so far
      const double margin_mm =
          std::min({p.x() - (origin_x_ + x0 * cell_mm_), origin_x_ + (x1 + 1) * cell_mm_ - p.x(),
                    p.y() - (origin_y_ + y0 * cell_mm_), origin_y_ + (y1 + 1) * cell_mm_ - p.y()});
      if (stop(std::max(0.0, margin_mm))) return;
    }
  }

 private:
  template <class Visit>
  void visit_cell(int x, int y, Visit& visit) const {
    for (int id : cells_[static_cast<size_t>(y) * columns_ + x]) visit(id);
  }
  int column(double x) const {
    return std::clamp(static_cast<int>(std::floor((x - origin_x_) / cell_mm_)), 0, columns_ - 1);
  }
  int row(double y) const {
    return std::clamp(static_cast<int>(std::floor((y - origin_y_) / cell_mm_)), 0, rows_ - 1);
  }

  double origin_x_ = 0.0, origin_y_ = 0.0, cell_mm_ = 1.0;
  int columns_ = 1, rows_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<int> cell_of_, slot_;  // per point: its cell and its index in that cell
  int alive_ = 0;
};

}  // namespace depotwin
