// Helpers shared by the planners that use synchronised minimum-time transitions.
#pragma once

#include <vector>

#include "core/limits.hpp"
#include "core/trajectory.hpp"
#include "motion/sync.hpp"

namespace depotwin {

// the per-axis moves from (p0, v0) to (p1, v1) under the Cartesian limits
std::vector<AxisMove> axis_moves(const Vec3& p0, const Vec3& v0, const Vec3& p1, const Vec3& v1,
                                 const MachineLimits& limits);

// a shutter-closed transition piece starting at t_begin: the synchronised
// minimum-time move of Thompson & Yoon eq. (39), generalised (see motion/sync.hpp)
TrajectoryPiece transition_piece(double t_begin_s, const Vec3& p0, const Vec3& v0, const Vec3& p1,
                                 const Vec3& v1, const MachineLimits& limits);

// PhaseMotion from per-axis profiles (3 entries)
PhaseMotion phase_motion(std::vector<AxisProfile> axes);

}  // namespace depotwin
