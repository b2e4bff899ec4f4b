#include "planners/ordering/neighbor_lists.hpp"

#include <algorithm>
#include <queue>
#include <utility>

#include "planners/ordering/point_grid.hpp"

namespace depotwin {

NeighborLists::NeighborLists(const TransitionCost& cost, int k) : cost_(cost) {
  const int count = cost.node_count();
  k_ = std::max(0, std::min(k, count - 2));
  offsets_.assign(count + 1, 0);
  entries_.reserve(static_cast<size_t>(count) * k_);
  const PointGrid grid(cost.positions());
  // max-heap of (distance, node): the k nearest seen so far
  std::priority_queue<std::pair<double, int>> nearest;
  std::vector<Neighbor> found;
  for (int v = 0; v < count && k_ > 0; ++v) {
    const Vec3& p = cost.position(v);
    const int partner = TransitionCost::partner(v);
    grid.search(
        p,
        [&](int u) {
          if (u == v || u == partner) return;
          const double d = (cost.position(u) - p).norm();
          if (static_cast<int>(nearest.size()) < k_) {
            nearest.push({d, u});
          } else if (std::make_pair(d, u) < nearest.top()) {
            nearest.pop();
            nearest.push({d, u});
          }
        },
        [&](double margin_mm) {
          return static_cast<int>(nearest.size()) == k_ && margin_mm > nearest.top().first;
        });
    // exact transition times, cheapest first (ties by node for determinism)
    found.clear();
    for (; !nearest.empty(); nearest.pop())
      found.push_back({nearest.top().second, cost(v, nearest.top().second)});
    std::sort(found.begin(), found.end(), [](const Neighbor& a, const Neighbor& b) {
      return a.cost_s != b.cost_s ? a.cost_s < b.cost_s : a.node < b.node;
    });
    entries_.insert(entries_.end(), found.begin(), found.end());
    offsets_[v + 1] = static_cast<int>(entries_.size());
  }
  if (k_ == 0) std::fill(offsets_.begin(), offsets_.end(), 0);
  entries_.push_back({});  // keeps &entries_[offset] valid for empty lists
}

double NeighborLists::cost(int a, int b) const {
  for (const Neighbor* n = begin(a); n != end(a); ++n)
    if (n->node == b) return n->cost_s;
  return cost_(a, b);
}

}  // namespace depotwin
