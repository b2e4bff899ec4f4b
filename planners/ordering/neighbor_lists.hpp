// Candidate lists for the local search: for every path end, its k nearest other ends
// (Euclidean, found on a grid), sorted by exact transition time.
#pragma once

#include <vector>

#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

struct Neighbor {
  int node = 0;
  double cost_s = 0.0;
};

class NeighborLists {
 public:
  // k nearest ends per node, never the node itself or its partner
  NeighborLists(const TransitionCost& cost, int k);

  int k() const { return k_; }
  // the neighbours of `node`, cheapest first
  const Neighbor* begin(int node) const { return &entries_[offsets_[node]]; }
  const Neighbor* end(int node) const { return &entries_[offsets_[node + 1]]; }
  // transition time between a and b: from a's list when there, else computed
  double cost(int a, int b) const;

 private:
  const TransitionCost& cost_;
  int k_;
  std::vector<int> offsets_;
  std::vector<Neighbor> entries_;
};

}  // namespace depotwin
