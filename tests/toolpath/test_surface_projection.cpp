// Projection straight down onto a surface (Embree BVH, exact double recompute): points on the
// hit triangle's plane, on the analytic surface at mesh vertices, within the chordal bound
// elsewhere; smooth normals within the tessellation bound; holes and the outside give no hit,
// a point exactly on the outline or a hole's edge does; the first hit on a closed solid is its
// top; a surface met on its back (wound facing down) gives the normals of the side seen.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/pose.hpp"
#include "toolpath/analytic_surfaces.hpp"
#include "toolpath/surface_projection.hpp"

namespace depotwin {
namespace {

// the distance of p from the plane of triangle t
double plane_distance(const TriangleMesh& mesh, int t, const Vec3& p) {
  const std::array<int, 3>& f = mesh.triangles[static_cast<std::size_t>(t)];
  return std::abs(mesh.facet_normal(static_cast<std::size_t>(t)).dot(p - mesh.vertices[f[0]]));
}

// the longest edge of the surface's triangles (those facing up), 3-D
double longest_top_edge(const TriangleMesh& mesh) {
  double longest = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.facet_normal(t).z() <= 0.0) continue;
    for (int c = 0; c < 3; ++c)
      longest = std::max(longest, (mesh.vertices[mesh.triangles[t][c]] -
                                   mesh.vertices[mesh.triangles[t][(c + 1) % 3]])
                                      .norm());
  }
  return longest;
}

struct Measured {
  int hits = 0;
  int at_vertices = 0;
  double plane = 0.0;          // largest distance from the hit triangle's plane
  double vertex_error = 0.0;   // largest |z - f| at mesh vertices
  double chordal = 0.0;        // largest |z - f|
  double normal_all = 0.0;     // largest angle to the analytic normal (rad)
  double normal_inside = 0.0;  // ... two cells or more inside the footprint
};

// project a grid at half the mesh's cell (every other point on a vertex) and compare
Measured measure(const HeightField& field, const TriangleMesh& mesh, double cell) {
  const SurfaceProjector projector(mesh);
  Measured m;
  const double step = 0.5 * cell;
  const int nx = static_cast<int>(std::lround((field.x_max - field.x_min) / step));
  const int ny = static_cast<int>(std::lround((field.y_max - field.y_min) / step));
  std::vector<Vec2> xy;
  for (int j = 1; j < ny; ++j)  // inside the footprint: its very edge is ambiguous
    for (int i = 1; i < nx; ++i) xy.emplace_back(field.x_min + i * step, field.y_min + j * step);
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(xy, hits);
  for (std::size_t k = 0; k < xy.size(); ++k) {
    const double x = xy[k].x(), y = xy[k].y();
    const std::optional<SurfaceHit>& hit = hits[k];
    if (!hit) continue;
    ++m.hits;
    EXPECT_EQ(hit->point_mm.x(), x);
    EXPECT_EQ(hit->point_mm.y(), y);
    m.plane = std::max(m.plane, plane_distance(mesh, hit->triangle, hit->point_mm));
    const double dz = std::abs(hit->point_mm.z() - field.z(x, y));
    m.chordal = std::max(m.chordal, dz);
    const int i = static_cast<int>(k % static_cast<std::size_t>(nx - 1)) + 1;
    const int j = static_cast<int>(k / static_cast<std::size_t>(nx - 1)) + 1;
    if (i % 2 == 0 && j % 2 == 0) {
      ++m.at_vertices;
      m.vertex_error = std::max(m.vertex_error, dz);
    }
    const double angle = axis_angle_rad(hit->normal, field.normal(x, y));
    m.normal_all = std::max(m.normal_all, angle);
    const double margin = 2.0 * cell;
    if (x > field.x_min + margin && x < field.x_max - margin && y > field.y_min + margin &&
        y < field.y_max - margin)
      m.normal_inside = std::max(m.normal_inside, angle);
  }
  return m;
}

