// Surface hatching (Shembekar et al., Algorithm 1): grid spacing across and along the lines,
// zig-zag, angles alternating per layer, layer offsets along the normal or z, the tool axis as
// slerp(z, n, alpha), breaks at holes and steps, determinism, the gap ratio.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <tuple>

#include "core/error.hpp"
#include "core/pose.hpp"
#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/hatching.hpp"

namespace depotwin {
namespace {

// z = height over [0, size_x] x [0, size_y]
HeightField plane(double size_x, double size_y, double height) {
  HeightField field;
  field.z = [height](double, double) { return height; };
  field.gradient = [](double, double) { return Eigen::Vector2d(0, 0); };
  field.hessian = [](double, double) { return Eigen::Matrix2d::Zero().eval(); };
  field.x_max = size_x;
  field.y_max = size_y;
  return field;
}

TriangleMesh plate(double size_x, double size_y, double height,
                   const std::vector<SurfaceHole>& holes = {}) {
  TessellationOptions options;
  options.holes = holes;
  return tessellate(plane(size_x, size_y, height), options);
}

// z = kink_z + slope |x - kink_x| over [0, 20.6] x [0, 4.2], a vertex column on the kink: a
// groove (slope > 0) or a ridge (slope < 0), whose grid points at 2 mm fall at 0.3 + 2 i
TriangleMesh v_shaped(double kink_z, double slope, double kink_x) {
  HeightField field = plane(20.6, 4.2, 0.0);
  field.z = [=](double x, double) { return kink_z + slope * std::abs(x - kink_x); };
  field.x_breaks = {kink_x};
  return tessellate(field, TessellationOptions{});
}

// every path: at least two points, consecutive points distinct, finite, unit tool axes, its
// info the same length
void expect_well_formed(const SurfaceHatch& hatch) {
  ASSERT_EQ(hatch.info.size(), hatch.toolpath.paths.size());
  for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
    const PrintPath& path = hatch.toolpath.paths[p];
    const HatchPathInfo& info = hatch.info[p];
    ASSERT_GE(path.points.size(), 2u);
    ASSERT_EQ(path.normals.size(), path.points.size());
    ASSERT_EQ(info.point_index.size(), path.points.size());
    ASSERT_EQ(info.surface_points_mm.size(), path.points.size());
    ASSERT_EQ(info.surface_normals.size(), path.points.size());
    EXPECT_EQ(path.layer, info.layer);
    EXPECT_EQ(path.source_index, static_cast<int>(p));
    for (std::size_t i = 0; i < path.points.size(); ++i) {
      ASSERT_TRUE(path.points[i].allFinite());
      ASSERT_NEAR(path.normals[i].norm(), 1.0, 1e-12);
      ASSERT_NEAR(info.surface_normals[i].norm(), 1.0, 1e-12);
      if (i > 0) {
        ASSERT_GT((path.points[i] - path.points[i - 1]).norm(), kJoinTolerance_mm);
      }
    }
  }
}

TEST(Hatching, FlatPlateGridAndZigZag) {
  // 10.2 x 6.2 mm: 21 points per line (0.1 .. 10.1), 13 lines (y = 0.1 .. 6.1), centred
  SurfaceHatchSpec spec;
  spec.angles_deg = {0};
  spec.speed_mm_s = 12.0;
  const SurfaceHatch hatch = hatch_surface(plate(10.2, 6.2, 2.0), spec);
  expect_well_formed(hatch);
  ASSERT_EQ(hatch.toolpath.paths.size(), 13u);
  EXPECT_EQ(hatch.lines_per_layer, std::vector<int>{13});
  EXPECT_EQ(hatch.points_per_line, std::vector<int>{21});
  for (int j = 0; j < 13; ++j) {
    const PrintPath& path = hatch.toolpath.paths[static_cast<std::size_t>(j)];
    const HatchPathInfo& info = hatch.info[static_cast<std::size_t>(j)];
    ASSERT_EQ(path.points.size(), 21u);
    EXPECT_EQ(info.line, j);
    EXPECT_EQ(info.reversed, j % 2 == 1);
    EXPECT_EQ(path.speed_mm_s, 12.0);
    EXPECT_EQ(path.layer, 0);
    for (int i = 0; i < 21; ++i) {
      const int along = j % 2 == 0 ? i : 20 - i;  // every other line reversed
      EXPECT_EQ(info.point_index[static_cast<std::size_t>(i)], along);
      const Vec3 expected(0.1 + 0.5 * along, 0.1 + 0.5 * j, 2.0);
      EXPECT_LT((path.points[static_cast<std::size_t>(i)] - expected).norm(), 1e-12);
      EXPECT_LT((path.normals[static_cast<std::size_t>(i)] - Vec3::UnitZ()).norm(), 1e-12);
    }
  }
  EXPECT_EQ(hatch.describe(1, 0), "layer 0, line 1, point 20");
}

TEST(Hatching, PartAWholeNumberOfSpacingsWideKeepsItsRim) {
  // 10 x 6 mm at 0.5 mm: the grid's rim lies on the outline, where a ray meets only triangle
  // edges. Every rim line and point is kept, on the exact grid, at 0 and at 90 degrees, on a
  // flat plate and on a tilted plane z = 1 + 0.2 x + 0.1 y (the rim point is on its plane).
  HeightField tilted = plane(10.0, 6.0, 0.0);
  tilted.z = [](double x, double y) { return 1.0 + 0.2 * x + 0.1 * y; };
  tilted.gradient = [](double, double) { return Eigen::Vector2d(0.2, 0.1); };
  const std::vector<std::pair<TriangleMesh, std::function<double(double, double)>>> parts = {
      {plate(10.0, 6.0, 2.0), [](double, double) { return 2.0; }},
      {tessellate(tilted, TessellationOptions{}), tilted.z}};
  for (const auto& [mesh, height] : parts) {
    for (const double angle : {0.0, 90.0}) {
      SCOPED_TRACE("angle " + std::to_string(angle));
      SurfaceHatchSpec spec;
      spec.angles_deg = {angle};
      const SurfaceHatch hatch = hatch_surface(mesh, spec);
      expect_well_formed(hatch);
      const bool along_x = angle == 0.0;
      const std::size_t lines = along_x ? 13 : 21, points = along_x ? 21 : 13;
      ASSERT_EQ(hatch.toolpath.paths.size(), lines);
      double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
      for (const PrintPath& path : hatch.toolpath.paths) {
        ASSERT_EQ(path.points.size(), points);
        for (const Vec3& p : path.points) {
          EXPECT_NEAR(p.x() / 0.5, std::round(p.x() / 0.5), 1e-9);
          EXPECT_NEAR(p.y() / 0.5, std::round(p.y() / 0.5), 1e-9);
          EXPECT_NEAR(p.z(), height(p.x(), p.y()), 1e-9);
          x_lo = std::min(x_lo, p.x()), x_hi = std::max(x_hi, p.x());
          y_lo = std::min(y_lo, p.y()), y_hi = std::max(y_hi, p.y());
        }
      }
      EXPECT_NEAR(x_lo, 0.0, 1e-9);
      EXPECT_NEAR(x_hi, 10.0, 1e-9);
      EXPECT_NEAR(y_lo, 0.0, 1e-9);
      EXPECT_NEAR(y_hi, 6.0, 1e-9);
    }
  }
}

// an STL holds floats: a plate 20 mm wide from x 0.3 is 19.99999923 mm wide as read (0.3f,
// 20.3f), and the grid lost a point: every line was 19 mm long, half a spacing short at each
// end. Read as 20 mm wide, its lines run from rim to rim at 1 mm.
TEST(Hatching, APartAsWideAsItsFloatsRoundIsHatchedRimToRim) {
  const double lo = static_cast<float>(0.3), hi = static_cast<float>(20.3);
  ASSERT_LT(hi - lo, 20.0);
  TriangleMesh mesh;
  mesh.vertices = {{lo, -3, 5}, {hi, -3, 5}, {hi, 3, 5}, {lo, 3, 5}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  SurfaceHatchSpec spec;
  spec.hatch_mm = 1.0;
  spec.angles_deg = {0};
  const SurfaceHatch hatch = hatch_surface(mesh, spec);
  expect_well_formed(hatch);
  ASSERT_EQ(hatch.toolpath.paths.size(), 7u);
  for (const PrintPath& path : hatch.toolpath.paths) {
    ASSERT_EQ(path.points.size(), 21u);
    EXPECT_NEAR(std::min(path.points.front().x(), path.points.back().x()), lo, 1e-5);
    EXPECT_NEAR(std::max(path.points.front().x(), path.points.back().x()), hi, 1e-5);
  }
}

// a 2 mm step between grid points, off their midpoint: the surface halfway lies below the
// chord, which cut 0.6 mm into the step's upper side (a wall 0.7 of a spacing past a grid
// point, up or down, and on the part's outline too); a point is put on the step's edge where
// the chord lifted by the tolerance meets it, and no chord cuts deeper than the tolerance:
// measured vertically along x, and as the distance into the part for lines that cross the
// wall at 50 and 60 degrees (the point beside an oblique wall once fell on its foot: 0.14 mm)
TEST(Hatching, AChordOverAStepBetweenGridPointsClimbsItsEdge) {
  for (const double angle : {0.0, 50.0, 60.0}) {
    for (const auto& [step_at, before, after] :
         {std::tuple{0.7, 5.0, 7.0}, std::tuple{0.3, 7.0, 5.0}, std::tuple{-2.85, 5.0, 7.0},
          std::tuple{0.9, 7.0, 5.0}}) {
      // (copies: a lambda cannot capture a structured binding in C++17)
      const double step_x = step_at, z_before = before, z_after = after;
      SCOPED_TRACE("step at x " + std::to_string(step_x) + ", lines at " + std::to_string(angle) +
                   " deg");
      // two plates at their heights either side of x = step_x, joined by a vertical wall
      TriangleMesh mesh;
      mesh.vertices = {{-5, -3, z_before}, {step_x, -3, z_before}, {step_x, 3, z_before},
                       {-5, 3, z_before},  {step_x, -3, z_after},  {5, -3, z_after},
                       {5, 3, z_after},    {step_x, 3, z_after}};
      mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}, {1, 4, 7}, {1, 7, 2}};
      const SurfaceProjector projector(mesh);
      SurfaceHatchSpec spec;
      spec.hatch_mm = 1.0;
      spec.angles_deg = {angle};
      const SurfaceHatch hatch = hatch_surface(projector, spec);
      expect_well_formed(hatch);
      if (angle == 0.0) {
        ASSERT_EQ(hatch.toolpath.paths.size(), 7u);  // the step breaks no line
      }
      // how far p lies inside the part: below the low plate, or below the high one and past
      // the wall (the nearer of the high top and the wall's upper edge)
      const double low = std::min(z_before, z_after), high = std::max(z_before, z_after);
      const auto depth = [&](const Vec3& p) {
        const double past_wall = z_after > z_before ? p.x() - step_x : step_x - p.x();
        if (past_wall <= 0.0) return low - p.z();
        return std::min(high - p.z(), std::hypot(past_wall, std::max(0.0, low - p.z())));
      };
      double deepest = 0.0, deepest_vertically = 0.0;
      for (const PrintPath& path : hatch.toolpath.paths)
        for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
          for (int k = 1; k < 400; ++k) {
            const Vec3 p = path.points[i] + (k / 400.0) * (path.points[i + 1] - path.points[i]);
            deepest = std::max(deepest, depth(p));
            const double surface = p.x() < step_x ? z_before : p.x() > step_x ? z_after : high;
            deepest_vertically = std::max(deepest_vertically, surface - p.z());
          }
      EXPECT_LE(deepest, spec.chord_tolerance_mm + 1e-9);
      if (angle == 0.0) {
        EXPECT_LE(deepest_vertically, spec.chord_tolerance_mm + 1e-9);
      }
    }
  }
}

