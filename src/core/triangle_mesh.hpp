// A triangle mesh in the work frame (mm): a part's surface as read from an STL file, projected
// onto by the hatching, measured against by the clearance check and drawn in the scene.
// Plain data; the STL reader is toolpath/stl.hpp.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/types.hpp"

namespace depotwin {

struct TriangleMesh {
  std::vector<Vec3> vertices;                 // mm
  std::vector<std::array<int, 3>> triangles;  // vertex indices, counter-clockwise seen from
                                              // outside (right-hand rule gives the normal)

  size_t triangle_count() const { return triangles.size(); }
  bool empty() const { return triangles.empty(); }
  // the unit normal of triangle t by the right-hand rule (zero for a degenerate triangle)
  Vec3 facet_normal(size_t t) const;
  double facet_area_mm2(size_t t) const;
  // axis-aligned bounds of the vertices (zero for an empty mesh)
  void bounds(Vec3& lo, Vec3& hi) const;
  // unit vertex normals, one per vertex: the facet normals of the triangles around each vertex
  // weighted by their corner angle there (independent of how the surface is tessellated);
  // zero for a vertex of degenerate triangles only
  std::vector<Vec3> vertex_normals() const;
  // x -> rotation x + offset on every vertex (triangle orientation is kept: rotations only)
  void transform(const Eigen::Matrix3d& rotation, const Vec3& offset);
};

}  // namespace depotwin
