// Nearest-neighbour print order (Ganganath et al., papers/004, Sec. III-B): from the
// start, repeatedly print next the path whose entry is reached soonest, choosing its
// direction too; then go to the end. Exact by transition time: a grid search ring by
// ring stops once the rings' lower bound on the time exceeds the best found.
#pragma once

#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

OrderResult nearest_neighbor_order(const TransitionCost& cost);

}  // namespace depotwin
