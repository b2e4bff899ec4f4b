#include "planners/motion/fine_edges.hpp"

#include <algorithm>

#include "core/segment_distance.hpp"

namespace depotwin {

FineEdgeMerge merge_polyline_edges(
    const std::vector<Vec3>& points, double max_error_mm, size_t max_points,
    const std::function<bool(size_t anchor, size_t edge)>& joinable) {
  FineEdgeMerge merged;
  const size_t n = points.size();
  if (n == 0) return merged;
  // the largest distance of points first+1 .. last-1 from the segment first-last
  const auto chord_error = [&](size_t first, size_t last) {
    double error = 0.0;
    for (size_t k = first + 1; k < last; ++k)
      error = std::max(error, point_segment_distance(points[k], points[first], points[last]));
    return error;
  };
  merged.kept.push_back(0);
  size_t anchor = 0;
  while (anchor + 1 < n) {
    size_t last = anchor + 1;
    double error = 0.0;
    double longest_edge = (points[last] - points[anchor]).norm();
    while (last + 1 < n && last + 1 - anchor <= max_points && joinable(anchor, last)) {
      const double next_edge = (points[last + 1] - points[last]).norm();
      const double chord = (points[last + 1] - points[anchor]).norm();
      if (!(chord >= std::max(longest_edge, next_edge))) break;
      const double longer = chord_error(anchor, last + 1);
      if (!(longer <= max_error_mm)) break;
      ++last;
      error = longer;
      longest_edge = std::max(longest_edge, next_edge);
    }
    merged.kept.push_back(last);
    merged.edge_error_mm.push_back(error);
    anchor = last;
  }
  return merged;
}

}  // namespace depotwin
