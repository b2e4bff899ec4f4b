// Jerk-limited speed changes along one straight line (a 1-D path coordinate s): the
// double-S family of motion/jerk.hpp (Biagiotti & Melchiorri, sec. 3.4) restricted to
// forward motion, with one extra rule for an extruder with a flow lag tau: while the speed
// falls, the deceleration stays below v / tau, so that a commanded flow that leads the
// speed (pressure advance: Qc = k (v + tau dv/dt), the lag model's exact inverse) never has
// to go negative, which the extruder cannot do. A deceleration under that rule is made of
// stages v -> max(v1, r v) (r = 0.7) each at acceleration min(a_max, v_next / tau), down to
// 2 % of the starting speed; a stop then ends with one S-curve at a_max (the flow error that
// last stretch leaves is at most 2 % of the speed for one lag time).
//
// Every profile starts and ends with zero acceleration, so lines join constant-speed curves
// (whose curvature, and so acceleration, is 0 at their ends) without an acceleration step.
#pragma once

#include "core/profile.hpp"

namespace depotwin {

struct LineLimits {
  double v_max_mm_s = 0.0;  // cruise cap along the line
  double a_max_mm_s2 = 0.0;
  double j_max_mm_s3 = 0.0;  // > 0
  double lag_s = 0.0;        // extruder flow lag: decelerations keep |a| <= v / lag_s; 0: none
};

// the fastest S-curve from speed v0 to v1 (zero acceleration at both ends): its duration and
// the distance it covers (decelerations staged under the lag rule)
double speed_change_duration(double v0_mm_s, double v1_mm_s, const LineLimits& limits);
double speed_change_distance(double v0_mm_s, double v1_mm_s, const LineLimits& limits);
// append that speed change to a profile (whose acceleration is 0 at its end)
void append_speed_change(AxisProfile& profile, double v0_mm_s, double v1_mm_s,
                         const LineLimits& limits);

// The largest speed v <= cap at one end of a line of `length_mm` from which the other end's
// speed `other_mm_s` can be reached along the line (v >= other): at the line's start when
// `at_start` (a deceleration v -> other), else at its end (an acceleration other -> v).
double reachable_speed(double other_mm_s, double length_mm, double cap_mm_s,
                       const LineLimits& limits, bool at_start);

// The time-optimal forward motion over length_mm from v0 to v1 (both reachable: see
// reachable_speed): an S-curve up to the highest peak <= v_max that fits, a cruise, an
// S-curve down. Starts at s = 0; InternalError when the speeds cannot be joined in the length.
AxisProfile line_profile(double length_mm, double v0_mm_s, double v1_mm_s,
                         const LineLimits& limits);

}  // namespace depotwin
