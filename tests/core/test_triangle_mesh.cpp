// TriangleMesh::face_outward_and_up: a mesh wound the wrong way (a closed solid inside out, an
// open surface facing down) is turned over, and one wound right is left alone, judged by the
// closed form of its signed volume and its signed projected area.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
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

}  // namespace
}  // namespace depotwin
