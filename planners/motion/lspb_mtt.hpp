// Thompson & Yoon 2014 (papers/000): LSPB on print segments, minimum-time moves on
// transitions, velocities averaged at shared joints.
#pragma once

#include <memory>

#include "planners/planner.hpp"

namespace depotwin {

class LspbMttPlanner : public Planner {
 public:
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
};

}  // namespace depotwin