TEST(Hatching, AnglesAlternatePerLayerAndLayersStack) {
  SurfaceHatchSpec spec;
  spec.angles_deg = {0, 90};
  spec.layers = 4;
  spec.layer_height_mm = 0.4;
  for (SurfaceHatchSpec::Offset offset :
       {SurfaceHatchSpec::Offset::normal, SurfaceHatchSpec::Offset::z}) {
    spec.offset = offset;
    const SurfaceHatch hatch = hatch_surface(plate(10.2, 6.2, 2.0), spec);
    expect_well_formed(hatch);
    EXPECT_EQ(hatch.toolpath.layer_count(), 4);
    EXPECT_EQ(hatch.lines_per_layer, (std::vector<int>{13, 21, 13, 21}));
    std::map<int, int> paths_per_layer;
    for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
      const PrintPath& path = hatch.toolpath.paths[p];
      ++paths_per_layer[path.layer];
      const Vec3 step = path.points[1] - path.points[0];
      if (path.layer % 2 == 0)
        EXPECT_NEAR(std::abs(step.x()), 0.5, 1e-12);  // along x
      else
        EXPECT_NEAR(std::abs(step.y()), 0.5, 1e-12);  // along y
      for (const Vec3& point : path.points) EXPECT_NEAR(point.z(), 2.0 + 0.4 * path.layer, 1e-12);
    }
    EXPECT_EQ(paths_per_layer, (std::map<int, int>{{0, 13}, {1, 21}, {2, 13}, {3, 21}}));
    // layers are printed in order and each layer's zig-zag starts afresh
    for (std::size_t p = 1; p < hatch.toolpath.paths.size(); ++p)
      EXPECT_LE(hatch.toolpath.paths[p - 1].layer, hatch.toolpath.paths[p].layer);
    for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p)
      if (p == 0 || hatch.info[p].layer != hatch.info[p - 1].layer) {
        EXPECT_FALSE(hatch.info[p].reversed);
      }
  }
}

