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
  // unit normals per triangle corner, smooth across edges but not across creases: the normal
  // at corner c of triangle t is the angle-weighted mean (as vertex_normals) of the facet
  // normals around that vertex that lie within crease_angle_rad of t's own facet normal and in
  // t's fan there: the triangles reached from t around the vertex across edges that exactly two
  // facets share (a facet's duplicate counts once and shares its original's fan). On a smooth
  // surface this is vertex_normals(); at a sharp edge (a solid's rim, where the top meets a
  // side wall) each side keeps its own normal instead of a 45-degree average; a facet that
  // meets t only at a non-manifold edge (three facets on it) or at the vertex alone is another
  // surface and is left out. The facet normal for a corner of a degenerate triangle (zero:
  // degenerate triangles only).
  std::vector<std::array<Vec3, 3>> corner_normals(double crease_angle_rad) const;
  // the enclosed volume by the divergence theorem (mm^3): positive when the triangles are wound
  // outward; taken about the bounds' centre so that a part far from the origin loses no digits
  double signed_volume_mm3() const;
  // x -> rotation x + offset on every vertex (triangle orientation is kept: rotations only)
  void transform(const Eigen::Matrix3d& rotation, const Vec3& offset);
  // Turns every triangle over (reverses its winding) where the whole mesh faces the wrong way:
  // a closed solid wound inside out (negative signed volume), or an open surface facing down
  // on the whole (its facets' signed areas projected on the xy plane sum below 0), as an STL
  // of a surface patch exported with its winding reversed is. A mesh that faces up, a closed
  // solid wound outward, or a closed one whose signed volume is 0 is left as it is. Returns
  // whether it turned the triangles over.
  bool face_outward_and_up();
  // Turns over the triangles wound against their neighbours, as an STL with some facets
  // reversed has them: across every edge that exactly two triangles share, the two must run
  // it in opposite directions. In each connected piece (joined by such edges) the winding of
  // the larger area is kept and the smaller's turned; edges of one triangle or of three or
  // more (non-manifold) and a facet's duplicate join nothing. A piece that cannot be wound
  // consistently (a Moebius strip: a loop of neighbours asks a triangle for both windings) has
  // no outside; each of its triangles is turned to face up instead (facet normal z >= 0), so
  // the side seen from above, which the hatch prints, is its front everywhere. Before
  // face_outward_and_up, which then judges the whole mesh.
  struct Orientation {
    size_t turned = 0;                  // triangles turned over (both kinds of piece)
    size_t unorientable_pieces = 0;     // pieces that cannot be wound consistently
    size_t unorientable_triangles = 0;  // the triangles of those pieces
  };
  Orientation orient_consistently();
};

}  // namespace depotwin
