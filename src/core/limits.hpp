// Kinematic limits the planners must respect, per Cartesian TCP axis (x, y, z).
// For machines whose joints are not the Cartesian axes (linear delta), the Machine
// maps its joint limits to these conservative Cartesian limits (see kinematics/).
#pragma once

#include <array>
#include <string>

namespace depotwin {

struct AxisLimits {
  double v_max_mm_s = 0.0;
  double a_max_mm_s2 = 0.0;
  double j_max_mm_s3 = 0.0;  // 0: no jerk limit
};

struct MachineLimits {
  std::array<AxisLimits, 3> axes{};  // x, y, z

  // the same limits on every axis
  static MachineLimits uniform(double v_max_mm_s, double a_max_mm_s2, double j_max_mm_s3 = 0.0);
  // "" when usable, else what is wrong (names the axis and field)
  std::string validate() const;
};

}  // namespace depotwin