TEST(Hatching, AnyAngleSpacingAcrossAndAlong) {
  const TriangleMesh mesh = plate(20.0, 15.0, 1.0);
  for (double angle : {45.0, 135.0, 30.0, -20.0}) {
    SCOPED_TRACE(angle);
    SurfaceHatchSpec spec;
    spec.angles_deg = {angle};
    spec.hatch_mm = 0.7;
    const SurfaceHatch hatch = hatch_surface(mesh, spec);
    expect_well_formed(hatch);
    const double theta = deg_to_rad(angle);
    const Vec3 d(std::cos(theta), std::sin(theta), 0.0);
    const Vec3 e(-d.y(), d.x(), 0.0);
    ASSERT_GT(hatch.toolpath.paths.size(), 20u);
    for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
      const PrintPath& path = hatch.toolpath.paths[p];
      const HatchPathInfo& info = hatch.info[p];
      const double sign = info.reversed ? -1.0 : 1.0;
      for (std::size_t i = 0; i + 1 < path.points.size(); ++i)  // 0.7 apart along d
        EXPECT_LT((path.points[i + 1] - path.points[i] - sign * 0.7 * d).norm(), 1e-12);
      // on its line: e . p is the same for every point ...
      for (const Vec3& point : path.points) EXPECT_NEAR(point.dot(e), path.points[0].dot(e), 1e-12);
      // ... and lines j, j + 1 are 0.7 apart across
      if (p > 0 && hatch.info[p - 1].line + 1 == info.line) {
        EXPECT_NEAR(path.points[0].dot(e) - hatch.toolpath.paths[p - 1].points[0].dot(e), 0.7,
                    1e-12);
      }
      if (p > 0) {
        EXPECT_NE(info.reversed, hatch.info[p - 1].reversed);  // zig-zag (no holes)
      }
    }
  }
}

TEST(Hatching, ToolAxisIsSlerpOfVerticalAndNormal) {
  SphereCapParams cap;  // R 40 mm: normals tilt up to 45 deg
  const HeightField field = sphere_cap_field(cap);
  const TriangleMesh mesh = sphere_cap(cap);
  for (double alpha : {0.0, 0.25, 0.5, 1.0}) {
    SurfaceHatchSpec spec;
    spec.alpha = alpha;
    spec.angles_deg = {45};
    const SurfaceHatch hatch = hatch_surface(mesh, spec);
    expect_well_formed(hatch);
    int checked = 0;
    for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
      const PrintPath& path = hatch.toolpath.paths[p];
      for (std::size_t i = 0; i < path.points.size(); ++i) {
        const Vec3& n = hatch.info[p].surface_normals[i];
        const Vec3& axis = path.normals[i];
        EXPECT_LT((axis - slerp_axis(Vec3::UnitZ(), n, alpha)).norm(), 1e-12);
        // tilted alpha of the way, in the plane of z and n
        EXPECT_NEAR(axis_angle_rad(Vec3::UnitZ(), axis), alpha * axis_angle_rad(Vec3::UnitZ(), n),
                    1e-12);
        EXPECT_NEAR(axis.dot(Vec3::UnitZ().cross(n)), 0.0, 1e-12);
        if (alpha == 0.0) {
          EXPECT_EQ(axis, Vec3::UnitZ());
        }
        if (alpha == 1.0) {
          EXPECT_LT((axis - n).norm(), 1e-12);
        }
        // the surface normal is the sphere's within the tessellation bound (kappa delta)
        const Vec3& s = hatch.info[p].surface_points_mm[i];
        EXPECT_LT(axis_angle_rad(n, field.normal(s.x(), s.y())), 0.05);
        ++checked;
      }
    }
    EXPECT_GT(checked, 5000);
  }
}

TEST(Hatching, LayerOffsetsAlongNormalOrZOnACurvedSurface) {
  CylinderParams params;
  const TriangleMesh mesh = cylinder(params);
  for (SurfaceHatchSpec::Offset offset :
       {SurfaceHatchSpec::Offset::normal, SurfaceHatchSpec::Offset::z}) {
    SurfaceHatchSpec spec;
    spec.layers = 3;
    spec.layer_height_mm = 0.6;
    spec.offset = offset;
    const SurfaceHatch hatch = hatch_surface(mesh, spec);
    expect_well_formed(hatch);
    for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
      const PrintPath& path = hatch.toolpath.paths[p];
      const HatchPathInfo& info = hatch.info[p];
      for (std::size_t i = 0; i < path.points.size(); ++i) {
        const Vec3 direction = offset == SurfaceHatchSpec::Offset::normal ? info.surface_normals[i]
                                                                          : Vec3::UnitZ().eval();
        EXPECT_LT(
            (path.points[i] - info.surface_points_mm[i] - 0.6 * path.layer * direction).norm(),
            1e-12);
        if (path.layer == 0 && i > 0) {  // on the surface, hatch_mm apart in (x, y)
          EXPECT_NEAR((path.points[i] - path.points[i - 1]).head<2>().norm(), 0.5, 1e-12);
        }
      }
    }
  }
}

