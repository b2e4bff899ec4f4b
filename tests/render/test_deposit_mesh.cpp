// The deposit mesh: closed-form vertex heights and colours from a known HeightMap, the relief
// along a part's normal, and resampling by block maxima that keeps a uniform line uniform.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

#include "render/deposit_mesh.hpp"

namespace depotwin {
namespace {

// nx x ny cells of 0.1 mm from (0, 0), thickness t(x, y)
template <typename Thickness>
HeightMap grid(int nx, int ny, Thickness thickness) {
  HeightMap map;
  map.cell_mm = 0.1;
  map.nx = nx;
  map.ny = ny;
  map.thickness_um.resize(static_cast<size_t>(nx) * ny);
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix)
      map.thickness_um[static_cast<size_t>(iy) * nx + ix] =
          static_cast<float>(thickness(ix * map.cell_mm, iy * map.cell_mm));
  return map;
}

Vec3 vertex(const DepositMesh& mesh, size_t v) {
  return Vec3(mesh.positions_mm[3 * v], mesh.positions_mm[3 * v + 1], mesh.positions_mm[3 * v + 2]);
}

// a ramp t = 10 x (um, x in mm) over 2 x 1 mm: every cell is drawn at its own centre, at
// z = lift + relief t / top, coloured viridis(t / top)
TEST(DepositMesh, VertexHeightsAndColoursAreTheClosedForm) {
  const HeightMap map = grid(20, 10, [](double x, double) { return 10.0 * x; });
  DepositMeshOptions options;
  options.relief_mm = 0.5;
  options.lift_mm = 0.01;
  options.min_relative_thickness = 0.0;
  const DepositMesh mesh = build_deposit_mesh(map, options);
  ASSERT_EQ(mesh.vertex_count(), 200u);
  EXPECT_EQ(mesh.stride, 1);
  EXPECT_FLOAT_EQ(mesh.colour_top_um, 19.0f);  // the peak: x = 1.9 mm
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3 p = vertex(mesh, v);
    const double t = 10.0 * p.x();
    EXPECT_NEAR(mesh.thickness_um[v], t, 1e-4);
    EXPECT_NEAR(p.z(), 0.01 + 0.5 * t / 19.0, 1e-5) << v;
    float expected[3];
    viridis(t / 19.0, expected);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mesh.colours[3 * v + c], expected[c], 1e-5);
  }
  // two triangles per grid square, counter-clockwise from above: upward normals
  EXPECT_EQ(mesh.triangles.size(), 6u * 19u * 9u);
  for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
    const Vec3 a = vertex(mesh, mesh.triangles[t]), b = vertex(mesh, mesh.triangles[t + 1]),
               c = vertex(mesh, mesh.triangles[t + 2]);
    EXPECT_GT((b - a).cross(c - a).z(), 0.0);
  }
  // the shading normal of the plane z = 0.01 + x / 3.8: (-1/3.8, 0, 1) normalised
  const Vec3 plane_normal = Vec3(-0.5 / 1.9, 0.0, 1.0).normalized();
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mesh.normals[3 * v + c], plane_normal[c], 1e-5);
  EXPECT_NEAR(mesh.lo_mm.x(), 0.0, 1e-6);
  EXPECT_NEAR(mesh.hi_mm.x(), 1.9, 1e-6);
  EXPECT_NEAR(mesh.hi_mm.z(), 0.51, 1e-6);
}

// a given colour top (a video's final one) scales colours and heights, and clamps above it
TEST(DepositMesh, AGivenColourTopScalesAndClamps) {
  const HeightMap map = grid(4, 4, [](double x, double) { return x < 0.15 ? 2.0 : 8.0; });
  DepositMeshOptions options;
  options.relief_mm = 1.0;
  options.lift_mm = 0.0;
  options.colour_top_um = 4.0;
  const DepositMesh mesh = build_deposit_mesh(map, options);
  ASSERT_EQ(mesh.vertex_count(), 16u);
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    EXPECT_NEAR(vertex(mesh, v).z(), mesh.thickness_um[v] < 3.0f ? 0.5 : 1.0, 1e-6);
}

