#include "toolpath/analytic_surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kMaxCells = 4e6;

using Vec2d = Eigen::Vector2d;
using Mat2d = Eigen::Matrix2d;

void require(bool ok, const std::string& key, const std::string& message) {
  if (!ok) throw InputError(key, message);
}

bool positive(double v) {
  return std::isfinite(v) && v > 0.0;
}

// A profile z = g(x) in pieces, each a quadratic a + b u + c u^2 (u = x - origin) or a circular
// arc z = zc + sign sqrt(r^2 - (x - xc)^2) (sign +1: convex, the upper half; -1: concave).
struct ProfilePiece {
  double x0 = 0.0, x1 = 0.0;
  bool arc = false;
  double origin = 0.0, a = 0.0, b = 0.0, c = 0.0;
  double xc = 0.0, zc = 0.0, r = 0.0, sign = 1.0;
};

struct Profile {
  std::vector<ProfilePiece> pieces;

  const ProfilePiece& at(double x) const {
    for (const ProfilePiece& p : pieces)
      if (x <= p.x1) return p;
    return pieces.back();
  }
  double root(const ProfilePiece& p, double x) const {
    const double u = x - p.xc;
    return std::sqrt(std::max(p.r * p.r - u * u, 1e-300));
  }
  double value(double x) const {
    const ProfilePiece& p = at(x);
    if (!p.arc) return p.a + (p.b + p.c * (x - p.origin)) * (x - p.origin);
    return p.zc + p.sign * root(p, x);
  }
  double slope(double x) const {
    const ProfilePiece& p = at(x);
    if (!p.arc) return p.b + 2.0 * p.c * (x - p.origin);
    return -p.sign * (x - p.xc) / root(p, x);
  }
  double second(double x) const {
    const ProfilePiece& p = at(x);
    if (!p.arc) return 2.0 * p.c;
    const double s = root(p, x);
    return -p.sign * p.r * p.r / (s * s * s);
  }
};

// a + b u + c u^2 with u = x - origin over [x0, x1]
ProfilePiece quadratic(double x0, double x1, double origin, double a, double b, double c) {
  ProfilePiece p;
  p.x0 = x0;
  p.x1 = x1;
  p.origin = origin;
  p.a = a;
  p.b = b;
  p.c = c;
  return p;
}

ProfilePiece arc(double x0, double x1, double xc, double zc, double r, double sign) {
  ProfilePiece p;
  p.x0 = x0;
  p.x1 = x1;
  p.arc = true;
  p.xc = xc;
  p.zc = zc;
  p.r = r;
  p.sign = sign;
  return p;
}

// z = g(x) + h(y) (+ offset) from two profiles
HeightField separable(const Profile& gx, const Profile& hy, double offset) {
  auto g = std::make_shared<Profile>(gx);
  auto h = std::make_shared<Profile>(hy);
  HeightField field;
  field.z = [g, h, offset](double x, double y) { return g->value(x) + h->value(y) + offset; };
  field.gradient = [g, h](double x, double y) { return Vec2d(g->slope(x), h->slope(y)); };
  field.hessian = [g, h](double x, double y) {
    Mat2d m;
    m << g->second(x), 0.0, 0.0, h->second(y);
    return m;
  };
  return field;
}

Profile flat(double x0, double x1, double z) {
  return Profile{{quadratic(x0, x1, x0, z, 0.0, 0.0)}};
}

std::vector<GridZone> joined(const std::vector<GridZone>& a, const std::vector<GridZone>& b) {
  std::vector<GridZone> all = a;
  all.insert(all.end(), b.begin(), b.end());
  return all;
}

}  // namespace

Vec3 HeightField::normal(double x, double y) const {
  const Vec2d g = gradient(x, y);
  return Vec3(-g.x(), -g.y(), 1.0).normalized();
}

SurfaceHole SurfaceHole::rectangle(const Eigen::Vector2d& center,
                                   const Eigen::Vector2d& half_size) {
  SurfaceHole hole;
  hole.shape = Shape::rectangle;
  hole.center_mm = center;
  hole.half_size_mm = half_size;
  return hole;
}

SurfaceHole SurfaceHole::circle(const Eigen::Vector2d& center, double radius) {
  SurfaceHole hole;
  hole.shape = Shape::circle;
  hole.center_mm = center;
  hole.radius_mm = radius;
  return hole;
}

bool SurfaceHole::contains(double x, double y) const {
  const Vec2d d = Vec2d(x, y) - center_mm;
  if (shape == Shape::circle) return d.squaredNorm() < radius_mm * radius_mm;
  return std::abs(d.x()) < half_size_mm.x() && std::abs(d.y()) < half_size_mm.y();
}

