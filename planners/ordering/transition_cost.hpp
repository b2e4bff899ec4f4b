// Transition times between print-path ends, the cost every sequencer minimises
// (Ganganath et al., papers/004, Sec. II-III).
//
// The ends are the nodes of a graph: print path i has its front at node 2i and its
// back at node 2i + 1; the job start is node 2N and the job end node 2N + 1. Every
// node has one partner, node ^ 1: the other end of its path, or start <-> end (the
// paper's virtual edge). A print order is then a Hamiltonian cycle that uses every
// partner edge; the other N + 1 edges are the transitions.
#pragma once

#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "planners/ordering/sequencer.hpp"

namespace depotwin {

enum class CostModel {
  machine,     // the synchronised per-axis minimum-time move (motion/sync.hpp)
  along_line,  // the paper's 1-D move along the straight line, direction changes free
};

// "machine" | "along_line"; throws InputError naming `order.cost_model` otherwise
CostModel parse_cost_model(const std::string& name);

class TransitionCost {
 public:
  // Throws InputError when a print path cannot be printed under the limits (speed above
  // v_max, fewer than two distinct points) or the limits are unusable.
  // (per path and per transition, the limits over their own box: TcpLimits)
  TransitionCost(const Toolpath& toolpath, const TcpLimits& limits, CostModel model);

  static int partner(int node) { return node ^ 1; }
  static int entry_node(int path, bool reversed) { return 2 * path + (reversed ? 1 : 0); }
  static int exit_node(int path, bool reversed) { return 2 * path + (reversed ? 0 : 1); }

  int path_count() const { return static_cast<int>(positions_.size() / 2) - 1; }
  int node_count() const { return static_cast<int>(positions_.size()); }
  int start_node() const { return node_count() - 2; }
  int end_node() const { return node_count() - 1; }
  CostModel model() const { return model_; }

  // time (s) of the transition leaving through end `from` at print velocity and entering
  // at end `to` at print velocity (start and end at rest). Symmetric: time reversal maps
  // the move from -> to onto to -> from.
  double operator()(int from, int to) const;

  // cheap lower bounds of operator(): from the nodes' positions, and for any two nodes
  // whose x-y Chebyshev distance is at least `distance_mm`
  double bound(int from, int to) const;
  double bound_for_distance(double distance_mm) const { return distance_mm / bound_speed_mm_s_; }

  const Vec3& position(int node) const { return positions_[node]; }
  // the print velocity leaving the path through this end (0 at the job's start and end)
  const Vec3& exit_velocity(int node) const { return exit_velocity_[node]; }
  const std::vector<Vec3>& positions() const { return positions_; }
  double print_time_s() const { return print_time_s_; }
  double print_length_mm() const { return print_length_mm_; }

  // print time plus every transition of the order (the sequencer's objective)
  double order_cost(const OrderResult& order) const;
  // straight-line length of the transitions of the order (mm), for the paper's "path length"
  double transition_length_mm(const OrderResult& order) const;

 private:
  double along_line_time(double distance_mm, double v0_mm_s, double v1_mm_s,
                         const MachineLimits& limits) const;
  // clamp roundoff in the exit velocities of one path's two ends; the first axis whose
  // limit the print speed really exceeds, or -1
  int clamp_exit_velocities(int front_node, const MachineLimits& limits, CostModel model);

  CostModel model_;
  TcpLimits tcp_limits_;
  std::vector<Vec3> positions_;
  std::vector<Vec3> exit_velocity_;  // leaving the path through this end (0 at start/end)
  std::vector<double> speed_mm_s_;   // print speed at this end (0 at start/end)
  double bound_speed_mm_s_ = 0.0;    // the fastest axis speed that enters bound_for_distance
  double print_time_s_ = 0.0;
  double print_length_mm_ = 0.0;
};

// the transition nodes of an order: start, entry 1, exit 1, ..., exit N, end
std::vector<int> order_nodes(const TransitionCost& cost, const OrderResult& order);

}  // namespace depotwin
