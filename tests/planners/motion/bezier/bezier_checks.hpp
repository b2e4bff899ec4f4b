// Checks shared by the bezier planner tests: the paper's speed-variation measure, the
// planner contract (rest at the ends, continuity, limits, coverage) and small toolpaths.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"

namespace depotwin::bezier_test {

inline const SampledMotion& sampled(const TrajectoryPiece& piece) {
  return std::get<SampledMotion>(piece.motion);
}

inline Toolpath single_path(std::vector<Vec3> points, double speed_mm_s) {
  Toolpath toolpath;
  toolpath.start_mm = points.front() + Vec3(-5.0, -5.0, 0.0);
  toolpath.end_mm = points.back() + Vec3(5.0, 5.0, 0.0);
  PrintPath path;
  path.points = std::move(points);
  path.speed_mm_s = speed_mm_s;
  toolpath.paths.push_back(path);
  return toolpath;
}

// The four-point path of the paper's Fig. 3 kind: three lines, two corners (the first
// turning left by 135 degrees, the second right by 135: (1, 0) -> (-1, 1)/sqrt 2 -> (1, 0)),
// lines long enough to reach full speed.
inline std::vector<Vec3> four_point_path() {
  return {Vec3(0, 0, 0), Vec3(30, 0, 0), Vec3(10, 20, 0), Vec3(40, 20, 0)};
}

// The paper's measure (Sec. 4.1, Fig. 4b): the relative variation of the TCP speed from the
// constant speed over the central, constant-speed part of the path (between the end of the
// start ramp and the start of the end ramp). The speed is measured as the paper's samples
// give it: distance between consecutive samples over T_s. The central part is where the
// planned speed (the samples' analytic velocity) equals the constant speed.
struct SpeedVariation {
  double max_rel = 0.0;  // max |v_k - v_c| / v_c
  size_t central_samples = 0;
};

inline SpeedVariation speed_variation(const SampledMotion& motion, double v_c) {
  const size_t n = motion.position_mm.size();
  size_t first = n, last = 0;
  for (size_t k = 0; k < n; ++k) {
    if (std::abs(motion.velocity_mm_s[k].norm() - v_c) <= 1e-9 * v_c) {
      first = std::min(first, k);
      last = k;
    }
  }
  SpeedVariation result;
  if (first >= last) return result;
  for (size_t k = first; k < last; ++k) {
    const double v = (motion.position_mm[k + 1] - motion.position_mm[k]).norm() / motion.period_s;
    result.max_rel = std::max(result.max_rel, std::abs(v - v_c) / v_c);
  }
  result.central_samples = last - first + 1;
  return result;
}

// Per-axis peaks of a piece's samples: velocity from the samples' analytic velocity,
// acceleration from second differences of the positions (the estimate the tests ask for).
struct SamplePeaks {
  Vec3 velocity = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
  size_t accel_peak_sample = 0;  // where the largest |a| (any axis) is
};

inline SamplePeaks sample_peaks(const SampledMotion& motion) {
  SamplePeaks peaks;
  const auto& p = motion.position_mm;
  const double h2 = motion.period_s * motion.period_s;
  double largest = -1.0;
  for (size_t k = 0; k < p.size(); ++k) {
    peaks.velocity = peaks.velocity.cwiseMax(motion.velocity_mm_s[k].cwiseAbs());
    if (k == 0 || k + 1 == p.size()) continue;
    const Vec3 a = (p[k + 1] - 2.0 * p[k] + p[k - 1]) / h2;
    peaks.accel = peaks.accel.cwiseMax(a.cwiseAbs());
    if (a.cwiseAbs().maxCoeff() > largest) {
      largest = a.cwiseAbs().maxCoeff();
      peaks.accel_peak_sample = k;
    }
  }
  return peaks;
}

// distance from a point to a segment
inline double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

inline double distance_to_polyline(const Vec3& p, const std::vector<Vec3>& points) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < points.size(); ++i)
    d = std::min(d, distance_to_segment(p, points[i], points[i + 1]));
  return d;
}