std::vector<double> grid_nodes(double lo, double hi, double cell_mm,
                               const std::vector<GridZone>& zones,
                               const std::vector<double>& breaks) {
  const double tolerance = 1e-9 * std::max(1.0, hi - lo);
  std::vector<double> cuts = {lo, hi};
  for (const GridZone& z : zones) {
    if (z.from_mm > lo && z.from_mm < hi) cuts.push_back(z.from_mm);
    if (z.to_mm > lo && z.to_mm < hi) cuts.push_back(z.to_mm);
  }
  for (double b : breaks)
    if (b > lo && b < hi) cuts.push_back(b);
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> points;
  for (double c : cuts)
    if (points.empty() || c - points.back() > tolerance) points.push_back(c);
  points.back() = hi;

  std::vector<double> nodes;
  for (std::size_t k = 0; k + 1 < points.size(); ++k) {
    const double p = points[k];
    const double q = points[k + 1];
    const double mid = 0.5 * (p + q);
    double cell = cell_mm;
    for (const GridZone& z : zones)
      if (mid > z.from_mm && mid < z.to_mm) cell = std::min(cell, z.cell_mm);
    const int n = std::max(1, static_cast<int>(std::ceil((q - p) / cell - 1e-9)));
    for (int i = 0; i < n; ++i) nodes.push_back(p + (q - p) * i / n);
  }
  nodes.push_back(hi);
  return nodes;
}

TriangleMesh tessellate(const HeightField& field, const TessellationOptions& options,
                        const std::string& key) {
  require(positive(options.cell_mm), key + ".cell_mm", "the cell size must be positive");
  for (const auto* zones : {&options.x_zones, &options.y_zones, &field.x_zones, &field.y_zones})
    for (const GridZone& z : *zones)
      require(positive(z.cell_mm), key + ".cell_mm", "a zone's cell size must be positive");
  require(!options.solid || positive(options.thickness_mm), key + ".thickness_mm",
          "the solid's thickness must be positive");
  require(std::isfinite(field.x_min) && std::isfinite(field.x_max) && field.x_max > field.x_min &&
              std::isfinite(field.y_min) && std::isfinite(field.y_max) && field.y_max > field.y_min,
          key, "the surface's footprint is empty");

  const std::vector<double> xs = grid_nodes(field.x_min, field.x_max, options.cell_mm,
                                            joined(field.x_zones, options.x_zones), field.x_breaks);
  const std::vector<double> ys = grid_nodes(field.y_min, field.y_max, options.cell_mm,
                                            joined(field.y_zones, options.y_zones), field.y_breaks);
  const int nx = static_cast<int>(xs.size()) - 1;
  const int ny = static_cast<int>(ys.size()) - 1;
  require(static_cast<double>(nx) * ny <= kMaxCells, key + ".cell_mm",
          "the grid would have " + std::to_string(static_cast<double>(nx) * ny) +
              " cells (at most 4e6): the cells are too small for the footprint");

  // the cells kept (not in a hole)
  std::vector<char> kept(static_cast<std::size_t>(nx) * ny, 1);
  auto cell = [&](int i, int j) { return static_cast<std::size_t>(j) * nx + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double cx = 0.5 * (xs[i] + xs[i + 1]);
      const double cy = 0.5 * (ys[j] + ys[j + 1]);
      for (const SurfaceHole& hole : options.holes)
        if (hole.contains(cx, cy)) kept[cell(i, j)] = 0;
    }
  auto is_kept = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < nx && j < ny && kept[cell(i, j)] != 0;
  };

  // top vertices at the nodes of kept cells, in node order
  TriangleMesh mesh;
  const int nodes_x = nx + 1;
  std::vector<int> top(static_cast<std::size_t>(nodes_x) * (ny + 1), -1);
  auto node = [&](int i, int j) { return static_cast<std::size_t>(j) * nodes_x + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      if (is_kept(i - 1, j - 1) || is_kept(i, j - 1) || is_kept(i - 1, j) || is_kept(i, j)) {
        top[node(i, j)] = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(field.point(xs[i], ys[j]));
      }
  require(!mesh.vertices.empty(), key, "the holes leave nothing of the surface");
  for (const Vec3& v : mesh.vertices)
    require(v.allFinite(), key, "the surface is not finite over its footprint");

  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (!is_kept(i, j)) continue;
      const int v00 = top[node(i, j)], v10 = top[node(i + 1, j)];
      const int v11 = top[node(i + 1, j + 1)], v01 = top[node(i, j + 1)];
      mesh.triangles.push_back({v00, v10, v11});
      mesh.triangles.push_back({v00, v11, v01});
    }
  if (!options.solid) return mesh;

  // the bottom on the same grid, facing down
  const std::size_t top_count = mesh.vertices.size();
  double z_low = mesh.vertices.front().z();
  for (const Vec3& v : mesh.vertices) z_low = std::min(z_low, v.z());
  for (std::size_t v = 0; v < top_count; ++v) {
    const Vec3 p = mesh.vertices[v];
    const double z = options.bottom == TessellationOptions::Bottom::flat
                         ? z_low - options.thickness_mm
                         : p.z() - options.thickness_mm;
    mesh.vertices.emplace_back(p.x(), p.y(), z);
  }
  auto below = [&](int v) { return v + static_cast<int>(top_count); };
  const std::size_t top_triangles = mesh.triangles.size();
  for (std::size_t t = 0; t < top_triangles; ++t) {
    const std::array<int, 3> f = mesh.triangles[t];
    mesh.triangles.push_back({below(f[0]), below(f[2]), below(f[1])});
  }
  // walls under every boundary edge a -> b of the top (counter-clockwise around the kept
  // cells seen from above, so outward is to the right)
  auto wall = [&](int a, int b) {
    mesh.triangles.push_back({a, below(a), below(b)});
    mesh.triangles.push_back({a, below(b), b});
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (!is_kept(i, j)) continue;
      const int v00 = top[node(i, j)], v10 = top[node(i + 1, j)];
      const int v11 = top[node(i + 1, j + 1)], v01 = top[node(i, j + 1)];
      if (!is_kept(i, j - 1)) wall(v00, v10);
      if (!is_kept(i + 1, j)) wall(v10, v11);
      if (!is_kept(i, j + 1)) wall(v11, v01);
      if (!is_kept(i - 1, j)) wall(v01, v00);
    }
  return mesh;
}

