#include "planners/ordering/lower_bound.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>
#include <vector>

#include <lemon/matching.h>
#include <lemon/smart_graph.h>

#include "core/error.hpp"
#include "planners/ordering/neighbor_lists.hpp"
#include "planners/ordering/point_grid.hpp"

namespace depotwin {

namespace {

using Graph = lemon::SmartGraph;
using Weights = Graph::EdgeMap<long long>;
using Matching = lemon::MaxWeightedPerfectMatching<Graph, Weights>;

// integer weights make LEMON exact (its duals come scaled by Matching::dualScale = 4);
// costs are rounded down so the bound stays valid
constexpr double kWeightScale = 1e6;  // microseconds
constexpr int kFirstNeighbors = 10;

long long weight_us(double time_s) {
  return static_cast<long long>(std::floor(time_s * kWeightScale));
}

}  // namespace

double matching_lower_bound(const TransitionCost& cost, MatchingBoundStats* stats) {
  const int n = cost.node_count();
  if (cost.path_count() == 0) return cost(cost.start_node(), cost.end_node());
  MatchingBoundStats local;
  MatchingBoundStats& counts = stats ? *stats : local;
  counts = {};

  // the first graph: the neighbour lists, both ways; more neighbours if it has no
  // perfect matching
  Graph graph;
  graph.reserveNode(n);
  for (int v = 0; v < n; ++v) graph.addNode();
  Weights weight(graph);
  std::unordered_set<long long> in_graph;
  auto pair_key = [n](int u, int v) {
    return static_cast<long long>(std::min(u, v)) * n + std::max(u, v);
  };
  auto add_pair = [&](int u, int v, double cost_s) {
    if (!in_graph.insert(pair_key(u, v)).second) return false;
    weight[graph.addEdge(graph.nodeFromId(u), graph.nodeFromId(v))] = -weight_us(cost_s);
    return true;
  };
  const PointGrid grid(cost.positions());
  for (int neighbors = kFirstNeighbors;; neighbors *= 2) {
    const NeighborLists lists(cost, neighbors);
    for (int v = 0; v < n; ++v)
      for (const Neighbor* u = lists.begin(v); u != lists.end(v); ++u)
        add_pair(v, u->node, u->cost_s);

    // pricing rounds: solve, then look for pairs the dual violates
    bool perfect = false;
    for (;;) {
      Matching matching(graph, weight);
      ++counts.rounds;
      if (!(perfect = matching.run())) break;
      // node potentials y of the optimal dual (scaled by dualScale); the blossom values
      // z are >= 0, so a pair outside the graph with y_u + y_v >= -dualScale * w(u, v)
      // satisfies its dual constraint whatever blossoms hold it
      std::vector<long long> y(n);
      for (int v = 0; v < n; ++v) y[v] = matching.nodeValue(graph.nodeFromId(v));
      auto slack = [&](int u, int v, double cost_lower_bound_s) {
        return Matching::dualScale * weight_us(cost_lower_bound_s) + y[u] + y[v];
      };

      // ends with very low y widen every search: test those against all others, and let
      // the ring searches assume y >= y_floor for the rest
      std::vector<long long> sorted = y;
      std::nth_element(sorted.begin(), sorted.begin() + n / 1000, sorted.end());
      const long long y_floor = sorted[n / 1000];

      std::vector<std::pair<int, int>> violated;
      auto test = [&](int u, int v) {
        if (v == u || v == TransitionCost::partner(u) || slack(u, v, cost.bound(u, v)) >= 0) return;
        if (slack(u, v, cost(u, v)) < 0 && !in_graph.count(pair_key(u, v)))
          violated.push_back({u, v});
      };
      for (int u = 0; u < n; ++u) {
        if (y[u] < y_floor) {
          for (int v = 0; v < n; ++v) test(u, v);
          continue;
        }
        grid.search(
            cost.position(u),
            [&](int v) {
              if (y[v] >= y_floor) test(u, v);
            },
            [&](double margin_mm) {
              return Matching::dualScale * weight_us(cost.bound_for_distance(margin_mm)) + y[u] +
                         y_floor >=
                     0;
            });
      }
      if (violated.empty()) {
        counts.graph_edges = static_cast<long>(in_graph.size());
        return cost.print_time_s() - static_cast<double>(matching.matchingWeight()) / kWeightScale;
      }
      for (const auto& [u, v] : violated) counts.added_pairs += add_pair(u, v, cost(u, v)) ? 1 : 0;
    }
    if (!perfect && neighbors >= n - 2)
      throw InternalError("lower bound: no perfect matching (bug)");
  }
}

}  // namespace depotwin
