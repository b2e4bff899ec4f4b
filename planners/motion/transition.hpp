// Helpers shared by the planners that use synchronised minimum-time transitions.
#pragma once

#include <vector>

#include "core/limits.hpp"
#include "core/trajectory.hpp"
#include "motion/sync.hpp"

namespace depotwin {

// the per-axis moves from (p0, v0) to (p1, v1) under the TCP limits (jerk-limited on the axes
// with a j_max)
std::vector<AxisMove> axis_moves(const Vec3& p0, const Vec3& v0, const Vec3& p1, const Vec3& v1,
                                 const MachineLimits& limits);

// A shutter-closed transition piece starting at t_begin: the synchronised minimum-time move
// of Thompson & Yoon eq. (39), generalised (see motion/sync.hpp), under the limits over the
// box the move may sweep (TcpLimits::for_transition). The tool turns from tool0 to tool1
// (axis and roll) on the way.
TrajectoryPiece transition_piece(double t_begin_s, const Vec3& p0, const Vec3& v0, const Vec3& p1,
                                 const Vec3& v1, const TcpLimits& limits,
                                 const ToolOrientation& tool0 = {},
                                 const ToolOrientation& tool1 = {});

// PhaseMotion from per-axis profiles (3 entries)
PhaseMotion phase_motion(std::vector<AxisProfile> axes);

// the tool axis (and roll) along a straight print segment from p0 (tool0) to p1 (tool1)
ToolAxisMotion segment_tool_axis(const Vec3& p0, const ToolOrientation& tool0, const Vec3& p1,
                                 const ToolOrientation& tool1);

}  // namespace depotwin
