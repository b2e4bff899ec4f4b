// TriangleMesh::face_outward_and_up: a mesh wound the wrong way (a closed solid inside out, an
// open surface facing down) is turned over, and one wound right is left alone, judged by the
// closed form of its signed volume and its signed projected area. orient_consistently: facets
// wound against their neighbours are turned to match the larger area around them; a surface
// without an outside (a Moebius strip) faces up triangle by triangle. corner_normals: smooth
// within a fan of facets joined by manifold edges, closed form on a bent sheet, and another
// surface met at a non-manifold edge or a lone vertex is not averaged in.
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

TEST(TriangleMesh, TrianglesWoundAgainstTheirNeighboursAreTurnedToMatch) {
  // a surface with every 7th facet reversed (and the first two, at a corner): those are turned
  // back, whichever way the rest runs, and a consistent mesh is left alone
  const TriangleMesh right = wavy_grid(12);
  TriangleMesh consistent = right;
  EXPECT_EQ(consistent.orient_consistently().turned, 0u);
  EXPECT_EQ(consistent.triangles, right.triangles);
  TriangleMesh mixed = right;
  size_t reversed = 0;
  for (size_t t = 0; t < mixed.triangle_count(); ++t)
    if (t < 2 || t % 7 == 3) {
      std::swap(mixed.triangles[t][1], mixed.triangles[t][2]);
      ++reversed;
    }
  TriangleMesh mixed_down = turned_over(mixed);
  EXPECT_EQ(mixed.orient_consistently().turned, reversed);
  EXPECT_EQ(mixed.triangles, right.triangles);
  EXPECT_EQ(mixed_down.orient_consistently().turned, reversed);
  EXPECT_EQ(mixed_down.triangles, turned_over(right).triangles);
  EXPECT_TRUE(mixed_down.face_outward_and_up());  // then the whole is turned up
  EXPECT_EQ(mixed_down.triangles, right.triangles);

  // a surface given twice (an STL holding a copy of itself): the copies run every shared edge
  // the same way, and nothing is wound wrong (10 of 32 triangles were turned before)
  TriangleMesh doubled = right;
  doubled.triangles.insert(doubled.triangles.end(), right.triangles.begin(), right.triangles.end());
  const TriangleMesh doubled_before = doubled;
  EXPECT_EQ(doubled.orient_consistently().turned, 0u);
  EXPECT_EQ(doubled.triangles, doubled_before.triangles);

  // a closed cube with one face (two triangles) reversed: its volume back to 8
  TriangleMesh box = cube(Vec3::Zero());
  std::swap(box.triangles[4][1], box.triangles[4][2]);
  std::swap(box.triangles[5][1], box.triangles[5][2]);
  EXPECT_EQ(box.orient_consistently().turned, 2u);
  EXPECT_EQ(box.triangles, cube(Vec3::Zero()).triangles);
  EXPECT_NEAR(box.signed_volume_mm3(), 8.0, 1e-12);

  // an edge of three triangles (non-manifold) joins nothing: such a fan is left as it is; a
  // Moebius strip cannot be wound consistently: its triangles face up, settled after one pass
  TriangleMesh fan;
  fan.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, -1, 0)};
  fan.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};  // edge 0-1 used three times
  const TriangleMesh fan_before = fan;
  EXPECT_EQ(fan.orient_consistently().turned, 0u);
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
  // the strip has no outside: each of its triangles faces up on its own
  const TriangleMesh::Orientation strip_oriented = strip.orient_consistently();
  EXPECT_EQ(strip_oriented.unorientable_pieces, 1u);
  EXPECT_EQ(strip_oriented.unorientable_triangles, 16u);
  EXPECT_GT(strip_oriented.turned, 0u);
  for (size_t t = 0; t < strip.triangle_count(); ++t)
    EXPECT_GE(strip.facet_normal(t).z(), 0.0) << "triangle " << t;
  EXPECT_EQ(strip.orient_consistently().turned, 0u);  // settled: a second pass turns nothing
  // the fan and the consistent meshes have no such piece
  EXPECT_EQ(fan.orient_consistently().unorientable_pieces, 0u);
  EXPECT_EQ(box.orient_consistently().unorientable_pieces, 0u);
}

// a sheet folded along x = 0 by +-20 degrees (a roof, 2 x 2 quads), triangulated so that every
// inner vertex sits on the fold: the corner normals there are the closed form (0, 0, 1) for
// the fold's two sides, and the facet normal elsewhere
TriangleMesh folded_sheet() {
  TriangleMesh mesh;
  const double slope = std::tan(20.0 * M_PI / 180.0);
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 2; ++i)
      mesh.vertices.emplace_back(i - 1.0, j - 1.0, -slope * std::abs(i - 1.0));
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int a = 3 * j + i;
      mesh.triangles.push_back({a, a + 1, a + 4});
      mesh.triangles.push_back({a, a + 4, a + 3});
    }
  return mesh;
}

