#include "core/pose.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace depotwin {

namespace {

// the unit rotation axis that turns a into b: a x b, or for opposite axes a perpendicular
Vec3 rotation_axis(const Vec3& a, const Vec3& b) {
  const Vec3 cross = a.cross(b);
  if (cross.norm() > 1e-12) return cross.normalized();
  // parallel or opposite: any perpendicular, the one nearest to x, else y
  Vec3 perpendicular = a.cross(Vec3::UnitX());
  if (perpendicular.norm() < 1e-6) perpendicular = a.cross(Vec3::UnitY());
  return perpendicular.normalized();
}

}  // namespace

double axis_angle_rad(const Vec3& a, const Vec3& b) {
  // atan2 of |a x b| and a . b: accurate for small and for near-opposite angles
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Vec3 slerp_axis(const Vec3& a, const Vec3& b, double s) {
  const double angle = axis_angle_rad(a, b);
  if (angle < 1e-12) return a;
  return Eigen::AngleAxisd(s * angle, rotation_axis(a, b)) * a;
}

Eigen::Matrix3d tool_frame(const Vec3& axis, double roll_rad) {
  // the shortest rotation from +z to the axis (a fixed half turn about x for -z)
  const Eigen::Matrix3d tilt =
      Eigen::Quaterniond::FromTwoVectors(vertical_tool_axis(), axis).toRotationMatrix();
  return tilt * Eigen::AngleAxisd(roll_rad, Vec3::UnitZ()).toRotationMatrix();
}

double roll_of_frame(const Eigen::Matrix3d& frame) {
  // the x column in the un-rolled frame of the same axis
  const Eigen::Matrix3d reference = tool_frame(frame.col(2).normalized(), 0.0);
  const Vec3 x = reference.transpose() * frame.col(0);
  return std::atan2(x.y(), x.x());
}

Vec3 slerp_rate(const Vec3& a, const Vec3& b) {
  const double angle = axis_angle_rad(a, b);
  if (angle < 1e-12) return Vec3::Zero();
  return angle * rotation_axis(a, b);
}

}  // namespace depotwin
