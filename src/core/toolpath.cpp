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
  return out;
}

double Toolpath::print_length_mm() const {
  double length = 0.0;
  for (const PrintPath& path : paths) length += path.length_mm();
  return length;
}

void Toolpath::bounds(Vec3& lo, Vec3& hi) const {
  lo = start_mm.cwiseMin(end_mm);
  hi = start_mm.cwiseMax(end_mm);
  for (const PrintPath& path : paths) {
    for (const Vec3& p : path.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
}

}  // namespace depotwin