// Tessellation bounds for the smooth normal (kappa: the largest principal curvature, delta:
// the longest 3-D edge). Each facet of a triangle whose corners lie on the surface is
// parallel to the surface normal somewhere within it, and the normal turns at most kappa per
// mm, so facet normals within one edge of a point differ from its normal by about kappa
// delta; angle-weighted averages and barycentric interpolation of unit vectors stay within
// that: angle <= kappa delta (first order; what the boundary's one-sided vertex fans reach).
// Inside, each vertex's fan on this grid is point-symmetric, the first-order terms cancel,
// and the error is second order: angle <= (kappa delta)^2.
void expect_normals_within_bounds(const Measured& m, double kappa, double delta) {
  EXPECT_LE(m.normal_all, kappa * delta);
  EXPECT_LE(m.normal_inside, (kappa * delta) * (kappa * delta));
}

TEST(SurfaceProjection, SphereCap) {
  SphereCapParams params;  // R 40 mm, 40 x 40 mm footprint, 1 mm cells
  for (bool solid : {false, true}) {
    params.mesh.solid = solid;
    const HeightField field = sphere_cap_field(params);
    const TriangleMesh mesh = sphere_cap(params);
    const Measured m = measure(field, mesh, params.mesh.cell_mm);
    EXPECT_EQ(m.hits, 79 * 79);  // every point inside the footprint hits
    EXPECT_EQ(m.at_vertices, 39 * 39);
    EXPECT_LE(m.plane, 1e-9);
    EXPECT_LE(m.vertex_error, 1e-9);
    const double chordal_bound = chordal_error_bound_mm(field, params.mesh);
    EXPECT_LE(chordal_bound, 0.018);  // as documented for the defaults
    EXPECT_LE(m.chordal, chordal_bound);
    EXPECT_GT(m.chordal, 0.5 * chordal_bound);  // the bound is not loose
    // kappa = 1 / 40; delta = 2.0 mm (the diagonal at a corner, slope 45 deg):
    // bounds 0.05 rad everywhere, 0.0025 rad inside (measured 0.024 and 0.00046)
    const double delta = longest_top_edge(mesh);
    EXPECT_NEAR(delta, 2.0, 0.1);
    expect_normals_within_bounds(m, 1.0 / params.radius_mm, delta);
  }
}

TEST(SurfaceProjection, ConvexAndConcaveCylinder) {
  CylinderParams params;  // R 30 mm along y, |x| <= 20, 1 mm cells
  for (bool concave : {false, true}) {
    params.concave = concave;
    const HeightField field = cylinder_field(params);
    const TriangleMesh mesh = cylinder(params);
    const Measured m = measure(field, mesh, params.mesh.cell_mm);
    EXPECT_EQ(m.hits, 79 * 79);
    EXPECT_LE(m.plane, 1e-9);
    EXPECT_LE(m.vertex_error, 1e-9);
    EXPECT_LE(m.chordal, chordal_error_bound_mm(field, params.mesh));
    // kappa = 1 / 30, delta = 1.67 mm: bounds 0.056 rad and 0.0031 rad (measured 0.022,
    // 0.00046)
    expect_normals_within_bounds(m, 1.0 / params.radius_mm, longest_top_edge(mesh));
  }
}

TEST(SurfaceProjection, HolesAndOutsideGiveNoHit) {
  SphereCapParams params;
  params.mesh.holes = {SurfaceHole::circle(Vec2(5, 5), 4.0),
                       SurfaceHole::rectangle(Vec2(-10, 0), Vec2(3, 6))};
  for (bool solid : {false, true}) {
    params.mesh.solid = solid;
    const SurfaceProjector projector(sphere_cap(params));
    EXPECT_FALSE(projector.project_down(5.0, 5.0));
    EXPECT_FALSE(projector.project_down(7.5, 5.0));
    EXPECT_FALSE(projector.project_down(-10.0, 0.0));
    EXPECT_FALSE(projector.project_down(-12.5, 5.5));
    EXPECT_FALSE(projector.project_down(25.0, 0.0));  // beyond the edge
    EXPECT_FALSE(projector.project_down(0.0, -20.5));
    EXPECT_FALSE(projector.height_at(5.0, 5.0));
    // beside the holes the surface is there
    EXPECT_TRUE(projector.project_down(5.0, 10.5));
    EXPECT_TRUE(projector.project_down(-10.0, 6.5));
    EXPECT_TRUE(projector.project_down(0.0, 0.0));
  }
}

