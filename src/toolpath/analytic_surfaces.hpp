// Analytic test parts: height fields z = f(x, y) tessellated on a grid whose vertices lie
// exactly on the surface, as a closed solid (the surface, side walls and a bottom, so a
// physics engine can load it as a mesh with a volume) or as the surface alone, with optional
// rectangular or circular holes. They stand in for the parts of Shembekar et al. (specimen
// A's curved beam, the car bonnet, the fillet of their Fig. 4) and give tests exact answers.
//
// Tessellation: a tensor grid over the footprint; each cell is split into two triangles along
// its (x_min, y_min)-(x_max, y_max) diagonal, counter-clockwise seen from above. Nodes are
// spaced at most `cell_mm` apart, finer inside the field's and the options' zones, uniformly
// between break points, and always include the field's break lines (where its curvature
// jumps, e.g. where a fillet meets a flat).
//
// Chordal error. On a triangle of a cell hx x hy the linear interpolant of f deviates from f
// by at most (1/8) (|f_xx| hx^2 + 2 |f_xy| hx hy + |f_yy| hy^2) (the interpolation error of a
// quadratic is sum_i lambda_i q(x_i - x), and the weights' variance in x is at most hx^2 / 4).
// `chordal_error_bound_mm` evaluates it over the grid (the Hessian sampled at each cell's
// corners and centre); each shape below states its figure at the defaults.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/triangle_mesh.hpp"

namespace depotwin {

// z = f(x, y) over the rectangle [x_min, x_max] x [y_min, y_max] (mm).
struct HeightField {
  std::function<double(double, double)> z;
  std::function<Eigen::Vector2d(double, double)> gradient;  // (df/dx, df/dy)
  std::function<Eigen::Matrix2d(double, double)> hessian;   // for the chordal error
  double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
  // x (or y) values where f's second derivative jumps: always grid nodes
  std::vector<double> x_breaks, y_breaks;
  // where the field asks for finer cells than TessellationOptions::cell_mm (tight curvature)
  struct Zone {
    double from_mm = 0.0;
    double to_mm = 0.0;
    double cell_mm = 1.0;
  };
  std::vector<Zone> x_zones, y_zones;

  Vec3 point(double x, double y) const { return Vec3(x, y, z(x, y)); }
  // the unit normal (-f_x, -f_y, 1) / |.|, pointing up
  Vec3 normal(double x, double y) const;
};

// Cells of at most cell_mm over [from_mm, to_mm] (finer than the default there).
using GridZone = HeightField::Zone;

// A hole through the part: every grid cell whose centre lies inside is left out (the hole's
// edge follows the cells).
struct SurfaceHole {
  enum class Shape { rectangle, circle };
  Shape shape = Shape::circle;
  Eigen::Vector2d center_mm = Eigen::Vector2d::Zero();
  Eigen::Vector2d half_size_mm = Eigen::Vector2d::Zero();  // rectangle
  double radius_mm = 0.0;                                  // circle

