// Exact reference values for small print-ordering instances, by plain enumeration
// (independent of the code under test).
#pragma once

#include <algorithm>
#include <limits>
#include <numeric>
#include <vector>

#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin::testing {

// every pair's transition time, once
inline std::vector<double> cost_matrix(const TransitionCost& cost) {
  const int n = cost.node_count();
  std::vector<double> matrix(n * n, 0.0);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      if (a != b) matrix[a * n + b] = cost(a, b);
  return matrix;
}

// the best order over all N! orders and 2^N directions (N <= 7)
inline double brute_force_optimum(const TransitionCost& cost) {
  const int paths = cost.path_count(), n = cost.node_count();
  const std::vector<double> c = cost_matrix(cost);
  std::vector<int> order(paths);
  std::iota(order.begin(), order.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    for (int directions = 0; directions < (1 << paths); ++directions) {
      double total = 0.0;
      int at = cost.start_node();
      for (int k = 0; k < paths; ++k) {
        const bool reversed = (directions >> k) & 1;
        total += c[at * n + TransitionCost::entry_node(order[k], reversed)];
        at = TransitionCost::exit_node(order[k], reversed);
      }
      best = std::min(best, total + c[at * n + cost.end_node()]);
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return cost.print_time_s() + best;
}

// print time + minimum perfect matching of all nodes, partner pairs excluded, by
// dynamic programming over subsets (node_count <= 20)
inline double brute_force_matching_bound(const TransitionCost& cost) {
  const int n = cost.node_count();
  const std::vector<double> c = cost_matrix(cost);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> best(1u << n, inf);
  best[0] = 0.0;
  for (unsigned mask = 1; mask < (1u << n); ++mask) {
    if (__builtin_popcount(mask) % 2 == 1) continue;
    const int low = __builtin_ctz(mask);
    for (int other = low + 1; other < n; ++other) {
      if (!((mask >> other) & 1) || other == TransitionCost::partner(low)) continue;
      const unsigned rest = mask & ~(1u << low) & ~(1u << other);
      best[mask] = std::min(best[mask], best[rest] + c[low * n + other]);
    }
  }
  return cost.print_time_s() + best[(1u << n) - 1];
}

inline OrderSpec spec(const std::string& method, const std::string& refine = "",
                      const std::string& cost_model = "machine", std::uint64_t seed = 1) {
  OrderSpec out;
  out.method = method, out.refine = refine, out.cost_model = cost_model, out.seed = seed;
  return out;
}

inline Toolpath paper_instance(int count, std::uint64_t seed) {
  RandomSegmentsSpec spec;
  spec.count = count;
  spec.seed = seed;
  return make_random_segments(spec);
}

}  // namespace depotwin::testing
