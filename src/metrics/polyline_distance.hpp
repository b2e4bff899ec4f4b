// The distance from many points to one polyline (a print path, in 3-D), exact: the same
// value as distance_to_polyline (motion_metrics.hpp) to the bit, the minimum over the
// polyline's segments of the same closed form, but without visiting every segment per point.
// A path error is measured at every 1 ms sample against its print path; on a long path (a
// slicer's spiral, a conformal hatch of thousands of points) visiting every segment made the
// metrics quadratic.
//
// The segments are binned on a uniform grid in (x, y): each cell lists the segments that can
// pass through it (their distance from the cell's centre, in x and y, at most its half
// diagonal). A query visits the cells in square rings around its point's cell; a segment not
// yet visited lies, in (x, y), outside the square searched so far, so it is at least the
// point's distance to that square's edge away (a 3-D distance is at least its (x, y) part).
// The search stops once the best distance found is within that bound.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/segment_distance.hpp"
#include "core/types.hpp"

namespace depotwin {

class PolylineDistance {
 public:
  explicit PolylineDistance(const std::vector<Vec3>& polyline);

  // the distance from `point` to the polyline: distance_to_polyline(point, polyline) exactly
  // (infinity for an empty polyline, the point's own distance for a single point)
  double operator()(const Vec3& point) const;

 private:
  // every segment: distance_to_polyline
  double scan_all(const Vec3& point) const;
  // the grid's cells (column i, row j) the segment from point k to k + 1 may pass through
  template <typename Visit>
  void for_each_cell_of_segment(std::size_t k, Visit&& visit) const;

  const std::vector<Vec3>& points_;
  bool binned_ = false;  // false: few segments, or a degenerate box; every segment is visited
  double origin_x_ = 0.0, origin_y_ = 0.0;  // the grid's lower corner
  double cell_ = 0.0;                       // cell side (mm)
  long nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> cell_start_;  // CSR: cell c's segments are
  std::vector<std::uint32_t> cell_items_;  // cell_items_[cell_start_[c] .. cell_start_[c + 1])
};

}  // namespace depotwin
