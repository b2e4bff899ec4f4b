// Time-optimal path parametrisation under TCP and joint limits: the time law s(t) of a
// geometric path p(s) (TOPP-RA, Pham & Pham, "A New Approach to Time-Optimal Path
// Parameterization Based on Reachability Analysis", IEEE T-RO 34(3), 2018).
//
// The path is given on a grid s_0 = 0 < s_1 < ... < s_N (mm) with, at every grid point, the
// TCP position p, its derivatives p' and p'' (one-sided where the path's curvature jumps: a
// blend's end, a corner where the path stops), the tool orientation and a bound on the TCP
// speed. With x = sdot^2 and u = sddot constant on each grid interval (so x is linear in s:
// x_{i+1} = x_i + 2 (s_{i+1} - s_i) u_i), every limit is linear in (u_i, x_i):
//   TCP speed       |p'| sdot <= v_path                 (x <= v_path^2 / |p'|^2)
//   TCP axis k      |p'_k| sdot <= v_k,  |p'_k u + p''_k x| <= a_k
//   joint j         |q'_j| sdot <= v_j,  |q'_j u + q''_j x| <= a_j
// Velocity limits bound x at each grid point, with the largest rate over both intervals at
// the point (the cubic through the rates and their slopes): x is linear on an interval, so the
// limit then holds all along it. Acceleration limits are imposed at BOTH ends of each interval
// with that end's one-sided derivatives (TOPP-RA's "interpolation" discretisation rather than
// collocation: the row at the far end uses x_{i+1} = x_i + 2 ds u_i, still linear in
// (u_i, x_i)), so they hold exactly at every grid point from both sides and, inside an
// interval, up to the change of p', p'', q', q'' across it (second order in ds).
//
// Algorithm (TOPP-RA): a backward pass computes the controllable sets K_i (the x_i from which
// the end can still be reached within the limits), each a 2-variable LP solved exactly: with
// u eliminated, every pair (lower bound on u, upper bound on u) of the interval's rows, all
// linear in x, gives one linear inequality in x, so K_i is an interval intersection. A forward
// pass then takes, at each grid point, the largest u that keeps x_{i+1} inside K_{i+1}: the
// greedy choice is time-optimal for the discretised problem (proved in the paper).
// Time follows from dt_i = 2 ds_i / (sqrt(x_i) + sqrt(x_{i+1})).
//
// Resampling at a fixed period T (1 ms): the duration is rounded up to whole periods: a law
// from rest starts up to one period late (at rest until then), else a law to rest holds its
// end, else the whole law is slowed uniformly (sdot * c, sddot * c^2, c <= 1: every limit
// still holds), so cruise speeds stay exact. Positions come from the quintic Hermite
// interpolant of (p, p', p'') on the grid interval, velocities are p'(s) sdot, tool axes and
// rolls from the path's own orientation (PathGrid::orientation_at) or slerped along s.
//
// A trajectory interpolates such samples by cubic Hermite segments (core/trajectory.hpp),
// whose acceleration is linear between samples: where the law's acceleration steps inside a
// sample period (a bang-bang switch, a curvature step at a blend's end) it overshoots by up to
// a third of the step. time_path() plans with kSampledAccelMargin (99 %) of each TCP
// acceleration limit (85 % of that over the first 10 periods of a law from rest, for the late
// start), checks the exact interpolated acceleration at both ends of every sample
// period and each sample's velocity against the TCP limits of the intervals they cross, and
// where one is exceeded refits the velocities of the samples nearby, per axis: an exact
// interval chain gives the velocities closest to the law's for which every cubic piece in a
// window stays within a_max and v_max (positions are untouched; the change is of order
// a_max T / 6). Where no window up to 130 periods fits, the TCP accelerations allowed there are
// lowered by 15 % and the path parametrised again (at most 12 rounds).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/pose.hpp"
#include "core/types.hpp"

namespace depotwin {

// One grid point of a path p(s) (s: arc length in mm, or any regular parameter in mm: the
// speed bound applies to |p'| sdot).
struct PathPoint {
  double s_mm = 0.0;
  Vec3 position_mm = Vec3::Zero();
  // dp/ds and d2p/ds2 on the interval that starts here (after) and on the one that ends here
  // (before); the same where the path is smooth
  Vec3 d1_after = Vec3::UnitX(), d2_after = Vec3::Zero();
  Vec3 d1_before = Vec3::UnitX(), d2_before = Vec3::Zero();
  // the TCP speed bound |p'| sdot <= speed_mm_s; 0: the path stops here; infinity: none
  double speed_mm_s = std::numeric_limits<double>::infinity();
  Vec3 tool_axis = vertical_tool_axis();
  double roll_rad = 0.0;
  // the path's derivatives may jump here (one-sided values differ): finite differences of
  // the joints do not reach across it
  bool is_break = false;
};

// A path on its grid, with optional joint positions and their derivatives per grid point.
struct PathGrid {
  std::string name = "path";  // for messages: "print path 3", "transition to print path 4"
  std::vector<PathPoint> points;
  std::vector<JointLimit> joint_limits;  // per joint; v_max or a_max <= 0: not limited
  std::vector<JointVector> q;            // per point (empty: no joint limits)
  std::vector<JointVector> dq_after, ddq_after, dq_before, ddq_before;  // dq/ds, d2q/ds2
  // the tool orientation at any s (the path's own, smooth): resampling takes the axis and roll
  // from it; empty: slerped between grid points (whose rate then steps at every grid point,
  // which joints that follow the axis see as acceleration spikes)
  std::function<void(double s_mm, Vec3& tool_axis, double& roll_rad)> orientation_at;

