// Multi-axis minimum-time moves: every axis starts and ends together, eq. (39) of Thompson &
// Yoon, generalised: the common duration is the smallest one that is feasible for every axis
// (not always the slowest axis' minimum, because an axis can have a blocked range of
// durations). An axis with a jerk limit moves by jerk-limited double-S profiles (jerk.hpp),
// one without by bang-coast-bang LSPB (mtt.hpp).
#pragma once

#include <vector>

#include "core/profile.hpp"
#include "motion/lspb.hpp"
#include "motion/mtt.hpp"

namespace depotwin {

struct AxisMove {
  AxisBoundary boundary;
  double v_max = 0.0;
  double a_max = 0.0;
  double j_max = 0.0;  // 0: no jerk limit (the acceleration may step)
};

struct SynchronizedMove {
  double duration_s = 0.0;
  std::vector<AxisProfile> axes;
};

// the durations in which one axis can make its move (jerk-limited when j_max > 0)
FeasibleDurations axis_feasible_durations(const AxisMove& axis);
// one axis' move of exactly `duration_s` (feasible: see axis_feasible_durations)
AxisProfile axis_fixed_time_move(const AxisMove& axis, double duration_s);

// smallest duration >= min_duration_s in every one of the feasible sets
double common_feasible_duration(const std::vector<FeasibleDurations>& sets,
                                double min_duration_s = 0.0);

// smallest duration >= min_duration_s feasible for every axis
double synchronized_duration(const std::vector<AxisMove>& axes, double min_duration_s = 0.0);

// every axis re-planned over the common duration (LSPB, eqs. 11-16, or double-S)
SynchronizedMove synchronized_move(const std::vector<AxisMove>& axes, double min_duration_s = 0.0);

}  // namespace depotwin