TEST(Hatching, HoleSplitsALineIntoTwoPaths) {
  // a 6 mm hole in the middle of a 20.2 x 10.2 plate; lines at y = 0.1 .. 10.1
  const TriangleMesh mesh =
      plate(20.2, 10.2, 2.0, {SurfaceHole::circle(Eigen::Vector2d(10.1, 5.1), 3.0)});
  SurfaceHatchSpec spec;
  spec.angles_deg = {0};
  const SurfaceHatch hatch = hatch_surface(mesh, spec);
  expect_well_formed(hatch);
  std::map<int, int> pieces;  // per line
  for (const HatchPathInfo& info : hatch.info) ++pieces[info.line];
  EXPECT_EQ(pieces.size(), 21u);
  EXPECT_EQ(pieces[10], 2);  // y = 5.1 through the hole's centre
  EXPECT_EQ(pieces[0], 1);
  EXPECT_EQ(pieces[20], 1);
  for (std::size_t p = 0; p < hatch.info.size(); ++p)
    for (const Vec3& point : hatch.toolpath.paths[p].points)
      EXPECT_GE((point.head<2>() - Eigen::Vector2d(10.1, 5.1)).norm(), 2.5);
  // the reversed line's pieces come in reverse order: printing goes on in one direction
  for (std::size_t p = 1; p < hatch.info.size(); ++p)
    if (hatch.info[p].line == hatch.info[p - 1].line) {
      const double gap_start = hatch.toolpath.paths[p - 1].back().x();
      const double gap_end = hatch.toolpath.paths[p].front().x();
      EXPECT_EQ(gap_end > gap_start, !hatch.info[p].reversed);
    }
}

// z = 0 up to x = 10, a ramp of the given slope up to 10 mm, flat after, over 20.2 x 4.2 mm
TriangleMesh ramp(double slope) {
  HeightField field = plane(20.2, 4.2, 0.0);
  field.z = [slope](double x, double) { return std::clamp(slope * (x - 10.0), 0.0, 10.0); };
  field.x_breaks = {10.0, 10.0 + 10.0 / slope};
  return tessellate(field, TessellationOptions{});
}

// A ramp steeper than the jump (consecutive points more than 3 spacings apart, slope above
// 70.5 deg) that still faces up is surface: each of the 9 lines runs across it whole (it used to
// break at every point and leave the ramp bare); a ramp that is a wall (n_z at most
// min_normal_z) splits every line in two. Steps proper (no surface between two heights) are in
// LoneGridPointsBetweenStepsAreReported.
TEST(Hatching, ASteepSlopeIsPrintedAWallSplitsALine) {
  // slope 10 (n_z 0.0995): the grid points x = 10.1 (z 1), 10.6 (z 6), 11.1 (z 10) are 5.0 and
  // 4.0 mm apart, over 3 x 0.5 mm
  const TriangleMesh steep = ramp(10.0);
  SurfaceHatchSpec spec;
  spec.angles_deg = {0};
  spec.min_normal_z = 0.0;  // the ramp counts as surface
  const SurfaceHatch across = hatch_surface(steep, spec);
  expect_well_formed(across);
  ASSERT_EQ(across.toolpath.paths.size(), 9u);
  for (const PrintPath& path : across.toolpath.paths) {
    EXPECT_NEAR(std::min(path.front().x(), path.back().x()), 0.1, 1e-9);
    EXPECT_NEAR(std::max(path.front().x(), path.back().x()), 20.1, 1e-9);
    const auto on_ramp = std::find_if(path.points.begin(), path.points.end(),
                                      [](const Vec3& p) { return std::abs(p.x() - 10.6) < 1e-9; });
    ASSERT_NE(on_ramp, path.points.end());
    EXPECT_NEAR(on_ramp->z(), 6.0, 1e-9);
  }
  // with the default least normal z (0.1) the ramp is a wall: every line in two, off it
  spec.min_normal_z = 0.1;
  const SurfaceHatch walls = hatch_surface(steep, spec);
  expect_well_formed(walls);
  ASSERT_EQ(walls.toolpath.paths.size(), 2u * 9u);
  for (const PrintPath& path : walls.toolpath.paths) {
    const bool low = std::min(path.front().x(), path.back().x()) < 10.0;
    EXPECT_NEAR(std::max(path.front().x(), path.back().x()), low ? 9.6 : 20.1, 1e-9);
    EXPECT_NEAR(std::min(path.front().x(), path.back().x()), low ? 0.1 : 11.1, 1e-9);
  }
  // a 75 deg ramp (n_z 0.259) with the defaults: points 1.93 mm apart up it, each line whole
  spec = SurfaceHatchSpec{};
  spec.angles_deg = {0};
  const SurfaceHatch seventy_five = hatch_surface(ramp(std::tan(deg_to_rad(75.0))), spec);
  expect_well_formed(seventy_five);
  EXPECT_EQ(seventy_five.toolpath.paths.size(), 9u);
}