  bool has_joints() const { return !q.empty(); }
  double length_mm() const { return points.empty() ? 0.0 : points.back().s_mm; }
};

// The joint positions at every grid pose (position, tool axis, roll) by the machine's joint
// map, each the solution nearest to the previous one, and their derivatives along s by finite
// differences within each run between breaks (joint_derivatives_by_differences). Where a joint
// moves more than a thousandth of its range between neighbouring grid points (near a
// singularity) the interval is halved (points from the grid's interpolation and
// orientation_at) until it does not, or to 1e-6 mm: a step that does not shrink is a jump of
// configuration. InputError naming the path and where when a pose is unreachable or a joint
// jumps.
void attach_joints(PathGrid& grid, const JointMap& map);
// dq/ds and d2q/ds2 from grid.q: 3-point differences inside a run, 4-point one-sided ones at
// its ends (second order in the grid step on every point)
void joint_derivatives_by_differences(PathGrid& grid);

// The TCP limits per grid interval: TcpLimits::over the box of each chunk of the path (about
// chunk_mm long, padded by the sag of the path between grid points), one query per chunk.
std::vector<MachineLimits> interval_tcp_limits(const PathGrid& grid, const TcpLimits& limits,
                                               double chunk_mm = 2.0);

struct TimeLawOptions {
  double sdot_begin = 0.0;  // boundary path speeds (0: from rest, to rest)
  double sdot_end = 0.0;
  // a factor (0, 1] on every acceleration limit, TCP and joints
  double accel_scale = 1.0;
  // per grid point, factors (0, 1] on the TCP acceleration / velocity limits there (empty: 1)
  std::vector<double> tcp_accel_scale;
  std::vector<double> tcp_speed_scale;
};

// The time law on the grid.
struct TimeLaw {
  std::vector<double> s_mm;  // the grid
  std::vector<double> x;     // sdot^2 at each grid point (mm^2/s^2)
  std::vector<double> u;     // sddot on each interval (mm/s^2), one fewer than points
  std::vector<double> t_s;   // time at each grid point, from 0

  double duration_s() const { return t_s.empty() ? 0.0 : t_s.back(); }
  double sdot(size_t i) const;
  // the grid interval holding time t (clamped); hint: the previous answer (searched forwards)
  size_t interval_at_time(double t, size_t hint = 0) const;
  // s, sdot, sddot at time t (clamped to [0, duration])
  void state(double t, double& s, double& sdot, double& sddot, size_t* hint = nullptr) const;
};

// The time-optimal law (TOPP-RA) on the grid under the TCP limits of each interval
// (interval_tcp_limits), the joint limits when the grid has joints, and the speed bounds.
// InputError naming the path and where when it cannot be followed: a point whose limits allow
// no speed with its neighbours also stopped (no way through), or boundary speeds that cannot
// be reached.
TimeLaw parametrize_path(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                         const TimeLawOptions& options = {});

// The largest constant path speed V (|p'| sdot = V, sddot what a constant TCP speed needs)
// within every limit at every grid point except those where the path stops (speed 0): the
// speed at which nothing needs to slow down anywhere on the path but the start/stop ramps.
// Infinity when nothing bounds it.
double constant_speed_bound(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                            const TimeLawOptions& options = {});

// The path at a fixed period.
struct PathSamples {
  double period_s = 0.001;
  std::vector<double> s_mm, sdot;  // the time law at sample k, time k * period_s
  std::vector<Vec3> position_mm, velocity_mm_s, tool_axis;
  std::vector<double> roll_rad;
  // samples whose velocity time_path() adjusted so the cubic interpolation keeps the limits
  int adjusted_samples = 0;

  size_t size() const { return position_mm.size(); }
  double duration_s() const { return size() < 2 ? 0.0 : double(size() - 1) * period_s; }
};

// position and dp/ds (and d2p/ds2) at s on the grid (quintic Hermite on the interval holding
// s); hint: the interval of the previous query (searched forwards from it)
void path_at(const PathGrid& grid, double s_mm, Vec3& position_mm, Vec3& d1,
             size_t* hint = nullptr);
void path_derivatives(const PathGrid& grid, double s_mm, Vec3& position_mm, Vec3& d1, Vec3& d2,
                      size_t* hint = nullptr);

// The law at period T, its duration rounded up to whole periods (a late start from rest, a held
// end at rest, else a uniform slow-down: see the header comment); the first and last samples
// are the path's ends exactly.
PathSamples sample_time_law(const PathGrid& grid, const TimeLaw& law, double period_s);

// TOPP-RA, resampling, and the check (and repair) of the cubic interpolation between samples
// against the TCP limits of the intervals they cross (see the header comment). The law is
// planned with kSampledAccelMargin of every TCP acceleration limit (times the options'
// factors): the slack the velocity fit needs where the law's acceleration is saturated on both
// sides of a step (a 1 % longer ramp).
constexpr double kSampledAccelMargin = 0.99;
struct TimedPath {
  TimeLaw law;          // the time law of the samples
  PathSamples samples;  // Hermite-safe samples at the period
  std::vector<MachineLimits> interval_limits;
  // the factors on the TCP acceleration limits the law was planned with, per point: the
  // options' times kSampledAccelMargin (and 0.85 over the first 10 periods of a law from
  // rest), times those lowered by repairs
  std::vector<double> tcp_accel_scale;
  std::vector<double> repair_scale;  // the repairs' factors alone, per point
  int repair_rounds = 0;             // re-parametrisations with lowered accelerations
};
TimedPath time_path(const PathGrid& grid, const std::vector<MachineLimits>& interval_limits,
                    double period_s, const TimeLawOptions& options = {});

}  // namespace depotwin
