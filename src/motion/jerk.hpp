// Jerk-limited minimum-time moves: one axis from (q0, v0, a = 0) to (q1, v1, a = 0) under
// |v| <= v_max, |a| <= a_max, |jerk| <= j_max, and several axes synchronised to one duration.
//
// The profile family ("double S", Biagiotti & Melchiorri, Trajectory Planning for Automatic
// Machines and Robots, 2008, sec. 3.4, generalised to any v0, v1 and to overshoot):
//   S-curve v0 -> v_p, cruise at v_p for t_c >= 0, S-curve v_p -> v1,   |v_p| <= v_max,
// where an S-curve va -> vb (zero acceleration at both ends) is the fastest one:
//   tau(dv) = 2 sqrt(dv / j)           if dv <= a^2 / j   (triangular acceleration)
//           = dv / a + a / j            otherwise          (trapezoidal acceleration)
// and it moves (va + vb) / 2 * tau. For a duration T the admissible peaks are those with
// g(v_p) = tau(|v_p - v0|) + tau(|v_p - v1|) <= T, and the displacement
//   D(v_p, T) = F(v_p) + v_p (T - g(v_p)),   F(v_p) = (v0 + v_p)/2 tau0 + (v_p + v1)/2 tau1,
// is strictly increasing in v_p (dD/dv_p = t_c + sum tau_i/2 - x_i tau_i'/2 > 0). The
// displacements reachable in exactly T form one interval [D_min(T), D_max(T)] (the
// constraints are convex and the dynamics linear), whose ends are the family members with
// the lowest and the highest admissible peak: the shortest profile of all is a family
// member. tests/motion/test_jerk.cpp checks this against an exhaustive discrete-time search
// over every bang-zero-bang jerk sequence.
//
// D_max(T) first falls then rises with T (F is convex where v_p <= 0 and increasing where
// v_p >= 0), so the durations where it falls short of d form one interval, and likewise
// for D_min overshooting: the feasible durations are [T_v, inf) minus at most two blocked
// intervals, T_v = tau(|v1 - v0|) (see FeasibleDurations in mtt.hpp).
//
// Fixed durations: the peak v_p solving D(v_p, T) = d. Where T is too short to pass through
// the velocities half-way between v0 and v1 (g > T there), the admissible peaks split into
// two intervals and their displacements leave a gap; a d in that gap is reached by the
// convex blend (phase by phase, jerk lambda j1 + (1 - lambda) j2) of the two family members
// bounding the gap, which keeps every limit. Hence every duration of the reported feasible
// set has a profile.
#pragma once

#include <vector>

#include "core/profile.hpp"
#include "motion/lspb.hpp"
#include "motion/mtt.hpp"

namespace depotwin {

// tau(dv): duration of the fastest rest-acceleration to rest-acceleration velocity change
// |dv| (see the top of this file)
double s_curve_duration(double dv, double a_max, double j_max);

// Durations T >= 0 in which the axis can go from (q0, v0, 0) to (q1, v1, 0): at most two
// closed intervals, the last one ending at +inf. Every one of them has a profile
// (jerk_fixed_time_move). Throws InternalError for non-positive or non-finite limits or
// |v0|, |v1| > v_max.
FeasibleDurations jerk_feasible_durations(const AxisBoundary& b, double v_max, double a_max,
                                          double j_max);

// the time-optimal jerk-limited profile
AxisProfile jerk_min_time_move(const AxisBoundary& b, double v_max, double a_max, double j_max);

// a profile of exactly `duration_s`, which must be feasible (InternalError otherwise)
AxisProfile jerk_fixed_time_move(const AxisBoundary& b, double duration_s, double v_max,
                                 double a_max, double j_max);

}  // namespace depotwin
