#include "core/limits.hpp"

#include <cmath>

namespace depotwin {

MachineLimits MachineLimits::uniform(double v_max_mm_s, double a_max_mm_s2, double j_max_mm_s3) {
  MachineLimits limits;
  for (AxisLimits& axis : limits.axes) axis = AxisLimits{v_max_mm_s, a_max_mm_s2, j_max_mm_s3};
  return limits;
}

std::string MachineLimits::validate() const {
  static const char* kAxisNames[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const AxisLimits& axis = axes[i];
    const std::string name = kAxisNames[i];
    if (!std::isfinite(axis.v_max_mm_s) || axis.v_max_mm_s <= 0.0)
      return "v_max of axis " + name + " must be a positive finite number";
    if (!std::isfinite(axis.a_max_mm_s2) || axis.a_max_mm_s2 <= 0.0)
      return "a_max of axis " + name + " must be a positive finite number";
    if (!std::isfinite(axis.j_max_mm_s3) || axis.j_max_mm_s3 < 0.0)
      return "j_max of axis " + name + " must be a finite number >= 0 (0: unlimited)";
  }
  return "";
}

}  // namespace depotwin
