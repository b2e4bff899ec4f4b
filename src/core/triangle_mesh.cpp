#include "core/triangle_mesh.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace depotwin {

Vec3 TriangleMesh::facet_normal(size_t t) const {
  const std::array<int, 3>& f = triangles[t];
  const Vec3 n = (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3::Zero();
}

double TriangleMesh::facet_area_mm2(size_t t) const {
  const std::array<int, 3>& f = triangles[t];
  return 0.5 * (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]).norm();
}

void TriangleMesh::bounds(Vec3& lo, Vec3& hi) const {
  if (vertices.empty()) {
    lo = hi = Vec3::Zero();
    return;
  }
  lo = hi = vertices.front();
  for (const Vec3& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

std::vector<Vec3> TriangleMesh::vertex_normals() const {
  std::vector<Vec3> normals(vertices.size(), Vec3::Zero());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Vec3 n = facet_normal(t);
    if (n.isZero()) continue;
    // each corner adds the facet normal weighted by the triangle's angle there
    for (int corner = 0; corner < 3; ++corner) {
      const Vec3& p = vertices[triangles[t][corner]];
      const Vec3 a = vertices[triangles[t][(corner + 1) % 3]] - p;
      const Vec3 b = vertices[triangles[t][(corner + 2) % 3]] - p;
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      normals[triangles[t][corner]] += angle * n;
    }
  }
  for (Vec3& n : normals) {
    const double length = n.norm();
    if (length > 0.0) n /= length;
  }
  return normals;
}

void TriangleMesh::transform(const Eigen::Matrix3d& rotation, const Vec3& offset) {
  for (Vec3& v : vertices) v = rotation * v + offset;
}

}  // namespace depotwin
