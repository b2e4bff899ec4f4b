// A lower bound on the cost of every print order (print time + transitions).
//
// The N + 1 transitions of any order join start, end and all 2N path ends in pairs: a
// perfect matching that never pairs a node with its partner (a path's own two ends, or
// start with end). So print time + the minimum-weight perfect matching of the ends
// bounds every sequencer from below.
//
// Computed exactly at any N by pricing: Edmonds' weighted matching (LEMON) on the
// neighbour-list graph, then its optimal dual (node potentials y and blossom values z,
// see lemon/matching.h) is checked against EVERY allowed pair with a grid search (the
// geometric time bound of a ring proves the pairs beyond it satisfied); violated pairs
// join the graph and it is solved again. When no pair is violated the dual is feasible
// for the complete graph, so the sparse matching is the complete graph's optimum. (A
// matching on a sparse graph alone would only be an UPPER bound on the true minimum.)
// Costs are rounded down to integer microseconds, which keeps the bound valid.
#pragma once

#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

struct MatchingBoundStats {
  int rounds = 0;        // matchings solved
  long added_pairs = 0;  // pairs added by pricing after the first round
  long graph_edges = 0;  // edges of the final graph
};

// print time + minimum-weight perfect matching of all ends (partner pairs excluded)
double matching_lower_bound(const TransitionCost& cost, MatchingBoundStats* stats = nullptr);

}  // namespace depotwin
