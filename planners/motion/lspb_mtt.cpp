#include "planners/motion/lspb_mtt.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "motion/lspb.hpp"
#include "motion/mtt.hpp"
#include "motion/sync.hpp"
#include "planners/motion/print_segments.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {

namespace {

// The velocity at the joint of two segments, eqs. (52)-(53): the average of their desired
// velocities; beyond the paper, each axis within both segments' v_max there (a machine's
// limits differ per segment's box: a line at 100 mm/s on x joined to one slowed to 99.7 by a
// delta's limits averaged 99.85, over the second's limit, and failed as an internal error)
Vec3 joint_velocity(const PrintSegment& before, const PrintSegment& after) {
  Vec3 v = 0.5 * (before.v_desired + after.v_desired);
  for (int axis = 0; axis < 3; ++axis) {
    const double v_max =
        std::min(before.limits.axes[axis].v_max_mm_s, after.limits.axes[axis].v_max_mm_s);
    v[axis] = std::clamp(v[axis], -v_max, v_max);
  }
  return v;
}

// Boundary velocities of every print segment, eqs. (48)-(53): the desired velocity at an
// isolated end, the joint velocity at a shared joint.
void assign_boundary_velocities(std::vector<PrintSegment>& segments) {
  for (size_t i = 0; i < segments.size(); ++i) {
    PrintSegment& s = segments[i];
    s.v_begin = s.v_desired;  // eqs. (48)-(49)
    s.v_end = s.v_desired;
    if (i > 0 && s.joined_to_previous) s.v_begin = joint_velocity(segments[i - 1], s);
    if (i + 1 < segments.size() && segments[i + 1].joined_to_previous)
      s.v_end = joint_velocity(s, segments[i + 1]);
  }
}

// The per-axis profiles of one print segment over the duration L / v (eq. 50), or over the
// shortest longer duration every axis can meet (with a warning). Without a jerk limit: the
// paper's LSPB (eqs. 11-16); with one: double-S moves, zero acceleration at both ends.
std::vector<AxisProfile> segment_profiles(const PrintSegment& s, double& duration_s,
                                          std::vector<std::string>& warnings) {
  const double nominal_s = s.length_mm / s.speed_mm_s;
  const std::vector<AxisMove> moves = axis_moves(s.p0, s.v_begin, s.p1, s.v_end, s.limits);
  std::vector<AxisProfile> axes;
  duration_s = nominal_s;
  bool lengthened = false;
  if (s.limits.jerk_limited()) {
    duration_s = synchronized_duration(moves, nominal_s);
    lengthened = duration_s > nominal_s;
    for (const AxisMove& move : moves) axes.push_back(axis_fixed_time_move(move, duration_s));
  } else {
    for (const AxisMove& move : moves) {
      auto lspb = solve_lspb(move.boundary, nominal_s, move.a_max, move.v_max);
      if (!lspb) break;
      axes.push_back(lspb->profile(move.boundary));
    }
    // beyond the paper: no LSPB exists in L / v (the segment is too short for its boundary
    // velocities); take the shortest longer duration every axis can meet
    if (axes.size() < moves.size()) {
      lengthened = true;
      duration_s = synchronized_duration(moves, nominal_s);
      axes.clear();
      for (const AxisMove& move : moves) axes.push_back(axis_fixed_time_move(move, duration_s));
    }
  }
  if (lengthened) {
    std::ostringstream warning;
    warning << "path " << s.path_index << " segment " << s.edge_index << ": no "
            << (s.limits.jerk_limited() ? "jerk-limited move" : "LSPB") << " in L/v = " << nominal_s
            << " s; lengthened to " << duration_s << " s (mean speed " << s.length_mm / duration_s
            << " instead of " << s.speed_mm_s << " mm/s)";
    warnings.push_back(warning.str());
  }
  return axes;
}

}  // namespace

Trajectory LspbMttPlanner::plan(const Toolpath& toolpath, const TcpLimits& limits) const {
  std::vector<PrintSegment> segments = split_into_segments(toolpath, limits);
  assign_boundary_velocities(segments);

  std::vector<TrajectoryPiece> pieces;
  pieces.reserve(2 * segments.size() + 1);  // a transition before each segment, one to the end
  std::vector<std::string> warnings;
  double t = 0.0;
  Vec3 position = toolpath.start_mm;
  Vec3 velocity = Vec3::Zero();
  ToolOrientation tool = toolpath.start_orientation();
  for (const PrintSegment& s : segments) {
    // shutter closed: minimum-time transition to the segment's start and velocity
    if (!s.joined_to_previous) {
      pieces.push_back(
          transition_piece(t, position, velocity, s.p0, s.v_begin, limits, tool, s.tool0));
      t = pieces.back().t_end_s;
    }
    // shutter open: per-axis LSPB over the segment time L / v, eq. (50)
    double duration_s = 0.0;
    std::vector<AxisProfile> axes = segment_profiles(s, duration_s, warnings);
    TrajectoryPiece piece;
    piece.t_begin_s = t;
    piece.t_end_s = t + duration_s;
    piece.path_index = s.path_index;
    piece.depositing = true;
    piece.desired_speed_mm_s = s.speed_mm_s;
    piece.motion = phase_motion(std::move(axes));
    piece.tool_axis = segment_tool_axis(s.p0, s.tool0, s.p1, s.tool1);
    pieces.push_back(std::move(piece));
    t += duration_s;
    position = s.p1;
    velocity = s.v_end;
    tool = s.tool1;
  }
  // shutter closed: to the end point, at rest
  pieces.push_back(transition_piece(t, position, velocity, toolpath.end_mm, Vec3::Zero(), limits,
                                    tool, toolpath.end_orientation()));
  return Trajectory("lspb_mtt", std::move(pieces), std::move(warnings));
}

}  // namespace depotwin
