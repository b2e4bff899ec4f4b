// placeholder until the bezier planner lands (issue 5); registered so names stay stable
#include "planners/bezier.hpp"

#include "core/error.hpp"

namespace depotwin {

std::vector<PlannerParameter> bezier_parameters() { return {}; }

std::unique_ptr<Planner> make_bezier_planner(const PlannerSpec&) {
  throw InputError("planners", "the bezier planner is not available yet");
}

}  // namespace depotwin
