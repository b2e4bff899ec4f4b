// A small conformal job for the plot tests, no simulator: an arch like Shembekar et al.'s
// curved beam (a circular arc along x), hatched in layers at 0 and 90 degrees with the tool
// axis tilted halfway to the surface normal, a plan sampled every 1 ms (travels lifted over
// the part), a thickness map per layer (Gaussian lines), and the joints of a 6-DOF arm.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/toolpath.hpp"
#include "core/triangle_mesh.hpp"
#include "metrics/motion_metrics.hpp"
#include "plots/plots.hpp"

namespace depotwin::testing_support {

struct ConformalFixture {
  double length_mm = 40.0, width_mm = 12.0, radius_mm = 60.0;
  TriangleMesh part;  // the arch as a closed solid (top, walls, flat bottom)
  Toolpath toolpath;
  MotionSamples planned;
  std::vector<HeightMap> layer_maps;
  std::vector<double> angles_deg;
  plots::JointSeries joints;

  // the arch: z = sqrt(R^2 - x^2) - sqrt(R^2 - (L/2)^2), its ends at z = 0
  double z(double x) const {
    return std::sqrt(radius_mm * radius_mm - x * x) -
           std::sqrt(radius_mm * radius_mm - 0.25 * length_mm * length_mm);
  }
  Vec3 normal(double x) const {
    return Vec3(x / std::sqrt(radius_mm * radius_mm - x * x), 0.0, 1.0).normalized();
  }

  plots::RunPlotInput input(const char* title = "arch / conformal") const {
    plots::RunPlotInput in;
    in.title = title;
    in.toolpath = &toolpath;
    in.planned = &planned;
    for (const HeightMap& map : layer_maps) in.layer_maps.push_back(&map);
    in.layer_angles_deg = angles_deg;
    in.part = &part;
    in.joints = &joints;
    return in;
  }
};

// the arch's surface and a flat bottom 2 mm below its ends, closed by walls (cells of `cell_mm`)
inline TriangleMesh arch_mesh(const ConformalFixture& f, double cell_mm) {
  TriangleMesh mesh;
  const int nx = static_cast<int>(std::lround(f.length_mm / cell_mm));
  const int ny = static_cast<int>(std::lround(f.width_mm / cell_mm));
  auto top = [&](int i, int j) { return j * (nx + 1) + i; };
  auto bottom = [&](int i, int j) { return (nx + 1) * (ny + 1) + j * (nx + 1) + i; };
  for (int layer = 0; layer < 2; ++layer)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const double x = -0.5 * f.length_mm + i * f.length_mm / nx;
        const double y = -0.5 * f.width_mm + j * f.width_mm / ny;
        mesh.vertices.push_back(Vec3(x, y, layer == 0 ? f.z(x) : -2.0));
      }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // counter-clockwise from above on top, from below on the bottom
      mesh.triangles.push_back({top(i, j), top(i + 1, j), top(i + 1, j + 1)});
      mesh.triangles.push_back({top(i, j), top(i + 1, j + 1), top(i, j + 1)});
      mesh.triangles.push_back({bottom(i, j), bottom(i + 1, j + 1), bottom(i + 1, j)});
      mesh.triangles.push_back({bottom(i, j), bottom(i, j + 1), bottom(i + 1, j + 1)});
    }
  for (int i = 0; i < nx; ++i)  // the walls at y = -w/2 and y = +w/2
    for (int side = 0; side < 2; ++side) {
      const int j = side == 0 ? 0 : ny;
      const std::array<int, 4> q = {top(i, j), top(i + 1, j), bottom(i + 1, j), bottom(i, j)};
      if (side == 0) {
        mesh.triangles.push_back({q[0], q[3], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[1]});
      } else {
        mesh.triangles.push_back({q[0], q[1], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[3]});
      }
    }
  for (int j = 0; j < ny; ++j)  // the walls at x = -L/2 and x = +L/2
    for (int side = 0; side < 2; ++side) {
      const int i = side == 0 ? 0 : nx;
      const std::array<int, 4> q = {top(i, j), top(i, j + 1), bottom(i, j + 1), bottom(i, j)};
      if (side == 0) {
        mesh.triangles.push_back({q[0], q[1], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[3]});
      } else {
        mesh.triangles.push_back({q[0], q[3], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[1]});
      }
    }
  return mesh;
}

// 6 joints of an arm in rad with the IRB 120's ranges: smooth motions, joint 5 coming within
// about 10 degrees of its upper limit
inline plots::JointSeries arm_joints(double duration_s) {
  plots::JointSeries series;
  const double deg = M_PI / 180.0;
  const double ranges[6][2] = {{-165, 165}, {-110, 110}, {-110, 70},
                               {-160, 160}, {-120, 120}, {-400, 400}};
  for (int j = 0; j < 6; ++j) {
    series.names.push_back("j" + std::to_string(j + 1));
    series.units.push_back("rad");
    series.min.push_back(ranges[j][0] * deg);
    series.max.push_back(ranges[j][1] * deg);
    series.position.emplace_back();
  }
  for (double t = 0.0; t <= duration_s + 1e-9; t += 0.002) {
    series.t_s.push_back(t);
    const double u = t / duration_s;
    const double q[6] = {20 * std::sin(2 * M_PI * u),
                         30 + 15 * std::sin(6 * M_PI * u),
                         -20 - 25 * std::cos(4 * M_PI * u),
                         60 * std::sin(M_PI * u),
                         60 + 50 * std::sin(2 * M_PI * u) * std::sin(2 * M_PI * u),
                         -90 + 180 * u};
    for (int j = 0; j < 6; ++j) series.position[j].push_back(q[j] * deg);
  }
  return series;
}

