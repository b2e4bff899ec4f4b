// Velocity and path error, computed exactly as docs/ARCHITECTURE.md defines them, from
// time samples of a motion: either the plan (Trajectory sampled every 1 ms) or the
// simulated nozzle. Pure functions; no MuJoCo.
#pragma once

#include <cstdint>
#include <vector>

#include "core/toolpath.hpp"
#include "core/trajectory.hpp"

namespace depotwin {

// One motion sampled in time (struct of arrays).
struct MotionSamples {
  std::vector<double> t_s;
  std::vector<Vec3> position_mm;
  std::vector<Vec3> velocity_mm_s;
  std::vector<std::uint8_t> depositing;    // material commanded on
  std::vector<int> path_index;             // -1 in transitions
  std::vector<double> desired_speed_mm_s;  // 0 in transitions

  size_t size() const { return t_s.size(); }
  void reserve(size_t n);
  void push_back(double t, const Vec3& p, const Vec3& v, bool deposit, int path, double desired);
};

// the plan sampled every period_s from 0 to its duration (both ends included)
MotionSamples sample_trajectory(const Trajectory& trajectory, double period_s);

// Over the samples where material is deposited: e = | |v| - v_des | / v_des.
struct VelocityErrorStats {
  double max_rel = 0.0;
  double rms_rel = 0.0;             // time-weighted
  double p95_rel = 0.0;             // time-weighted 95th percentile
  double frac_len_over_1pct = 0.0;  // fraction of deposited path length with e > 0.01
  double counted_s = 0.0;           // the time the figures cover: 0 where no sample counts
                                    // (the steady error of a run that is all ramps: n/a)
};
VelocityErrorStats velocity_error(const MotionSamples& samples);

// A stretch of time excluded from a statistic: the samples with begin_s < t < end_s.
struct TimeSpan {
  double begin_s = 0.0;
  double end_s = 0.0;
};

// The planned speed counts as having reached the desired speed within this relative margin
// (the cruise of an LSPB or a trapezoid is exact; a Bezier path's central part is within
// 1e-9); a ramp ends where the plan first comes this close.
constexpr double kRampTolerance_rel = 1e-4;
// a stretch that never reaches its desired speed counts as at speed where it holds its own
// top speed (within kRampTolerance_rel) for at least this long: a cruise, not a peak
constexpr double kHeldTopSpeed_s = 0.01;

// The start and end ramps of a plan (the papers' "central part" is what lies between):
// every printed stretch (a maximal run of consecutive samples that deposit with a desired
// speed; connected paths printed in one go are one stretch, their joints are not ramps) has
// a start ramp from its first sample up to and including the first sample whose planned
// speed reaches (1 - kRampTolerance_rel) x the desired speed, and an end ramp from the last
// such sample (included) to its end. The sample at speed is part of the ramp because the
// servo follows its setpoints a control period late: on the delta the simulated nozzle is
// still 11 % short of 5 mm/s there, and within 0.4 % one period later. A stretch that never
// reaches the desired speed is at speed from the first to the last time it holds its own top
// planned speed (within the same margin) for kHeldTopSpeed_s or longer: a line held below its
// speed on purpose (by the limits, or conformal's constant scale-down) has a steady part
// whose error is that shortfall. One that never holds it (its top a peak, or peaks: short
// moves' triangles) is ramp throughout: one span, as is a stretch at speed at one sample
// only (its start and end ramps share that sample, counted once). The spans reach half a sample
// period beyond their outer samples (open ends), so that the samples of another run at other times
// (the simulation's) fall in them as the plan's would.
std::vector<TimeSpan> speed_ramps(const MotionSamples& planned);

// velocity_error over the samples outside the spans (the steady error: outside the ramps)
VelocityErrorStats velocity_error(const MotionSamples& samples,
                                  const std::vector<TimeSpan>& excluded);

// the total time of the spans (s)
double total_time_s(const std::vector<TimeSpan>& spans);

// Distance from the nozzle point to the nearest point of the print path being printed.
struct PathErrorStats {
  double max_mm = 0.0;
  double rms_mm = 0.0;  // time-weighted
};
PathErrorStats path_error(const MotionSamples& samples, const Toolpath& toolpath);
// per sample, that distance (mm): NaN where the sample deposits nothing or names no path of
// `toolpath` (a distance itself is never NaN: infinity at worst); each path's segments are
// binned once (polyline_distance.hpp)
std::vector<double> path_distances(const MotionSamples& samples, const Toolpath& toolpath);

// distance from a point to a polyline
double distance_to_polyline(const Vec3& point, const std::vector<Vec3>& polyline);

// per-sample relative speed error (0 where not depositing), for plots and tests
std::vector<double> relative_speed_error(const MotionSamples& samples);

}  // namespace depotwin