TEST(SurfaceProjection, PointsOnTheOutlineHitTheTopOnEverySide) {
  // a solid z = 1 + 0.2 x + 0.1 y over [0, 10] x [0, 6] with a 2 x 2 mm square hole at (5, 3):
  // a ray exactly on the outline or the hole's edge meets only triangle edges (and walls),
  // which Embree counts on one side; every such point is on the top, at its exact height
  HeightField field;
  field.z = [](double x, double y) { return 1.0 + 0.2 * x + 0.1 * y; };
  field.gradient = [](double, double) { return Vec2(0.2, 0.1); };
  field.hessian = [](double, double) { return Eigen::Matrix2d::Zero().eval(); };
  field.x_max = 10.0;
  field.y_max = 6.0;
  TessellationOptions options;
  options.holes = {SurfaceHole::rectangle(Vec2(5, 3), Vec2(1, 1))};
  const SurfaceProjector projector(tessellate(field, options));
  std::vector<Vec2> rim;
  for (int i = 0; i <= 20; ++i) {
    const double x = 0.5 * i, y = 0.3 * i;
    rim.insert(rim.end(), {{x, 0.0}, {x, 6.0}, {0.0, y}, {10.0, y}});
  }
  for (int i = 0; i <= 4; ++i) {
    const double t = 4.0 + 0.5 * i;
    rim.insert(rim.end(), {{t, 2.0}, {t, 4.0}, {4.0, t - 1.0}, {6.0, t - 1.0}});
  }
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(rim, hits);
  for (std::size_t k = 0; k < rim.size(); ++k) {
    const double x = rim[k].x(), y = rim[k].y();
    const std::optional<SurfaceHit> hit = projector.project_down(x, y);
    ASSERT_TRUE(hit) << x << ", " << y;
    ASSERT_TRUE(hits[k]) << x << ", " << y;
    EXPECT_TRUE(hit->faces_up()) << x << ", " << y;
    EXPECT_EQ(hit->point_mm, hits[k]->point_mm);
    EXPECT_EQ(hit->point_mm.head<2>(), rim[k]);
    EXPECT_NEAR(hit->point_mm.z(), field.z(x, y), 1e-12);
  }
  // a micrometre off the outline, or inside the hole, is off the part
  for (const Vec2& off : {Vec2(-1e-3, 3.0), Vec2(10.001, 3.0), Vec2(5.0, -1e-3), Vec2(5.0, 6.001),
                          Vec2(5.0, 3.0), Vec2(4.001, 2.999)})
    EXPECT_FALSE(projector.project_down(off.x(), off.y())) << off.transpose();
}

TEST(SurfaceProjection, FirstHitOnAClosedSolidIsTheTop) {
  CurvedBeamParams params;  // a 4 mm shell: the ray crosses the top, then the bottom
  const HeightField field = curved_beam_field(params);
  const SurfaceProjector projector(curved_beam(params));
  for (double x : {-30.1, -10.3, 0.2, 17.7, 32.0}) {
    const std::optional<SurfaceHit> hit = projector.project_down(x, 1.3);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->point_mm.z(), field.z(x, 1.3), chordal_error_bound_mm(field, params.mesh));
    EXPECT_TRUE(hit->faces_up());
    EXPECT_GT(hit->facet_normal.z(), 0.9);
    EXPECT_NEAR(*projector.height_at(x, 1.3), hit->point_mm.z(), 1e-12);
  }
}

