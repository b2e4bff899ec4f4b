// A tool pose: where the nozzle tip is and which way the nozzle points. The nozzle is
// symmetric about its axis, so a pose has five degrees of freedom: the roll about the axis
// is free. A machine with a wrist (arm6) chooses it and carries it as `roll_rad`: the tool's
// rotation about its axis, measured from the reference frame of that axis (tool_frame).
// Machines that hold the nozzle by translation only ignore it.
#pragma once

#include <Eigen/Core>

#include "core/types.hpp"

namespace depotwin {

// The vertical tool axis: a nozzle pointing straight down at a substrate facing up.
inline Vec3 vertical_tool_axis() {
  return Vec3::UnitZ();
}

struct Pose {
  Vec3 position_mm = Vec3::Zero();  // the TCP (nozzle tip) in the work frame
  // unit vector from the tip up into the tool, so along the surface normal when printing
  // square to a surface; +z for a vertical nozzle over a flat substrate
  Vec3 tool_axis = vertical_tool_axis();
  // the roll about the tool axis (rad, not wrapped), from tool_frame(tool_axis, 0)
  double roll_rad = 0.0;

  Pose() = default;
  // implicit from a position alone: a vertical nozzle there
  Pose(const Vec3& position, const Vec3& axis = vertical_tool_axis(),  // NOLINT
       double roll = 0.0)
      : position_mm(position), tool_axis(axis), roll_rad(roll) {}
};

// The tool's orientation alone: its unit axis and the roll about it (rad).
struct ToolOrientation {
  Vec3 axis = vertical_tool_axis();
  double roll_rad = 0.0;
};

// The tool frame of an axis and a roll: columns x, y, z with z = axis, and x the work
// frame's x turned onto the plane normal to the axis by the shortest rotation from +z to
// the axis, then rolled by roll_rad about the axis. Continuous in the axis everywhere but at
// -z (a nozzle pointing up), where the shortest rotation is undefined (a fixed choice there).
Eigen::Matrix3d tool_frame(const Vec3& axis, double roll_rad);

// The roll of a frame whose z column is the unit axis: the angle (rad, in (-pi, pi]) that
// tool_frame(axis, roll) needs to reproduce its x column.
double roll_of_frame(const Eigen::Matrix3d& frame);

// The rate of a pose: TCP velocity and the tool's angular velocity (its component along the
// tool axis, the roll, moves nothing).
struct PoseRate {
  Vec3 linear_mm_s = Vec3::Zero();
  Vec3 angular_rad_s = Vec3::Zero();

  PoseRate() = default;
  // implicit from a TCP velocity alone: the tool does not turn
  PoseRate(const Vec3& linear, const Vec3& angular = Vec3::Zero())  // NOLINT
      : linear_mm_s(linear), angular_rad_s(angular) {}
};

// the angle (rad) between two unit axes
double axis_angle_rad(const Vec3& a, const Vec3& b);

// The unit axis a fraction s in [0, 1] of the way from a to b by the shortest rotation
// (spherical linear interpolation); a for nearly equal axes. Opposite axes rotate about any
// perpendicular (a stable choice).
Vec3 slerp_axis(const Vec3& a, const Vec3& b, double s);

// The angular velocity (rad per unit of s) of slerp_axis(a, b, s): the rotation axis a x b
// scaled by the angle; zero for equal axes.
Vec3 slerp_rate(const Vec3& a, const Vec3& b);

}  // namespace depotwin
