// The distance from a point to a segment, shared by the metrics (path error, export) and the
// planners (uniform's block compressor measures a dropped point against its merged edge).
#pragma once

#include <algorithm>

#include "core/types.hpp"

namespace depotwin {

// the distance from `point` to the segment [a, b] (a point when a == b): to the nearest point
// a + u (b - a), u clamped to [0, 1]
inline double point_segment_distance(const Vec3& point, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double u = len2 > 0.0 ? std::clamp((point - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + u * ab - point).norm();
}

}  // namespace depotwin
