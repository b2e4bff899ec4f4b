#include "core/limits.hpp"

#include <algorithm>
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

bool MachineLimits::jerk_limited() const {
  return std::any_of(axes.begin(), axes.end(),
                     [](const AxisLimits& axis) { return axis.j_max_mm_s3 > 0.0; });
}

TcpLimits::TcpLimits(const MachineLimits& limits) : requested_(limits) {}

TcpLimits::TcpLimits(const MachineLimits& requested, BoxLimits over_box,
                     std::shared_ptr<const JointMap> joint_map)
    : requested_(requested), over_box_(std::move(over_box)), joint_map_(std::move(joint_map)) {}

MachineLimits TcpLimits::over(const Vec3& lo_mm, const Vec3& hi_mm) const {
  if (!over_box_) return requested_;
  return over_box_(lo_mm.cwiseMin(hi_mm), lo_mm.cwiseMax(hi_mm));
}

MachineLimits TcpLimits::along(const Vec3& a_mm, const Vec3& b_mm) const {
  return over(a_mm.cwiseMin(b_mm), a_mm.cwiseMax(b_mm));
}

MachineLimits TcpLimits::for_transition(const Vec3& a_mm, const Vec3& va_mm_s, const Vec3& b_mm,
                                        const Vec3& vb_mm_s) const {
  if (!over_box_) return requested_;
  const Vec3 lo = a_mm.cwiseMin(b_mm), hi = a_mm.cwiseMax(b_mm);
  const Vec3 speed = va_mm_s.cwiseAbs().cwiseMax(vb_mm_s.cwiseAbs());
  // a larger box gives lower accelerations, hence longer stopping distances: grow the box
  // from the user's accelerations until the limits over it stop shrinking
  MachineLimits limits = requested_;
  for (int round = 0; round < 8; ++round) {
    Vec3 pad = Vec3::Zero();
    for (int axis = 0; axis < 3; ++axis)
      pad[axis] = speed[axis] * speed[axis] / (2.0 * limits.axes[axis].a_max_mm_s2);
    const MachineLimits next = over_box_(lo - pad, hi + pad);
    bool settled = true;
    for (int axis = 0; axis < 3; ++axis)
      settled = settled && next.axes[axis].a_max_mm_s2 >= limits.axes[axis].a_max_mm_s2 * 0.999;
    limits = next;
    if (settled) break;
  }
  // the boundary velocities themselves were checked on their print segments
  for (int axis = 0; axis < 3; ++axis)
    limits.axes[axis].v_max_mm_s = std::max(limits.axes[axis].v_max_mm_s, speed[axis]);
  return limits;
}

}  // namespace depotwin
