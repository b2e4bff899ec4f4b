#include "toolpath/surface_projection.hpp"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr int kPacket = 16;
// a hit this near an edge of its triangle (barycentric coordinate) may be on a neighbour's too
constexpr double kOnEdge = 1e-6;
// how far uncover's ray looks inside the hit triangle: this share of the way to its centroid
constexpr double kInward = 1e-3;
// a triangle met on its edge this steep or steeper (n_z below cos 60 deg) gives way to a
// flatter one beside it at the same height (flatten)
constexpr double kSteepFacetZ = 0.5;

void check_device(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw InternalError(std::string("Embree: ") + what + " failed (error " +
                        std::to_string(static_cast<int>(error)) + ")");
}

}  // namespace

struct SurfaceProjector::Impl {
  TriangleMesh mesh;
  std::vector<std::array<Vec3, 3>> corner_normals;
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  Vec3 center = Vec3::Zero();   // Embree works in float about this point
  float ray_z = 1.0f;           // ray origins' z (centred frame), above the mesh
  double edge_offset_mm = 0.0;  // how far edge_hit looks beside a point (see there)
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  Impl(TriangleMesh m, const SurfaceProjectorOptions& options) : mesh(std::move(m)) {
    for (const Vec3& v : mesh.vertices)
      if (!v.allFinite()) throw InternalError("SurfaceProjector: a mesh vertex is not finite");
    mesh.bounds(lo, hi);
    center = 0.5 * (lo + hi);
    const double extent = (hi - lo).maxCoeff();
    ray_z = static_cast<float>(hi.z() - center.z() + 1.0 + 1e-3 * extent);
    // a hundred times the float rounding of the centred coordinates (6e-8 of the extent)
    edge_offset_mm = 1e-5 * std::max((hi - lo).head<2>().maxCoeff(), 1.0);
    corner_normals = mesh.corner_normals(deg_to_rad(options.crease_angle_deg));

    // one thread: the build is deterministic and leaves the shared cores alone
    device = rtcNewDevice("threads=1,verbose=0");
    if (device == nullptr) throw InternalError("Embree: rtcNewDevice failed");
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (!mesh.empty()) {
      RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
      auto* vertices = static_cast<float*>(
          rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                  3 * sizeof(float), mesh.vertices.size()));
      auto* indices = static_cast<unsigned*>(
          rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                  3 * sizeof(unsigned), mesh.triangles.size()));
      check_device(device, "buffer allocation");
      for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        for (int i = 0; i < 3; ++i)
          vertices[3 * v + static_cast<std::size_t>(i)] =
              static_cast<float>(mesh.vertices[v][i] - center[i]);
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int i = 0; i < 3; ++i)
          indices[3 * t + static_cast<std::size_t>(i)] =
              static_cast<unsigned>(mesh.triangles[t][static_cast<std::size_t>(i)]);
      rtcCommitGeometry(geometry);
      rtcAttachGeometry(scene, geometry);
      rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(scene);
    check_device(device, "building the BVH");
  }

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  Vec3 smooth_normal(int t, const Vec3& b) const {
    const std::array<Vec3, 3>& n = corner_normals[static_cast<std::size_t>(t)];
    const Vec3 sum = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
    const double length = sum.norm();
    return length > 0.0 ? Vec3(sum / length) : mesh.facet_normal(static_cast<std::size_t>(t));
  }

  // the hits of four rays edge_offset_mm beside (x, y) (diagonally), each recomputed exactly at
  // (x, y) on its triangle's plane
  std::array<std::optional<SurfaceHit>, 4> hits_beside(double x, double y) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(16) RTCRayHit4 packet;
    alignas(16) int valid[4] = {-1, -1, -1, -1};
    for (int k = 0; k < 4; ++k) {
      const double dx = (k & 1) ? -edge_offset_mm : edge_offset_mm;
      const double dy = (k & 2) ? -edge_offset_mm : edge_offset_mm;
      set_down_ray(packet, k, x + dx, y + dy);
    }
    rtcIntersect4(valid, scene, &context, &packet);
    std::array<std::optional<SurfaceHit>, 4> hits;
    for (int k = 0; k < 4; ++k) hits[static_cast<std::size_t>(k)] = lane_hit(packet, k, x, y);
    return hits;
  }

  // Embree decides a ray exactly on a boundary edge of the surface (the outline, a hole's
  // edge) for one side only, so a part a whole number of grid cells wide is hit along one rim
  // and missed along the other. A ray that misses, or meets the edge of a wall, is tried again
  // beside (hits_beside); the highest hit facing up among them is taken. Nothing if none.
  std::optional<SurfaceHit> edge_hit(double x, double y) const {
    std::optional<SurfaceHit> best;
    for (const std::optional<SurfaceHit>& hit : hits_beside(x, y))
      if (hit && hit->facet_normal.z() > 0.0 && (!best || hit->point_mm.z() > best->point_mm.z()))
        best = hit;
    return best;
  }

  // hit: the ray's own answer at (x, y), replaced by edge_hit's where it misses or meets a
  // wall's edge and edge_hit finds one (in place: most points keep theirs, uncopied)
  void settle(double x, double y, std::optional<SurfaceHit>& hit) const {
    if (hit && hit->facet_normal.z() > 0.0) {
      if (hit->barycentric.minCoeff() < kOnEdge) {
        uncover(x, y, *hit);
        if (hit->facet_normal.z() < kSteepFacetZ) flatten(x, y, *hit);
      }
      return;
    }
    std::optional<SurfaceHit> beside = edge_hit(x, y);
    if (beside) hit = beside;
  }

  // A point on an edge is on every triangle that shares it, and Embree names any of them: a
  // facet hung under the top on its diagonal (a non-manifold STL) is as near as the top, and
  // its normal would tilt the layers offset there. A ray just inside the hit triangle (toward
  // its centroid) tells: where it meets another triangle higher up, the hit one is hidden
  // beside the edge, and the point is taken on the one seen instead (at the same height).
  void uncover(double x, double y, SurfaceHit& hit) const {
    const std::array<int, 3>& f = mesh.triangles[static_cast<std::size_t>(hit.triangle)];
    const Vec3 centroid = (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3.0;
    const Vec2 inner = Vec2(x, y) + kInward * (centroid.head<2>() - Vec2(x, y));
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rayhit;
    set_down_ray(rayhit, inner.x(), inner.y());
    rtcIntersect1(scene, &context, &rayhit);
    if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID ||
        static_cast<int>(rayhit.hit.primID) == hit.triangle)
      return;
    const SurfaceHit own_inside =
        exact_hit(inner.x(), inner.y(), hit.triangle, hit.point_mm.z() - center.z(), 0.0f, 0.0f);
    const std::optional<SurfaceHit> seen_inside =
        ray_hit(inner.x(), inner.y(), rayhit.hit.geomID, rayhit.hit.primID, rayhit.ray.tfar,
                rayhit.hit.u, rayhit.hit.v);
    if (!seen_inside || seen_inside->facet_normal.z() <= 0.0 ||
        seen_inside->point_mm.z() <= own_inside.point_mm.z() + edge_offset_mm)
      return;
    const SurfaceHit seen =
        exact_hit(x, y, seen_inside->triangle, hit.point_mm.z() - center.z(), 0.0f, 0.0f);
    if (std::abs(seen.point_mm.z() - hit.point_mm.z()) <= edge_offset_mm) hit = seen;
  }

  // A steep triangle met on its edge (a sliver between two flat facets, mesh noise a few
  // micrometres high) would leave the point without a printable surface or tilt its normal
  // far over: the flattest triangle met beside it at the same height there is taken instead.
  void flatten(double x, double y, SurfaceHit& hit) const {
    for (const std::optional<SurfaceHit>& beside : hits_beside(x, y))
      if (beside && beside->facet_normal.z() > hit.facet_normal.z() &&
          std::abs(beside->point_mm.z() - hit.point_mm.z()) <= edge_offset_mm)
        hit = *beside;
  }

  // one ray straight down from above the mesh at (x, y)
  void set_down_ray(RTCRayHit& rayhit, double x, double y) const {
    rayhit.ray.org_x = static_cast<float>(x - center.x());
    rayhit.ray.org_y = static_cast<float>(y - center.y());
    rayhit.ray.org_z = ray_z;
    rayhit.ray.dir_x = 0.0f;
    rayhit.ray.dir_y = 0.0f;
    rayhit.ray.dir_z = -1.0f;
    rayhit.ray.tnear = 0.0f;
    rayhit.ray.tfar = std::numeric_limits<float>::infinity();
    rayhit.ray.mask = ~0u;
    rayhit.ray.flags = 0;
    rayhit.ray.time = 0.0f;
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }

  // ray k of a packet: straight down from above the mesh at (x, y)
  template <typename Packet>
  void set_down_ray(Packet& packet, int k, double x, double y) const {
    set_ray(packet, k,
            {static_cast<float>(x - center.x()), static_cast<float>(y - center.y()), ray_z},
            {0.0f, 0.0f, -1.0f}, std::numeric_limits<float>::infinity());
  }

  // ray k of a packet from `origin` (centred frame) along `direction` up to tfar times it
  template <typename Packet>
  static void set_ray(Packet& packet, int k, const std::array<float, 3>& origin,
                      const std::array<float, 3>& direction, float tfar) {
    packet.ray.org_x[k] = origin[0];
    packet.ray.org_y[k] = origin[1];
    packet.ray.org_z[k] = origin[2];
    packet.ray.dir_x[k] = direction[0];
    packet.ray.dir_y[k] = direction[1];
    packet.ray.dir_z[k] = direction[2];
    packet.ray.tnear[k] = 0.0f;
    packet.ray.tfar[k] = tfar;
    packet.ray.mask[k] = ~0u;
    packet.ray.flags[k] = 0;
    packet.ray.time[k] = 0.0f;
    packet.ray.id[k] = static_cast<unsigned>(k);
    packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }

  // a ray's answer as the exact hit at (x, y); nothing if the ray missed
  std::optional<SurfaceHit> ray_hit(double x, double y, unsigned geom_id, unsigned prim_id,
                                    float tfar, float u, float v) const {
    if (geom_id == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    return exact_hit(x, y, static_cast<int>(prim_id), static_cast<double>(ray_z - tfar), u, v);
  }

  // ray k of a packet's answer (see ray_hit)
  template <typename Packet>
  std::optional<SurfaceHit> lane_hit(const Packet& packet, int k, double x, double y) const {
    return ray_hit(x, y, packet.hit.geomID[k], packet.hit.primID[k], packet.ray.tfar[k],
                   packet.hit.u[k], packet.hit.v[k]);
  }

  // the exact hit at (x, y) on triangle t; embree_z: Embree's hit height (centred frame),
  // used only for a vertical triangle, whose plane gives no z
  SurfaceHit exact_hit(double x, double y, int t, double embree_z, float u, float v) const {
    const std::array<int, 3>& f = mesh.triangles[static_cast<std::size_t>(t)];
    const Vec3& a = mesh.vertices[f[0]];
    const Vec3& b = mesh.vertices[f[1]];
    const Vec3& c = mesh.vertices[f[2]];
    const Vec3 n = (b - a).cross(c - a);
    const double length = n.norm();
    SurfaceHit hit;
    hit.triangle = t;
    hit.facet_normal = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
    if (length > 0.0 && std::abs(n.z()) > 1e-12 * length) {
      // on the plane: n . (p - a) = 0 with p = (x, y, z)
      const double z = a.z() - (n.x() * (x - a.x()) + n.y() * (y - a.y())) / n.z();
      hit.point_mm = Vec3(x, y, z);
      // barycentric coordinates from the (x, y) projection (n.z is twice its signed area)
      const double wa = ((b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x)) / n.z();
      const double wb = ((c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x)) / n.z();
      hit.barycentric = Vec3(wa, wb, 1.0 - wa - wb);
    } else {
      hit.point_mm = Vec3(x, y, embree_z + center.z());
      hit.barycentric = Vec3(1.0 - static_cast<double>(u) - static_cast<double>(v), u, v);
    }
    // a point Embree placed in t by a float decision may be a rounding outside it
    hit.barycentric = hit.barycentric.cwiseMax(0.0);
    const double sum = hit.barycentric.sum();
    hit.barycentric = sum > 0.0 ? Vec3(hit.barycentric / sum) : Vec3::Constant(1.0 / 3.0);
    hit.normal = smooth_normal(t, hit.barycentric);
    // the side the ray meets is the one seen from above: a triangle facing down there (a
    // patch wound the other way, a band with a twist) is printed on its back, which faces up
    if (hit.facet_normal.z() < 0.0) {
      hit.facet_normal = -hit.facet_normal;
      hit.normal = -hit.normal;
    }
    return hit;
  }
};

