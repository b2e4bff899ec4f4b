// Synthetic inputs for the plot tests, no simulator: a toolpath, a plan built from cubic
// Hermite pieces (transitions between paths, printing along them), a "simulated" copy that
// lags and wobbles, a thickness map of Gaussian lines and its centreline profiles.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/heightmap.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"
#include "metrics/motion_metrics.hpp"
#include "plots/plots.hpp"

namespace depotwin::testing_support {

struct PlotFixture {
  Toolpath toolpath;
  Trajectory trajectory;
  std::vector<plots::TimeInterval> expected_transitions;  // as the builder made them
  MotionSamples planned, simulated;
  HeightMap thickness;
  std::vector<plots::LineProfile> profiles;
  double target_um = 0.0, mean_um = 0.0;

  plots::RunPlotInput input(const char* title = "fixture / synthetic") const {
    plots::RunPlotInput in;
    in.title = title;
    in.toolpath = &toolpath;
    in.planned = &planned;
    in.simulated = simulated.size() > 0 ? &simulated : nullptr;
    in.transitions = plots::transition_intervals(trajectory);
    in.thickness = &thickness;
    in.profiles = profiles;
    in.target_thickness_um = target_um;
    in.mean_thickness_um = mean_um;
    return in;
  }
};

// cubic Hermite from (p0, v0) to (p1, v1) over duration_s, sampled every 1 ms
inline TrajectoryPiece hermite_piece(double t_begin_s, double duration_s, const Vec3& p0,
                                     const Vec3& v0, const Vec3& p1, const Vec3& v1, int path_index,
                                     double desired_speed_mm_s) {
  SampledMotion motion;
  motion.period_s = 0.001;
  const long steps = std::max(1L, std::lround(duration_s / motion.period_s));
  const double h = steps * motion.period_s;  // a whole number of samples
  for (long k = 0; k <= steps; ++k) {
    const double s = static_cast<double>(k) / steps;
    const double s2 = s * s, s3 = s2 * s;
    motion.position_mm.push_back((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * h * v0 +
                                 (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * h * v1);
    motion.velocity_mm_s.push_back(((6 * s2 - 6 * s) * p0 + (-6 * s2 + 6 * s) * p1) / h +
                                   (3 * s2 - 4 * s + 1) * v0 + (3 * s2 - 2 * s) * v1);
  }
  TrajectoryPiece piece;
  piece.t_begin_s = t_begin_s;
  piece.t_end_s = t_begin_s + steps * motion.period_s;
  piece.path_index = path_index;
  piece.depositing = path_index >= 0;
  piece.desired_speed_mm_s = path_index >= 0 ? desired_speed_mm_s : 0.0;
  piece.motion = motion;
  return piece;
}

// distance from p to segment ab (XY)
inline double segment_distance_mm(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double u = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + u * ab - p).norm();
}

// Plan the toolpath of two-point paths: a transition to each path unless it continues the
// previous one (then the joint velocity is the average of both directions, as eq. (52)-(53)
// of file 000 do), printing at the path speed, a transition to the end. A flying start and
// end begin and finish at the path speed: a toolpath starting on its first path and ending
// on its last then has no transition at all.
inline PlotFixture make_plot_fixture(const Toolpath& toolpath, double transition_s,
                                     bool with_simulation = true, bool flying = false) {
  PlotFixture f;
  f.toolpath = toolpath;
  std::vector<TrajectoryPiece> pieces;
  double t = 0.0;
  Vec3 position = toolpath.start_mm, velocity = Vec3::Zero();
  const size_t n = toolpath.paths.size();
  auto direction = [&](size_t i) {
    const PrintPath& p = toolpath.paths[i];
    return Vec3((p.back() - p.front()).normalized());
  };
  if (flying) velocity = direction(0) * toolpath.paths[0].speed_mm_s;
  for (size_t i = 0; i < n; ++i) {
    const PrintPath& path = toolpath.paths[i];
    const Vec3 entry_velocity = direction(i) * path.speed_mm_s;
    if ((path.front() - position).norm() > kJoinTolerance_mm) {
      pieces.push_back(hermite_piece(t, transition_s, position, velocity, path.front(),
                                     entry_velocity, -1, 0.0));
      f.expected_transitions.push_back({t, pieces.back().t_end_s});
      t = pieces.back().t_end_s;
      velocity = entry_velocity;
    }
    // the exit velocity: averaged into the next path when it continues this one
    Vec3 exit_velocity = entry_velocity;
    if (i + 1 < n && (toolpath.paths[i + 1].front() - path.back()).norm() <= kJoinTolerance_mm)
      exit_velocity = 0.5 * (entry_velocity + direction(i + 1) * toolpath.paths[i + 1].speed_mm_s);
    pieces.push_back(hermite_piece(t, path.length_mm() / path.speed_mm_s, path.front(), velocity,
                                   path.back(), exit_velocity, static_cast<int>(i),
                                   path.speed_mm_s));
    t = pieces.back().t_end_s;
    position = path.back();
    velocity = exit_velocity;
  }
  if ((toolpath.end_mm - position).norm() > kJoinTolerance_mm || (!flying && velocity.norm() > 0)) {
    pieces.push_back(
        hermite_piece(t, transition_s, position, velocity, toolpath.end_mm, Vec3::Zero(), -1, 0));
    f.expected_transitions.push_back({t, pieces.back().t_end_s});
  }
  f.trajectory = Trajectory("synthetic", std::move(pieces));
  f.planned = sample_trajectory(f.trajectory, 0.001);

  // the "simulation": 20 ms behind the plan plus a small wobble, on the same clock
  if (with_simulation) {
    f.simulated.reserve(f.planned.size());
    for (size_t k = 0; k < f.planned.size(); ++k) {
      const double t_s = f.planned.t_s[k];
      const TrajectorySample lag = f.trajectory.at(std::max(0.0, t_s - 0.02));
      const Vec3 wobble(0.01 * std::sin(40.0 * t_s), 0.01 * std::cos(31.0 * t_s), 0.0);
      const Vec3 wobble_v(0.4 * std::cos(40.0 * t_s), -0.31 * std::sin(31.0 * t_s), 0.0);
      f.simulated.push_back(t_s, lag.position_mm + wobble, lag.velocity_mm_s + wobble_v,
                            f.planned.depositing[k], f.planned.path_index[k],
                            f.planned.desired_speed_mm_s[k]);
    }
  }

  // Gaussian lines along every path (sigma 0.15 mm, 10 um peak) on a 0.02 mm grid
  Vec3 lo, hi;
  toolpath.bounds(lo, hi);
  HeightMap& map = f.thickness;
  map.cell_mm = 0.02;
  map.origin_x_mm = lo.x() - 0.5;
  map.origin_y_mm = lo.y() - 0.5;
  map.nx = static_cast<int>(std::ceil((hi.x() - lo.x() + 1.0) / map.cell_mm)) + 1;
  map.ny = static_cast<int>(std::ceil((hi.y() - lo.y() + 1.0) / map.cell_mm)) + 1;
  map.thickness_um.assign(static_cast<size_t>(map.nx) * map.ny, 0.0f);
  const double sigma_mm = 0.15, peak_um = 10.0;
  for (int iy = 0; iy < map.ny; ++iy)
    for (int ix = 0; ix < map.nx; ++ix) {
      const Vec3 p(map.origin_x_mm + ix * map.cell_mm, map.origin_y_mm + iy * map.cell_mm, 0.0);
      double sum_um = 0.0;
      for (const PrintPath& path : toolpath.paths) {
        const double d = segment_distance_mm(p, path.front(), path.back());
        sum_um += peak_um * std::exp(-0.5 * d * d / (sigma_mm * sigma_mm));
      }
      map.thickness_um[static_cast<size_t>(iy) * map.nx + ix] = static_cast<float>(sum_um);
    }

  // centreline profiles from the nearest cell every 0.05 mm
  double sum_um = 0.0;
  long count = 0;
  for (size_t i = 0; i < n; ++i) {
    plots::LineProfile profile;
    profile.path_index = static_cast<int>(i);
    const PrintPath& path = toolpath.paths[i];
    const double length_mm = path.length_mm();
    for (double s = 0.0; s <= length_mm + 1e-9; s += 0.05) {
      const Vec3 p = path.front() + s / length_mm * (path.back() - path.front());
      const int ix = static_cast<int>(std::lround((p.x() - map.origin_x_mm) / map.cell_mm));
      const int iy = static_cast<int>(std::lround((p.y() - map.origin_y_mm) / map.cell_mm));
      profile.arc_length_mm.push_back(s);
      profile.thickness_um.push_back(map.at(ix, iy));
      sum_um += map.at(ix, iy);
      ++count;
    }
    f.profiles.push_back(std::move(profile));
  }
  f.mean_um = count > 0 ? sum_um / count : 0.0;
  f.target_um = peak_um;
  return f;
}

inline PrintPath line(double x0, double y0, double x1, double y1, double speed_mm_s = 3.0) {
  PrintPath path;
  path.points = {Vec3(x0, y0, 0), Vec3(x1, y1, 0)};
  path.speed_mm_s = speed_mm_s;
  return path;
}

// the shape of Thompson & Yoon's Fig. 7: two joined segments, one more joined at an acute
// angle, two isolated segments; a 10 mm feature
inline Toolpath thompson_like_toolpath() {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(0, 0, 0);
  toolpath.end_mm = Vec3(12, 0, 0);
  toolpath.paths = {line(1, 1, 6, 1), line(6, 1, 9, 5), line(9, 5, 4, 4), line(1, 7, 9, 7),
                    line(9, 9, 1, 11)};
  return toolpath;
}

// one straight line from start to end: printed throughout, no transition
inline Toolpath single_line_toolpath() {
  Toolpath toolpath;
  toolpath.paths = {line(0, 0, 10, 0, 2.5)};  // 4 s: a whole number of 1 ms samples
  toolpath.start_mm = toolpath.paths[0].front();
  toolpath.end_mm = toolpath.paths[0].back();
  return toolpath;
}

// a serpentine raster of 10 mm lines 1 mm apart: with 0.5 s transitions, about 30 s for 7 lines
inline Toolpath raster_toolpath(int lines) {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-2, -2, 0);
  for (int i = 0; i < lines; ++i)
    toolpath.paths.push_back(i % 2 == 0 ? line(0, i, 10, i) : line(10, i, 0, i));
  toolpath.end_mm = Vec3(12, lines + 1.0, 0);
  return toolpath;
}

}  // namespace depotwin::testing_support
