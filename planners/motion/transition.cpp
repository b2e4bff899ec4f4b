#include "planners/motion/transition.hpp"

namespace depotwin {

std::vector<AxisMove> axis_moves(const Vec3& p0, const Vec3& v0, const Vec3& p1, const Vec3& v1,
                                 const MachineLimits& limits) {
  std::vector<AxisMove> moves(3);
  for (int axis = 0; axis < 3; ++axis) {
    moves[axis].boundary = AxisBoundary{p0[axis], p1[axis], v0[axis], v1[axis]};
    moves[axis].v_max = limits.axes[axis].v_max_mm_s;
    moves[axis].a_max = limits.axes[axis].a_max_mm_s2;
  }
  return moves;
}

PhaseMotion phase_motion(std::vector<AxisProfile> axes) {
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) motion.axes[axis] = std::move(axes[axis]);
  return motion;
}

TrajectoryPiece transition_piece(double t_begin_s, const Vec3& p0, const Vec3& v0, const Vec3& p1,
                                 const Vec3& v1, const MachineLimits& limits) {
  SynchronizedMove move = synchronized_move(axis_moves(p0, v0, p1, v1, limits));
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  piece.t_end_s = t_begin_s + move.duration_s;
  piece.path_index = -1;
  piece.depositing = false;
  piece.motion = phase_motion(std::move(move.axes));
  return piece;
}

}  // namespace depotwin
