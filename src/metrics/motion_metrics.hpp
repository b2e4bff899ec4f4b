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
  std::vector<std::uint8_t> depositing;     // material commanded on
  std::vector<int> path_index;              // -1 in transitions
  std::vector<double> desired_speed_mm_s;   // 0 in transitions

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
};
VelocityErrorStats velocity_error(const MotionSamples& samples);

// Distance from the nozzle point to the nearest point of the print path being printed.
struct PathErrorStats {
  double max_mm = 0.0;
  double rms_mm = 0.0;  // time-weighted
};
PathErrorStats path_error(const MotionSamples& samples, const Toolpath& toolpath);

// distance from a point to a polyline
double distance_to_polyline(const Vec3& point, const std::vector<Vec3>& polyline);

// per-sample relative speed error (0 where not depositing), for plots and tests
std::vector<double> relative_speed_error(const MotionSamples& samples);

}  // namespace depotwin
