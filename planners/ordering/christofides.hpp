// Christofides adapted to print ordering (Ganganath et al., papers/004, Sec. III-C):
//  1. a minimum spanning tree grown (Kruskal) from the forest of print paths plus the
//     virtual start-end edge, over the transition times;
//  2. a minimum-weight perfect matching of the tree's odd-degree ends (LEMON);
//  3. an Euler circuit of forest + tree + matching, cut at the virtual edge;
//  4. shortcuts: the paths in the order (and direction) the Euler path prints them,
//     every run of transition edges between two paths replaced by one transition.
// Up to kDenseLimit paths the tree and the matching use every pair of ends; above it
// they use the neighbour lists, with the nearest cross-component edges added until
// the tree connects and a greedy nearest pairing of any ends left unmatched.
#pragma once

#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

OrderResult christofides_order(const TransitionCost& cost);

}  // namespace depotwin
