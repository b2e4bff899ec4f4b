#include "planners/ordering/christofides.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>
#include <vector>

#include <lemon/matching.h>
#include <lemon/smart_graph.h>

#include "core/error.hpp"
#include "planners/ordering/point_grid.hpp"

namespace depotwin {

namespace {

constexpr int kDenseLimit = 400;      // paths; above it the sparse candidate graphs
constexpr int kSparseNeighbors = 10;  // candidate edges per end in the sparse graphs
constexpr double kWeightScale = 1e6;  // matching weights in integer microseconds

struct WeightedEdge {
  double cost_s;
  int u, v;
  bool operator<(const WeightedEdge& o) const {
    return std::tie(cost_s, u, v) < std::tie(o.cost_s, o.u, o.v);
  }
};

class UnionFind {
 public:
  explicit UnionFind(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent_[std::max(a, b)] = std::min(a, b);
    return true;
  }

 private:
  std::vector<int> parent_;
};

// candidate transition edges: every pair of ends, or the neighbour lists
std::vector<WeightedEdge> candidate_edges(const TransitionCost& cost, const std::vector<int>& nodes,
                                          bool dense) {
  std::vector<WeightedEdge> edges;
  if (dense) {
    for (size_t i = 0; i < nodes.size(); ++i)
      for (size_t j = i + 1; j < nodes.size(); ++j)
        if (TransitionCost::partner(nodes[i]) != nodes[j])
          edges.push_back({cost(nodes[i], nodes[j]), nodes[i], nodes[j]});
    return edges;
  }
  // the k nearest among `nodes` only: a sub-problem's own neighbour lists
  std::vector<Vec3> points;
  for (int v : nodes) points.push_back(cost.position(v));
  const PointGrid grid(points);
  std::vector<std::pair<double, int>> near;
  for (size_t i = 0; i < nodes.size(); ++i) {
    near.clear();
    grid.search(
        points[i],
        [&](int j) {
          if (j != static_cast<int>(i) && TransitionCost::partner(nodes[i]) != nodes[j])
            near.push_back({(points[j] - points[i]).norm(), j});
        },
        [&](double margin_mm) {
          if (static_cast<int>(near.size()) < kSparseNeighbors) return false;
          std::nth_element(near.begin(), near.begin() + kSparseNeighbors - 1, near.end());
          return margin_mm > near[kSparseNeighbors - 1].first;
        });
    std::sort(near.begin(), near.end());
    for (size_t k = 0; k < near.size() && k < static_cast<size_t>(kSparseNeighbors); ++k) {
      const int a = nodes[i], b = nodes[near[k].second];
      edges.push_back({cost(a, b), std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end(),
                          [](const WeightedEdge& x, const WeightedEdge& y) {
                            return x.u == y.u && x.v == y.v;
                          }),
              edges.end());
  return edges;
}

// step 1: Kruskal from the forest; adds the nearest cross-component edges when the
// sparse candidates leave the tree disconnected
std::vector<WeightedEdge> spanning_tree(const TransitionCost& cost, bool dense) {
  const int n = cost.node_count();
  UnionFind components(n);
  for (int v = 0; v < n; v += 2) components.unite(v, v + 1);
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  std::vector<WeightedEdge> edges = candidate_edges(cost, all, dense);
  std::vector<WeightedEdge> tree;
  int missing = n / 2 - 1;  // N + 1 forest components need N tree edges
  while (true) {
    std::sort(edges.begin(), edges.end());
    for (const WeightedEdge& e : edges)
      if (components.unite(e.u, e.v)) tree.push_back(e), --missing;
    if (missing == 0) return tree;
    // every end outside the largest component proposes its nearest foreign end
    std::vector<int> size(n, 0);
    for (int v = 0; v < n; ++v) ++size[components.find(v)];
    const int largest = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
    edges.clear();
    for (int v = 0; v < n; ++v) {
      const int own = components.find(v);
      if (own == largest) continue;
      double best_s = std::numeric_limits<double>::infinity();
      int best = -1;
      for (int u = 0; u < n; ++u) {
        if (components.find(u) == own || cost.bound(v, u) >= best_s) continue;
        const double time_s = cost(v, u);
        if (time_s < best_s) best_s = time_s, best = u;
      }
      edges.push_back({best_s, std::min(v, best), std::max(v, best)});
    }
  }
}

// step 2: minimum-weight perfect matching of `odd` (LEMON, as a maximum-weight matching
// with weights W - cost so that the most edges win first), then a greedy pairing of
// anything a sparse candidate graph left out
std::vector<WeightedEdge> odd_matching(const TransitionCost& cost, const std::vector<int>& odd,
                                       bool dense) {
  const std::vector<WeightedEdge> edges = candidate_edges(cost, odd, dense);
  std::vector<int> index_of(cost.node_count(), -1);
  for (size_t i = 0; i < odd.size(); ++i) index_of[odd[i]] = static_cast<int>(i);

  using Graph = lemon::SmartGraph;
  Graph graph;
  std::vector<Graph::Node> node(odd.size());
  for (auto& x : node) x = graph.addNode();
  Graph::EdgeMap<long long> weight(graph);
  long long max_cost = 0;
  for (const WeightedEdge& e : edges)
    max_cost = std::max(max_cost, std::llround(e.cost_s * kWeightScale));
  const long long big = (max_cost + 1) * (static_cast<long long>(odd.size()) / 2 + 1);
  for (const WeightedEdge& e : edges) {
    const Graph::Edge edge = graph.addEdge(node[index_of[e.u]], node[index_of[e.v]]);
    weight[edge] = big - std::llround(e.cost_s * kWeightScale);
  }
  lemon::MaxWeightedMatching<Graph, Graph::EdgeMap<long long>> matching(graph, weight);
  matching.run();

  std::vector<WeightedEdge> matched;
  std::vector<int> leftover;
  for (size_t i = 0; i < odd.size(); ++i) {
    const Graph::Node mate = matching.mate(node[i]);
    if (mate == lemon::INVALID) {
      leftover.push_back(odd[i]);
      continue;
    }
    const int j = graph.id(mate);
    if (static_cast<int>(i) < j) matched.push_back({cost(odd[i], odd[j]), odd[i], odd[j]});
  }
  // greedy: each leftover end with its cheapest leftover partner
  std::vector<bool> used(leftover.size(), false);
  for (size_t i = 0; i < leftover.size(); ++i) {
    if (used[i]) continue;
    size_t best = i;
    double best_s = std::numeric_limits<double>::infinity();
    for (size_t j = i + 1; j < leftover.size(); ++j) {
      if (used[j]) continue;
      const double time_s = cost(leftover[i], leftover[j]);
      if (time_s < best_s) best_s = time_s, best = j;
    }
    if (best == i) throw InternalError("christofides: odd number of odd-degree ends (bug)");
    used[i] = used[best] = true;
    matched.push_back({best_s, leftover[i], leftover[best]});
  }
  return matched;
}

}  // namespace

OrderResult christofides_order(const TransitionCost& cost) {
  const int n = cost.node_count();
  const bool dense = cost.path_count() <= kDenseLimit;
  if (cost.path_count() == 0) return {};

  // the multigraph: partner edges first (ids 0 .. N, edge k joins 2k and 2k + 1), then
  // the tree and the matching
  std::vector<std::pair<int, int>> edges;
  for (int v = 0; v < n; v += 2) edges.push_back({v, v + 1});
  std::vector<int> degree(n, 1);
  for (const WeightedEdge& e : spanning_tree(cost, dense)) {
    edges.push_back({e.u, e.v});
    ++degree[e.u], ++degree[e.v];
  }
  std::vector<int> odd;
  for (int v = 0; v < n; ++v)
    if (degree[v] % 2 == 1) odd.push_back(v);
  for (const WeightedEdge& e : odd_matching(cost, odd, dense)) edges.push_back({e.u, e.v});

  // step 3: Euler circuit from the start (Hierholzer, iterative)
  std::vector<std::vector<int>> incident(n);
  for (int id = 0; id < static_cast<int>(edges.size()); ++id) {
    incident[edges[id].first].push_back(id);
    incident[edges[id].second].push_back(id);
  }
  std::vector<size_t> next_incident(n, 0);
  std::vector<bool> used(edges.size(), false);
  std::vector<std::pair<int, int>> stack{
      {cost.start_node(), -1}};              // (node, edge used to get there)
  std::vector<std::pair<int, int>> circuit;  // reversed circuit
  while (!stack.empty()) {
    const int v = stack.back().first;
    size_t& k = next_incident[v];
    while (k < incident[v].size() && used[incident[v][k]]) ++k;
    if (k == incident[v].size()) {
      circuit.push_back(stack.back());
      stack.pop_back();
      continue;
    }
    const int id = incident[v][k];
    used[id] = true;
    stack.push_back({edges[id].first == v ? edges[id].second : edges[id].first, id});
  }
  if (circuit.size() != edges.size() + 1)
    throw InternalError("christofides: the multigraph is not connected (bug)");
  std::reverse(circuit.begin(), circuit.end());

  // cut at the virtual start-end edge: walk the circuit from just after it
  const int virtual_edge = cost.start_node() / 2;
  const int m = static_cast<int>(edges.size());
  int cut = 1;
  while (circuit[cut].second != virtual_edge) ++cut;
  std::vector<std::pair<int, int>> path;  // (from, to) per edge, from the start to the end
  for (int s = 1; s < m; ++s) {
    const int k = (cut + s - 1) % m + 1;  // circuit entries 1..m hold the edges
    const int prev = (k - 2 + m) % m + 1;
    path.push_back({circuit[prev].first, circuit[k].first});
  }
  if (path.front().first != cost.start_node()) {
    std::reverse(path.begin(), path.end());
    for (auto& [from, to] : path) std::swap(from, to);
  }

  // step 4: shortcuts, print each path in the direction the Euler path crosses it
  OrderResult result;
  std::vector<bool> printed(cost.path_count(), false);
  for (const auto& [from, to] : path) {
    if (TransitionCost::partner(from) != to || from / 2 >= cost.path_count()) continue;
    if (printed[from / 2]) continue;  // a doubled partner edge from the greedy pairing
    printed[from / 2] = true;
    result.order.push_back(from / 2);
    result.reversed.push_back(from % 2 == 1);
  }
  if (static_cast<int>(result.order.size()) != cost.path_count())
    throw InternalError("christofides: the Euler path misses a print path (bug)");
  return result;
}

}  // namespace depotwin
