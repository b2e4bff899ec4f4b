#include "planners/motion/transition.hpp"

namespace depotwin {

std::vector<AxisMove> axis_moves(const Vec3& p0, const Vec3& v0, const Vec3& p1, const Vec3& v1,
                                 const MachineLimits& limits) {
  std::vector<AxisMove> moves(3);
  for (int axis = 0; axis < 3; ++axis) {
    moves[axis].boundary = AxisBoundary{p0[axis], p1[axis], v0[axis], v1[axis]};
    moves[axis].v_max = limits.axes[axis].v_max_mm_s;
    moves[axis].a_max = limits.axes[axis].a_max_mm_s2;
    moves[axis].j_max = limits.axes[axis].j_max_mm_s3;
  }
  return moves;
}

PhaseMotion phase_motion(std::vector<AxisProfile> axes) {
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) motion.axes[axis] = std::move(axes[axis]);
  return motion;
}

ToolAxisMotion segment_tool_axis(const Vec3& p0, const ToolOrientation& tool0, const Vec3& p1,
                                 const ToolOrientation& tool1) {
  ToolAxisMotion motion;
  motion.begin = tool0.axis;
  motion.end = tool1.axis;
  motion.roll_begin = tool0.roll_rad;
  motion.roll_end = tool1.roll_rad;
  motion.along_chord = true;
  motion.chord_begin_mm = p0;
  motion.chord_end_mm = p1;
  return motion;
}

TrajectoryPiece transition_piece(double t_begin_s, const Vec3& p0, const Vec3& v0, const Vec3& p1,
                                 const Vec3& v1, const TcpLimits& limits,
                                 const ToolOrientation& tool0, const ToolOrientation& tool1) {
  const MachineLimits box_limits = limits.for_transition(p0, v0, p1, v1);
  SynchronizedMove move = synchronized_move(axis_moves(p0, v0, p1, v1, box_limits));
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  piece.t_end_s = t_begin_s + move.duration_s;
  piece.path_index = -1;
  piece.depositing = false;
  piece.motion = phase_motion(std::move(move.axes));
  // the axis turns in time, at rest at both ends
  piece.tool_axis.begin = tool0.axis;
  piece.tool_axis.end = tool1.axis;
  piece.tool_axis.roll_begin = tool0.roll_rad;
  piece.tool_axis.roll_end = tool1.roll_rad;
  return piece;
}

}  // namespace depotwin
