// A jerk-limited time law along a path (the conformal planner under a j_max): the TOPP-RA
// profile (path_parametrization.hpp) as a ceiling, and under it double-S moves in arc length
// between the ceiling's lowest points.
//
// TOPP-RA gives, at every grid point, the highest x = sdot^2 from which the path can still be
// followed within every speed and acceleration limit (TCP axes and joints). A TCP axis' jerk
// along the path is
//   j_k = p'_k sdddot + 3 p''_k sdot sddot + p'''_k sdot^3            (p' = dp/ds, ...)
// and the joints' accelerations q'_j sddot + q''_j sdot^2. The ceiling x_lim(s) is the TOPP-RA
// profile lowered where the curvature terms would take more than their share:
//   |p''_k| x <= kNormalAccelShare a_k,  |q''_j| x <= kNormalAccelShare a_j,
//   |p'''_k| x^(3/2) <= kCurvatureJerkShare kJerkShare j_k.
// Its local minima (rests, fine points, slow blends) become critical points where the law has
// zero path acceleration; between two of them the law is the time-optimal double-S move in s
// (motion/jerk.hpp) from the lower critical speed to the other, under scalar limits that hold
// along the whole stretch:
//   sddot <= A_m = min over the stretch of (a_k - |p''_k| x_lim) / |p'_k| (and the joints'),
//          lowered until 3 |p''_k| sqrt(x_lim) A_m <= kCrossJerkShare kJerkShare j_k,
//   sdddot <= J_m = min of (kJerkShare j_k - 3 |p''_k| sqrt(x_lim) A_m - |p'''_k| x_lim^(3/2))
//                  / |p'_k|,
// so every term stays within its share and the sum within each limit. The critical speeds
// are lowered until every stretch can hold its S-curve; where an S-curve rises above the
// ceiling inside its stretch, the point it crosses becomes a critical point too, and again.
// p''' is the grid's second derivatives differenced per interval. The law is sampled at the
// period like TOPP-RA's (a late start from rest), and the samples' cubic interpolation checked
// against the TCP limits: its acceleration at both ends of every period, and its jerk as the
// 1 ms finite differences see it (sampled_jerk.hpp); where one is exceeded the shares are
// lowered by kJerkRepairScale around it (and the ceiling by the speed's excess squared where a
// speed was: between grid points an S-curve can rise a little above a ceiling bound by v_max)
// and the law planned again (at most kJerkRepairRounds).
// Joint jerk is not planned: the machines that take a joint j_max (xy_stage, cartesian) have
// their joints along the TCP axes, whose j_max it becomes; linear_delta and arm6 refuse one.
#pragma once

#include <vector>

#include "planners/motion/path_parametrization.hpp"

namespace depotwin {

constexpr double kJerkShare = 0.9;           // of j_max for the law (the rest: interpolation)
constexpr double kNormalAccelShare = 0.3;    // of a_max for the curvature's sdot^2 term
constexpr double kCurvatureJerkShare = 0.2;  // of the jerk share for p''' sdot^3
constexpr double kCrossJerkShare = 0.3;      // of the jerk share for 3 p'' sdot sddot
constexpr double kJerkAccelShare = 0.98;     // of a_max for the law (the rest: interpolation)
constexpr int kJerkRepairRounds = 12;
constexpr double kJerkRepairScale = 0.85;
// a period whose jerk is r times its limit lowers the shares around it to kJerkRepairMargin / r
// where that is lower
constexpr double kJerkRepairMargin = 0.95;

// The jerk-limited law and its samples; law is the TOPP-RA ceiling's, repair_rounds the rounds
// of lowered shares, tcp_accel_scale the TOPP-RA factors (options' times kSampledAccelMargin).
TimedPath jerk_limited_time_path(const PathGrid& grid,
                                 const std::vector<MachineLimits>& interval_limits, double period_s,
                                 const TimeLawOptions& options = {});

// The largest constant speed the jerk-limited law keeps everywhere but at stops: TOPP-RA's
// constant_speed_bound within the curvature terms' shares above.
double jerk_constant_speed_bound(const PathGrid& grid,
                                 const std::vector<MachineLimits>& interval_limits,
                                 const TimeLawOptions& options = {});

}  // namespace depotwin