TEST(SurfaceProjection, SmoothNormalsStopAtTheRim) {
  // the top corner normals on a solid's rim ignore the wall (a crease); on the sphere cap's
  // edge cell the normal stays within the surface bound instead of leaning out by ~25 deg
  SphereCapParams params;
  const HeightField field = sphere_cap_field(params);
  const SurfaceProjector projector(sphere_cap(params));
  const std::optional<SurfaceHit> hit = projector.project_down(19.75, 0.25);
  ASSERT_TRUE(hit);
  EXPECT_LT(axis_angle_rad(hit->normal, field.normal(19.75, 0.25)), 0.03);
}

// a facet hung under a flat top on its diagonal (a non-manifold STL: three facets on one edge)
// is as near as the top along the diagonal, where Embree may name it: the point is on the top,
// which is what is seen beside it, with the top's normal (it tilted the offset layers 19 deg);
// on a ridge, where both sides are seen, each point keeps the side it was found on
TEST(SurfaceProjection, APointOnAnEdgeIsOnTheTriangleSeenBesideIt) {
  TriangleMesh top;
  top.vertices = {{-10, -10, 1}, {10, -10, 1}, {10, 10, 1}, {-10, 10, 1}, {10, -10, -4}};
  top.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 4, 2}};  // the last one hangs under the diagonal
  const SurfaceProjector projector(top);
  std::vector<Vec2> diagonal;
  for (int k = -40; k <= 40; ++k) diagonal.emplace_back(0.25 * k, 0.25 * k);
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(diagonal, hits);
  for (std::size_t k = 0; k < diagonal.size(); ++k) {
    const std::optional<SurfaceHit> single =
        projector.project_down(diagonal[k].x(), diagonal[k].y());
    for (const std::optional<SurfaceHit>& hit : {hits[k], single}) {
      ASSERT_TRUE(hit) << diagonal[k].transpose();
      EXPECT_NE(hit->triangle, 2) << diagonal[k].transpose();
      EXPECT_NEAR(hit->point_mm.z(), 1.0, 1e-12);
      EXPECT_LT((hit->normal - Vec3::UnitZ()).norm(), 1e-12) << diagonal[k].transpose();
    }
  }
  // a roof (slopes of 0.2 either side of x = 0): a point on the ridge is on a slope, both seen
  TriangleMesh roof;
  roof.vertices = {{-5, -5, 0}, {0, -5, 1}, {0, 5, 1}, {-5, 5, 0}, {5, -5, 0}, {5, 5, 0}};
  roof.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  const SurfaceProjector roof_projector(roof);
  for (double y : {-2.5, 0.0, 3.25}) {
    const std::optional<SurfaceHit> ridge = roof_projector.project_down(0.0, y);
    ASSERT_TRUE(ridge);
    EXPECT_NEAR(ridge->point_mm.z(), 1.0, 1e-12);
    EXPECT_NEAR(std::abs(ridge->facet_normal.x()), 0.2 / std::sqrt(1.04), 1e-12);
  }
}

// two plates 10 um apart in height joined by a sliver 0.1 um wide (mesh noise), its lower
// edge on the line y = 0: a point there was taken on the sliver (n_z 0.01, no surface to
// print) and the whole line was dropped; it is on the flat plate met beside it, at its height
TEST(SurfaceProjection, APointOnASliversEdgeIsOnTheFlatFacetBesideIt) {
  TriangleMesh mesh;
  mesh.vertices = {{-10, -8, 5},     {10, -8, 5},       {10, 0, 5},    {-10, 0, 5},
                   {10, 1e-4, 5.01}, {-10, 1e-4, 5.01}, {10, 8, 5.01}, {-10, 8, 5.01}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}, {3, 4, 5}, {5, 4, 6}, {5, 6, 7}};
  ASSERT_LT(mesh.facet_normal(2).z(), 0.02);  // the sliver
  const SurfaceProjector projector(mesh);
  std::vector<Vec2> on_the_edge;
  for (int k = -8; k <= 8; ++k) on_the_edge.emplace_back(k, 0.0);
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(on_the_edge, hits);
  for (std::size_t k = 0; k < on_the_edge.size(); ++k) {
    ASSERT_TRUE(hits[k]) << k;
    EXPECT_TRUE(hits[k]->faces_up()) << on_the_edge[k].transpose();
    EXPECT_LT((hits[k]->facet_normal - Vec3::UnitZ()).norm(), 1e-12);
    EXPECT_NEAR(hits[k]->point_mm.z(), 5.0, 1e-12);
  }
}

