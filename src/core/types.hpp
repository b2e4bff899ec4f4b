// Shared scalar/vector aliases and unit conversions used by every module.
// User-facing quantities are mm, s, mm/s, mm/s^2 and degrees; MuJoCo works in SI
// metres. Convert only through the helpers below.
#pragma once

#include <Eigen/Core>

namespace depotwin {

using Vec3 = Eigen::Vector3d;

constexpr double kMmPerM = 1000.0;
constexpr double kPi = 3.14159265358979323846;

inline double mm_to_m(double mm) {
  return mm / kMmPerM;
}
inline double m_to_mm(double m) {
  return m * kMmPerM;
}
inline double deg_to_rad(double deg) {
  return deg * kPi / 180.0;
}
inline double rad_to_deg(double rad) {
  return rad * 180.0 / kPi;
}

}  // namespace depotwin
