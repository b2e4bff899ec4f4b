// Minimum-time one-axis moves under |v| <= v_max, |a| <= a_max, and the set of
// durations in which a move can be completed (needed to synchronise axes).
//
// Thompson & Yoon (papers/000) eqs. (19)-(38) fix the acceleration signs by
// sgn(q1 - q0) (eqs. 33-35) and their flowchart (Fig. 5) returns the first valid
// candidate, not the fastest. That is not time-optimal when v0 or v1 point against
// the displacement (the move may have to overshoot and come back, or the first
// candidate runs the wrong way round). min_time_move() is exact for every
// |v0|, |v1| <= v_max: it takes the earliest duration in which the displacement lies
// between the slowest and the fastest bang-coast-bang profile. mtt_paper_duration()
// keeps the paper's rule for comparison.
#pragma once

#include <utility>
#include <vector>

#include "core/profile.hpp"
#include "motion/lspb.hpp"

namespace depotwin {

// Durations T >= 0 in which an axis can go from (q0, v0) to (q1, v1) with bang-coast-bang
// acceleration of magnitude a_max and |v| <= v_max: a union of at most two closed
// intervals [t_min, a] u [b, inf). The gap (a, b) is the "blocked" range: e.g. d = 0,
// v0 = v1 = 3 mm/s, a = 30 mm/s^2 finishes only at T = 0 or T >= 0.4 s.
struct FeasibleDurations {
  std::vector<std::pair<double, double>> intervals;  // sorted, disjoint; last ends at +inf

  double t_min() const { return intervals.front().first; }
  bool contains(double t, double tolerance = 1e-12) const;
  // smallest feasible duration >= t
  double earliest_at_least(double t) const;
};

FeasibleDurations feasible_durations(const AxisBoundary& b, double v_max, double a_max);

// The time-optimal profile (exact for every boundary with |v0|, |v1| <= v_max).
AxisProfile min_time_move(const AxisBoundary& b, double v_max, double a_max);

// A profile of exactly `duration_s` (which must be feasible, see feasible_durations):
// the LSPB of eqs. (11)-(16) with |a| = a_max and |v_c| <= v_max. Throws InternalError
// if the duration is infeasible.
AxisProfile fixed_time_move(const AxisBoundary& b, double duration_s, double v_max, double a_max);

// The paper's own MTT, eqs. (19)-(38): a triangular profile (22)-(28) whose peak is
// clamped to v_max with the signs of (33)-(35). Returns its duration, or a negative
// number when its constraints (27)-(28) admit no solution. For comparison in tests.
double mtt_paper_duration(const AxisBoundary& b, double v_max, double a_max);

}  // namespace depotwin