// A roof folded along x = 1, its right side split at m = (1, 0.5) on the fold while the left
// side's facet keeps the whole edge (1, 0)-(1, 1): a T-junction. m has only the right side's
// facets around it, and the edge, one facet on each side, used to split the fans at (1, 0)
// and (1, 1): every normal on the fold leaned to its own side, by half the fold's 22 deg (a
// wavy sheet with such splits had its offset layer bent 0.03 mm and the arm slowed to 0.03
// mm/s). The facet across counts at m as a corner of angle pi and joins the fans at the
// edge's ends: on the fold every normal is straight up, as on the same roof unsplit.
TEST(TriangleMesh, ATJunctionOnAFoldWeighsBothSides) {
  const double slope = 0.2;
  TriangleMesh roof;
  roof.vertices = {{0, 0, 0}, {1, 0, slope}, {1, 1, slope},  {0, 1, 0},
                   {2, 0, 0}, {2, 1, 0},     {1, 0.5, slope}};
  roof.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 6}, {6, 4, 5}, {6, 5, 2}};
  const auto normals = roof.corner_normals(60.0 * M_PI / 180.0);
  for (size_t t = 0; t < roof.triangle_count(); ++t)
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3& p = roof.vertices[roof.triangles[t][corner]];
      const Vec3 expected = p.x() == 1.0 ? Vec3(0, 0, 1) : roof.facet_normal(t);
      EXPECT_LT((normals[t][corner] - expected).norm(), 1e-12)
          << "triangle " << t << " corner " << corner << " at (" << p.transpose() << ")";
    }
}

TEST(TriangleMesh, CornerNormalsAverageAFansFacetsByTheirAngles) {
  const TriangleMesh sheet = folded_sheet();
  const auto normals = sheet.corner_normals(60.0 * M_PI / 180.0);
  ASSERT_EQ(normals.size(), sheet.triangle_count());
  for (size_t t = 0; t < sheet.triangle_count(); ++t)
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3& p = sheet.vertices[sheet.triangles[t][corner]];
      // on the fold both sides weigh equally (the same angles on each side): straight up
      const Vec3 expected = p.x() == 0.0 ? Vec3(0, 0, 1) : sheet.facet_normal(t);
      EXPECT_LT((normals[t][corner] - expected).norm(), 1e-12)
          << "triangle " << t << " corner " << corner;
    }
  // a crease angle below the fold's 40 degrees keeps each side's own normal
  const auto creased = sheet.corner_normals(30.0 * M_PI / 180.0);
  for (size_t t = 0; t < sheet.triangle_count(); ++t)
    for (int corner = 0; corner < 3; ++corner)
      EXPECT_LT((creased[t][corner] - sheet.facet_normal(t)).norm(), 1e-12);
}

// an STL may hang a hidden facet on the top's diagonal (three facets on one edge), or touch
// another surface at one vertex; neither tilts the top's normals (it tilted the offset layers
// of a flat top by 13 degrees at the diagonal's ends); a facet's duplicate changes nothing
TEST(TriangleMesh, CornerNormalsLeaveOutFacetsMetAtANonManifoldEdgeOrAVertexAlone) {
  TriangleMesh top;
  top.vertices = {{-10, -10, 1}, {10, -10, 1}, {10, 10, 1}, {-10, 10, 1}};
  top.triangles = {{0, 1, 2}, {0, 2, 3}};
  const double crease = 60.0 * M_PI / 180.0;
  // a facet under the top on its diagonal, facing up 19.5 degrees from vertical
  TriangleMesh hung = top;
  hung.vertices.emplace_back(10, -10, -4);
  hung.triangles.push_back({0, 4, 2});
  ASSERT_GT(hung.facet_normal(2).z(), std::cos(crease));  // within the crease angle
  // a facet tilted 26.6 degrees touching the top's corner 2 only
  TriangleMesh touching = top;
  touching.vertices.emplace_back(20, 10, 1);
  touching.vertices.emplace_back(10, 20, 1 + 5);
  touching.triangles.push_back({2, 4, 5});
  ASSERT_GT(touching.facet_normal(2).z(), std::cos(crease));
  for (const TriangleMesh* mesh : {&hung, &touching}) {
    const auto normals = mesh->corner_normals(crease);
    for (size_t t = 0; t < 2; ++t)
      for (int corner = 0; corner < 3; ++corner)
        EXPECT_LT((normals[t][corner] - Vec3(0, 0, 1)).norm(), 1e-12)
            << "triangle " << t << " corner " << corner;
    // the other surface keeps its own facet normal
    for (int corner = 0; corner < 3; ++corner)
      EXPECT_LT((normals[2][corner] - mesh->facet_normal(2)).norm(), 1e-12);
  }
  // the folded sheet with one facet twice, once turned over: the same normals as without
  const TriangleMesh sheet = folded_sheet();
  TriangleMesh doubled = sheet;
  doubled.triangles.push_back(sheet.triangles[2]);
  doubled.triangles.push_back(
      {sheet.triangles[5][0], sheet.triangles[5][2], sheet.triangles[5][1]});
  const auto expected = sheet.corner_normals(crease);
  const auto normals = doubled.corner_normals(crease);
  for (size_t t = 0; t < sheet.triangle_count(); ++t)
    for (int corner = 0; corner < 3; ++corner)
      EXPECT_LT((normals[t][corner] - expected[t][corner]).norm(), 1e-12)
          << "triangle " << t << " corner " << corner;
  for (int corner = 0; corner < 3; ++corner)
    EXPECT_LT((normals[sheet.triangle_count()][corner] - expected[2][corner]).norm(), 1e-12);
}

}  // namespace
}  // namespace depotwin