// A roof z = 20 - 0.7 |x - 9.6|: its ridge falls between grid points 2 mm apart (8.3, 10.3). The
// paper's chord across it runs below the ridge (the nozzle inside the part); refined, no chord's
// halfway point is more than the tolerance below the surface, and as the surface under a chord
// is a tent (one kink), no point of it is more than twice that.
TEST(Hatching, ChordsAcrossARidgeAreRefinedToTheTolerance) {
  const double ridge_x = 9.6, slope = 0.7;
  const TriangleMesh mesh = v_shaped(20.0, -slope, ridge_x);
  const SurfaceProjector projector(mesh);
  SurfaceHatchSpec spec;
  spec.hatch_mm = 2.0;
  spec.angles_deg = {0};
  // the largest depth of the surface above a chord, sampled finely
  const auto deepest_cut = [&](const SurfaceHatch& hatch) {
    double deepest = 0.0;
    for (const PrintPath& path : hatch.toolpath.paths)
      for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
        for (int k = 1; k < 200; ++k) {
          const Vec3 p = path.points[i] + (k / 200.0) * (path.points[i + 1] - path.points[i]);
          if (const std::optional<double> h = projector.height_at(p.x(), p.y()))
            deepest = std::max(deepest, *h - p.z());
        }
    return deepest;
  };

  // the paper's grid: the chord between the grid points either side of the ridge
  spec.chord_tolerance_mm = 0.0;
  const SurfaceHatch grid = hatch_surface(projector, spec);
  expect_well_formed(grid);
  const PrintPath& first = grid.toolpath.paths.front();
  std::size_t across = 0;
  while (std::max(first.points[across].x(), first.points[across + 1].x()) < ridge_x ||
         std::min(first.points[across].x(), first.points[across + 1].x()) > ridge_x)
    ++across;
  const Vec3& a = first.points[across];
  const Vec3& b = first.points[across + 1];
  const double chord_z = a.z() + (ridge_x - a.x()) / (b.x() - a.x()) * (b.z() - a.z());
  EXPECT_GT(20.0 - chord_z, 0.5);
  EXPECT_NEAR(deepest_cut(grid), 20.0 - chord_z, 1e-3);

  // refined at 0.01 mm (the default is 0.05 mm)
  spec.chord_tolerance_mm = 0.01;
  const SurfaceHatch refined = hatch_surface(projector, spec);
  expect_well_formed(refined);
  ASSERT_EQ(refined.toolpath.paths.size(), grid.toolpath.paths.size());
  EXPECT_LE(deepest_cut(refined), 2.0 * spec.chord_tolerance_mm + 1e-9);
  for (std::size_t p = 0; p < refined.toolpath.paths.size(); ++p) {
    const PrintPath& path = refined.toolpath.paths[p];
    // points added around the ridge only: the grid's points kept, at most 2 per halving
    EXPECT_GT(path.points.size(), grid.toolpath.paths[p].points.size());
    EXPECT_LE(path.points.size(), grid.toolpath.paths[p].points.size() + 20);
    for (const Vec3& q : grid.toolpath.paths[p].points)
      EXPECT_TRUE(std::any_of(path.points.begin(), path.points.end(),
                              [&](const Vec3& r) { return (r - q).norm() < 1e-12; }));
    for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
      if (std::abs(path.points[i].x() - ridge_x) > 2.0 &&
          std::abs(path.points[i + 1].x() - ridge_x) > 2.0) {
        EXPECT_NEAR((path.points[i + 1] - path.points[i]).head<2>().norm(), 2.0, 1e-9);
      }
  }
}

// A V-groove z = 10 + 0.7 |x - c| offset along its normals: each side's points move along its
// own facet normal (corner normals do not average across the crease), so layer k's two offset
// lines cross at x = c, z = 10 + k h sqrt(1 + 0.7^2), and the points beyond the crossing fold
// back over it. Cut, every path runs forward along x and its lowest point is that crossing.
// The crease between grid points 8.3 and 10.3 (c = 9.6), and on grid point 10.3, whose offset
// along one side's normal lies over the other side, 0.40 mm into layer 0 at layer 1 (dropped:
// the chord passes over the crease).
void expect_offsets_clear_the_crease(double crease_x);

TEST(Hatching, OffsetLayersDoNotFoldBackOverAConcaveCrease) {
  for (const double crease_x : {9.6, 10.3}) {
    SCOPED_TRACE("crease at x = " + std::to_string(crease_x));
    expect_offsets_clear_the_crease(crease_x);
  }
}

void expect_offsets_clear_the_crease(double crease_x) {
  const double slope = 0.7, layer_height = 1.0;
  const TriangleMesh mesh = v_shaped(10.0, slope, crease_x);
  SurfaceHatchSpec spec;
  spec.hatch_mm = 2.0;
  spec.angles_deg = {0};
  spec.layers = 4;
  spec.layer_height_mm = layer_height;
  const SurfaceHatch hatch = hatch_surface(mesh, spec);
  expect_well_formed(hatch);
  for (std::size_t p = 0; p < hatch.toolpath.paths.size(); ++p) {
    const PrintPath& path = hatch.toolpath.paths[p];
    const double direction = path.back().x() > path.front().x() ? 1.0 : -1.0;
    for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
      EXPECT_GT(direction * (path.points[i + 1].x() - path.points[i].x()), 0.0)
          << "path " << p << " point " << i;
    if (path.layer == 0) continue;
    // never below the offsets' crossing; on it where the grid points either side have passed
    // each other (from layer 2: 8.3 + 0.573 k > 10.3 - 0.573 k), above it (a chord over the
    // concave corner) where they have not
    const auto lowest =
        std::min_element(path.points.begin(), path.points.end(),
                         [](const Vec3& a, const Vec3& b) { return a.z() < b.z(); });
    const double apex_z = 10.0 + path.layer * layer_height * std::sqrt(1.0 + slope * slope);
    EXPECT_GE(lowest->z(), apex_z - 1e-9) << "path " << p;
    if (path.layer >= 2) {
      EXPECT_NEAR(lowest->x(), crease_x, 1e-9) << "path " << p;
      EXPECT_NEAR(lowest->z(), apex_z, 1e-9) << "path " << p;
    }
    // and every point a layer's offset from both faces at least (to rounding)
    const double offset = path.layer * layer_height;
    for (const Vec3& point : path.points) {
      const double clear_of_left =
          (point - Vec3(crease_x, 0, 10)).dot(Vec3(-slope, 0, 1)) / std::sqrt(1.0 + slope * slope);
      const double clear_of_right =
          (point - Vec3(crease_x, 0, 10)).dot(Vec3(slope, 0, 1)) / std::sqrt(1.0 + slope * slope);
      EXPECT_GE(std::min(clear_of_left, clear_of_right), offset - 1e-9) << "path " << p;
    }
  }
}

