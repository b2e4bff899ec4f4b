#include "planners/ordering/local_search.hpp"

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace depotwin {

namespace {

constexpr double kMinGain_s = 1e-9;
constexpr int kMaxChainNodes = 6;  // or_opt moves chains of at most 3 paths (6 ends)
// nodes searched between two looks at the interrupt flag
constexpr long kInterruptCheckNodes = 256;

// The cycle over the path ends as an array with positions, so a stretch can be
// reversed in place (the shorter side of the cycle is reversed).
class Tour {
 public:
  explicit Tour(const std::vector<int>& cycle) : node_at_(cycle), pos_of_(cycle.size()) {
    for (int i = 0; i < size(); ++i) pos_of_[node_at_[i]] = i;
  }

  int size() const { return static_cast<int>(node_at_.size()); }
  int pos(int v) const { return pos_of_[v]; }
  int next(int v) const { return node_at_[pos_of_[v] + 1 == size() ? 0 : pos_of_[v] + 1]; }
  int prev(int v) const { return node_at_[pos_of_[v] == 0 ? size() - 1 : pos_of_[v] - 1]; }
  // the tour neighbour joined to v by its transition (the other one is its partner)
  int across(int v) const {
    const int n = next(v);
    return n == TransitionCost::partner(v) ? prev(v) : n;
  }
  // nodes on the forward path a .. b, both included
  int forward_count(int a, int b) const { return (pos(b) - pos(a) + size()) % size() + 1; }

  // Replace the tour edges (a, b) and (c, d) by (a, c) and (b, d), where one reading
  // direction of the cycle passes a, b, ..., c, d: the 2-opt move, orientation-free.
  void two_opt_move(int a, int b, int c, int d) {
    (void)d;
    if (next(a) == b)
      reverse_path(b, c);
    else
      reverse_path(c, b);
  }

 private:
  // reverse the forward path from .. to (or, equivalently on a cycle, the rest)
  void reverse_path(int from, int to) {
    const int n = size();
    int i = pos(from), j = pos(to);
    int length = (j - i + n) % n + 1;
    if (2 * length > n) {
      std::swap(i, j);
      i = (i + 1) % n;
      j = (j - 1 + n) % n;
      length = n - length;
    }
    for (int s = 0; s < length / 2; ++s) {
      std::swap(node_at_[i], node_at_[j]);
      pos_of_[node_at_[i]] = i;
      pos_of_[node_at_[j]] = j;
      i = i + 1 == n ? 0 : i + 1;
      j = j == 0 ? n - 1 : j - 1;
    }
  }

  std::vector<int> node_at_, pos_of_;
};

// A 3-opt move seen from the current tour: removing three transitions leaves the
// stretches A = a1..a2, B = b1..b2 and C = c1..c0 (forward); the reconnection is one
// of the four that changes all three edges.
struct ThreeOptMove {
  enum Pattern { kBA, kBAr, kBrA, kArBr };  // new cycle C B A, C B A', C B' A, C A' B'
  int c0, a1, a2, b1, b2, c1;
  Pattern pattern;
};

using Edge = std::pair<int, int>;
Edge undirected(int a, int b) {
  return a < b ? Edge{a, b} : Edge{b, a};
}

// Which reconnection removing (t1,t2), (t3,t4), (t5,t6) and adding (t2,t3), (t4,t5),
// (t6,t1) is; false when the result is not a single cycle.
bool classify(const Tour& tour, const std::array<int, 6>& t, ThreeOptMove& move) {
  const int n = tour.size();
  // orient each removed edge forward (left -> right) and sort them along the tour
  std::array<Edge, 3> removed;
  for (int e = 0; e < 3; ++e) {
    const int x = t[2 * e], y = t[2 * e + 1];
    removed[e] = tour.next(x) == y ? Edge{x, y} : Edge{y, x};
  }
  const int origin = tour.pos(removed[0].first);
  auto offset = [&](const Edge& e) { return (tour.pos(e.first) - origin + n) % n; };
  if (offset(removed[2]) < offset(removed[1])) std::swap(removed[1], removed[2]);
  move.c0 = removed[0].first, move.a1 = removed[0].second;
  move.a2 = removed[1].first, move.b1 = removed[1].second;
  move.b2 = removed[2].first, move.c1 = removed[2].second;

  std::array<Edge, 3> added{undirected(t[1], t[2]), undirected(t[3], t[4]), undirected(t[5], t[0])};
  std::sort(added.begin(), added.end());
  auto matches = [&](Edge e1, Edge e2, Edge e3) {
    std::array<Edge, 3> pattern{undirected(e1.first, e1.second), undirected(e2.first, e2.second),
                                undirected(e3.first, e3.second)};
    std::sort(pattern.begin(), pattern.end());
    return pattern == added;
  };
  const ThreeOptMove& m = move;
  if (matches({m.c0, m.b1}, {m.b2, m.a1}, {m.a2, m.c1}))
    return move.pattern = ThreeOptMove::kBA, true;
  if (matches({m.c0, m.b1}, {m.b2, m.a2}, {m.a1, m.c1}))
    return move.pattern = ThreeOptMove::kBAr, true;
  if (matches({m.c0, m.b2}, {m.b1, m.a1}, {m.a2, m.c1}))
    return move.pattern = ThreeOptMove::kBrA, true;
  if (matches({m.c0, m.a2}, {m.a1, m.b2}, {m.b1, m.c1}))
    return move.pattern = ThreeOptMove::kArBr, true;
  return false;
}

// or_opt accepts a 3-opt move only when it relocates one short chain (possibly reversed)
bool moves_short_chain(const Tour& tour, const ThreeOptMove& m) {
  const int a = tour.forward_count(m.a1, m.a2), b = tour.forward_count(m.b1, m.b2);
  const int c = tour.size() - a - b;
  switch (m.pattern) {
    case ThreeOptMove::kBA:
      return std::min({a, b, c}) <= kMaxChainNodes;  // any one moves
    case ThreeOptMove::kBAr:
      return a <= kMaxChainNodes;  // A moves, reversed
    case ThreeOptMove::kBrA:
      return b <= kMaxChainNodes;  // B moves, reversed
    case ThreeOptMove::kArBr:
      return c <= kMaxChainNodes;  // C moves, reversed
  }
  return false;
}

// every 3-opt reconnection as two or three 2-opt moves
void apply(Tour& tour, const ThreeOptMove& m) {
  switch (m.pattern) {
    case ThreeOptMove::kBA:  // c0 a1..a2 b1..b2 c1 -> c0 b2..b1 a2..a1 c1 -> C B A
      tour.two_opt_move(m.c0, m.a1, m.b2, m.c1);
      tour.two_opt_move(m.c0, m.b2, m.b1, m.a2);
      tour.two_opt_move(m.b2, m.a2, m.a1, m.c1);
      break;
    case ThreeOptMove::kBAr:
      tour.two_opt_move(m.c0, m.a1, m.b2, m.c1);
      tour.two_opt_move(m.c0, m.b2, m.b1, m.a2);
      break;
    case ThreeOptMove::kBrA:
      tour.two_opt_move(m.c0, m.a1, m.b2, m.c1);
      tour.two_opt_move(m.b1, m.a2, m.a1, m.c1);
      break;
    case ThreeOptMove::kArBr:
      tour.two_opt_move(m.c0, m.a1, m.a2, m.b1);
      tour.two_opt_move(m.a1, m.b1, m.b2, m.c1);
      break;
  }
}

class LocalSearch {
 public:
  LocalSearch(Tour& tour, const NeighborLists& neighbors, Refinement refinement)
      : tour_(tour), neighbors_(neighbors), refinement_(refinement) {}

  LocalSearchStats run() {
    // don't-look bits: only nodes next to a recent change are searched again
    const int n = tour_.size();
    queue_.assign(n, 0);
    queued_.assign(n, false);
    for (int v = 0; v < n; ++v) push(v);
    for (long searched = 0; count_ > 0; ++searched) {
      // a signal asked to stop (core/interrupt.hpp)
      if (searched % kInterruptCheckNodes == 0) throw_if_interrupted();
      const int t1 = queue_[head_];
      head_ = (head_ + 1) % n, --count_;
      queued_[t1] = false;
      if (improve_from(t1)) push(t1);
    }
    return stats_;
  }

 private:
  struct Best {
    double gain_s = kMinGain_s;
    int depth = 0;
    std::array<int, 6> t{};
    ThreeOptMove three_opt{};
  };

  void push(int v) {
    if (queued_[v]) return;
    queued_[v] = true;
    queue_[(head_ + count_) % tour_.size()] = v;
    ++count_;
  }

  // the best improving move that removes t1's transition; applied if found
  bool improve_from(int t1) {
    const int t2 = tour_.across(t1);
    const double g1 = neighbors_.cost(t1, t2);
    Best best;
    for (const Neighbor* n3 = neighbors_.begin(t2); n3 != neighbors_.end(t2); ++n3) {
      // gain criterion: each partial sum must stay positive (lists are sorted)
      if (g1 - n3->cost_s <= kMinGain_s) break;
      const int t3 = n3->node;
      if (t3 == t1) continue;
      const int t4 = tour_.across(t3);
      const double g2 = g1 - n3->cost_s + neighbors_.cost(t3, t4);

      // close with (t4, t1): a 2-opt move when both edges run the same way
      if ((tour_.next(t1) == t2) == (tour_.next(t4) == t3)) {
        const double gain = g2 - neighbors_.cost(t4, t1);
        if (gain > best.gain_s && two_opt_allowed(t1, t2, t4)) best = {gain, 2, {t1, t2, t3, t4}};
      }
      if (refinement_ == Refinement::two_opt) continue;

      // or go one level deeper: add (t4, t5), remove (t5, t6), close with (t6, t1)
      for (const Neighbor* n5 = neighbors_.begin(t4); n5 != neighbors_.end(t4); ++n5) {
        if (g2 - n5->cost_s <= kMinGain_s) break;
        const int t5 = n5->node;
        if (t5 == t3 || t5 == t1 || t5 == t2) continue;
        const int t6 = tour_.across(t5);
        const double gain = g2 - n5->cost_s + neighbors_.cost(t5, t6) - neighbors_.cost(t6, t1);
        if (gain <= best.gain_s) continue;
        ThreeOptMove move;
        if (!classify(tour_, {t1, t2, t3, t4, t5, t6}, move)) continue;
        if (refinement_ == Refinement::or_opt && !moves_short_chain(tour_, move)) continue;
        best = {gain, 3, {t1, t2, t3, t4, t5, t6}, move};
      }
    }
    if (best.depth == 0) return false;

    if (best.depth == 2)
      tour_.two_opt_move(best.t[0], best.t[1], best.t[3], best.t[2]);
    else
      apply(tour_, best.three_opt);
    for (int k = 0; k < 2 * best.depth; ++k) push(best.t[k]);
    ++stats_.moves;
    stats_.gain_s += best.gain_s;
    return true;
  }

  // or_opt flips at most a short chain in place; the other searches take any 2-opt move
  bool two_opt_allowed(int t1, int t2, int t4) const {
    if (refinement_ != Refinement::or_opt) return true;
    const int reversed =
        tour_.next(t1) == t2 ? tour_.forward_count(t2, t4) : tour_.forward_count(t4, t2);
    return std::min(reversed, tour_.size() - reversed) <= kMaxChainNodes;
  }

  Tour& tour_;
  const NeighborLists& neighbors_;
  Refinement refinement_;
  std::vector<int> queue_;  // circular FIFO of nodes whose don't-look bit is off
  std::vector<bool> queued_;
  int head_ = 0, count_ = 0;
  LocalSearchStats stats_;
};

}  // namespace

Refinement parse_refinement(const std::string& name) {
  if (name == "two_opt") return Refinement::two_opt;
  if (name == "three_opt") return Refinement::three_opt;
  if (name == "or_opt") return Refinement::or_opt;
  throw InputError("order.refine",
                   "unknown refinement '" + name + "' (expected two_opt, three_opt or or_opt)");
}

LocalSearchStats refine_order(OrderResult& order, const TransitionCost& cost,
                              const NeighborLists& neighbors, Refinement refinement) {
  Tour tour(order_nodes(cost, order));
  const LocalSearchStats stats = LocalSearch(tour, neighbors, refinement).run();

  // read the cycle back from the start, away from the virtual edge to the end
  order.order.clear();
  order.reversed.clear();
  for (int entry = tour.across(cost.start_node()); entry != cost.end_node();
       entry = tour.across(TransitionCost::partner(entry))) {
    order.order.push_back(entry / 2);
    order.reversed.push_back(entry % 2 == 1);
  }
  return stats;
}

}  // namespace depotwin