// `layers` layers alternating 0 / 90 degrees, hatch_mm apart, offset along the normal
inline ConformalFixture make_conformal_fixture(int layers = 2, double hatch_mm = 1.0) {
  ConformalFixture f;
  f.part = arch_mesh(f, 0.5);
  const double layer_mm = 0.4, speed_mm_s = 10.0;
  for (int k = 0; k < layers; ++k) {
    const bool along_x = k % 2 == 0;
    f.angles_deg.push_back(along_x ? 0.0 : 90.0);
    const double across = along_x ? f.width_mm : f.length_mm;
    const double along = along_x ? f.length_mm : f.width_mm;
    const int lines = static_cast<int>(std::floor((across - 1.0) / hatch_mm)) + 1;
    const int points = static_cast<int>(std::floor((along - 1.0) / 0.5)) + 1;
    for (int l = 0; l < lines; ++l) {
      PrintPath path;
      path.layer = k;
      path.speed_mm_s = speed_mm_s;
      for (int p = 0; p < points; ++p) {
        const int q = l % 2 == 0 ? p : points - 1 - p;  // zig-zag
        const double a = -0.5 * (along - 1.0) + 0.5 * q;
        const double c = -0.5 * (across - 1.0) + hatch_mm * l;
        const double x = along_x ? a : c, y = along_x ? c : a;
        const Vec3 n = f.normal(x);
        path.points.push_back(Vec3(x, y, f.z(x)) + k * layer_mm * n);
        // halfway between vertical and the normal (alpha = 0.5)
        path.normals.push_back((Vec3::UnitZ() + n).normalized());
      }
      path.source_index = static_cast<int>(f.toolpath.paths.size());
      f.toolpath.paths.push_back(path);
    }
  }
  f.toolpath.start_mm = Vec3(-0.5 * f.length_mm - 5, -0.5 * f.width_mm - 5, 15);
  f.toolpath.end_mm = Vec3(0.5 * f.length_mm + 5, 0.5 * f.width_mm + 5, 15);

  // the plan: printing at the path speed along each path, travels in straight lines lifted
  // 2 mm in the middle at 40 mm/s, sampled every 1 ms
  double t = 0.0;
  const double period_s = 0.001;
  Vec3 at = f.toolpath.start_mm;
  auto travel = [&](const Vec3& to) {
    const double length = (to - at).norm();
    const int steps = std::max(1, static_cast<int>(std::ceil(length / 40.0 / period_s)));
    for (int s = 0; s < steps; ++s) {
      const double u = static_cast<double>(s) / steps;
      const Vec3 p = at + u * (to - at) + Vec3(0, 0, 2.0 * 4 * u * (1 - u));
      f.planned.push_back(t, p, (to - at) / (steps * period_s), false, -1, 0.0);
      t += period_s;
    }
    at = to;
  };
  for (size_t i = 0; i < f.toolpath.paths.size(); ++i) {
    const PrintPath& path = f.toolpath.paths[i];
    travel(path.front());
    for (size_t j = 1; j < path.points.size(); ++j) {
      const Vec3 a = path.points[j - 1], b = path.points[j];
      const int steps =
          std::max(1, static_cast<int>(std::lround((b - a).norm() / speed_mm_s / period_s)));
      for (int s = 0; s < steps; ++s) {
        f.planned.push_back(t, a + (static_cast<double>(s) / steps) * (b - a),
                            (b - a) / (steps * period_s), true, static_cast<int>(i), speed_mm_s);
        t += period_s;
      }
    }
    at = path.back();
  }
  travel(f.toolpath.end_mm);
  f.planned.push_back(t, at, Vec3::Zero(), false, -1, 0.0);

  // a thickness map per layer: Gaussian lines (sigma 0.4 mm, 4 um + 1 um per layer peak)
  for (int k = 0; k < layers; ++k) {
    HeightMap map;
    map.cell_mm = 0.1;
    map.origin_x_mm = -0.5 * f.length_mm;
    map.origin_y_mm = -0.5 * f.width_mm;
    map.nx = static_cast<int>(std::lround(f.length_mm / map.cell_mm)) + 1;
    map.ny = static_cast<int>(std::lround(f.width_mm / map.cell_mm)) + 1;
    map.thickness_um.assign(static_cast<size_t>(map.nx) * map.ny, 0.0f);
    const bool along_x = k % 2 == 0;
    const double sigma = 0.4, peak = 4.0 + k;
    for (const PrintPath& path : f.toolpath.paths) {
      if (path.layer != k) continue;
      const double c = along_x ? path.front().y() : path.front().x();
      const double a0 = along_x ? std::min(path.front().x(), path.back().x())
                                : std::min(path.front().y(), path.back().y());
      const double a1 = along_x ? std::max(path.front().x(), path.back().x())
                                : std::max(path.front().y(), path.back().y());
      for (int iy = 0; iy < map.ny; ++iy)
        for (int ix = 0; ix < map.nx; ++ix) {
          const double x = map.origin_x_mm + ix * map.cell_mm;
          const double y = map.origin_y_mm + iy * map.cell_mm;
          const double d_across = (along_x ? y : x) - c;
          const double a = along_x ? x : y;
          const double d_along = a < a0 ? a0 - a : (a > a1 ? a - a1 : 0.0);
          const double d2 = d_across * d_across + d_along * d_along;
          map.thickness_um[static_cast<size_t>(iy) * map.nx + ix] +=
              static_cast<float>(peak * std::exp(-0.5 * d2 / (sigma * sigma)));
        }
    }
    f.layer_maps.push_back(std::move(map));
  }
  f.joints = arm_joints(t);
  return f;
}

}  // namespace depotwin::testing_support
