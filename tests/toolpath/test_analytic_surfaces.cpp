// Analytic parts: vertices exactly on the surface, solids closed and outward, the chordal
// error within its bound (and the documented figures), and each shape's geometry (the beam's
// sag, the bonnet's roll, the fillet step's radii and slope).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "core/error.hpp"
#include "toolpath/analytic_surfaces.hpp"

namespace depotwin {
namespace {

// every undirected edge is used by exactly two triangles, once each way (closed, oriented)
void expect_closed(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> directed;
  for (const std::array<int, 3>& f : mesh.triangles)
    for (int c = 0; c < 3; ++c) ++directed[{f[c], f[(c + 1) % 3]}];
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto opposite = directed.find({edge.second, edge.first});
    if (count != 1 || opposite == directed.end() || opposite->second != 1) ++bad;
  }
  EXPECT_EQ(bad, 0) << "edges not shared by exactly two oppositely oriented triangles";
}

// the enclosed volume by the divergence theorem (positive for outward triangles)
double volume_mm3(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const std::array<int, 3>& f : mesh.triangles)
    six_v += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]]));
  return six_v / 6.0;
}

// the largest |z - f| at the centroids and edge midpoints of the top triangles
double measured_chordal_error(const HeightField& field, const TriangleMesh& mesh) {
  double worst = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.facet_normal(t).z() <= 0.0) continue;
    const std::array<int, 3>& f = mesh.triangles[t];
    const Vec3& a = mesh.vertices[f[0]];
    const Vec3& b = mesh.vertices[f[1]];
    const Vec3& c = mesh.vertices[f[2]];
    for (const Vec3& p :
         {Vec3((a + b + c) / 3), Vec3((a + b) / 2), Vec3((b + c) / 2), Vec3((c + a) / 2)})
      worst = std::max(worst, std::abs(p.z() - field.z(p.x(), p.y())));
  }
  return worst;
}

void expect_vertices_on_surface(const HeightField& field, const TriangleMesh& mesh) {
  for (const Vec3& v : mesh.vertices) ASSERT_EQ(v.z(), field.z(v.x(), v.y()));
}

// the curvature of a profile z(x) from the field's derivatives in x
double curvature_x(const HeightField& field, double x, double y) {
  const double slope = field.gradient(x, y).x();
  return std::abs(field.hessian(x, y)(0, 0)) / std::pow(1.0 + slope * slope, 1.5);
}

TEST(AnalyticSurfaces, EveryShapeClosedOnTheSurfaceAndWithinItsChordalBound) {
  struct Case {
    const char* name;
    HeightField field;
    TessellationOptions mesh;
    double documented_bound_mm;
  };
  const std::vector<Case> cases = {
      {"sphere_cap", sphere_cap_field({}), SphereCapParams{}.mesh, 0.018},
      {"cylinder", cylinder_field({}), CylinderParams{}.mesh, 0.011},
      {"curved_beam", curved_beam_field({}), CurvedBeamParams{}.mesh, 0.0005},
      {"car_bonnet", car_bonnet_field({}), CarBonnetParams{}.mesh, 0.004},
      {"fillet_step", fillet_step_field({}), FilletStepParams{}.mesh, 0.0014},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    TessellationOptions surface_only = c.mesh;
    surface_only.solid = false;
    const TriangleMesh surface = tessellate(c.field, surface_only);
    expect_vertices_on_surface(c.field, surface);
    const double bound = chordal_error_bound_mm(c.field, c.mesh);
    EXPECT_LE(bound, c.documented_bound_mm);
    const double measured = measured_chordal_error(c.field, surface);
    EXPECT_LE(measured, bound);
    EXPECT_GT(measured, 0.3 * bound);  // and the bound is not loose

    const TriangleMesh solid = tessellate(c.field, c.mesh);
    expect_closed(solid);
    EXPECT_GT(volume_mm3(solid), 0.0);
    for (const Vec3& v : solid.vertices) ASSERT_TRUE(v.allFinite());
  }
}

TEST(AnalyticSurfaces, SolidWithHolesIsClosed) {
  SphereCapParams params;
  params.mesh.holes = {SurfaceHole::circle(Eigen::Vector2d(5, 5), 4.0),
                       SurfaceHole::rectangle(Eigen::Vector2d(-10, 0), Eigen::Vector2d(3, 6))};
  const TriangleMesh mesh = sphere_cap(params);
  expect_closed(mesh);
  const TriangleMesh whole = sphere_cap(SphereCapParams{});
  EXPECT_LT(volume_mm3(mesh), volume_mm3(whole));
}

