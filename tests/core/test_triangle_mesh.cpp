// TriangleMesh::face_outward_and_up: a mesh wound the wrong way (a closed solid inside out, an
// open surface facing down) is turned over, and one wound right is left alone, judged by the
// closed form of its signed volume and its signed projected area. orient_consistently: facets
// wound against their neighbours are turned to match the larger area around them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <utility>

#include "core/triangle_mesh.hpp"

namespace depotwin {
namespace {

// a closed cube of side 2 at `centre`, wound counter-clockwise seen from outside
TriangleMesh cube(const Vec3& centre) {
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.vertices.push_back(centre + Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

TriangleMesh turned_over(TriangleMesh mesh) {
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

TEST(TriangleMesh, ASolidWoundInsideOutIsTurnedOver) {
  for (const Vec3& centre : {Vec3(0, 0, 0), Vec3(1e6, -1e6, 500)}) {
    TriangleMesh outward = cube(centre);
    ASSERT_NEAR(outward.signed_volume_mm3(), 8.0, 1e-9);
    EXPECT_FALSE(outward.face_outward_and_up());
    EXPECT_EQ(outward.triangles, cube(centre).triangles);
    TriangleMesh inside_out = turned_over(cube(centre));
    EXPECT_TRUE(inside_out.face_outward_and_up()) << centre.transpose();
    EXPECT_EQ(inside_out.triangles, cube(centre).triangles);
  }
  // a missing triangle (an STL with a hole) is still judged as a solid, not by the hole
  TriangleMesh holed = cube(Vec3::Zero());
  holed.triangles.pop_back();
  EXPECT_FALSE(holed.face_outward_and_up());
  TriangleMesh holed_inside_out = turned_over(holed);
  EXPECT_TRUE(holed_inside_out.face_outward_and_up());
  EXPECT_EQ(holed_inside_out.triangles, holed.triangles);
}

TEST(TriangleMesh, AnOpenSurfaceFacingDownIsTurnedUp) {
  // a 2 x 2 grid of squares on z = x y / 10, counter-clockwise from above
  TriangleMesh up;
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i) up.vertices.emplace_back(i, j, i * j / 10.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i;
      up.triangles.push_back({a, a + 1, a + 4});
      up.triangles.push_back({a, a + 4, a + 3});
    }
  for (size_t t = 0; t < up.triangle_count(); ++t) ASSERT_GT(up.facet_normal(t).z(), 0.0);
  TriangleMesh kept = up;
  EXPECT_FALSE(kept.face_outward_and_up());
  EXPECT_EQ(kept.triangles, up.triangles);
  TriangleMesh down = turned_over(up);
  EXPECT_TRUE(down.face_outward_and_up());
  EXPECT_EQ(down.triangles, up.triangles);
  // an empty mesh has nothing to turn
  TriangleMesh empty;
  EXPECT_FALSE(empty.face_outward_and_up());
}

// an n x n grid of squares on z = sin(x / 3) cos(y / 4), counter-clockwise from above
TriangleMesh wavy_grid(int n) {
  TriangleMesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.vertices.emplace_back(i, j, std::sin(i / 3.0) * std::cos(j / 4.0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = (n + 1) * j + i;
      mesh.triangles.push_back({a, a + 1, a + n + 2});
      mesh.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  return mesh;
}

// a separate patch facing down beside one facing up is counted with its projected area; a
// closed solid beside them is not (its projected areas cancel), nor is a patch facing up
TEST(TriangleMesh, DownFacingPiecesAreTheOpenOnesFacingDownOnTheWhole) {
  TriangleMesh mesh = wavy_grid(4);  // 16 mm^2 projected, facing up
  const TriangleMesh second = turned_over(wavy_grid(3));
  const int offset = static_cast<int>(mesh.vertices.size());
  for (const Vec3& v : second.vertices) mesh.vertices.push_back(v + Vec3(10.0, 0.0, 0.0));
  for (auto t : second.triangles)
    mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const TriangleMesh solid = cube(Vec3(0.0, 20.0, 0.0));
  const int solid_offset = static_cast<int>(mesh.vertices.size());
  for (const Vec3& v : solid.vertices) mesh.vertices.push_back(v);
  for (auto t : solid.triangles)
    mesh.triangles.push_back({t[0] + solid_offset, t[1] + solid_offset, t[2] + solid_offset});
  EXPECT_FALSE(mesh.face_outward_and_up());  // on the whole it faces up
  const TriangleMesh::DownFacingPieces down = mesh.down_facing_pieces();
  EXPECT_EQ(down.pieces, 3u);
  EXPECT_EQ(down.down, 1u);
  EXPECT_NEAR(down.down_area_mm2, 9.0, 1e-12);
  EXPECT_EQ(wavy_grid(4).down_facing_pieces().down, 0u);
}

TEST(TriangleMesh, TrianglesWoundAgainstTheirNeighboursAreTurnedToMatch) {
  // a surface with every 7th facet reversed (and the first two, at a corner): those are turned
  // back, whichever way the rest runs, and a consistent mesh is left alone
  const TriangleMesh right = wavy_grid(12);
  TriangleMesh consistent = right;
  EXPECT_EQ(consistent.orient_consistently(), 0u);
  EXPECT_EQ(consistent.triangles, right.triangles);
  TriangleMesh mixed = right;
  size_t reversed = 0;
  for (size_t t = 0; t < mixed.triangle_count(); ++t)
    if (t < 2 || t % 7 == 3) {
      std::swap(mixed.triangles[t][1], mixed.triangles[t][2]);
      ++reversed;
    }
  TriangleMesh mixed_down = turned_over(mixed);
  EXPECT_EQ(mixed.orient_consistently(), reversed);
  EXPECT_EQ(mixed.triangles, right.triangles);
  EXPECT_EQ(mixed_down.orient_consistently(), reversed);
  EXPECT_EQ(mixed_down.triangles, turned_over(right).triangles);
  EXPECT_TRUE(mixed_down.face_outward_and_up());  // then the whole is turned up
  EXPECT_EQ(mixed_down.triangles, right.triangles);

  // a surface given twice (an STL holding a copy of itself): the copies run every shared edge
  // the same way, and nothing is wound wrong (10 of 32 triangles were turned before)
  TriangleMesh doubled = right;
  doubled.triangles.insert(doubled.triangles.end(), right.triangles.begin(), right.triangles.end());
  const TriangleMesh doubled_before = doubled;
  EXPECT_EQ(doubled.orient_consistently(), 0u);
  EXPECT_EQ(doubled.triangles, doubled_before.triangles);

  // a closed cube with one face (two triangles) reversed: its volume back to 8
  TriangleMesh box = cube(Vec3::Zero());
  std::swap(box.triangles[4][1], box.triangles[4][2]);
  std::swap(box.triangles[5][1], box.triangles[5][2]);
  EXPECT_EQ(box.orient_consistently(), 2u);
  EXPECT_EQ(box.triangles, cube(Vec3::Zero()).triangles);
  EXPECT_NEAR(box.signed_volume_mm3(), 8.0, 1e-12);

  // an edge of three triangles (non-manifold) joins nothing: such a fan is left as it is; a
  // Moebius strip cannot be wound consistently and settles after one pass
  TriangleMesh fan;
  fan.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, -1, 0)};
  fan.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // edge 0-1 used three times
  const TriangleMesh fan_before = fan;
  EXPECT_EQ(fan.orient_consistently(), 0u);
  EXPECT_EQ(fan.triangles, fan_before.triangles);
  TriangleMesh strip;
  for (int k = 0; k < 8; ++k) {
    const double a = 2.0 * 3.141592653589793 * k / 8.0, w = 0.3 * std::cos(a / 2.0);
    strip.vertices.emplace_back(std::cos(a) * (1 + w), std::sin(a) * (1 + w),
                                0.3 * std::sin(a / 2));
    strip.vertices.emplace_back(std::cos(a) * (1 - w), std::sin(a) * (1 - w),
                                -0.3 * std::sin(a / 2));
  }
  for (int k = 0; k < 8; ++k) {
    const int a = 2 * k, b = 2 * k + 1;
    const int c = k < 7 ? 2 * k + 2 : 1, d = k < 7 ? 2 * k + 3 : 0;  // the half twist
    strip.triangles.push_back({a, b, c});
    strip.triangles.push_back({b, d, c});
  }
  strip.orient_consistently();
  EXPECT_EQ(strip.orient_consistently(), 0u);  // settled: a second pass turns nothing
}

}  // namespace
}  // namespace depotwin
