// Shared checks for the planner contract (tests/contract and other planner tests).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <variant>

#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"
#include "metrics/motion_metrics.hpp"

namespace depotwin::testing_support {

// A seeded random toolpath: isolated segments and connected chains inside a 40 mm box.
inline Toolpath random_toolpath(std::uint64_t seed, double speed_mm_s) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(-20.0, 20.0), length(0.5, 12.0),
      heading(0.0, 2 * kPi);
  std::uniform_int_distribution<int> chain_length(1, 4), path_count(1, 5);
  Toolpath toolpath;
  toolpath.start_mm = Vec3(coordinate(rng), coordinate(rng), 0);
  toolpath.end_mm = Vec3(coordinate(rng), coordinate(rng), 0);
  const int paths = path_count(rng);
  for (int i = 0; i < paths; ++i) {
    PrintPath path;
    path.speed_mm_s = speed_mm_s;
    path.source_index = i;
    Vec3 p(coordinate(rng), coordinate(rng), 0);
    path.points.push_back(p);
    const int edges = chain_length(rng);
    for (int k = 0; k < edges; ++k) {
      const double h = heading(rng), l = length(rng);
      p += Vec3(l * std::cos(h), l * std::sin(h), 0);
      path.points.push_back(p);
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

// A seeded random 3-D toolpath whose tool axes vary: chains of edges over a bumpy surface
// (z in [0, 6] mm), each point's normal tilted up to 40 deg and turning smoothly along it.
inline Toolpath random_toolpath_3d(std::uint64_t seed, double speed_mm_s) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(-20.0, 20.0), length(1.0, 10.0),
      heading(0.0, 2 * kPi), height(0.0, 6.0), tilt(0.0, deg_to_rad(40.0));
  std::uniform_int_distribution<int> chain_length(1, 4), path_count(1, 4);
  const auto random_axis = [&] {
    const double t = tilt(rng), h = heading(rng);
    return Vec3(std::sin(t) * std::cos(h), std::sin(t) * std::sin(h), std::cos(t));
  };
  Toolpath toolpath;
  toolpath.start_mm = Vec3(coordinate(rng), coordinate(rng), height(rng));
  toolpath.end_mm = Vec3(coordinate(rng), coordinate(rng), height(rng));
  const int paths = path_count(rng);
  for (int i = 0; i < paths; ++i) {
    PrintPath path;
    path.speed_mm_s = speed_mm_s;
    path.source_index = i;
    Vec3 p(coordinate(rng), coordinate(rng), height(rng));
    path.points.push_back(p);
    path.normals.push_back(random_axis());
    const int edges = chain_length(rng);
    for (int k = 0; k < edges; ++k) {
      const double h = heading(rng), l = length(rng);
      p += Vec3(l * std::cos(h), l * std::sin(h), 0);
      p.z() = height(rng) * 0.3;
      path.points.push_back(p);
      path.normals.push_back(random_axis());
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

// The orientation channel: a unit tool axis everywhere that turns continuously, and on a
// print path the path's own axis where the nozzle is (vertical for paths without normals).
inline void expect_tool_axis_contract(const Trajectory& trajectory, const Toolpath& toolpath) {
  const double step_s = 0.001;
  Vec3 previous = trajectory.at(0.0).tool_axis;
  std::vector<size_t> edge_hint(toolpath.paths.size(), 0);
  for (double t = 0.0; t <= trajectory.duration_s(); t += step_s) {
    const TrajectorySample s = trajectory.at(t);
    ASSERT_NEAR(s.tool_axis.norm(), 1.0, 1e-9) << "t " << t;
    // at most 0.2 rad per ms: continuous
    ASSERT_LT(axis_angle_rad(previous, s.tool_axis), 0.2) << "tool axis jumps at t " << t;
    previous = s.tool_axis;
    if (!s.depositing || s.path_index < 0) continue;
    // on the path: the path's axis at the nearest point (close: the nozzle follows the path)
    const PrintPath& path = toolpath.paths[s.path_index];
    const Vec3 expected = path.tool_axis_near(s.position_mm, edge_hint[s.path_index]);
    ASSERT_LT(axis_angle_rad(expected, s.tool_axis), 0.05) << "t " << t;
  }
  // exactly the path's axes where a print piece starts or ends on a path point
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (!piece.depositing) continue;
    const PrintPath& path = toolpath.paths[piece.path_index];
    for (const double t : {piece.t_begin_s, piece.t_end_s}) {
      const TrajectorySample s = trajectory.at(t == piece.t_end_s ? t - 1e-12 : t);
      for (size_t i = 0; i < path.points.size(); ++i) {
        if ((path.points[i] - s.position_mm).norm() < 1e-9) {
          EXPECT_LT(axis_angle_rad(path.tool_axis(i), s.tool_axis), 1e-6) << "t " << t;
        }
      }
    }
  }
}

// A jerk-limited plan: every phase of every piece within the jerk and acceleration limits,
// and the acceleration continuous across phases and pieces (no step anywhere). A piece given
// as samples (a curved blend) is checked by finite differences of its samples at its own
// period: second differences within a_max, third differences within j_max (a third difference
// over h^3 is a weighted mean of the jerk, so it cannot exceed the largest jerk), and its
// acceleration at each end, by one-sided differences, meets the neighbouring pieces' within
// what the jerk limit allows over a few periods.
inline void expect_jerk_limited(const Trajectory& trajectory, const MachineLimits& limits) {
  std::array<double, 3> previous_end{0.0, 0.0, 0.0};
  double previous_period_s = 0.0;  // > 0 after a sampled piece: its end is known to differences
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (const auto* sampled = std::get_if<SampledMotion>(&piece.motion)) {
      const std::vector<Vec3>& p = sampled->position_mm;
      const double h = sampled->period_s;
      ASSERT_GE(p.size(), 4u) << "a sampled piece of a jerk-limited plan has at least 4 samples";
      for (int axis = 0; axis < 3; ++axis) {
        const AxisLimits& limit = limits.axes[axis];
        for (size_t k = 1; k + 1 < p.size(); ++k) {
          const double a = (p[k + 1][axis] - 2 * p[k][axis] + p[k - 1][axis]) / (h * h);
          EXPECT_LE(std::abs(a), limit.a_max_mm_s2 * (1 + 1e-3)) << "axis " << axis;
        }
        for (size_t k = 1; k + 2 < p.size(); ++k) {
          const double j =
              (p[k + 2][axis] - 3 * p[k + 1][axis] + 3 * p[k][axis] - p[k - 1][axis]) / (h * h * h);
          EXPECT_LE(std::abs(j), limit.j_max_mm_s3 * (1 + 1e-3)) << "axis " << axis;
        }
        // the ends' accelerations, second order one-sided
        const double a_begin =
            (2 * p[0][axis] - 5 * p[1][axis] + 4 * p[2][axis] - p[3][axis]) / (h * h);
        const size_t n = p.size() - 1;
        const double a_end =
            (2 * p[n][axis] - 5 * p[n - 1][axis] + 4 * p[n - 2][axis] - p[n - 3][axis]) / (h * h);
        EXPECT_NEAR(a_begin, previous_end[axis], 3 * limit.j_max_mm_s3 * h)
            << "acceleration step at t " << piece.t_begin_s;
        previous_end[axis] = a_end;
      }
      previous_period_s = h;
      continue;
    }
    const auto& phases = std::get<PhaseMotion>(piece.motion);
    for (int axis = 0; axis < 3; ++axis) {
      const AxisProfile& profile = phases.axes[axis];
      const AxisLimits& limit = limits.axes[axis];
      EXPECT_LE(profile.peak_jerk(), limit.j_max_mm_s3 * (1 + 1e-9)) << "axis " << axis;
      EXPECT_LE(profile.peak_acceleration(), limit.a_max_mm_s2 * (1 + 1e-9)) << "axis " << axis;
      double a = profile.a_start();
      // after a sampled piece, its end acceleration is known to a few jerk periods only
      EXPECT_NEAR(a, previous_end[axis], std::max(1e-6, 3 * limit.j_max_mm_s3 * previous_period_s))
          << "acceleration step at t " << piece.t_begin_s;
      for (const Phase& phase : profile.phases()) {
        EXPECT_NEAR(phase.a0, a, 1e-6) << "acceleration step in axis " << axis;
        a = phase.a_end();
      }
      previous_end[axis] = a;
    }
    previous_period_s = 0.0;
  }
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(previous_end[axis], 0.0, 1e-6);
}

// The largest per-axis speed, acceleration and jerk of a plan against its limits, by finite
// differences of the plan sampled every `period_s` from t = 0 (the grid the simulation's
// controller reads it on): v = dp / h, a = d2p / h^2, j = d3p / h^3 of the positions, and
// a = dv / h, j = d2v / h^2 of the velocities. Each is an average of the true derivative over
// its stencil, so a plan within its limits stays within them here; a step of the acceleration
// shows as a jerk of about step / h. Ratios to the limit (jerk: 0 where an axis has no j_max).
struct FiniteDifferencePeaks {
  std::array<double, 3> speed_ratio{}, accel_ratio{}, jerk_ratio{};
  std::array<double, 3> jerk_at_s{};  // where each axis' jerk ratio peaks
  double max_speed_ratio() const {
    return *std::max_element(speed_ratio.begin(), speed_ratio.end());
  }
  double max_accel_ratio() const {
    return *std::max_element(accel_ratio.begin(), accel_ratio.end());
  }
  double max_jerk_ratio() const { return *std::max_element(jerk_ratio.begin(), jerk_ratio.end()); }
};

inline FiniteDifferencePeaks finite_difference_peaks(const Trajectory& trajectory,
                                                     const MachineLimits& limits,
                                                     double period_s = 0.001) {
  FiniteDifferencePeaks peaks;
  const double h = period_s;
  // three periods of rest beyond the end (Trajectory::at clamps): the stencils reach it
  const long count = static_cast<long>(std::ceil(trajectory.duration_s() / h)) + 4;
  std::vector<Vec3> p(count), v(count);
  for (long k = 0; k < count; ++k) {
    const TrajectorySample s = trajectory.at(k * h);
    p[k] = s.position_mm;
    v[k] = s.velocity_mm_s;
  }
  for (int axis = 0; axis < 3; ++axis) {
    const AxisLimits& limit = limits.axes[axis];
    double& speed = peaks.speed_ratio[axis];
    double& accel = peaks.accel_ratio[axis];
    double& jerk = peaks.jerk_ratio[axis];
    for (long k = 0; k + 1 < count; ++k) {
      speed = std::max(speed, std::abs(p[k + 1][axis] - p[k][axis]) / h / limit.v_max_mm_s);
      accel = std::max(accel, std::abs(v[k + 1][axis] - v[k][axis]) / h / limit.a_max_mm_s2);
      if (k + 2 < count) {
        const double a = (p[k + 2][axis] - 2 * p[k + 1][axis] + p[k][axis]) / (h * h);
        accel = std::max(accel, std::abs(a) / limit.a_max_mm_s2);
      }
      if (!(limit.j_max_mm_s3 > 0.0) || k + 2 >= count) continue;
      double j = std::abs(v[k + 2][axis] - 2 * v[k + 1][axis] + v[k][axis]) / (h * h);
      if (k + 3 < count)
        j = std::max(
            j, std::abs(p[k + 3][axis] - 3 * p[k + 2][axis] + 3 * p[k + 1][axis] - p[k][axis]) /
                   (h * h * h));
      if (j / limit.j_max_mm_s3 > jerk) {
        jerk = j / limit.j_max_mm_s3;
        peaks.jerk_at_s[axis] = (k + 1) * h;
      }
    }
  }
  return peaks;
}

// A plan within its limits by finite differences (finite_difference_peaks): speed and
// acceleration within rounding, jerk within 1 + jerk_tolerance.
inline void expect_finite_difference_limits(const Trajectory& trajectory,
                                            const MachineLimits& limits,
                                            double jerk_tolerance = 0.01) {
  const FiniteDifferencePeaks peaks = finite_difference_peaks(trajectory, limits);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(peaks.speed_ratio[axis], 1 + 1e-6) << "axis " << axis;
    EXPECT_LE(peaks.accel_ratio[axis], 1 + 1e-6) << "axis " << axis;
    EXPECT_LE(peaks.jerk_ratio[axis], 1 + jerk_tolerance)
        << "axis " << axis << " jerk peaks at t " << peaks.jerk_at_s[axis];
  }
}

// The planner contract: starts and ends at rest at the start and end points, continuous
// position, per-axis limits held, every print path covered with material on, nothing
// deposited in transitions.
inline void expect_contract(const Trajectory& trajectory, const Toolpath& toolpath,
                            const MachineLimits& limits, double path_tolerance_mm = 1e-6) {
  ASSERT_GT(trajectory.duration_s(), 0.0);
  const TrajectorySample first = trajectory.at(0.0), last = trajectory.at(trajectory.duration_s());
  EXPECT_LT((first.position_mm - toolpath.start_mm).norm(), 1e-9);
  EXPECT_LT(first.velocity_mm_s.norm(), 1e-9);
  EXPECT_LT((last.position_mm - toolpath.end_mm).norm(), 1e-9);
  EXPECT_LT(last.velocity_mm_s.norm(), 1e-9);

  // pieces: contiguous, continuous across boundaries, material only on print paths
  const auto& pieces = trajectory.pieces();
  for (size_t i = 0; i < pieces.size(); ++i) {
    const TrajectoryPiece& piece = pieces[i];
    EXPECT_EQ(piece.depositing, piece.path_index >= 0) << "piece " << i;
    if (i == 0) continue;
    Vec3 p_end, v_end, a_end, p_begin, v_begin, a_begin;
    const TrajectoryPiece& previous = pieces[i - 1];
    evaluate_motion(previous, previous.t_end_s - previous.t_begin_s, p_end, v_end, a_end);
    evaluate_motion(piece, 0.0, p_begin, v_begin, a_begin);
    EXPECT_LT((p_end - p_begin).norm(), 1e-9) << "position jump at piece " << i;
    EXPECT_LT((v_end - v_begin).norm(), 1e-6) << "velocity jump at piece " << i;
  }

  // limits at 1 ms samples and at every piece boundary
  const MotionSamples samples = sample_trajectory(trajectory, 0.001);
  for (size_t k = 0; k < samples.size(); ++k) {
    const TrajectorySample s = trajectory.at(samples.t_s[k]);
    for (int axis = 0; axis < 3; ++axis) {
      ASSERT_LE(std::abs(s.velocity_mm_s[axis]), limits.axes[axis].v_max_mm_s * (1 + 1e-9))
          << "axis " << axis << " t " << s.t_s;
      ASSERT_LE(std::abs(s.acceleration_mm_s2[axis]), limits.axes[axis].a_max_mm_s2 * (1 + 1e-6))
          << "axis " << axis << " t " << s.t_s;
    }
  }

  // every path: its ends are reached with material on, and its edges' midpoints are traced
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    const PrintPath& path = toolpath.paths[i];
    std::vector<Vec3> deposited;
    for (size_t k = 0; k < samples.size(); ++k)
      if (samples.depositing[k] && samples.path_index[k] == static_cast<int>(i))
        deposited.push_back(samples.position_mm[k]);
    for (const TrajectoryPiece& piece : pieces) {
      if (piece.path_index != static_cast<int>(i)) continue;
      Vec3 p, v, a;
      evaluate_motion(piece, 0.0, p, v, a);
      deposited.push_back(p);
      evaluate_motion(piece, piece.t_end_s - piece.t_begin_s, p, v, a);
      deposited.push_back(p);
    }
    ASSERT_FALSE(deposited.empty()) << "path " << i << " never printed";
    auto nearest = [&](const Vec3& q) {
      double best = 1e300;
      for (const Vec3& d : deposited) best = std::min(best, (d - q).norm());
      return best;
    };
    EXPECT_LT(nearest(path.front()), path_tolerance_mm) << "path " << i << " start";
    EXPECT_LT(nearest(path.back()), path_tolerance_mm) << "path " << i << " end";
    // edge midpoints are traced closely. LSPB with averaged joint velocities (eqs. 52-53)
    // leaves the straight line while an axis changes its velocity by up to v at a_max; the
    // offset that builds up is below v^2 / (4 a_max) (v (v / a_max + a_max / j_max) / 4 when the
    // change is a jerk-limited S-curve), so allow that, 5 % of the edge and one sample's travel
    double a_min = limits.axes[0].a_max_mm_s2, ramp_s = 0.0;
    for (const AxisLimits& axis : limits.axes) a_min = std::min(a_min, axis.a_max_mm_s2);
    for (const AxisLimits& axis : limits.axes)
      if (axis.j_max_mm_s3 > 0.0) ramp_s = std::max(ramp_s, axis.a_max_mm_s2 / axis.j_max_mm_s3);
    const double blend_offset = path.speed_mm_s * (path.speed_mm_s / a_min + ramp_s) / 4;
    for (size_t k = 0; k + 1 < path.points.size(); ++k) {
      const double length = (path.points[k + 1] - path.points[k]).norm();
      const Vec3 mid = 0.5 * (path.points[k] + path.points[k + 1]);
      EXPECT_LT(nearest(mid),
                blend_offset + 0.05 * length + 0.001 * path.speed_mm_s + path_tolerance_mm)
          << "path " << i << " edge " << k;
    }
    // the path is printed in one go: its pieces are consecutive in time, apart from pieces
    // with the material off between them (a shutter-closed loop at a corner)
    int first_piece = -1, last_piece = -1, count = 0, closed = 0;
    for (size_t p = 0; p < pieces.size(); ++p) {
      if (pieces[p].path_index != static_cast<int>(i)) continue;
      if (first_piece < 0) first_piece = static_cast<int>(p);
      last_piece = static_cast<int>(p);
      ++count;
    }
    for (int p = first_piece; p >= 0 && p <= last_piece; ++p)
      if (pieces[p].path_index < 0) ++closed;
    EXPECT_EQ(last_piece - first_piece + 1, count + closed) << "path " << i << " printed in parts";
  }
}

}  // namespace depotwin::testing_support
