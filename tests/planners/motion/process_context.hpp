// A planning context for the planner tests: the process a deposit-aware planner predicts with,
// of the given type and a 0.4 mm line, the rest at its defaults.
#pragma once

#include <memory>

#include "deposition/process.hpp"
#include "planners/planner.hpp"

namespace depotwin {

inline PlanningContext process_context(ProcessType type) {
  DepositionSettings process;
  process.type = type;
  process.bead_width_mm = 0.4;
  PlanningContext context;
  context.process = std::make_shared<const DepositionSettings>(process);
  return context;
}

}  // namespace depotwin