  static SurfaceHole rectangle(const Eigen::Vector2d& center, const Eigen::Vector2d& half_size);
  static SurfaceHole circle(const Eigen::Vector2d& center, double radius);
  bool contains(double x, double y) const;
};

struct TessellationOptions {
  double cell_mm = 1.0;                    // the grid's cell size at most
  std::vector<GridZone> x_zones, y_zones;  // finer cells (besides the field's own zones)
  bool solid = true;                       // closed solid; false: the surface alone
  // the bottom of the solid: flat, thickness_mm below the lowest point of the surface; or
  // parallel, thickness_mm below every point (a shell of constant vertical thickness)
  enum class Bottom { flat, parallel };
  Bottom bottom = Bottom::flat;
  double thickness_mm = 3.0;
  std::vector<SurfaceHole> holes;
};

// The mesh of the field: the surface's vertices lie exactly on it (f evaluated at the grid
// nodes). The solid adds walls along every boundary edge of the surface (outer edge and hole
// edges, subdivided at the surface's boundary vertices, so the mesh is watertight) and the
// bottom on the same grid. Orientation: outward (right-hand rule). InputError (key) for a
// non-positive cell size or thickness, an empty footprint, or a grid over 4e6 cells.
TriangleMesh tessellate(const HeightField& field, const TessellationOptions& options,
                        const std::string& key = "toolpath.surface");

// the grid's nodes along x (or y) as tessellate places them
std::vector<double> grid_nodes(double lo, double hi, double cell_mm,
                               const std::vector<GridZone>& zones,
                               const std::vector<double>& breaks);

// The bound above on |mesh - f| (vertical, mm) over the grid tessellate builds.
double chordal_error_bound_mm(const HeightField& field, const TessellationOptions& options);

// ---- shapes (each: its parameters with defaults, the field, the mesh) ----

// A spherical cap z = apex - R + sqrt(R^2 - x^2 - y^2) over a rectangle centred on the
// apex (concave: the bowl z = apex + R - sqrt(...)). The footprint's corners must lie
// inside the sphere's silhouette. Defaults: R 40, 40 x 40 mm, cells 1 mm: chordal error
// <= 0.018 mm (at the corners, slope 45 deg).
struct SphereCapParams {
  double radius_mm = 40.0;
  double half_x_mm = 20.0;
  double half_y_mm = 20.0;
  double apex_z_mm = 10.0;
  bool concave = false;
  TessellationOptions mesh{};
};
HeightField sphere_cap_field(const SphereCapParams& p, const std::string& key = "toolpath.surface");
TriangleMesh sphere_cap(const SphereCapParams& p, const std::string& key = "toolpath.surface");

// A cylinder with its axis along y: z = apex - R + sqrt(R^2 - x^2) (concave: apex + R -
// sqrt(...)), |x| <= half_x < R, |y| <= half_y. Defaults: R 30, 40 x 40 mm, cells 1 mm:
// chordal error <= 0.011 mm (at |x| = 20, slope 42 deg).
struct CylinderParams {
  double radius_mm = 30.0;
  double half_x_mm = 20.0;
  double half_y_mm = 20.0;
  double apex_z_mm = 10.0;
  bool concave = false;
  TessellationOptions mesh{};
};
HeightField cylinder_field(const CylinderParams& p, const std::string& key = "toolpath.surface");
TriangleMesh cylinder(const CylinderParams& p, const std::string& key = "toolpath.surface");

// Like Shembekar et al.'s specimen A: a circular arch along x, length x width, its crown
// `sag_mm` above its ends (which sit at z = 0; x in [-length/2, length/2], y in
// [-width/2, width/2]), a shell `thickness` thick (parallel bottom). Defaults: 65 x 14 mm,
// sag 6 mm (arc radius 91.0 mm, end slope 21 deg), 4 mm thick, cells 0.5 mm: chordal error
// <= 0.0005 mm.
struct CurvedBeamParams {
  double length_mm = 65.0;
  double width_mm = 14.0;
  double sag_mm = 6.0;
  TessellationOptions mesh = [] {
    TessellationOptions o;
    o.cell_mm = 0.5;
    o.bottom = TessellationOptions::Bottom::parallel;
    o.thickness_mm = 4.0;
    return o;
  }();
};
HeightField curved_beam_field(const CurvedBeamParams& p,
                              const std::string& key = "toolpath.surface");
TriangleMesh curved_beam(const CurvedBeamParams& p, const std::string& key = "toolpath.surface");

// A car-bonnet-like shell over x in [0, length] (rear to front), y in [-width/2, width/2]:
// gently doubly curved, z = g(x) - y^2 / (2 crown_radius_y) with g a parabola of radius
// crown_radius_x at the rear edge (g'(0) = 0), falling towards the front, and a rolled front
// edge: g continues tangentially into a circular arc of roll_radius that rolls down until
// the slope is roll_end_slope_deg at x = length. The lowest point is at z = 0. Defaults:
// 150 x 130 mm, radii 600 / 350 mm, a 15 mm roll down to 50 deg (the last 8 mm), 27.8 mm high;
// cells 2 mm, 0.25 mm in x over the roll: chordal error <= 0.004 mm.
struct CarBonnetParams {
  double length_mm = 150.0;
  double width_mm = 130.0;
  double crown_radius_x_mm = 600.0;
  double crown_radius_y_mm = 350.0;
  double roll_radius_mm = 15.0;
  double roll_end_slope_deg = 50.0;
  double roll_cell_mm = 0.25;  // the cells in x over the roll (a zone of the field)
  TessellationOptions mesh = [] {
    TessellationOptions o;
    o.cell_mm = 2.0;
    o.thickness_mm = 3.0;
    return o;
  }();
};
HeightField car_bonnet_field(const CarBonnetParams& p, const std::string& key = "toolpath.surface");
TriangleMesh car_bonnet(const CarBonnetParams& p, const std::string& key = "toolpath.surface");
// where the roll begins (x, mm)
double car_bonnet_roll_start_mm(const CarBonnetParams& p);

// A step along x (the paper's Fig. 4 case, where an arm slows at the fillet): flat at z = 0
// for x in [0, flat_before], a concave fillet of fillet_radius turning up to slope_deg, a
// straight slope, a convex fillet of the same radius back to flat at z = step_height, flat
// for flat_after; y in [-width/2, width/2]. Defaults: 20 mm flat, 2 mm fillets, 40 deg,
// 10 mm high (the slope 10.8 mm long in x), 20 mm flat, 30 mm wide; cells 1 mm, 0.1 mm in x over
// the fillets: chordal error <= 0.0014 mm (the flats and the slope are exact).
struct FilletStepParams {
  double flat_before_mm = 20.0;
  double fillet_radius_mm = 2.0;
  double slope_deg = 40.0;
  double step_height_mm = 10.0;
  double flat_after_mm = 20.0;
  double width_mm = 30.0;
  double fillet_cell_mm = 0.1;  // the cells in x over the fillets (zones of the field)
  TessellationOptions mesh = [] {
    TessellationOptions o;
    o.cell_mm = 1.0;
    o.thickness_mm = 3.0;
    return o;
  }();
};
HeightField fillet_step_field(const FilletStepParams& p,
                              const std::string& key = "toolpath.surface");
TriangleMesh fillet_step(const FilletStepParams& p, const std::string& key = "toolpath.surface");

}  // namespace depotwin
