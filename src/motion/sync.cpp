#include "motion/sync.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "motion/jerk.hpp"

namespace depotwin {

FeasibleDurations axis_feasible_durations(const AxisMove& axis) {
  if (axis.j_max > 0.0)
    return jerk_feasible_durations(axis.boundary, axis.v_max, axis.a_max, axis.j_max);
  return feasible_durations(axis.boundary, axis.v_max, axis.a_max);
}

AxisProfile axis_fixed_time_move(const AxisMove& axis, double duration_s) {
  if (axis.j_max > 0.0)
    return jerk_fixed_time_move(axis.boundary, duration_s, axis.v_max, axis.a_max, axis.j_max);
  return fixed_time_move(axis.boundary, duration_s, axis.v_max, axis.a_max);
}

double common_feasible_duration(const std::vector<FeasibleDurations>& sets, double min_duration_s) {
  // raise the candidate until every set accepts it; each set has at most one gap, so this
  // settles after a few rounds
  double t = std::max(0.0, min_duration_s);
  for (int round = 0; round < 64; ++round) {
    double next = t;
    for (const FeasibleDurations& set : sets) next = std::max(next, set.earliest_at_least(next));
    if (next == t) return t;
    t = next;
  }
  throw InternalError("synchronised move: no common duration found");
}

double synchronized_duration(const std::vector<AxisMove>& axes, double min_duration_s) {
  std::vector<FeasibleDurations> sets;
  sets.reserve(axes.size());
  for (const AxisMove& axis : axes) sets.push_back(axis_feasible_durations(axis));
  return common_feasible_duration(sets, min_duration_s);
}

SynchronizedMove synchronized_move(const std::vector<AxisMove>& axes, double min_duration_s) {
  SynchronizedMove move;
  move.duration_s = synchronized_duration(axes, min_duration_s);
  move.axes.reserve(axes.size());
  for (const AxisMove& axis : axes)
    move.axes.push_back(axis_fixed_time_move(axis, move.duration_s));
  return move;
}

}  // namespace depotwin