TEST(SurfaceProjection, BatchEqualsSingleRays) {
  CylinderParams params;
  params.mesh.holes = {SurfaceHole::circle(Vec2(0, 0), 5.0)};
  const SurfaceProjector projector(cylinder(params));
  std::vector<Vec2> xy;
  for (int k = 0; k < 1000; ++k)  // scattered, some outside or in the hole
    xy.emplace_back(-25.0 + std::fmod(k * 0.618034 * 50.0, 50.0),
                    -25.0 + std::fmod(k * 0.754878 * 50.0, 50.0));
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down(xy, hits);
  ASSERT_EQ(hits.size(), xy.size());
  int found = 0;
  for (std::size_t k = 0; k < xy.size(); ++k) {
    const std::optional<SurfaceHit> single = projector.project_down(xy[k].x(), xy[k].y());
    ASSERT_EQ(single.has_value(), hits[k].has_value()) << k;
    if (!single) continue;
    ++found;
    EXPECT_EQ(single->triangle, hits[k]->triangle);
    EXPECT_EQ(single->point_mm, hits[k]->point_mm);
    EXPECT_EQ(single->normal, hits[k]->normal);
  }
  EXPECT_GT(found, 500);
  EXPECT_LT(found, 1000);
}

// a surface wound facing down is met from above on its back: the hit gives the normals of
// that side, the same as the surface wound facing up gives (it was an unprintable underside)
TEST(SurfaceProjection, AnInvertedMeshIsSeenFromAboveOnItsBack) {
  SphereCapParams params;
  params.mesh.solid = false;
  const TriangleMesh up = sphere_cap(params);
  TriangleMesh down = up;
  for (std::array<int, 3>& f : down.triangles) std::swap(f[1], f[2]);
  ASSERT_LT(down.facet_normal(0).z(), 0.0);
  const SurfaceProjector upward(up), downward(down);
  for (const auto& [x, y] : {std::pair{1.0, 2.0}, std::pair{-3.5, 0.25}, std::pair{0.0, 0.0}}) {
    const std::optional<SurfaceHit> seen = downward.project_down(x, y);
    const std::optional<SurfaceHit> reference = upward.project_down(x, y);
    ASSERT_TRUE(seen && reference) << x << ", " << y;
    EXPECT_TRUE(seen->faces_up()) << x << ", " << y;
    EXPECT_EQ(seen->triangle, reference->triangle);
    EXPECT_NEAR((seen->point_mm - reference->point_mm).norm(), 0.0, 1e-12);
    EXPECT_NEAR((seen->facet_normal - reference->facet_normal).norm(), 0.0, 1e-12);
    EXPECT_NEAR((seen->normal - reference->normal).norm(), 0.0, 1e-12);
  }
}

TEST(SurfaceProjection, EmptyMeshIsNeverHit) {
  const SurfaceProjector projector{TriangleMesh{}};
  EXPECT_FALSE(projector.project_down(0.0, 0.0));
  std::vector<std::optional<SurfaceHit>> hits;
  projector.project_down({Vec2(0, 0), Vec2(1, 1)}, hits);
  EXPECT_FALSE(hits[0] || hits[1]);
}

}  // namespace
}  // namespace depotwin