double chordal_error_bound_mm(const HeightField& field, const TessellationOptions& options) {
  const std::vector<double> xs = grid_nodes(field.x_min, field.x_max, options.cell_mm,
                                            joined(field.x_zones, options.x_zones), field.x_breaks);
  const std::vector<double> ys = grid_nodes(field.y_min, field.y_max, options.cell_mm,
                                            joined(field.y_zones, options.y_zones), field.y_breaks);
  double bound = 0.0;
  for (std::size_t j = 0; j + 1 < ys.size(); ++j)
    for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
      const double hx = xs[i + 1] - xs[i];
      const double hy = ys[j + 1] - ys[j];
      // the Hessian's largest entries over the cell (sampled just inside its corners, so a
      // corner on a break line reads this cell's side, and at its centre)
      double fxx = 0.0, fxy = 0.0, fyy = 0.0;
      const double inset = 1e-9;
      for (const auto& [sx, sy] : {std::pair<double, double>{inset, inset},
                                   {1 - inset, inset},
                                   {inset, 1 - inset},
                                   {1 - inset, 1 - inset},
                                   {0.5, 0.5}}) {
        const Mat2d h = field.hessian(xs[i] + sx * hx, ys[j] + sy * hy);
        fxx = std::max(fxx, std::abs(h(0, 0)));
        fxy = std::max(fxy, std::abs(h(0, 1)));
        fyy = std::max(fyy, std::abs(h(1, 1)));
      }
      bound = std::max(bound, (fxx * hx * hx + 2.0 * fxy * hx * hy + fyy * hy * hy) / 8.0);
    }
  return bound;
}

// ---- shapes ----

HeightField sphere_cap_field(const SphereCapParams& p, const std::string& key) {
  require(positive(p.radius_mm), key + ".radius_mm", "the radius must be positive");
  require(positive(p.half_x_mm) && positive(p.half_y_mm), key + ".size",
          "the footprint must have a positive size");
  require(std::isfinite(p.apex_z_mm), key + ".apex_z_mm", "the apex height must be finite");
  const double corner = std::hypot(p.half_x_mm, p.half_y_mm);
  require(corner < 0.99 * p.radius_mm, key + ".radius_mm",
          "the footprint's corners (" + std::to_string(corner) +
              " mm from the apex) must lie well inside the sphere's radius");
  const double r = p.radius_mm;
  const double sign = p.concave ? -1.0 : 1.0;  // convex: the dome; concave: the bowl
  const double apex = p.apex_z_mm;
  HeightField field;
  field.z = [=](double x, double y) {
    return apex + sign * (std::sqrt(r * r - x * x - y * y) - r);
  };
  field.gradient = [=](double x, double y) {
    const double s = std::sqrt(r * r - x * x - y * y);
    return Vec2d(-sign * x / s, -sign * y / s);
  };
  field.hessian = [=](double x, double y) {
    const double s = std::sqrt(r * r - x * x - y * y);
    const double s3 = s * s * s;
    Mat2d m;
    m << -(r * r - y * y) / s3, -x * y / s3, -x * y / s3, -(r * r - x * x) / s3;
    return Mat2d(sign * m);
  };
  field.x_min = -p.half_x_mm;
  field.x_max = p.half_x_mm;
  field.y_min = -p.half_y_mm;
  field.y_max = p.half_y_mm;
  return field;
}