// A roof z = 20 - 0.7 |x - r| offset along its normals: each side's points move along its own
// facet normal, and the chord from the ridge's offset point (along one side's normal) to the
// next point on the other side came within 0.52 mm of the ridge at layer 1 (offset 1 mm): the
// nozzle half a layer into the one below. With the arc about the ridge added, every point of
// every chord keeps the layer's offset from the roof, less the chord tolerance; with the
// paper's grid (chord tolerance 0) the chords still cut in. The ridge between grid points and
// on one (10.3).
TEST(Hatching, OffsetLayersKeepTheirOffsetOverAConvexCrease) {
  const double slope = 0.7;
  for (const double ridge_x : {9.6, 10.3}) {
    SCOPED_TRACE("ridge at x = " + std::to_string(ridge_x));
    const TriangleMesh mesh = v_shaped(20.0, -slope, ridge_x);
    SurfaceHatchSpec spec;
    spec.hatch_mm = 2.0;
    spec.angles_deg = {0};
    spec.layers = 4;
    spec.layer_height_mm = 1.0;
    // the least distance, over every chord of layers 1.., from the roof, less the layer's offset
    const auto least_clearance = [&](const SurfaceHatch& hatch) {
      double least = INFINITY;
      for (const PrintPath& path : hatch.toolpath.paths) {
        if (path.layer == 0) continue;
        for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
          for (int k = 0; k <= 200; ++k) {
            const Vec3 p = path.points[i] + (k / 200.0) * (path.points[i + 1] - path.points[i]);
            const Vec2 v(p.x() - ridge_x, p.z() - 20.0);
            double distance = INFINITY;  // to the roof's two half-lines from the ridge
            for (const Vec2& u : {Vec2(-1, -slope).normalized(), Vec2(1, -slope).normalized()})
              distance = std::min(distance, (v - std::max(0.0, v.dot(u)) * u).norm());
            least = std::min(least, distance - path.layer * spec.layer_height_mm);
          }
      }
      return least;
    };
    const SurfaceHatch rounded = hatch_surface(mesh, spec);
    expect_well_formed(rounded);
    EXPECT_GE(least_clearance(rounded), -spec.chord_tolerance_mm);
    // forward along x throughout (the arc's points in order)
    for (const PrintPath& path : rounded.toolpath.paths) {
      const double direction = path.back().x() > path.front().x() ? 1.0 : -1.0;
      for (std::size_t i = 0; i + 1 < path.points.size(); ++i)
        EXPECT_GT(direction * (path.points[i + 1].x() - path.points[i].x()), 0.0);
    }
    spec.chord_tolerance_mm = 0.0;
    EXPECT_LT(least_clearance(hatch_surface(mesh, spec)), -0.2);
  }
}

// The arc about a convex crease takes at most kMaxCreaseChords chords: far out (layer 7 at
// 100 mm a layer: 700 mm from the roof) at the least tolerance, the 70 deg turn of the V would
// take 1 143 chords; a tolerance of atoms took millions a crease (out of memory on
// shembekar_beam). Every layer's arc within its tolerance where the cap leaves it.
TEST(Hatching, AConvexCreasesArcHasAtMostItsCapOfChords) {
  const TriangleMesh mesh = v_shaped(20.0, -0.7, 9.6);
  SurfaceHatchSpec spec;
  spec.hatch_mm = 2.0;
  spec.angles_deg = {0};
  spec.layers = 8;
  spec.layer_height_mm = 100.0;
  spec.chord_tolerance_mm = SurfaceHatchSpec::kLeastChordTolerance_mm;
  const SurfaceHatch hatch = hatch_surface(mesh, spec);
  const std::size_t grid_points = hatch.toolpath.paths.front().points.size();
  const double turn = 2.0 * std::atan(0.7);
  for (const PrintPath& path : hatch.toolpath.paths) {
    const double offset = path.layer * spec.layer_height_mm;
    const double wanted =
        offset > 0.0 ? std::ceil(turn / (2.0 * std::acos(1.0 - spec.chord_tolerance_mm / offset)))
                     : 0.0;
    const double chords = std::min(wanted, double{SurfaceHatchSpec::kMaxCreaseChords});
    SCOPED_TRACE("layer " + std::to_string(path.layer) + ", arc of " + std::to_string(wanted));
    // the arc's points (its ends among them) beside the grid's, one each side of the crease
    EXPECT_LE(path.points.size(), grid_points + static_cast<std::size_t>(chords) + 1);
    if (path.layer == 7) {
      EXPECT_GT(wanted, SurfaceHatchSpec::kMaxCreaseChords);
    }
  }
}

// A band around the z axis (radius 30 mm, 20 mm wide, centred 20 mm up) turning over by half
// a turn along its length and cut open where its ends would meet: wound consistently, it faces
// up on one half and down on the other, and both halves are seen from above.
TriangleMesh twisted_band() {
  const double pi = 3.141592653589793, radius = 30.0, half_width = 10.0;
  const int along = 120, across = 8;
  TriangleMesh band;
  for (int i = 0; i <= along; ++i)
    for (int j = 0; j <= across; ++j) {
      const double u = 2.0 * pi * i / along, v = -half_width + 2.0 * half_width * j / across;
      const double r = radius + v * std::cos(u / 2.0);
      band.vertices.emplace_back(r * std::cos(u), r * std::sin(u), 20.0 + v * std::sin(u / 2.0));
    }
  for (int i = 0; i < along; ++i)
    for (int j = 0; j < across; ++j) {
      const int a = i * (across + 1) + j, b = a + across + 1;
      band.triangles.push_back({a, b, b + 1});
      band.triangles.push_back({a, b + 1, a + 1});
    }
  return band;
}

// what is seen from above is printed, whichever way its triangles are wound: the band's half
// facing down is printed on its back (it was left out, silently), as much of it as of the band
// with every triangle turned to face up, and a mesh turned over whole hatches as it was
TEST(Hatching, TheSideSeenFromAboveIsPrintedWhicheverWayItIsWound) {
  const TriangleMesh band = twisted_band();
  std::size_t facing_down = 0;
  TriangleMesh faced_up = band;
  for (std::size_t t = 0; t < band.triangle_count(); ++t)
    if (band.facet_normal(t).z() < 0.0) {
      ++facing_down;
      std::swap(faced_up.triangles[t][1], faced_up.triangles[t][2]);
    }
  ASSERT_GT(facing_down, band.triangle_count() / 3);
  SurfaceHatchSpec spec;
  spec.hatch_mm = 1.0;
  spec.min_normal_z = 0.3;
  const auto points = [&](const TriangleMesh& mesh, int side) {
    std::size_t count = 0;
    for (const PrintPath& path : hatch_surface(mesh, spec).toolpath.paths)
      for (const Vec3& p : path.points) count += (side > 0) == (p.y() > 0.0);
    return count;
  };
  // the band faces up where y < 0 (u in (pi, 2 pi)) and down where y > 0, or the other way
  for (const int side : {-1, 1}) {
    const std::size_t printed = points(band, side), reference = points(faced_up, side);
    EXPECT_GT(reference, 500u) << side;
    EXPECT_GT(static_cast<double>(printed), 0.95 * static_cast<double>(reference)) << side;
  }
  // a bonnet and its copy turned over whole: the same hatch, point for point
  TriangleMesh bonnet = car_bonnet(CarBonnetParams{});
  TriangleMesh turned = bonnet;
  for (std::array<int, 3>& f : turned.triangles) std::swap(f[1], f[2]);
  spec = SurfaceHatchSpec{};
  spec.layers = 2;
  const SurfaceHatch a = hatch_surface(bonnet, spec), b = hatch_surface(turned, spec);
  ASSERT_EQ(a.toolpath.paths.size(), b.toolpath.paths.size());
  ASSERT_GT(a.toolpath.paths.size(), 0u);
  for (std::size_t p = 0; p < a.toolpath.paths.size(); ++p) {
    ASSERT_EQ(a.toolpath.paths[p].points.size(), b.toolpath.paths[p].points.size()) << p;
    for (std::size_t i = 0; i < a.toolpath.paths[p].points.size(); ++i) {
      // (the smooth normal's corners are summed in another order: rounding apart)
      EXPECT_NEAR((a.toolpath.paths[p].points[i] - b.toolpath.paths[p].points[i]).norm(), 0.0,
                  1e-9);
      EXPECT_NEAR((a.toolpath.paths[p].normals[i] - b.toolpath.paths[p].normals[i]).norm(), 0.0,
                  1e-12);
    }
  }
}

