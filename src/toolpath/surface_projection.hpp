// Projection onto a part's surface straight down (-z): the step of Shembekar et al.'s
// Algorithm 1 that takes a grid point in the (x, y) plane to the surface, done by ray casting
// against a BVH (Embree 3) instead of testing every triangle for every point.
//
// Embree works in single precision; each hit is recomputed in double against the triangle
// Embree reports: the ray's (x, y) are kept exactly and z comes from the triangle's plane, so
// a projected point lies on that plane to rounding (1e-12 mm at part scale), and the
// barycentric coordinates (for the smooth normal) are computed in double too. Near an edge
// Embree may report either triangle; both planes meet at the edge, so the point moves by no
// more than the float error of the decision (1e-6 mm at 100 mm).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/triangle_mesh.hpp"

namespace depotwin {

using Vec2 = Eigen::Vector2d;

// Where a ray straight down first meets the surface.
struct SurfaceHit {
  Vec3 point_mm = Vec3::Zero();  // (x, y) of the ray exactly, z on the hit triangle's plane
  // The normals are those of the side the ray meets, seen from above: where the triangle is
  // wound facing down (a patch exported the other way, a band with a twist) both are turned
  // over, so the visible side is the one printed.
  // the hit triangle's unit normal (right-hand rule, turned up where it faced down)
  Vec3 facet_normal = Vec3::UnitZ();
  // the smooth unit normal: the triangle's corner normals (TriangleMesh::corner_normals:
  // angle-weighted vertex normals that do not average across creases) interpolated by the
  // hit's barycentric coordinates and renormalised (turned with the facet's)
  Vec3 normal = Vec3::UnitZ();
  int triangle = -1;                // index in the mesh
  Vec3 barycentric = Vec3::Zero();  // of the point in the triangle (clamped to it)

  // a printable top surface: both normals point up by more than min_normal_z. A vertical wall
  // (n_z = 0) is not, nor a hit whose smooth normal still points down (a fold, where the
  // surface turns over).
  bool faces_up(double min_normal_z = 0.0) const {
    return facet_normal.z() > min_normal_z && normal.z() > min_normal_z;
  }
};

struct SurfaceProjectorOptions {
  // edges whose facets turn by more than this are creases: normals are not smoothed across
  // them (a solid's rim between its top and a side wall). Smooth surfaces tessellated finer
  // than this angle per triangle are smoothed everywhere.
  double crease_angle_deg = 30.0;
};

// Built once per mesh (the BVH, the corner normals), then queried many times. Move-only.
class SurfaceProjector {
 public:
  // InternalError if Embree fails or a vertex is not finite; an empty mesh is never hit
  explicit SurfaceProjector(TriangleMesh mesh, const SurfaceProjectorOptions& options = {});
  ~SurfaceProjector();
  SurfaceProjector(SurfaceProjector&&) noexcept;
  SurfaceProjector& operator=(SurfaceProjector&&) noexcept;
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;

  // The first surface a ray straight down from above the mesh meets at (x, y): the top
  // surface. Nothing where the ray misses (outside the part, through a hole); a point on the
  // outline or a hole's edge (within 1e-5 of the part's size) is on the part, its hit on the
  // plane of the top triangle there. The hit may face sideways (see SurfaceHit::faces_up).
  std::optional<SurfaceHit> project_down(double x_mm, double y_mm) const;
  // Many points at once (packets of 16 rays); `hits` is resized to xy.size().
  void project_down(const std::vector<Vec2>& xy,
                    std::vector<std::optional<SurfaceHit>>& hits) const;
  // the height of the top surface at (x, y), or nothing where it misses
  std::optional<double> height_at(double x_mm, double y_mm) const;
  // Where each straight segment (from, to) first meets the surface, going from `from`: the
  // fraction of the way, in [0, 1]; nothing where it meets none (packets of 16 rays).
  // `fractions` is resized to segments.size().
  void first_crossings(const std::vector<std::pair<Vec3, Vec3>>& segments,
                       std::vector<std::optional<double>>& fractions) const;

  const TriangleMesh& mesh() const;
  // the smooth normal of triangle t at barycentric coordinates b (normalised)
  Vec3 smooth_normal(int triangle, const Vec3& barycentric) const;
  // the mesh's bounds
  const Vec3& lower_bound() const;
  const Vec3& upper_bound() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace depotwin