SurfaceProjector::SurfaceProjector(TriangleMesh mesh, const SurfaceProjectorOptions& options)
    : impl_(std::make_unique<Impl>(std::move(mesh), options)) {}
SurfaceProjector::~SurfaceProjector() = default;
SurfaceProjector::SurfaceProjector(SurfaceProjector&&) noexcept = default;
SurfaceProjector& SurfaceProjector::operator=(SurfaceProjector&&) noexcept = default;

std::optional<SurfaceHit> SurfaceProjector::project_down(double x_mm, double y_mm) const {
  const Impl& im = *impl_;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit;
  im.set_down_ray(rayhit, x_mm, y_mm);
  rtcIntersect1(im.scene, &context, &rayhit);
  std::optional<SurfaceHit> hit = im.ray_hit(x_mm, y_mm, rayhit.hit.geomID, rayhit.hit.primID,
                                             rayhit.ray.tfar, rayhit.hit.u, rayhit.hit.v);
  im.settle(x_mm, y_mm, hit);
  return hit;
}

void SurfaceProjector::project_down(const std::vector<Vec2>& xy,
                                    std::vector<std::optional<SurfaceHit>>& hits) const {
  const Impl& im = *impl_;
  hits.resize(xy.size());
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // parallel rays side by side
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[kPacket];
  for (std::size_t start = 0; start < xy.size(); start += kPacket) {
    const int count = static_cast<int>(std::min<std::size_t>(kPacket, xy.size() - start));
    for (int k = 0; k < kPacket; ++k) {
      const Vec2& p = xy[start + static_cast<std::size_t>(std::min(k, count - 1))];
      valid[k] = k < count ? -1 : 0;
      im.set_down_ray(packet, k, p.x(), p.y());
    }
    rtcIntersect16(valid, im.scene, &context, &packet);
    for (int k = 0; k < count; ++k) {
      const Vec2& p = xy[start + static_cast<std::size_t>(k)];
      std::optional<SurfaceHit>& hit = hits[start + static_cast<std::size_t>(k)];
      hit = im.lane_hit(packet, k, p.x(), p.y());
      im.settle(p.x(), p.y(), hit);
    }
  }
}

