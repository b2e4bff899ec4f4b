// The aerosol shutter (Thompson & Yoon, papers/000, section II-A): a blade that blocks
// the continuous jet while the stage moves between print paths. Pure functions, no MuJoCo.
//
// Open fraction: linear in the blade angle over its blocking travel [closed, open]
// (0 at or before `closed`, 1 at or beyond `open`). At rest the blade sits `overtravel`
// (a fraction of the travel) beyond either end, so its servo is already moving at ramp
// speed when the jet begins to clear and is fully settled before the next event.
//
// Commanded travel fraction r(t) (the blade reference; 0 = closed, 1 = open):
//   r(t) = -e + overlap([t - e T, t + (1 + e) T], depositing) / T
// with T the open/close time and e the overtravel: the depositing flag averaged over a
// look-ahead window. For every print interval [t1, t2] (and every gap) at least (1 + e) T
// long this is a linear ramp that crosses the blocking travel over [t1 - T, t1] (opening)
// and [t2 - T, t2] (closing): the blade is fully open when printing starts, fully closed
// when it ends, and the integral of the open fraction min(max(r, 0), 1) equals the
// planned depositing time exactly (so the closed time equals the planned transition time).
// A shorter gap g closes the blade only partly (least open fraction 1 + e - g / T: a gap
// under e T leaves it open), a shorter print opens it only partly.
#pragma once

#include <utility>
#include <vector>

#include "core/trajectory.hpp"

namespace depotwin {

struct ShutterGeometry {
  double closed_angle_rad = 0.0;  // blocking travel: open fraction 0 here...
  double open_angle_rad = 1.0;    // ...and 1 here
  double overtravel = 0.0;        // rest positions beyond either end (fraction of the travel)
  double time_s = 0.02;           // time to sweep the blocking travel (open/close time)

  double angle_at(double travel_fraction) const {
    return closed_angle_rad + travel_fraction * (open_angle_rad - closed_angle_rad);
  }
};

// open fraction of the jet for a blade angle: linear over the blocking travel, clamped
double shutter_open_fraction(double angle_rad, const ShutterGeometry& geometry);

// the blade reference of a trajectory (see the header comment)
class ShutterReference {
 public:
  ShutterReference() = default;
  // depositing intervals taken from the trajectory's pieces (adjacent ones merged);
  // nothing is deposited outside [0, duration]
  ShutterReference(const Trajectory& trajectory, double time_s, double overtravel);

  // commanded travel fraction r(t) (may leave [0, 1] by the overtravel) and its rate dr/dt
  void at(double t_s, double& travel_fraction, double& rate_1_s) const;
  // min(max(r(t), 0), 1): the open fraction of an ideal blade
  double open_fraction(double t_s) const;

  const std::vector<std::pair<double, double>>& depositing_intervals() const { return intervals_; }

 private:
  bool depositing_at(double t_s) const;
  double overlap(double from_s, double to_s) const;

  std::vector<std::pair<double, double>> intervals_;  // sorted, disjoint [begin, end]
  double time_s_ = 0.02;
  double overtravel_ = 0.0;
};

}  // namespace depotwin
