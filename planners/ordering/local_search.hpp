// Local search over print orders (the k-opt refinements of Ganganath et al., papers/004,
// Sec. III-D), with neighbour lists and don't-look bits so it scales to N = 10^4.
//
// The order is kept as a cycle over the path ends (see transition_cost.hpp) in which
// every partner edge (print path, and the virtual start-end edge) is fixed; moves only
// swap transition edges. Reversing a stretch of the cycle therefore also reverses the
// print direction of every path in it, so direction flips come for free.
//   two_opt:   remove two transitions, reconnect (reverses the stretch between them)
//   or_opt:    move a chain of 1-3 paths elsewhere, either way round, or flip it in place
//   three_opt: remove three transitions, every reconnection (includes 2-opt and or-opt)
#pragma once

#include <string>

#include "planners/ordering/neighbor_lists.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

enum class Refinement { two_opt, three_opt, or_opt };

// "two_opt" | "three_opt" | "or_opt"; throws InputError naming `order.refine` otherwise
Refinement parse_refinement(const std::string& name);

struct LocalSearchStats {
  long moves = 0;       // improving moves applied
  double gain_s = 0.0;  // total time saved
};

// Improves `order` in place until no move over the neighbour lists helps; each applied
// move lowers the cost by more than 1e-9 s, so the cost never increases.
LocalSearchStats refine_order(OrderResult& order, const TransitionCost& cost,
                              const NeighborLists& neighbors, Refinement refinement);

}  // namespace depotwin