TEST(AnalyticSurfaces, CurvedBeamIsSpecimenA) {
  const CurvedBeamParams params;
  const HeightField field = curved_beam_field(params);
  EXPECT_DOUBLE_EQ(field.z(0.0, 0.0), 6.0);  // crown 6 mm above the ends
  EXPECT_NEAR(field.z(-32.5, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(field.z(32.5, 3.0), 0.0, 1e-12);
  const TriangleMesh mesh = curved_beam(params);
  Vec3 lo, hi;
  mesh.bounds(lo, hi);
  EXPECT_EQ(hi - lo, Vec3(65.0, 14.0, 10.0));  // 6 mm sag + 4 mm below the ends
  // a shell 4 mm thick under every point: its volume is exactly 4 x the footprint
  EXPECT_NEAR(volume_mm3(mesh), 4.0 * 65.0 * 14.0, 1e-9);
  // a circular arc: constant curvature 1 / 91.02 mm
  const double radius = (32.5 * 32.5 + 36.0) / 12.0;
  for (double x : {-30.0, -5.0, 0.0, 20.0})
    EXPECT_NEAR(curvature_x(field, x, 0.0), 1.0 / radius, 1e-12);
}

TEST(AnalyticSurfaces, CarBonnetRollsDownAtTheFront) {
  const CarBonnetParams params;
  const HeightField field = car_bonnet_field(params);
  const double x_r = car_bonnet_roll_start_mm(params);
  EXPECT_NEAR(x_r, 141.96, 0.01);
  // the lowest point (front corners) at z = 0, the highest at the rear centre
  EXPECT_NEAR(field.z(150.0, 65.0), 0.0, 1e-12);
  EXPECT_NEAR(field.z(150.0, -65.0), 0.0, 1e-12);
  EXPECT_EQ(field.gradient(0.0, 0.0), Eigen::Vector2d(0, 0));
  // the roll ends at 50 deg, tangent to the crown where it begins, radius 15 mm
  EXPECT_NEAR(std::atan(-field.gradient(150.0, 0.0).x()), deg_to_rad(50.0), 1e-12);
  EXPECT_NEAR(field.gradient(x_r - 1e-9, 0.0).x(), field.gradient(x_r + 1e-9, 0.0).x(), 1e-9);
  EXPECT_NEAR(field.z(x_r - 1e-9, 0.0), field.z(x_r + 1e-9, 0.0), 1e-9);
  for (double x : {x_r + 0.5, 146.0, 150.0})
    EXPECT_NEAR(curvature_x(field, x, 10.0), 1.0 / 15.0, 1e-9);
  // gently doubly curved elsewhere
  EXPECT_NEAR(field.hessian(50.0, 20.0)(0, 0), -1.0 / 600.0, 1e-15);
  EXPECT_NEAR(field.hessian(50.0, 20.0)(1, 1), -1.0 / 350.0, 1e-15);
  const TriangleMesh mesh = car_bonnet(params);
  Vec3 lo, hi;
  mesh.bounds(lo, hi);
  EXPECT_EQ(lo.head<2>(), Eigen::Vector2d(0, -65));
  EXPECT_EQ(hi.head<2>(), Eigen::Vector2d(150, 65));
  EXPECT_EQ(lo.z(), -3.0);  // flat bottom 3 mm below the lowest point
}

TEST(AnalyticSurfaces, FilletStepHasItsFilletsAndSlope) {
  const FilletStepParams params;
  const HeightField field = fillet_step_field(params);
  EXPECT_EQ(field.z(10.0, 0.0), 0.0);
  EXPECT_EQ(field.z(field.x_max - 5.0, 0.0), 10.0);
  const double run = 2.0 * std::sin(deg_to_rad(40.0));
  const double rise = 2.0 * (1.0 - std::cos(deg_to_rad(40.0)));
  const double slope_length = (10.0 - 2.0 * rise) / std::tan(deg_to_rad(40.0));
  EXPECT_NEAR(field.x_max, 20.0 + 2.0 * run + slope_length + 20.0, 1e-12);
  EXPECT_NEAR(slope_length, 10.8, 0.01);
  const double mid = 20.0 + run + 0.5 * slope_length;
  EXPECT_NEAR(field.gradient(mid, 0.0).x(), std::tan(deg_to_rad(40.0)), 1e-12);
  // both fillets have radius 2 mm (curvature 0.5 / mm), the flats and slope none
  EXPECT_NEAR(curvature_x(field, 20.0 + 0.5 * run, 0.0), 0.5, 1e-9);
  EXPECT_NEAR(curvature_x(field, 20.0 + 1.5 * run + slope_length, 0.0), 0.5, 1e-9);
  EXPECT_EQ(curvature_x(field, mid, 0.0), 0.0);
  // tangent where the fillet meets the flat and the slope
  for (double x : {20.0, 20.0 + run, 20.0 + run + slope_length, 20.0 + 2.0 * run + slope_length})
    EXPECT_NEAR(field.gradient(x - 1e-9, 0.0).x(), field.gradient(x + 1e-9, 0.0).x(), 1e-6);
  // the grid has nodes on the four break lines
  const TriangleMesh mesh = fillet_step(params);
  for (double x : field.x_breaks) {
    bool found = false;
    for (const Vec3& v : mesh.vertices) found = found || v.x() == x;
    EXPECT_TRUE(found) << x;
  }
}

TEST(AnalyticSurfaces, BadParametersAreInputErrors) {
  SphereCapParams sphere;
  sphere.half_x_mm = 40.0;
  EXPECT_THROW(sphere_cap(sphere), InputError);
  CylinderParams cyl;
  cyl.mesh.cell_mm = 0.0;
  EXPECT_THROW(cylinder(cyl), InputError);
  CurvedBeamParams beam;
  beam.sag_mm = 40.0;
  EXPECT_THROW(curved_beam(beam), InputError);
  FilletStepParams step;
  step.step_height_mm = 0.5;  // lower than its two fillets
  EXPECT_THROW(fillet_step(step), InputError);
  CarBonnetParams bonnet;
  bonnet.mesh.cell_mm = 0.001;  // 2e10 cells
  EXPECT_THROW(car_bonnet(bonnet), InputError);
}

}  // namespace
}  // namespace depotwin