void SurfaceProjector::first_crossings(const std::vector<std::pair<Vec3, Vec3>>& segments,
                                       std::vector<std::optional<double>>& fractions) const {
  const Impl& im = *impl_;
  fractions.assign(segments.size(), std::nullopt);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[kPacket];
  for (std::size_t start = 0; start < segments.size(); start += kPacket) {
    const int count = static_cast<int>(std::min<std::size_t>(kPacket, segments.size() - start));
    for (int k = 0; k < kPacket; ++k) {
      const auto& [from, to] = segments[start + static_cast<std::size_t>(std::min(k, count - 1))];
      valid[k] = k < count ? -1 : 0;
      // from `from` along to - from: the segment is t in [0, 1]
      const Vec3 origin = from - im.center, direction = to - from;
      Impl::set_ray(packet, k,
                    {static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                     static_cast<float>(origin.z())},
                    {static_cast<float>(direction.x()), static_cast<float>(direction.y()),
                     static_cast<float>(direction.z())},
                    1.0f);
    }
    rtcIntersect16(valid, im.scene, &context, &packet);
    for (int k = 0; k < count; ++k)
      if (packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID)
        fractions[start + static_cast<std::size_t>(k)] = static_cast<double>(packet.ray.tfar[k]);
  }
}

std::optional<double> SurfaceProjector::height_at(double x_mm, double y_mm) const {
  const std::optional<SurfaceHit> hit = project_down(x_mm, y_mm);
  if (!hit) return std::nullopt;
  return hit->point_mm.z();
}

const TriangleMesh& SurfaceProjector::mesh() const {
  return impl_->mesh;
}

Vec3 SurfaceProjector::smooth_normal(int triangle, const Vec3& barycentric) const {
  return impl_->smooth_normal(triangle, barycentric);
}

const Vec3& SurfaceProjector::lower_bound() const {
  return impl_->lo;
}

const Vec3& SurfaceProjector::upper_bound() const {
  return impl_->hi;
}

}  // namespace depotwin
