// A job of one polyline, for the planner tests: printed at one speed, starting and ending where
// the polyline does (no travels).
#pragma once

#include <vector>

#include "core/toolpath.hpp"

namespace depotwin {

inline Toolpath polyline_job(const std::vector<Vec3>& points, double speed_mm_s) {
  Toolpath toolpath;
  PrintPath path;
  path.points = points;
  path.speed_mm_s = speed_mm_s;
  toolpath.paths.push_back(path);
  toolpath.start_mm = points.front();
  toolpath.end_mm = points.back();
  return toolpath;
}

}  // namespace depotwin