TriangleMesh sphere_cap(const SphereCapParams& p, const std::string& key) {
  return tessellate(sphere_cap_field(p, key), p.mesh, key);
}

HeightField cylinder_field(const CylinderParams& p, const std::string& key) {
  require(positive(p.radius_mm), key + ".radius_mm", "the radius must be positive");
  require(positive(p.half_x_mm) && positive(p.half_y_mm), key + ".size",
          "the footprint must have a positive size");
  require(p.half_x_mm < 0.99 * p.radius_mm, key + ".radius_mm",
          "the footprint's half width across the axis must lie well inside the radius");
  require(std::isfinite(p.apex_z_mm), key + ".apex_z_mm", "the apex height must be finite");
  const double sign = p.concave ? -1.0 : 1.0;
  Profile g{{arc(-p.half_x_mm, p.half_x_mm, 0.0, -sign * p.radius_mm, p.radius_mm, sign)}};
  HeightField field = separable(g, flat(-p.half_y_mm, p.half_y_mm, 0.0), p.apex_z_mm);
  field.x_min = -p.half_x_mm;
  field.x_max = p.half_x_mm;
  field.y_min = -p.half_y_mm;
  field.y_max = p.half_y_mm;
  return field;
}

TriangleMesh cylinder(const CylinderParams& p, const std::string& key) {
  return tessellate(cylinder_field(p, key), p.mesh, key);
}

HeightField curved_beam_field(const CurvedBeamParams& p, const std::string& key) {
  require(positive(p.length_mm) && positive(p.width_mm), key + ".size",
          "the beam's length and width must be positive");
  require(positive(p.sag_mm) && p.sag_mm < 0.45 * p.length_mm, key + ".sag_mm",
          "the sag must be positive and under 0.45 of the length (ends below vertical)");
  const double half = 0.5 * p.length_mm;
  const double r = (half * half + p.sag_mm * p.sag_mm) / (2.0 * p.sag_mm);
  Profile g{{arc(-half, half, 0.0, p.sag_mm - r, r, 1.0)}};
  HeightField field = separable(g, flat(-0.5 * p.width_mm, 0.5 * p.width_mm, 0.0), 0.0);
  field.x_min = -half;
  field.x_max = half;
  field.y_min = -0.5 * p.width_mm;
  field.y_max = 0.5 * p.width_mm;
  return field;
}

TriangleMesh curved_beam(const CurvedBeamParams& p, const std::string& key) {
  return tessellate(curved_beam_field(p, key), p.mesh, key);
}

double car_bonnet_roll_start_mm(const CarBonnetParams& p) {
  // x_r + r (sin(phi1) - sin(phi0(x_r))) = length, phi0 = atan(x_r / Rx): the parabola's
  // slope angle where the roll takes over (a contraction: phi0 changes slowly with x_r)
  const double phi1 = deg_to_rad(p.roll_end_slope_deg);
  double x_r = p.length_mm - p.roll_radius_mm * std::sin(phi1);
  for (int k = 0; k < 100; ++k)
    x_r = p.length_mm -
          p.roll_radius_mm * (std::sin(phi1) - std::sin(std::atan(x_r / p.crown_radius_x_mm)));
  return x_r;
}

