// The toolpath as a flat list of straight print segments (one per polyline edge), with
// their desired velocities (Thompson & Yoon eqs. 40-47) and which ones share a joint.
#pragma once

#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"

namespace depotwin {

struct PrintSegment {
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();  // mm
  double length_mm = 0.0;                     // eq. (51)
  double speed_mm_s = 0.0;
  Vec3 v_desired = Vec3::Zero();  // speed times the unit direction, eqs. (40)-(47)
  Vec3 v_begin = Vec3::Zero(), v_end = Vec3::Zero();  // boundary velocities (planner)
  ToolOrientation tool0, tool1;                       // tool axes (and rolls) at p0, p1
  MachineLimits limits;             // the TCP limits over the segment's box (TcpLimits::along)
  int path_index = 0;               // index into Toolpath::paths
  int edge_index = 0;               // edge within that path
  bool joined_to_previous = false;  // starts where the previous segment ends: print on through
};

// Throws InputError when a segment is degenerate or its desired velocity exceeds an
// axis' v_max over the segment (the planner could not print it at the requested speed).
std::vector<PrintSegment> split_into_segments(const Toolpath& toolpath, const TcpLimits& limits);

}  // namespace depotwin
