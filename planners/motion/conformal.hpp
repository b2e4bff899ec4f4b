// Shembekar, Yoon et al. 2018 (papers/002, DETC2018-85975): conformal printing with a 6-DOF
// arm, sec. 4 "Trajectory parameters" and 4.1 "Velocity control", on a time-optimal path
// parametrisation under TCP and joint limits (path_parametrization.hpp, TOPP-RA).
//
// Each print path is printed from rest to rest (lead_in: its ramps moved onto straight
// extensions of its end edges, cut off with the material off, see ConformalSettings). Its
// polyline is flown by at interior points like RobotStudio's zone data (fly-by points): around
// point i a quadratic Bezier blend of size
//   delta_i = min(zone_mm, 0.5 * the shorter adjacent edge)
// from P_i - delta_i d_in through P_i (control point) to P_i + delta_i d_out, tangent to both
// edges, so position is C1 and the curvature steps at the blend's ends. The blend's apex is
// the point nearest P_i for turns up to 109.5 deg and passes at
//   (delta_i / 2) sin(theta_i / 2) <= zone_mm / 2        (theta_i: the turn at P_i)
// from it: this is the stated bound (a larger deviation is reported in the warnings, which
// cannot happen unless the geometry is broken). The orientation is blended over the same
// zone: the axis runs a spherical quadratic Bezier (de Casteljau with slerps) from the edge
// axis at the blend's start through N_i to the edge axis at its end, the roll a quadratic
// Bezier through roll_i, both C1 against the position with the edges' slerps. Spherical
// blends need no chart (axes may point anywhere but straight down, where the roll's reference
// frame, tool_frame, is undefined; conformal work keeps them within 90 deg of +z). Like ABB's
// zone_ori, the blend shrinks where the blended axis would leave the axis the polyline asks at
// the nearest point (on the adjacent edges, slerped) by more than zone_ori_deg. Turns sharper
// than 170 deg, blends that would shrink below 1 um and zone_mm = 0 are fine points: the path
// stops there (a warning names each such point).
//
// The time law is path_parametrization's (TOPP-RA on an arc-length grid of step ds_mm, finer
// where a joint turns fast and halving towards every rest), under the TCP limits over each
// 2 mm chunk of path (TcpLimits::over) and, when the limits carry a joint map, every joint's
// velocity and acceleration limit along the path, sampled at period_s with the orientation
// taken from the blended geometry itself. `control` (sec. 4.1):
//   none   the TCP is commanded the desired speed; where the joints cannot follow, the time
//          law slows it and the flow stays nominal (flow fraction 1): material per mm rises by
//          v_desired / v, the paper's Fig. 4a blob at a fillet;
//   speed  the paper's scale-down: the whole path at one constant TCP speed, the largest <= the
//          desired one at which no joint has to slow anywhere on it (constant_speed_bound), and
//          the flow scaled by the same constant factor v_line / v_desired;
//   flow   TCP as in none; the commanded flow follows the planned speed sample by sample
//          (flow fraction |v| / v_desired): constant material per mm;
//   both   the constant line speed of `speed` and the flow of `flow` (ramps included).
//
// The paper's offset-point gap test (sec. 4.1) is kept as a report (conformal_report): for
// consecutive points p_i, p_{i+1} with unit normals (the tool axes) the gap ratio
//   g = |(p_{i+1} + d n_{i+1}) - (p_i + d n_i)| / |p_{i+1} - p_i|
// (d = gap_offset_mm, the paper's 1-4 mm) is > 1 on convex and < 1 on concave stretches; to
// first order g - 1 = d * kappa_n, the normal curvature along the path (exactly (R + d) / R
// on an arc of radius R with radial normals). The paper interpolates the extrusion rate
// (and joint speeds) between the extreme gaps; this planner instead controls speed and flow
// from the exact joint rates along the path (the joint map), which the gap ratio approximates.
//
// Transitions between print paths (and from the toolpath's start, to its end): the nozzle
// lifts lift_mm along the tool axis, moves, and lowers along the next axis, one rest-to-rest
// path (corners blended with half the shorter adjacent leg) under the same time law, limits
// and joint map, shutter closed; the axis and roll turn with a smoothstep in arc length
// between the end of the lift and the start of the lowering. A transition that only turns the
// tool in place (lift_mm = 0) lifts by 1 mm to do so. Where the machine's joint map cannot
// reach the lifted poses (a machine without a z axis) the transition goes straight, and one
// warning says how many did.
//
// Under a jerk limit (a j_max in force anywhere on the job) every blend, of print paths and of
// transitions, is the quartic with zero curvature at both ends (continuous curvature, so the
// acceleration has no step at any speed), and the time law is jerk_time_law.hpp's: double-S
// moves in arc length under the TOPP-RA profile, each TCP axis' jerk within its j_max on the
// samples by finite differences. `speed` and `both` cruise at jerk_constant_speed_bound.
// Joint jerk is not planned (arm6 refuses a joint j_max).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "planners/planner.hpp"