TEST(Hatching, Deterministic) {
  SurfaceHatchSpec spec;
  spec.layers = 3;
  spec.angles_deg = {45, 135};
  const TriangleMesh mesh = car_bonnet(CarBonnetParams{});
  const SurfaceHatch a = hatch_surface(mesh, spec);
  const SurfaceHatch b = hatch_surface(mesh, spec);
  ASSERT_EQ(a.toolpath.paths.size(), b.toolpath.paths.size());
  for (std::size_t p = 0; p < a.toolpath.paths.size(); ++p) {
    ASSERT_EQ(a.toolpath.paths[p].points, b.toolpath.paths[p].points);
    ASSERT_EQ(a.toolpath.paths[p].normals, b.toolpath.paths[p].normals);
    ASSERT_EQ(a.info[p].point_index, b.info[p].point_index);
  }
  expect_well_formed(a);
}

TEST(Hatching, GapRatio) {
  // points on a circle of radius R, normals outward (convex) or inward (concave): the offset
  // points lie on a circle of radius R + d or R - d
  const double r = 30.0, d = 2.0, phi = 0.02;
  const Vec3 p0(-r * std::sin(phi), 0, r * std::cos(phi));
  const Vec3 p1(r * std::sin(phi), 0, r * std::cos(phi));
  EXPECT_NEAR(gap_ratio(p0, p0 / r, p1, p1 / r, d), (r + d) / r, 1e-12);
  EXPECT_NEAR(gap_ratio(p0, -p0 / r, p1, -p1 / r, d), (r - d) / r, 1e-12);
  EXPECT_NEAR(gap_ratio(p0, Vec3::UnitZ(), p1, Vec3::UnitZ(), d), 1.0, 1e-15);
  EXPECT_EQ(gap_ratio(p0, Vec3::UnitZ(), p0, Vec3::UnitX(), d), 1.0);

  // along hatch lines across the convex / concave cylinder
  for (bool concave : {false, true}) {
    CylinderParams params;
    params.concave = concave;
    SurfaceHatchSpec spec;
    spec.angles_deg = {0};
    const SurfaceHatch hatch = hatch_surface(cylinder(params), spec);
    const HatchPathInfo& info = hatch.info[5];
    for (std::size_t i = 10; i + 10 < info.surface_points_mm.size(); ++i) {
      const double ratio = gap_ratio(info.surface_points_mm[i], info.surface_normals[i],
                                     info.surface_points_mm[i + 1], info.surface_normals[i + 1], d);
      const double expected = concave ? (30.0 - d) / 30.0 : (30.0 + d) / 30.0;
      EXPECT_NEAR(ratio, expected, 0.01);
    }
  }
}

// a rectangle at height z over [x0, x1] x [y0, y1], in nx x ny cells of two triangles each,
// added to `mesh`; facing up, or down (wound clockwise seen from above)
void add_rectangle(TriangleMesh& mesh, double x0, double x1, double y0, double y1, double z, int nx,
                   int ny, bool up = true) {
  const int first = static_cast<int>(mesh.vertices.size());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      mesh.vertices.push_back(Vec3(x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny, z));
  auto at = [&](int i, int j) { return first + j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      mesh.triangles.push_back(up ? std::array<int, 3>{a, b, c} : std::array<int, 3>{a, c, b});
      mesh.triangles.push_back(up ? std::array<int, 3>{a, c, d} : std::array<int, 3>{a, d, c});
    }
}

// the closed box [x0, x1] x [y0, y1] x [z0, z1], its faces outward (or inward: a cavity)
void add_box(TriangleMesh& mesh, const Vec3& lo, const Vec3& hi, bool outward = true) {
  const int first = static_cast<int>(mesh.vertices.size());
  for (int k = 0; k < 8; ++k)
    mesh.vertices.push_back(
        Vec3(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z()));
  // each face counter-clockwise seen from outside
  const int faces[6][4] = {{4, 5, 7, 6}, {0, 2, 3, 1}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    const std::array<int, 4> q{first + f[0], first + f[1], first + f[2], first + f[3]};
    if (outward) {
      mesh.triangles.push_back({q[0], q[1], q[2]});
      mesh.triangles.push_back({q[0], q[2], q[3]});
    } else {
      mesh.triangles.push_back({q[0], q[2], q[1]});
      mesh.triangles.push_back({q[0], q[3], q[2]});
    }
  }
}

