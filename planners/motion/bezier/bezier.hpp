// Giberti, Sbaglia & Urgo 2017 (papers/001): straight lines joined by quadratic (rational)
// Bezier blends with fillet distance delta, traversed at constant speed by a 2nd-order
// Taylor update of the curve parameter.
//
// Per print path: fine chords merged first (beyond the paper: consecutive straight edges within
// merge_mm of one line become it, so a curve given as short chords has room for its fillets);
// the polyline's corners are replaced by blends (eq. 8 / eq. 18) between
// points at distance delta before and after each corner (clipped to half the shorter
// adjacent line, with a warning). The path is sampled at period T_s: on lines by eq. (5)
// with grid-aligned trapezoidal ramps (exact on a line), on blends at constant speed by
// eq. (4), across joints by eqs. (11)-(13). The path starts and ends at rest; transitions
// between paths are synchronised minimum-time moves, rest to rest.
//
// Limits: per path, those over the path's box (TcpLimits; with the lead-in extensions). A
// blend's speed is capped so that v^2 kappa on every axis stays within a_max
// (4/3 of it at the blend's ends, where the accel step falls between two samples and the
// Hermite interpolation overshoots by up to 4/3) and v |tangent| within v_max; the lines
// around it slow down and speed up with trapezoidal ramps (forward/backward pass). Each
// slowed corner is named in a warning. Where a corner is so sharp that crossing its blend
// slowly takes longer than stopping at the corner (exact reversals always), the path stops
// at the corner instead, also with a warning. A line too fast for an axis' v_max at the
// print speed is an InputError, as for the other planners. After sampling, the cubic Hermite
// interpolation of the samples is checked against the limits (its acceleration is linear
// between samples, so the check is exact); a blend that still overshoots (a very sharp one,
// curvature changing within one sample) is slowed a little more and the path re-sampled.
//
// Lead-in (optional): the first and last line are extended with material off; the ramp up
// ends exactly at P_0 on a sample, printing stops at the first sample past P_n (less than
// v T_s beyond it), so the flow runs only at print speed (unless a corner is slowed).
// The extensions may leave the toolpath's bounds by v^2 / (2 a) plus a few samples.
//
// Under a jerk limit (the limits carry a j_max), what changes and what stays:
// - lines: S-curves on the sample grid (bezier_profile.hpp: jerk +-j', 0 switching only at
//   samples, zero acceleration at both ends of each), so the Taylor update stays exact on them
//   (it adds j T^3 / 6 per step) and the cubic interpolation of the samples reproduces them;
//   the passes ask each line for the room of its S-curve (jerk_grid_room);
// - corners: Giberti et al.'s quadratic blend steps the curvature from 0 to kappa at its ends,
//   so at speed v the acceleration would step by v^2 kappa, an infinite jerk. The blend becomes
//   the rational quartic with the same entry, corner, exit and weight whose curvature is 0 at
//   both ends (BezierBlend degree 4): crossed at constant speed, its acceleration ramps from 0
//   and its jerk is v^3 d3p/ds3, capped per axis at kBlendJerkShare j_max (the blend speed
//   v <= (0.9 j_max / |d3p/ds3|)^(1/3), with the a_max and v_max caps as before). Slowing and
//   ramping around a quadratic blend cannot help: its curvature steps at any speed but zero.
//   The stop-or-blend choice compares S-curve times;
// - what stays of the paper: the fillet distance and the weight, constant speed on every blend
//   by the Taylor update of u (eqs. 3-5) with the joint corrections (eqs. 11-13), the forward /
//   backward passes, the sampled output. Exact arcs are chorded within chord_tolerance_mm (a
//   circle entered from its tangent also steps the curvature) and their chords' corners
//   blended;
// - after sampling, the jerk the 1 ms finite differences see on the interpolated samples
//   (sampled_jerk.hpp) is checked with the accelerations: a blend near an excess is slowed by
//   the cube root of it and the path sampled again.
// Without j_max the plan is the paper's, bit for bit as before.
#pragma once

#include <memory>
#include <vector>

#include "planners/planner.hpp"

namespace depotwin {

struct BezierSettings {
  double delta_mm = 0.5;             // fillet distance
  std::vector<double> weights{1.0};  // one for every corner, or one per corner in order
  double period_s = 0.001;           // sample period T_s of the Taylor update
  bool lead_in = false;              // ramp on extensions of the first/last line, flow off
  double merge_mm = 0.01;            // fine chords merged within this (0: off)
};

class BezierPlanner : public Planner {
 public:
  explicit BezierPlanner(BezierSettings settings) : settings_(std::move(settings)) {}
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
  const BezierSettings& settings() const { return settings_; }

 private:
  BezierSettings settings_;
};

std::vector<PlannerParameter> bezier_parameters();
// settings from a (range-checked) spec; throws InputError for what ranges cannot express
BezierSettings bezier_settings(const PlannerSpec& spec);
std::unique_ptr<Planner> make_bezier_planner(const PlannerSpec& spec);

}  // namespace depotwin
