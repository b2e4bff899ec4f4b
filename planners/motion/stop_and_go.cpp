#include "planners/motion/stop_and_go.hpp"

#include <algorithm>
#include <cmath>

#include "motion/jerk.hpp"
#include "planners/motion/print_segments.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

// Rest-to-rest trapezoid (or triangle) over `length` along one line, capped at v and a.
AxisProfile along_line_trapezoid(double length, double v, double a) {
  AxisProfile s(0.0, 0.0);
  if (length >= v * v / a) {
    s.append(v / a, a);
    s.append((length - v * v / a) / v, 0.0);
    s.append(v / a, -a);
  } else {
    const double t_half = std::sqrt(length / a);
    s.append(t_half, a);
    s.append(t_half, -a);
  }
  return s;
}

// the same timing on one Cartesian axis: q(t) = q0 + u * s(t)
AxisProfile scaled(const AxisProfile& along, double q0, double u) {
  AxisProfile axis(q0, 0.0);
  for (const Phase& phase : along.phases()) {
    if (phase.jerk == 0.0)
      axis.append(phase.duration_s, u * phase.a0);
    else
      axis.append_jerk(phase.duration_s, u * phase.jerk);
  }
  return axis;
}

}  // namespace

Trajectory StopAndGoPlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  const std::vector<PrintSegment> segments = split_into_segments(toolpath, limits);
  std::vector<TrajectoryPiece> pieces;
  pieces.reserve(2 * segments.size() + 1);  // a transition before each segment, one to the end
  double t = 0.0;
  Vec3 position = toolpath.start_mm;
  ToolOrientation tool = toolpath.start_orientation();
  for (const PrintSegment& s : segments) {
    // transitions between separate segments: rest to rest, shutter closed
    if (!s.joined_to_previous) {
      pieces.push_back(
          transition_piece(t, position, Vec3::Zero(), s.p0, Vec3::Zero(), limits, tool, s.tool0));
      t = pieces.back().t_end_s;
    }
    // the line's own speed, acceleration and jerk caps: no axis beyond its limits over it
    const Vec3 u = (s.p1 - s.p0) / s.length_mm;
    double v = s.speed_mm_s, a = std::numeric_limits<double>::infinity();
    double j = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(u[axis]) < 1e-15) continue;
      const AxisLimits& limit = s.limits.axes[axis];
      v = std::min(v, limit.v_max_mm_s / std::abs(u[axis]));
      a = std::min(a, limit.a_max_mm_s2 / std::abs(u[axis]));
      if (limit.j_max_mm_s3 > 0.0) j = std::min(j, limit.j_max_mm_s3 / std::abs(u[axis]));
    }
    // rest to rest along the line: a trapezoid, or a double-S under a jerk limit
    const AxisProfile along =
        std::isfinite(j) ? jerk_min_time_move(AxisBoundary{0.0, s.length_mm, 0.0, 0.0}, v, a, j)
                         : along_line_trapezoid(s.length_mm, v, a);
    std::vector<AxisProfile> axes;
    for (int axis = 0; axis < 3; ++axis) axes.push_back(scaled(along, s.p0[axis], u[axis]));
    TrajectoryPiece piece;
    piece.t_begin_s = t;
    piece.t_end_s = t + along.duration_s();
    piece.path_index = s.path_index;
    piece.depositing = true;  // material on throughout, ramps included
    piece.desired_speed_mm_s = s.speed_mm_s;
    piece.motion = phase_motion(std::move(axes));
    piece.tool_axis = segment_tool_axis(s.p0, s.tool0, s.p1, s.tool1);
    pieces.push_back(std::move(piece));
    t = pieces.back().t_end_s;
    position = s.p1;
    tool = s.tool1;
  }
  pieces.push_back(transition_piece(t, position, Vec3::Zero(), toolpath.end_mm, Vec3::Zero(),
                                    limits, tool, toolpath.end_orientation()));
  return Trajectory("stop_and_go", std::move(pieces));
}

}  // namespace depotwin