// What the hatch cannot reach from above: a shelf over half of a lower plate hides that
// half (3000 of the 9000 mm² facing up), a cavity's floor inside a closed box is hidden
// (400 of 2400 + 400 mm²); a solid's own walls, bottom and a cavity's ceiling do not face up
TEST(Hatching, HiddenTopSurfaceIsTheUpFacingAreaUnderAnother) {
  TriangleMesh shelf;
  add_rectangle(shelf, -50, 0, -30, 30, 20, 5, 6);   // 3000 mm² at z 20
  add_rectangle(shelf, -50, 50, -30, 30, 1, 10, 6);  // 6000 mm² at z 1, half under the shelf
  const HiddenSurface under_shelf = hidden_top_surface(SurfaceProjector(shelf));
  EXPECT_NEAR(under_shelf.up_area_mm2, 9000.0, 1e-9);
  EXPECT_NEAR(under_shelf.hidden_area_mm2, 3000.0, 1e-9);
  EXPECT_EQ(under_shelf.lower_mm, Vec3(-50, -30, 1));
  EXPECT_EQ(under_shelf.upper_mm, Vec3(0, 30, 1));

  TriangleMesh cavity;
  add_box(cavity, Vec3(-30, -20, 0), Vec3(30, 20, 20));
  add_box(cavity, Vec3(-10, -10, 5), Vec3(10, 10, 10), false);
  const HiddenSurface inside = hidden_top_surface(SurfaceProjector(cavity));
  EXPECT_NEAR(inside.up_area_mm2, 2400.0 + 400.0, 1e-9);
  EXPECT_NEAR(inside.hidden_area_mm2, 400.0, 1e-9);
  EXPECT_EQ(inside.lower_mm, Vec3(-10, -10, 5));
  EXPECT_EQ(inside.upper_mm, Vec3(10, 10, 5));
}

// Nothing is hidden on a height field: a solid bonnet (walls and bottom), a plate whose top is
// written twice (coplanar duplicates), a patch facing down (nothing faces up)
TEST(Hatching, HiddenTopSurfaceIsNoneOnAHeightField) {
  const HiddenSurface bonnet = hidden_top_surface(SurfaceProjector(car_bonnet(CarBonnetParams{})));
  EXPECT_GT(bonnet.up_area_mm2, 150.0 * 130.0);
  EXPECT_EQ(bonnet.hidden_area_mm2, 0.0);
  TriangleMesh twice;
  add_rectangle(twice, 0, 40, 0, 20, 3, 4, 2);
  add_rectangle(twice, 0, 40, 0, 20, 3, 4, 2);
  const HiddenSurface doubled = hidden_top_surface(SurfaceProjector(twice));
  EXPECT_NEAR(doubled.up_area_mm2, 1600.0, 1e-9);
  EXPECT_EQ(doubled.hidden_area_mm2, 0.0);
  TriangleMesh down;
  add_rectangle(down, 0, 40, 0, 20, 3, 4, 2, false);
  add_rectangle(down, 0, 40, 0, 20, 1, 4, 2, false);
  EXPECT_EQ(hidden_top_surface(SurfaceProjector(down)).up_area_mm2, 0.0);
}

// A groove 0.6 mm wide, 10 mm deep, across a 20 x 10 mm top, at a 0.5 mm hatch: lines across
// it (0 deg) have one grid point on its floor, between their two printed pieces, which no line
// prints (21 of the 21 x 41 grid points); lines along it (90 deg) print its floor whole. The
// same floor at the part's end is where a line merely stops short: not counted.
TEST(Hatching, LoneGridPointsBetweenStepsAreReported) {
  TriangleMesh groove;
  add_rectangle(groove, -10, -0.3, -5, 5, 15, 4, 2);
  add_rectangle(groove, -0.3, 0.3, -5, 5, 5, 1, 2);
  add_rectangle(groove, 0.3, 10, -5, 5, 15, 4, 2);
  SurfaceHatchSpec spec;
  spec.angles_deg = {0, 90};
  spec.layers = 2;
  const SurfaceHatch hatch = hatch_surface(groove, spec);
  ASSERT_EQ(hatch.lone_points.size(), 2u);
  EXPECT_EQ(hatch.lone_points[0].angle_deg, 0.0);
  EXPECT_EQ(hatch.lone_points[0].count, 21);
  EXPECT_EQ(hatch.lone_points[0].grid_points, 21 * 41);
  EXPECT_NEAR(hatch.lone_points[0].lower_mm.x(), 0.0, 1e-9);
  EXPECT_NEAR(hatch.lone_points[0].upper_mm.x(), 0.0, 1e-9);
  EXPECT_NEAR(hatch.lone_points[0].lower_mm.y(), -5.0, 1e-9);
  EXPECT_NEAR(hatch.lone_points[0].upper_mm.y(), 5.0, 1e-9);
  EXPECT_NEAR(hatch.lone_points[0].lower_mm.z(), 5.0, 1e-9);
  EXPECT_EQ(hatch.lone_points[1].angle_deg, 90.0);
  EXPECT_EQ(hatch.lone_points[1].count, 0);
  // no point of the 0 deg layer lies on the floor
  for (const PrintPath& path : hatch.toolpath.paths) {
    if (path.layer != 0) continue;
    for (const Vec3& p : path.points) EXPECT_GT(p.z(), 10.0);
  }

  TriangleMesh end;
  add_rectangle(end, -10, -0.3, -5, 5, 15, 4, 2);
  add_rectangle(end, -0.3, 0.3, -5, 5, 5, 1, 2);
  spec.angles_deg = {0};
  spec.layers = 1;
  const SurfaceHatch stops_short = hatch_surface(end, spec);
  ASSERT_EQ(stops_short.lone_points.size(), 1u);
  EXPECT_EQ(stops_short.lone_points[0].count, 0);
}

TEST(Hatching, BadSpecsAreInputErrors) {
  const TriangleMesh mesh = plate(5.0, 5.0, 0.0);
  auto problem_key = [&](const SurfaceHatchSpec& spec) -> std::string {
    try {
      hatch_surface(mesh, spec);
    } catch (const InputError& e) {
      return e.problems().front().key;
    }
    return "no error";
  };
  SurfaceHatchSpec spec;
  spec.hatch_mm = 0.0;
  EXPECT_EQ(problem_key(spec), "toolpath.surface.hatch_mm");
  spec = SurfaceHatchSpec{};
  spec.angles_deg = {};
  EXPECT_EQ(problem_key(spec), "toolpath.surface.angles_deg");
  spec = SurfaceHatchSpec{};
  spec.alpha = 1.5;
  EXPECT_EQ(problem_key(spec), "toolpath.surface.alpha");
  spec = SurfaceHatchSpec{};
  spec.layers = 0;
  EXPECT_EQ(problem_key(spec), "toolpath.surface.layers");
  spec = SurfaceHatchSpec{};
  spec.hatch_mm = 1e-4;  // 2.5e9 grid points
  EXPECT_EQ(problem_key(spec), "toolpath.surface.hatch_mm");
}

}  // namespace
}  // namespace depotwin
