#include "motion/sync.hpp"

#include <cmath>

#include "core/error.hpp"
#include "motion/mtt.hpp"

namespace depotwin {

double synchronized_duration(const std::vector<AxisMove>& axes, double min_duration_s) {
  std::vector<FeasibleDurations> sets;
  sets.reserve(axes.size());
  for (const AxisMove& axis : axes)
    sets.push_back(feasible_durations(axis.boundary, axis.v_max, axis.a_max));
  // raise the candidate until every axis accepts it; each axis has at most one gap,
  // so this settles after a few rounds
  double t = std::max(0.0, min_duration_s);
  for (int round = 0; round < 64; ++round) {
    double next = t;
    for (const FeasibleDurations& set : sets) next = std::max(next, set.earliest_at_least(next));
    if (next == t) return t;
    t = next;
  }
  throw InternalError("synchronised move: no common duration found");
}

SynchronizedMove synchronized_move(const std::vector<AxisMove>& axes, double min_duration_s) {
  SynchronizedMove move;
  move.duration_s = synchronized_duration(axes, min_duration_s);
  for (const AxisMove& axis : axes)
    move.axes.push_back(fixed_time_move(axis.boundary, move.duration_s, axis.v_max, axis.a_max));
  return move;
}

}  // namespace depotwin