HeightField car_bonnet_field(const CarBonnetParams& p, const std::string& key) {
  require(positive(p.length_mm) && positive(p.width_mm), key + ".size",
          "the bonnet's length and width must be positive");
  require(positive(p.crown_radius_x_mm) && positive(p.crown_radius_y_mm), key + ".crown_radius",
          "the crown radii must be positive");
  require(positive(p.roll_radius_mm) && p.roll_radius_mm < p.crown_radius_x_mm,
          key + ".roll_radius_mm", "the roll radius must be positive and under the crown's");
  require(p.roll_end_slope_deg > 0.0 && p.roll_end_slope_deg < 80.0, key + ".roll_end_slope_deg",
          "the roll's end slope must be in (0, 80) degrees");
  require(positive(p.roll_cell_mm), key + ".roll_cell_mm", "the roll's cells must be positive");
  const double x_r = car_bonnet_roll_start_mm(p);
  const double phi0 = std::atan(x_r / p.crown_radius_x_mm);
  require(x_r > 0.0 && phi0 < deg_to_rad(p.roll_end_slope_deg), key + ".roll_radius_mm",
          "the roll does not fit: the bonnet is too short or its crown too steep");
  const double c = -0.5 / p.crown_radius_x_mm;
  const double g_r = c * x_r * x_r;
  const double r = p.roll_radius_mm;
  Profile g{{quadratic(0.0, x_r, 0.0, 0.0, 0.0, c),
             arc(x_r, p.length_mm, x_r - r * std::sin(phi0), g_r - r * std::cos(phi0), r, 1.0)}};
  const double half_w = 0.5 * p.width_mm;
  Profile h{{quadratic(-half_w, half_w, 0.0, 0.0, 0.0, -0.5 / p.crown_radius_y_mm)}};
  const double lowest = g.value(p.length_mm) + h.value(half_w);
  HeightField field = separable(g, h, -lowest);
  field.x_min = 0.0;
  field.x_max = p.length_mm;
  field.y_min = -half_w;
  field.y_max = half_w;
  field.x_breaks = {x_r};
  field.x_zones = {GridZone{x_r, p.length_mm, p.roll_cell_mm}};
  return field;
}

TriangleMesh car_bonnet(const CarBonnetParams& p, const std::string& key) {
  return tessellate(car_bonnet_field(p, key), p.mesh, key);
}

HeightField fillet_step_field(const FilletStepParams& p, const std::string& key) {
  require(std::isfinite(p.flat_before_mm) && p.flat_before_mm >= 0.0 &&
              std::isfinite(p.flat_after_mm) && p.flat_after_mm >= 0.0,
          key + ".flat_mm", "the flats' lengths must be finite and not negative");
  require(positive(p.fillet_radius_mm), key + ".fillet_radius_mm",
          "the fillet radius must be positive");
  require(p.slope_deg > 0.0 && p.slope_deg < 80.0, key + ".slope_deg",
          "the slope must be in (0, 80) degrees");
  require(positive(p.width_mm), key + ".width_mm", "the width must be positive");
  require(positive(p.fillet_cell_mm), key + ".fillet_cell_mm",
          "the fillets' cells must be positive");
  const double theta = deg_to_rad(p.slope_deg);
  const double r = p.fillet_radius_mm;
  const double rise = r * (1.0 - std::cos(theta));  // of each fillet
  const double run = r * std::sin(theta);
  require(std::isfinite(p.step_height_mm) && p.step_height_mm >= 2.0 * rise,
          key + ".step_height_mm",
          "the step must be at least as high as its two fillets (" + std::to_string(2.0 * rise) +
              " mm)");
  const double h = p.step_height_mm;
  const double x1 = p.flat_before_mm;
  const double x2 = x1 + run;
  const double x3 = x2 + (h - 2.0 * rise) / std::tan(theta);
  const double x4 = x3 + run;
  const double x5 = x4 + p.flat_after_mm;
  require(x5 > 0.0, key, "the step has no length");
  Profile g{{quadratic(0.0, x1, 0.0, 0.0, 0.0, 0.0), arc(x1, x2, x1, r, r, -1.0),
             quadratic(x2, x3, x2, rise, std::tan(theta), 0.0), arc(x3, x4, x4, h - r, r, 1.0),
             quadratic(x4, x5, x4, h, 0.0, 0.0)}};
  HeightField field = separable(g, flat(-0.5 * p.width_mm, 0.5 * p.width_mm, 0.0), 0.0);
  field.x_min = 0.0;
  field.x_max = x5;
  field.y_min = -0.5 * p.width_mm;
  field.y_max = 0.5 * p.width_mm;
  field.x_breaks = {x1, x2, x3, x4};
  field.x_zones = {GridZone{x1, x2, p.fillet_cell_mm}, GridZone{x3, x4, p.fillet_cell_mm}};
  return field;
}

TriangleMesh fillet_step(const FilletStepParams& p, const std::string& key) {
  return tessellate(fillet_step_field(p, key), p.mesh, key);
}

}  // namespace depotwin
