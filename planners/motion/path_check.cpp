#include "planners/motion/path_check.hpp"

#include <cmath>

#include "core/error.hpp"

namespace depotwin {

void validate_print_path(const PrintPath& path, const std::string& name, double same_point_mm) {
  if (path.points.size() < 2) throw InputError(name, "a print path needs at least two points");
  if (!(path.speed_mm_s > 0.0) || !std::isfinite(path.speed_mm_s))
    throw InputError(name, "print speed must be positive");
  if (!path.normals.empty() && path.normals.size() != path.points.size())
    throw InputError(name, "needs one normal per point");
  if (!path.rolls.empty() && path.rolls.size() != path.points.size())
    throw InputError(name, "needs one roll per point");
  for (size_t i = 0; i < path.points.size(); ++i) {
    if (!path.points[i].allFinite())
      throw InputError(name, "point " + std::to_string(i) + " is not finite");
    if (i > 0 && !((path.points[i] - path.points[i - 1]).norm() > same_point_mm))
      throw InputError(name, "segment " + std::to_string(i - 1) + " has zero length");
    if (!path.normals.empty() &&
        (!path.normals[i].allFinite() || !(std::abs(path.normals[i].norm() - 1.0) <= 1e-6)))
      throw InputError(name, "normal " + std::to_string(i) + " is not a unit vector");
  }
}

}  // namespace depotwin
