// The naive baseline: every print segment is a rest-to-rest trapezoid along the line,
// capped at the print speed, with material on throughout (a machine without look-ahead).
// Transitions are the synchronised minimum-time moves of lspb_mtt. With a jerk limit the
// ramps and transitions are jerk-limited double-S moves.
#pragma once

#include "planners/planner.hpp"

namespace depotwin {

class StopAndGoPlanner : public Planner {
 public:
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
};

}  // namespace depotwin
