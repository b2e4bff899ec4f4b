#include "planners/motion/print_segments.hpp"

#include <cmath>
#include <sstream>

#include "core/error.hpp"

namespace depotwin {

std::vector<PrintSegment> split_into_segments(const Toolpath& toolpath,
                                              const TcpLimits& tcp_limits) {
  static const char* kAxis[3] = {"x", "y", "z"};
  // sized once: a toolpath may have 10^5 segments
  std::vector<PrintSegment> segments;
  size_t count = 0;
  for (const PrintPath& path : toolpath.paths) count += path.points.size() - 1;
  segments.reserve(count);
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    const PrintPath& path = toolpath.paths[i];
    const std::string where = "toolpath path " + std::to_string(path.source_index);
    if (!(path.speed_mm_s > 0.0) || !std::isfinite(path.speed_mm_s))
      throw InputError(where, "print speed must be positive");
    for (size_t k = 0; k + 1 < path.points.size(); ++k) {
      PrintSegment s;
      s.p0 = path.points[k];
      s.p1 = path.points[k + 1];
      s.length_mm = (s.p1 - s.p0).norm();
      if (!(s.length_mm > kJoinTolerance_mm))
        throw InputError(where, "segment " + std::to_string(k) + " has zero length");
      s.speed_mm_s = path.speed_mm_s;
      // eqs. (40)-(47): the desired velocity along the segment. The paper splits it with
      // the slope m and sgn(x1 - x0); the unit direction gives the same components in 3-D.
      s.v_desired = s.speed_mm_s * (s.p1 - s.p0) / s.length_mm;
      s.tool0 = path.orientation(k);
      s.tool1 = path.orientation(k + 1);
      // the limits over this segment alone (the machine's, where the tool is)
      s.limits = tcp_limits.along(s.p0, s.p1);
      const MachineLimits& limits = s.limits;
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(s.v_desired[axis]) > limits.axes[axis].v_max_mm_s * (1 + 1e-12)) {
          std::ostringstream msg;
          msg << "segment " << k << " needs " << std::abs(s.v_desired[axis]) << " mm/s on axis "
              << kAxis[axis] << " at print speed " << s.speed_mm_s << " mm/s, above v_max "
              << limits.axes[axis].v_max_mm_s;
          throw InputError(where, msg.str());
        }
      }
      s.path_index = static_cast<int>(i);
      s.edge_index = static_cast<int>(k);
      s.joined_to_previous =
          !segments.empty() && (segments.back().p1 - s.p0).norm() <= kJoinTolerance_mm;
      if (s.joined_to_previous) s.p0 = segments.back().p1;  // one point, exactly
      segments.push_back(s);
    }
  }
  return segments;
}

}  // namespace depotwin