// The project's planner contract, run on one plan: starts and ends at rest at the
// toolpath's start and end, continuous position, per-axis limits held (velocity and
// acceleration estimated from the trajectory sampled at a fine step, plus the samples'
// own second differences), every print path covered with material on, nothing deposited
// in transitions. `corner_cut_mm`: how far from a polyline corner the path may leave it.
inline void expect_contract(const Trajectory& trajectory, const Toolpath& toolpath,
                            const MachineLimits& limits, double corner_cut_mm) {
  const double tol_v = 1e-6, tol_a = 1e-6;
  // rest at the ends, at the right places
  const TrajectorySample first = trajectory.at(0.0);
  const TrajectorySample last = trajectory.at(trajectory.duration_s());
  EXPECT_LT((first.position_mm - toolpath.start_mm).norm(), 1e-9);
  EXPECT_LT((last.position_mm - toolpath.end_mm).norm(), 1e-9);
  EXPECT_LT(first.velocity_mm_s.norm(), 1e-9);
  EXPECT_LT(last.velocity_mm_s.norm(), 1e-9);

  // pieces: transitions deposit nothing, every path has depositing pieces
  std::vector<int> printed(toolpath.paths.size(), 0);
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (piece.path_index < 0) {
      EXPECT_FALSE(piece.depositing);
    } else {
      EXPECT_TRUE(piece.depositing);
      ASSERT_LT(piece.path_index, static_cast<int>(toolpath.paths.size()));
      ++printed[piece.path_index];
    }
  }
  for (size_t i = 0; i < printed.size(); ++i) EXPECT_GE(printed[i], 1) << "path " << i;

  // continuity and limits on a fine time grid (also across piece boundaries)
  const double dt = 2.5e-4;
  const int steps = static_cast<int>(std::ceil(trajectory.duration_s() / dt));
  Vec3 previous = first.position_mm;
  double max_jump = 0.0;
  for (int i = 1; i <= steps; ++i) {
    const TrajectorySample s = trajectory.at(std::min(i * dt, trajectory.duration_s()));
    max_jump = std::max(max_jump, (s.position_mm - previous).norm());
    previous = s.position_mm;
    for (int axis = 0; axis < 3; ++axis) {
      const AxisLimits& lim = limits.axes[axis];
      ASSERT_LE(std::abs(s.velocity_mm_s[axis]), lim.v_max_mm_s * (1 + tol_v) + 1e-9)
          << "axis " << axis << " at t = " << s.t_s;
      ASSERT_LE(std::abs(s.acceleration_mm_s2[axis]), lim.a_max_mm_s2 * (1 + tol_a) + 1e-6)
          << "axis " << axis << " at t = " << s.t_s;
    }
  }
  double v_max = 0.0;
  for (const AxisLimits& lim : limits.axes) v_max = std::max(v_max, lim.v_max_mm_s);
  EXPECT_LE(max_jump, std::sqrt(3.0) * v_max * dt * (1 + 1e-6));

  // the samples themselves: second differences within a_max
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (!std::holds_alternative<SampledMotion>(piece.motion)) continue;
    const SamplePeaks peaks = sample_peaks(sampled(piece));
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(peaks.velocity[axis], limits.axes[axis].v_max_mm_s * (1 + tol_v));
      EXPECT_LE(peaks.accel[axis], limits.axes[axis].a_max_mm_s2 * (1 + tol_a) + 1e-6);
    }
  }

  // coverage: every point of every path away from its corners is passed with material on
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    const std::vector<Vec3>& points = toolpath.paths[i].points;
    std::vector<Vec3> deposited;
    for (const TrajectoryPiece& piece : trajectory.pieces()) {
      if (piece.path_index != static_cast<int>(i) || !piece.depositing) continue;
      const SampledMotion& m = sampled(piece);
      deposited.insert(deposited.end(), m.position_mm.begin(), m.position_mm.end());
    }
    ASSERT_GE(deposited.size(), 2u);
    for (size_t e = 0; e + 1 < points.size(); ++e) {
      const Vec3 a = points[e], b = points[e + 1];
      const double length = (b - a).norm();
      for (int q = 0; q <= 20; ++q) {
        const Vec3 p = a + (b - a) * (q / 20.0);
        // (the chord between the last sample on a line and the first on a blend leaves the
        // line by ~kappa (v T)^2 / 2: keep 0.1 mm clear of the blend's ends)
        const double clear = corner_cut_mm + 0.1;
        const bool near_corner =
            (e > 0 && (p - a).norm() < clear) || (e + 2 < points.size() && (p - b).norm() < clear);
        if (near_corner || length < 1e-9) continue;
        EXPECT_LT(distance_to_polyline(p, deposited), 1e-6)
            << "path " << i << " edge " << e << " point " << q;
      }
    }
  }
}

// Random polylines in 3-D: `count` paths of 2..6 points, edges of 0.3..15 mm, turns of any
// angle (reversals included now and then), speeds 2..20 mm/s. Seeded.
inline Toolpath random_polylines(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Toolpath toolpath;
  toolpath.start_mm = Vec3(0, 0, 0);
  toolpath.end_mm = Vec3(50, 50, 5);
  for (int i = 0; i < count; ++i) {
    PrintPath path;
    path.source_index = i;
    path.speed_mm_s = 2.0 + 18.0 * unit(rng);
    Vec3 p(100 * unit(rng), 100 * unit(rng), 5 * unit(rng));
    path.points.push_back(p);
    const int points = 2 + static_cast<int>(5 * unit(rng));
    Vec3 dir(1, 0, 0);
    for (int k = 1; k < points; ++k) {
      if (unit(rng) < 0.15 && k > 1) {
        dir = -dir;  // an exact reversal
      } else {
        Vec3 random(unit(rng) - 0.5, unit(rng) - 0.5, 0.3 * (unit(rng) - 0.5));
        dir = random.normalized();
      }
      const double length = 0.3 + 14.7 * unit(rng);
      p += length * dir;
      path.points.push_back(p);
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

}  // namespace depotwin::bezier_test