namespace depotwin {

// The plan keeps this fraction of each joint's speed and acceleration limit: the servos
// overshoot their reference by 0.4-2.3 % in simulation (the arm's joints 3-5 on the beam), so a
// plan at 100 % showed as limit violations of a machine that was never asked too much.
constexpr double kJointLimitHeadroom = 0.95;

enum class ConformalControl { none, speed, flow, both };

struct ConformalSettings {
  ConformalControl control = ConformalControl::none;
  double zone_mm = 0.25;       // fly-by zone (ABB's z1 over 0.5 mm points flies by every one)
  double zone_ori_deg = 1.5;   // largest deviation of the blended axis from the path's
  double gap_offset_mm = 2.0;  // offset d of the gap test
  double lift_mm = 1.0;        // transitions lift along the tool axis (0: straight)
  double period_s = 0.001;     // sample period
  double ds_mm = 0.05;         // grid step of the time law
  // > 0: print paths decelerate at most by |v| / flow_lag_s, what an extruder's flow lagging
  // its command by this time can follow when the command leads the speed (`uniform` sets it;
  // not a scenario parameter). 0: no such bound.
  double flow_lag_s = 0.0;
  // true: zone_mm bounds each blend's deviation, not its size. A blend at a turn theta may be
  // as long as keeps its apex within zone_mm / 2 of its point, zone_mm / sin(theta / 2) (still
  // at most half the shorter edge, and shrunk for the orientation as above): a faceted
  // surface's slight turns are flown by over their whole edges (`uniform` sets it, its
  // tolerance the bound; not a scenario parameter: the paper's zones keep their size).
  bool zone_bounds_deviation_only = false;
  // true: each print path is planned with straight extensions of its end edges, as long as its
  // ramps from and to rest, and printed only between them (the material off on them): the path
  // itself at its cruise speed from end to end, as an aerosol stream that cannot be modulated
  // needs (`uniform` sets it for aerosol; the scenario's `lead_in: 1`). Not taken, with a
  // warning, where the machine cannot reach an extension or it would lower the cruise speed.
  bool lead_in = false;
};

// The gap test over a toolpath: every pair of consecutive points of every path.
struct GapReport {
  double offset_mm = 2.0;
  int convex = 0, concave = 0, flat = 0;  // pairs with g > 1, g < 1, |g - 1| <= 1e-9
  double min_ratio = 1.0, max_ratio = 1.0;
  int min_path = -1, min_edge = -1;  // where the extremes are: path index, edge (points k, k+1)
  int max_path = -1, max_edge = -1;
};
GapReport conformal_report(const Toolpath& toolpath, double gap_offset_mm = 2.0);

// What the planner decided per print path (for metrics).
struct ConformalPathReport {
  int path_index = 0;
  double desired_speed_mm_s = 0.0;
  // the largest constant speed no limit slows anywhere but at stops (<= desired)
  double constant_speed_bound_mm_s = 0.0;
  double line_speed_mm_s = 0.0;  // the cruise speed commanded (speed/both: that bound)
  double flow_fraction_min = 1.0, flow_fraction_max = 1.0;  // over the path's samples
  int stop_points = 0;                                      // interior fine points
  double max_blend_deviation_mm = 0.0;  // the blended path from the polyline's points
  int adjusted_samples = 0;             // velocities fitted for the cubic interpolation
  int repair_rounds = 0;
  double lead_in_mm = 0.0, lead_out_mm = 0.0;  // lead_in: the extensions taken (0: none)
};
struct ConformalPlanReport {
  GapReport gaps;
  std::vector<ConformalPathReport> paths;
  double blend_deviation_bound_mm = 0.0;  // zone_mm / 2
};

class ConformalPlanner : public Planner {
 public:
  explicit ConformalPlanner(ConformalSettings settings) : settings_(settings) {}
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const override;
  // the same, with what was decided per path
  Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits,
                  ConformalPlanReport* report) const;
  const ConformalSettings& settings() const { return settings_; }

 private:
  ConformalSettings settings_;
};

std::vector<PlannerParameter> conformal_parameters();
ConformalSettings conformal_settings(const PlannerSpec& spec);
std::unique_ptr<Planner> make_conformal_planner(const PlannerSpec& spec);

}  // namespace depotwin