// on a part z = 2 + 0.5 x the relief stands along its normal (-0.5, 0, 1)/|.|; off the part
// (x > 1.5 mm) on z = 0, upright
TEST(DepositMesh, OnAPartTheReliefStandsAlongTheNormal) {
  const HeightMap map = grid(20, 5, [](double, double) { return 4.0; });
  DepositMeshOptions options;
  options.relief_mm = 0.3;
  options.lift_mm = 0.0;
  options.surface_height_mm = [](double x, double) -> std::optional<double> {
    if (x > 1.5) return std::nullopt;
    return 2.0 + 0.5 * x;
  };
  const DepositMesh mesh = build_deposit_mesh(map, options);
  ASSERT_EQ(mesh.vertex_count(), 100u);
  const Vec3 normal = Vec3(-0.5, 0.0, 1.0).normalized();
  long on_part = 0, off_part = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    // every cell is meshed, row by row: vertex v is cell (v % 20, v / 20)
    const double cell_x = static_cast<double>(v % 20) * 0.1,
                 cell_y = static_cast<double>(v / 20) * 0.1;
    const Vec3 p = vertex(mesh, v);
    if (cell_x <= 1.5 + 1e-9) {
      ++on_part;
      const Vec3 expected = Vec3(cell_x, cell_y, 2.0 + 0.5 * cell_x) + 0.3 * normal;
      EXPECT_LT((p - expected).norm(), 1e-5) << cell_x;
    } else {
      ++off_part;
      EXPECT_LT((p - Vec3(cell_x, cell_y, 0.3)).norm(), 1e-5) << cell_x;
    }
  }
  EXPECT_EQ(on_part, 16 * 5);
  EXPECT_EQ(off_part, 4 * 5);
  // upright when asked
  options.along_normal = false;
  const DepositMesh upright = build_deposit_mesh(map, options);
  for (size_t v = 0; v < upright.vertex_count(); ++v) {
    const Vec3 p = vertex(upright, v);
    if (p.x() <= 1.5 + 1e-9) {
      EXPECT_NEAR(p.z(), 2.0 + 0.5 * p.x() + 0.3, 1e-5);
    }
  }
}

// A part's wall down to the table is not hung with a curtain of deposit: no grid square is
// meshed across a rise of more than 10 grid steps. A plateau 3 mm high (30 steps) for
// x < 1 mm, the table beyond: no triangle joins the two. Slopes of 5 steps per step (79 deg)
// and less keep every square.
TEST(DepositMesh, NoCurtainDownAPartsWall) {
  const HeightMap map = grid(20, 5, [](double, double) { return 4.0; });
  DepositMeshOptions options;
  options.min_relative_thickness = 0.0;
  options.surface_height_mm = [](double x, double) -> std::optional<double> {
    if (x > 0.95) return std::nullopt;
    return 3.0;
  };
  const DepositMesh wall = build_deposit_mesh(map, options);
  ASSERT_EQ(wall.vertex_count(), 100u);
  // 9 x 4 squares on the plateau, 9 x 4 on the table, none across the wall
  EXPECT_EQ(wall.triangles.size(), 6u * (9u + 9u) * 4u);
  for (size_t t = 0; t < wall.triangles.size(); t += 3) {
    int on_plateau = 0;
    for (int k = 0; k < 3; ++k) on_plateau += vertex(wall, wall.triangles[t + k]).x() < 0.95;
    EXPECT_TRUE(on_plateau == 0 || on_plateau == 3) << t;
  }
  for (double slope : {0.9, 5.0}) {
    options.surface_height_mm = [slope](double x, double) -> std::optional<double> {
      return slope * x;
    };
    EXPECT_EQ(build_deposit_mesh(map, options).triangles.size(), 6u * 19u * 4u) << slope;
  }
}

