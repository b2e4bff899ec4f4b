// Multi-axis minimum-time moves: every axis starts and ends together, eq. (39)
// of Thompson & Yoon, generalised: the common duration is the smallest one that is
// feasible for every axis (not always the slowest axis' minimum, because an axis can
// have a blocked range of durations).
#pragma once

#include <vector>

#include "core/profile.hpp"
#include "motion/lspb.hpp"

namespace depotwin {

struct AxisMove {
  AxisBoundary boundary;
  double v_max = 0.0;
  double a_max = 0.0;
};

struct SynchronizedMove {
  double duration_s = 0.0;
  std::vector<AxisProfile> axes;
};

// smallest duration >= min_duration_s feasible for every axis
double synchronized_duration(const std::vector<AxisMove>& axes, double min_duration_s = 0.0);

// every axis re-planned over the common duration (LSPB, eqs. 11-16)
SynchronizedMove synchronized_move(const std::vector<AxisMove>& axes, double min_duration_s = 0.0);

}  // namespace depotwin
