#include "planners/ordering/nearest_neighbor.hpp"

#include <limits>
#include <vector>

#include "planners/ordering/point_grid.hpp"

namespace depotwin {

OrderResult nearest_neighbor_order(const TransitionCost& cost) {
  const int path_count = cost.path_count();
  // only path ends are candidates; the start and end nodes leave the grid at once
  PointGrid grid(cost.positions());
  grid.remove(cost.start_node());
  grid.remove(cost.end_node());

  OrderResult result;
  result.order.reserve(path_count);
  result.reversed.reserve(path_count);
  int current = cost.start_node();
  for (int step = 0; step < path_count; ++step) {
    // the cheapest entry (ties: the lower node number, so the order is reproducible)
    double best_s = std::numeric_limits<double>::infinity();
    int best_node = -1;
    grid.search(
        cost.position(current),
        [&](int node) {
          if (cost.bound(current, node) > best_s) return;
          const double time_s = cost(current, node);
          if (time_s < best_s || (time_s == best_s && node < best_node))
            best_s = time_s, best_node = node;
        },
        [&](double margin_mm) { return cost.bound_for_distance(margin_mm) > best_s; });

    const int path = best_node / 2;
    const bool reversed = best_node % 2 == 1;
    result.order.push_back(path);
    result.reversed.push_back(reversed);
    grid.remove(2 * path);
    grid.remove(2 * path + 1);
    current = TransitionCost::exit_node(path, reversed);
  }
  return result;
}

}  // namespace depotwin