// cells far from the deposit carry no vertex, and nothing thinner than the threshold is drawn
TEST(DepositMesh, OnlyTheDepositAndItsRimAreMeshed) {
  // one 3 x 3 patch of 5 um in a 20 x 20 grid of zeros
  const HeightMap map = grid(20, 20, [](double x, double y) {
    return (x > 0.95 && x < 1.25 && y > 0.95 && y < 1.25) ? 5.0 : 0.0;
  });
  const DepositMesh mesh = build_deposit_mesh(map, DepositMeshOptions{});
  EXPECT_EQ(mesh.vertex_count(), 25u);  // the patch and a ring of one cell
  EXPECT_EQ(mesh.triangles.size(), 6u * 16u);
  EXPECT_TRUE(build_deposit_mesh(grid(5, 5, [](double, double) { return 0.0; }), {}).empty());
}

// A straight bead of uniform crest (a Gaussian across, sigma 0.25 mm) at an angle that walks
// across the grid: resampled by block maxima to a small budget, every vertex on the crest line
// keeps the crest's thickness to within the grid's sampling of it (a mean or a point sample
// would swing by tens of percent from block to block: the mottled look)
TEST(DepositMesh, ResamplingKeepsAUniformLineUniform) {
  const double angle = 0.37, sigma = 0.25;
  HeightMap map;
  map.cell_mm = 0.02;
  map.nx = 1000;
  map.ny = 400;
  map.thickness_um.resize(static_cast<size_t>(map.nx) * map.ny);
  for (int iy = 0; iy < map.ny; ++iy)
    for (int ix = 0; ix < map.nx; ++ix) {
      const double x = ix * map.cell_mm, y = iy * map.cell_mm;
      const double across = -std::sin(angle) * x + std::cos(angle) * (y - 1.0);
      map.thickness_um[static_cast<size_t>(iy) * map.nx + ix] =
          static_cast<float>(3.0 * std::exp(-0.5 * across * across / (sigma * sigma)));
    }
  DepositMeshOptions options;
  options.max_vertices = 3000;
  const DepositMesh mesh = build_deposit_mesh(map, options);
  EXPECT_LE(mesh.vertex_count(), 3000u);
  EXPECT_GT(mesh.stride, 2);
  // per block column along the line, the thickest vertex: the crest, everywhere the same
  const double step_mm = mesh.stride * map.cell_mm;
  std::vector<float> crest(static_cast<size_t>((map.nx + mesh.stride - 1) / mesh.stride), 0.0f);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto column = static_cast<size_t>(std::floor(vertex(mesh, v).x() / step_mm + 1e-9));
    crest[column] = std::max(crest[column], mesh.thickness_um[v]);
  }
  int columns = 0;
  for (size_t column = 1; column < crest.size(); ++column) {
    const double x = (column + 0.5) * step_mm;
    if (1.0 + std::tan(angle) * x > 7.0) break;  // near the grid's edge, where the line leaves
    ++columns;
    EXPECT_NEAR(crest[column], 3.0f, 3.0f * 0.01f) << column;
  }
  EXPECT_GT(columns, 20);
}

TEST(Viridis, RunsFromDarkPurpleToYellowWithRisingLightness) {
  float rgb[3];
  viridis(0.0, rgb);
  EXPECT_NEAR(rgb[0], 68 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[1], 1 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[2], 84 / 255.0, 1e-6);
  viridis(1.0, rgb);
  EXPECT_NEAR(rgb[0], 253 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[1], 231 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[2], 37 / 255.0, 1e-6);
  // perceptual: the luma rises monotonically, so thicker always looks lighter
  double previous = -1.0;
  for (int i = 0; i <= 64; ++i) {
    viridis(i / 64.0, rgb);
    const double luma = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    EXPECT_GT(luma, previous) << i;
    previous = luma;
  }
}

}  // namespace
}  // namespace depotwin
