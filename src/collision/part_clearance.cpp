// Distance between convex machine shapes and a non-convex part mesh, on FCL's OBBRSS tree.
//
// Why not fcl::distance(mesh, shape): with FCL 0.7 (checked on Debian's 0.7.0)
//  - sphere vs mesh returns the sphere's nearest point in the sphere's own frame, and when the
//    sphere touches a triangle the leaf test leaves the distance uninitialised (the result is
//    whatever was on the stack, often 0);
//  - capsule vs mesh goes through GJK on the rounded support function: errors of 1e-7..5e-7 mm at
//    the default tolerance, where the swept-sphere form is exact;
//  - in contact, mesh vs shape gives -1 and no depth (enable_signed_distance asks collide() for
//    one contact, not the deepest), and there is no early-out below a threshold.
// So the tree walk is ours: FCL builds the OBBRSS tree (copied into a compact node array), its
// RSS-to-RSS distance bounds a box, GJK measures boxes and cylinders per triangle (EPA or MPR in
// contact); spheres, capsules (and the capsule around a cylinder) are bounded by a point /
// segment against each node's rectangle, and measured as a point / segment against the triangle
// in closed form, less the radius. fcl::distance on the same tool is ~30x slower (bench).
#include "collision/part_clearance.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace depotwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// GJK stops when a step improves the distance by less than this (mm): boxes converge exactly,
// cylinders to within about 1e-7 mm above a plate (the tests hold them to 1e-6). A tighter
// tolerance (1e-10) cost the arm's planning a quarter more time for no difference that matters
// to a clearance in millimetres
constexpr double kGjkTolerance = 1e-7;
// EPA in contact stops when its bounds on the depth are this close (mm)
constexpr double kEpaTolerance = 1e-9;
constexpr unsigned kGjkIterations = 1000;

// the closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5);
// abc has area
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// closest points c1 on segment p1q1 and c2 on p2q2 (Ericson 5.1.9); either may be a point
void closest_segment_segment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                             Vec3& c1, Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

// closest points between segment p0p1 and triangle abc (with area); the distance
double segment_triangle(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b, const Vec3& c,
                        Vec3& on_segment, Vec3& on_triangle) {
  const Vec3 n = (b - a).cross(c - a);
  const double s0 = n.dot(p0 - a), s1 = n.dot(p1 - a);
  if (((s0 <= 0 && s1 >= 0) || (s0 >= 0 && s1 <= 0)) && s0 != s1) {
    const Vec3 x = p0 + s0 / (s0 - s1) * (p1 - p0);  // where the segment meets the plane
    if ((b - a).cross(x - a).dot(n) >= 0 && (c - b).cross(x - b).dot(n) >= 0 &&
        (a - c).cross(x - c).dot(n) >= 0) {
      on_segment = on_triangle = x;
      return 0;
    }
  }
  // apart (or in the plane): the nearest pair has an end of the segment or an edge in it
  double best = kInf;
  auto consider = [&](const Vec3& s, const Vec3& t) {
    const double d2 = (s - t).squaredNorm();
    if (d2 < best) {
      best = d2;
      on_segment = s;
      on_triangle = t;
    }
  };
  consider(p0, closest_on_triangle(p0, a, b, c));
  consider(p1, closest_on_triangle(p1, a, b, c));
  const std::array<std::pair<const Vec3*, const Vec3*>, 3> edges{{{&a, &b}, {&b, &c}, {&c, &a}}};
  for (const auto& [u, v] : edges) {
    Vec3 cs, ce;
    closest_segment_segment(p0, p1, *u, *v, cs, ce);
    consider(cs, ce);
  }
  return std::sqrt(best);
}

struct Nearest {
  double d = kInf;
  int tri = -1;  // the tree's triangle index
  Vec3 on_shape = Vec3::Zero(), on_part = Vec3::Zero();
};

// the penetration of a polytope (at pose) into triangle abc by libccd's GJK + EPA, through FCL's
// support functions: the translation that separates them. Sets `out` and returns true when they
// overlap and EPA succeeded.
template <typename Geometry>
bool penetration(const Geometry& geometry, const Eigen::Isometry3d& pose, const Vec3& a,
                 const Vec3& b, const Vec3& c, Nearest& out) {
  using Init = fcl::detail::GJKInitializer<double, Geometry>;
  struct Objects {  // libccd's objects are heap allocated
    void* shape;
    void* triangle;
    ~Objects() {
      Init::deleteGJKObject(shape);
      fcl::detail::triDeleteGJKObject(triangle);
    }
  } objects{Init::createGJKObject(geometry, pose), fcl::detail::triCreateGJKObject(a, b, c)};
  double d = 0;
  Vec3 on_shape, on_tri;
  try {
    fcl::detail::GJKSignedDistance(objects.shape, Init::getSupportFunction(), objects.triangle,
                                   fcl::detail::triGetSupportFunction(), kGjkIterations,
                                   kEpaTolerance, &d, &on_shape, &on_tri);
  } catch (const std::exception&) {  // FCL gives up on degenerate polytopes
    return false;
  }
  if (!(d <= 0)) return false;
  out.d = d;
  out.on_shape = on_shape;
  out.on_part = on_tri;
  return true;
}

// A node of the part's tree, copied from FCL's OBBRSS tree: its RSS, the rectangle [0, l0] x
// [0, l1] spanned by axes u, v from corner `to`, swept by a sphere of radius r. 128 bytes where
// FCL's node (OBB and RSS) is 4 cache lines: on a large part the walk waits on memory.
struct alignas(64) Node {
  Vec3 u, v, w, to;  // w = u x v
  double l0 = 0, l1 = 0, r = 0;
  int first = 0;  // >= 0: children first and first + 1; < 0: a leaf, triangle slot -first - 1

  bool leaf() const { return first < 0; }
  int slot() const { return -first - 1; }
  Vec3 local(const Vec3& p) const {
    const Vec3 d = p - to;
    return Vec3(u.dot(d), v.dot(d), w.dot(d));
  }
  Vec3 local_direction(const Vec3& d) const { return Vec3(u.dot(d), v.dot(d), w.dot(d)); }
  fcl::RSSd rss() const {
    fcl::RSSd b;
    b.axis.col(0) = u;
    b.axis.col(1) = v;
    b.axis.col(2) = w;
    b.To = to;
    b.l[0] = l0;
    b.l[1] = l1;
    b.r = r;
    return b;
  }
};

// squared distance from q (in a rectangle's frame) to the rectangle [0, l0] x [0, l1] x {0}
double point_rectangle2(const Vec3& q, double l0, double l1) {
  const double dx = q.x() - std::clamp(q.x(), 0.0, l0), dy = q.y() - std::clamp(q.y(), 0.0, l1);
  return dx * dx + dy * dy + q.z() * q.z();
}

// distance from point p to node b's RSS (0 inside)
double point_rss(const Vec3& p, const Node& b) {
  return std::max(0.0, std::sqrt(point_rectangle2(b.local(p), b.l0, b.l1)) - b.r);
}

// squared distance from segment q0q1 (in a rectangle's frame) to the rectangle [0, l0] x [0, l1]
// x {0}: along the segment the distance's components are piecewise linear, breaking where the
// segment crosses x = 0, x = l0, y = 0, y = l1; on each piece the square is a quadratic
double segment_rectangle2(const Vec3& q0, const Vec3& q1, double l0, double l1) {
  const Vec3 dq = q1 - q0;
  std::array<double, 6> t{};  // 0, the crossings in order, 1
  int n = 1;
  for (int k = 0; k < 2; ++k) {
    if (dq[k] == 0) continue;
    for (double edge : {0.0, k == 0 ? l0 : l1}) {
      const double tk = (edge - q0[k]) / dq[k];
      if (!(tk > 0 && tk < 1)) continue;
      int j = n++;
      for (; j > 1 && t[j - 1] > tk; --j) t[j] = t[j - 1];
      t[j] = tk;
    }
  }
  t[n++] = 1;
  double best = kInf;
  for (int i = 0; i + 1 < n; ++i) {
    const double ta = t[i], tb = t[i + 1], mid = 0.5 * (ta + tb);
    // the active components as a + b t: outside the rectangle's span in x, in y, and z
    std::array<double, 3> a{0, 0, q0.z()}, b{0, 0, dq.z()};
    for (int k = 0; k < 2; ++k) {
      const double x = q0[k] + mid * dq[k], hi = k == 0 ? l0 : l1;
      if (x < 0) {
        a[k] = -q0[k];
        b[k] = -dq[k];
      } else if (x > hi) {
        a[k] = q0[k] - hi;
        b[k] = dq[k];
      }
    }
    // the quadratic's minimum on the piece; the square summed from the components there (no
    // cancellation near 0)
    const double bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const double ts = bb > 0 ? std::clamp(-ab / bb, ta, tb) : ta;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (a[k] + b[k] * ts) * (a[k] + b[k] * ts);
    best = std::min(best, d2);
  }
  return best;
}

// distance from segment p0p1 to node b's RSS (0 inside)
double segment_rss(const Vec3& p0, const Vec3& p1, const Node& b) {
  return std::max(0.0, std::sqrt(segment_rectangle2(b.local(p0), b.local(p1), b.l0, b.l1)) - b.r);
}

// one shape at its world pose, ready for the walk
struct PosedShape {
  CollisionShape::Type type = CollisionShape::Type::sphere;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Vec3 size = Vec3::Zero();
  Vec3 p0 = Vec3::Zero(), p1 = Vec3::Zero();  // the core segment of a sphere (a point) or capsule
  double radius = 0;                          // sphere, capsule, cylinder
  fcl::RSSd box_bound;  // a box: its largest face's rectangle swept by its smallest half extent
};

std::string shape_label(const CollisionShape& shape, size_t index) {
  return shape.name.empty() ? "shape " + std::to_string(index) : shape.name;
}

PosedShape pose_shape(const CollisionShape& shape, const Eigen::Isometry3d& pose,
                      const std::string& label) {
  const Vec3& sz = shape.size_mm;
  auto bad_size = [&](const std::string& what) {
    std::ostringstream text;
    text << "size_mm (" << sz.x() << ", " << sz.y() << ", " << sz.z() << "): " << what;
    throw InputError(label, text.str());
  };
  if (!sz.allFinite()) bad_size("not finite");
  PosedShape s;
  s.type = shape.type;
  s.pose = pose;
  s.size = sz;
  const Vec3 c = pose.translation();
  const Eigen::Matrix3d R = pose.linear();
  switch (shape.type) {  // p0, p1: the core segment; a cylinder is bounded by its capsule
    case CollisionShape::Type::sphere:
      if (!(sz.x() > 0)) bad_size("a sphere needs a radius > 0");
      s.radius = sz.x();
      s.p0 = s.p1 = c;
      break;
    case CollisionShape::Type::capsule:
    case CollisionShape::Type::cylinder: {
      const bool capsule = shape.type == CollisionShape::Type::capsule;
      if (!(sz.x() > 0) || !(capsule ? sz.y() >= 0 : sz.y() > 0))
        bad_size(capsule ? "a capsule needs a radius > 0 and a half-length >= 0"
                         : "a cylinder needs a radius > 0 and a half-length > 0");
      s.radius = sz.x();
      const Vec3 axis = R.col(2);
      s.p0 = c - sz.y() * axis;
      s.p1 = c + sz.y() * axis;
      break;
    }
    case CollisionShape::Type::box: {
      if (!(sz.minCoeff() > 0)) bad_size("a box needs half extents > 0");
      // the rectangle across the two largest half extents, swept by the smallest
      std::array<int, 3> order{0, 1, 2};
      std::sort(order.begin(), order.end(), [&](int i, int j) { return sz[i] > sz[j]; });
      const Vec3 u = R.col(order[0]), v = R.col(order[1]);
      s.box_bound.axis.col(0) = u;
      s.box_bound.axis.col(1) = v;
      s.box_bound.axis.col(2) = u.cross(v);
      s.box_bound.To = c - sz[order[0]] * u - sz[order[1]] * v;
      s.box_bound.l[0] = 2 * sz[order[0]];
      s.box_bound.l[1] = 2 * sz[order[1]];
      s.box_bound.r = sz[order[2]];
      break;
    }
  }
  return s;
}

// the shape's extent along unit direction n (support in +n plus support in -n)
double width_along(const PosedShape& s, const Vec3& n) {
  const Eigen::Matrix3d R = s.pose.linear();
  switch (s.type) {
    case CollisionShape::Type::sphere:
      return 2 * s.radius;
    case CollisionShape::Type::capsule:
      return 2 * s.radius + 2 * s.size.y() * std::abs(R.col(2).dot(n));
    case CollisionShape::Type::cylinder: {
      const double c = std::abs(R.col(2).dot(n));
      return 2 * s.size.y() * c + 2 * s.radius * std::sqrt(std::max(0.0, 1 - c * c));
    }
    case CollisionShape::Type::box:
      return 2 * (s.size.x() * std::abs(R.col(0).dot(n)) + s.size.y() * std::abs(R.col(1).dot(n)) +
                  s.size.z() * std::abs(R.col(2).dot(n)));
  }
  return 0;
}

// a fixed-size stack with a heap fallback for unusually deep trees (no allocation per query)
class NodeStack {
 public:
  bool empty() const { return size_ == 0; }
  void push(int node, double bound) {
    if (size_ < kInline) {
      inline_[size_] = {node, bound};
    } else {
      overflow_.resize(size_ - kInline + 1);
      overflow_.back() = {node, bound};
    }
    ++size_;
  }
  std::pair<int, double> pop() {
    --size_;
    if (size_ < kInline) return inline_[size_];
    auto top = overflow_.back();
    overflow_.pop_back();
    return top;
  }

 private:
  static constexpr size_t kInline = 128;
  std::array<std::pair<int, double>, kInline> inline_;
  std::vector<std::pair<int, double>> overflow_;
  size_t size_ = 0;
};

// ray directions for the inside test: generic, so a ray through a vertex or along an edge of a
// machined (axis-aligned) part is unlikely; the next one is tried when a hit is too close to call
const std::array<Vec3, 3> kRayDirections{Vec3(0.3746, 0.5021, 0.7794).normalized(),
                                         Vec3(-0.6213, 0.2749, -0.7338).normalized(),
                                         Vec3(0.1457, -0.8663, 0.4779).normalized()};

}  // namespace

struct PartClearance::Impl {
  std::vector<Node> nodes;                     // the tree, root first
  std::vector<std::array<Vec3, 3>> triangles;  // the triangles with area, in leaf order
  std::vector<int> original;                   // triangle slot -> part_mm triangle
  bool closed = false;                         // every edge shared by an even number of triangles
  double scale = 1;  // the part's bounding-box diagonal (mm), for tolerances

  // the exact test of one shape against one triangle; negative in contact (see the header)
  Nearest leaf(const PosedShape& s, int tri) const;
  // a lower bound on the shape's distance to the triangles under a node (0 when they may touch)
  double bound(const PosedShape& s, int node) const;
  // the shape's nearest triangle among those closer than `limit` (d stays +inf when none is);
  // returns as soon as d < stop_below
  void walk(const PosedShape& s, double limit, double stop_below, Nearest& best) const;
  // whether point p is inside the closed part (ray parity)
  bool inside(const Vec3& p) const;
  // the shape's result: walk, then on a closed part the sign
  Nearest query(const PosedShape& s, double limit, double stop_below) const;
};

Nearest PartClearance::Impl::leaf(const PosedShape& s, int tri) const {
  const Vec3 &a = triangles[tri][0], &b = triangles[tri][1], &c = triangles[tri][2];
  Nearest out;
  out.tri = tri;
  fcl::detail::GJKSolver_libccd<double> solver;  // a few numbers: one per call, nothing shared
  solver.distance_tolerance = kGjkTolerance;
  solver.max_distance_iterations = kGjkIterations;
  const double tiny = 1e-12 * scale;
  switch (s.type) {
    case CollisionShape::Type::sphere:
    case CollisionShape::Type::capsule: {
      Vec3 core = s.p0, on_tri = s.p0;
      double dc = 0;
      if (s.type == CollisionShape::Type::sphere) {
        on_tri = closest_on_triangle(core, a, b, c);
        dc = (on_tri - core).norm();
      } else {
        dc = segment_triangle(s.p0, s.p1, a, b, c, core, on_tri);
      }
      if (dc > tiny) {
        out.d = dc - s.radius;  // exact, also as a penetration depth while the core is clear
        out.on_part = on_tri;
        out.on_shape = core + s.radius / dc * (on_tri - core);
        return out;
      }
      // the core touches the triangle: the shape reaches at least its radius through it
      out.d = -s.radius;
      out.on_part = on_tri;
      out.on_shape = on_tri - s.radius * (b - a).cross(c - a).normalized();
      if (s.type == CollisionShape::Type::capsule) {  // the axis pierces it: MPR's estimate
        const fcl::Capsuled capsule(s.radius, 2 * s.size.y());
        Vec3 contact, normal;
        double depth = 0;
        if (solver.shapeTriangleIntersect(capsule, s.pose, a, b, c, &contact, &depth, &normal) &&
            depth > s.radius) {
          out.d = -depth;
          out.on_shape = out.on_part = contact;
        }
      }
      return out;
    }
    case CollisionShape::Type::box:
    case CollisionShape::Type::cylinder: {
      auto gjk = [&](const auto& geometry) {
        double d = 0;
        Vec3 on_shape, on_tri;
        if (solver.shapeTriangleDistance(geometry, s.pose, a, b, c, &d, &on_shape, &on_tri)) {
          out.d = d;
          out.on_shape = on_shape;
          out.on_part = on_tri;
          return;
        }
        // in contact: EPA for a box (a polytope: it ends, exact); on a rounded shape EPA needs
        // ever more faces as its tolerance shrinks (a capsule's cap: 0.8 s at 1e-6 mm), so
        // FCL's MPR estimate there, and where EPA fails (it may overstate a box's depth ~2x)
        if (s.type == CollisionShape::Type::box && penetration(geometry, s.pose, a, b, c, out))
          return;
        Vec3 contact, normal;
        double depth = 0;
        if (solver.shapeTriangleIntersect(geometry, s.pose, a, b, c, &contact, &depth, &normal)) {
          out.d = -depth;
          out.on_shape = out.on_part = contact;
        } else {  // GJK and MPR disagree: touching
          out.d = 0;
          out.on_shape = out.on_part = closest_on_triangle(s.pose.translation(), a, b, c);
        }
      };
      if (s.type == CollisionShape::Type::box)
        gjk(fcl::Boxd(2 * s.size));
      else
        gjk(fcl::Cylinderd(s.radius, 2 * s.size.y()));
      return out;
    }
  }
  return out;
}

double PartClearance::Impl::bound(const PosedShape& s, int node) const {
  const Node& n = nodes[node];
  switch (s.type) {
    case CollisionShape::Type::sphere:
      return std::max(0.0, point_rss(s.p0, n) - s.radius);
    case CollisionShape::Type::capsule:
    case CollisionShape::Type::cylinder:  // its capsule
      return std::max(0.0, segment_rss(s.p0, s.p1, n) - s.radius);
    case CollisionShape::Type::box:
      return s.box_bound.distance(n.rss());
  }
  return 0;
}

void PartClearance::Impl::walk(const PosedShape& s, double limit, double stop_below,
                               Nearest& best) const {
  // nodes at least `cut` away cannot improve; in contact (cut <= 0), every overlapping node can
  // hold a deeper penetration
  auto pruned = [&](double lower) {
    const double cut = std::min(limit, best.d);
    return cut > 0 ? lower >= cut : lower > 0;
  };
  // a sphere's or capsule's triangle test costs about as much as a bound: no bound for leaves
  const bool cheap_leaves =
      s.type == CollisionShape::Type::sphere || s.type == CollisionShape::Type::capsule;
  auto test_leaf = [&](int node) {
    // a cylinder's GJK converges slowly on its round side: first two closed-form lower bounds,
    // its capsule (never farther than the cylinder) and, for a triangle wholly beyond one of
    // its end faces, that face's plane, so triangles that cannot beat the best skip the GJK
    if (s.type == CollisionShape::Type::cylinder) {
      const auto& tri = triangles[nodes[node].slot()];
      Vec3 on_core, on_tri;
      double lower =
          segment_triangle(s.p0, s.p1, tri[0], tri[1], tri[2], on_core, on_tri) - s.radius;
      const Vec3 axis = (s.p1 - s.p0).normalized();
      double beyond_p0 = kInf, beyond_p1 = kInf;
      for (const Vec3& v : tri) {
        beyond_p0 = std::min(beyond_p0, (s.p0 - v).dot(axis));
        beyond_p1 = std::min(beyond_p1, (v - s.p1).dot(axis));
      }
      lower = std::max({lower, beyond_p0, beyond_p1});
      if (pruned(lower)) return false;
    }
    const Nearest hit = leaf(s, nodes[node].slot());
    if (hit.d < best.d) best = hit;
    return best.d < stop_below;
  };
  NodeStack stack;
  if (cheap_leaves && nodes[0].leaf()) {
    test_leaf(0);
    return;
  }
  const double root_bound = bound(s, 0);
  if (!pruned(root_bound)) stack.push(0, root_bound);
  while (!stack.empty()) {
    const auto [id, lower] = stack.pop();
    if (pruned(lower)) continue;  // best improved since it was pushed
    const Node& node = nodes[id];
    if (node.leaf()) {
      if (test_leaf(id)) return;
      continue;
    }
    std::array<std::pair<int, double>, 2> children{{{node.first, 0}, {node.first + 1, 0}}};
    int open = 0;
    for (auto& child : children) {
      if (cheap_leaves && nodes[child.first].leaf()) {
        if (test_leaf(child.first)) return;
        continue;
      }
      child.second = bound(s, child.first);
      children[open++] = child;
    }
    // the nearer child on top, so it is searched first
    if (open == 2 && children[0].second < children[1].second) std::swap(children[0], children[1]);
    for (int k = 0; k < open; ++k) {
      if (pruned(children[k].second)) continue;
      stack.push(children[k].first, children[k].second);
      // what it will read next, fetched while the walk goes on (the walk waits on memory)
      const Node& next = nodes[children[k].first];
      if (next.leaf()) {
        __builtin_prefetch(&triangles[next.slot()]);
      } else {
        const char* pair = reinterpret_cast<const char*>(&nodes[next.first]);
        for (size_t line = 0; line < 2 * sizeof(Node); line += 64) __builtin_prefetch(pair + line);
      }
    }
  }
}

bool PartClearance::Impl::inside(const Vec3& p) const {
  const double eps = 1e-9;
  bool result = false;
  for (const Vec3& dir : kRayDirections) {
    int crossings = 0;
    bool fragile = false;
    NodeStack stack;
    stack.push(0, 0);
    while (!stack.empty() && !fragile) {
      const Node& node = nodes[stack.pop().first];
      // the ray against the box around the node's RSS (slabs in its frame, a little padded)
      const Vec3 o = node.local(p), d = node.local_direction(dir);
      const Vec3 lo(-node.r, -node.r, -node.r), hi(node.l0 + node.r, node.l1 + node.r, node.r);
      const double pad = eps * scale;
      double t0 = 0, t1 = kInf;
      for (int k = 0; k < 3 && t0 <= t1; ++k) {
        if (std::abs(d[k]) < 1e-300) {
          if (o[k] < lo[k] - pad || o[k] > hi[k] + pad) t1 = -1;
          continue;
        }
        double ta = (lo[k] - pad - o[k]) / d[k], tb = (hi[k] + pad - o[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (t0 > t1) continue;
      if (!node.leaf()) {
        stack.push(node.first, 0);
        stack.push(node.first + 1, 0);
        continue;
      }
      // Moller-Trumbore; a hit near an edge, a vertex, the ray's origin or along the plane is
      // too close to call and the next direction is tried
      const auto& [a, b, c] = triangles[node.slot()];
      const Vec3 e1 = b - a, e2 = c - a, q = dir.cross(e2);
      const double det = e1.dot(q);
      if (std::abs(det) <= eps * e1.norm() * e2.norm()) {  // along the plane, through the box
        fragile = true;
        continue;
      }
      const Vec3 r = p - a;
      const double u = r.dot(q) / det;
      const Vec3 w = r.cross(e1);
      const double v = dir.dot(w) / det, t = e2.dot(w) / det;
      if (u < -eps || v < -eps || u + v > 1 + eps || t < -eps * scale) continue;
      if (u < eps || v < eps || u + v > 1 - eps || t < eps * scale) {
        fragile = true;
        continue;
      }
      ++crossings;
    }
    result = crossings % 2 == 1;
    if (!fragile) return result;
  }
  return result;  // every direction grazed something: the last one's count
}

Nearest PartClearance::Impl::query(const PosedShape& s, double limit, double stop_below) const {
  Nearest best;
  walk(s, limit, stop_below, best);
  if (!closed || best.d <= 0) return best;
  // clear of the surface: inside or outside the solid as its centre is
  if (!inside(s.pose.translation())) return best;
  if (best.tri < 0 || best.d >= limit) {  // pruned by `limit`: its own nearest point
    best = Nearest();
    walk(s, kInf, -kInf, best);
  }
  const Vec3 out = best.on_part - best.on_shape;
  best.d = -(best.d + width_along(s, out / out.norm()));
  return best;
}

PartClearance::PartClearance(const TriangleMesh& part_mm) : impl_(std::make_unique<Impl>()) {
  const auto& V = part_mm.vertices;
  if (part_mm.empty()) throw InputError("part", "the mesh has no triangles");
  for (size_t i = 0; i < V.size(); ++i) {
    if (!V[i].allFinite()) {
      std::ostringstream text;
      text << "vertex " << i << " is not finite (" << V[i].x() << ", " << V[i].y() << ", "
           << V[i].z() << ")";
      throw InputError("part", text.str());
    }
  }
  std::vector<fcl::Triangle> kept;
  kept.reserve(part_mm.triangles.size());
  Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
  for (size_t t = 0; t < part_mm.triangles.size(); ++t) {
    const auto& tri = part_mm.triangles[t];
    for (int k : tri) {
      if (k < 0 || static_cast<size_t>(k) >= V.size())
        throw InputError("part", "triangle " + std::to_string(t) + " has vertex index " +
                                     std::to_string(k) + " of " + std::to_string(V.size()));
    }
    const Vec3 &a = V[tri[0]], &b = V[tri[1]], &c = V[tri[2]];
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!((b - a).cross(c - a).norm() > 1e-12 * longest)) continue;  // no area
    kept.emplace_back(tri[0], tri[1], tri[2]);
    impl_->original.push_back(static_cast<int>(t));
    for (int k : tri) {
      lo = lo.cwiseMin(V[k]);
      hi = hi.cwiseMax(V[k]);
    }
  }
  if (kept.empty()) throw InputError("part", "no triangle of the mesh has an area");
  impl_->scale = std::max((hi - lo).norm(), 1e-9);

  // closed: every edge (vertices at the same coordinates merged) used an even number of times
  std::map<std::array<double, 3>, int> welded;
  std::vector<int> weld(V.size());
  for (size_t i = 0; i < V.size(); ++i)
    weld[i] = welded
                  .emplace(std::array<double, 3>{V[i].x(), V[i].y(), V[i].z()},
                           static_cast<int>(welded.size()))
                  .first->second;
  std::unordered_map<uint64_t, int> edge_uses;
  for (const auto& tri : kept) {
    for (int k = 0; k < 3; ++k) {
      uint64_t i = weld[tri[k]], j = weld[tri[(k + 1) % 3]];
      if (i > j) std::swap(i, j);
      ++edge_uses[(i << 32) | j];
    }
  }
  impl_->closed = std::all_of(edge_uses.begin(), edge_uses.end(),
                              [](const auto& e) { return e.second % 2 == 0; });

  // FCL builds the tree (OBBRSS, split at the mean); its nodes are copied, leaves' triangles
  // stored in leaf order
  fcl::BVHModel<fcl::OBBRSSd> bvh;
  const std::vector<fcl::Vector3d> vertices(V.begin(), V.end());
  if (bvh.beginModel(static_cast<int>(kept.size()), static_cast<int>(vertices.size())) !=
          fcl::BVH_OK ||
      bvh.addSubModel(vertices, kept) != fcl::BVH_OK || bvh.endModel() != fcl::BVH_OK)
    throw InternalError("PartClearance: FCL could not build the part's tree");
  auto& nodes = impl_->nodes;
  nodes.resize(static_cast<size_t>(bvh.getNumBVs()));
  std::vector<int> kept_original = std::move(impl_->original);
  impl_->original.clear();
  impl_->triangles.reserve(kept.size());
  for (int i = 0; i < bvh.getNumBVs(); ++i) {
    const auto& from = bvh.getBV(i);
    const fcl::RSSd& rss = from.bv.rss;
    Node& n = nodes[static_cast<size_t>(i)];
    n.u = rss.axis.col(0);
    n.v = rss.axis.col(1);
    n.w = n.u.cross(n.v);
    n.to = rss.To;
    n.l0 = rss.l[0];
    n.l1 = rss.l[1];
    n.r = rss.r;
    if (from.isLeaf()) {
      const int t = from.primitiveId();
      const fcl::Triangle& tri = kept[static_cast<size_t>(t)];
      n.first = -static_cast<int>(impl_->triangles.size()) - 1;
      impl_->triangles.push_back({V[tri[0]], V[tri[1]], V[tri[2]]});
      impl_->original.push_back(kept_original[static_cast<size_t>(t)]);
    } else {
      n.first = from.leftChild();
      if (from.rightChild() != n.first + 1)
        throw InternalError("PartClearance: FCL's tree does not keep siblings together");
    }
  }
}

PartClearance::~PartClearance() = default;
PartClearance::PartClearance(PartClearance&&) noexcept = default;
PartClearance& PartClearance::operator=(PartClearance&&) noexcept = default;

size_t PartClearance::triangle_count() const {
  return impl_->triangles.size();
}

bool PartClearance::closed() const {
  return impl_->closed;
}

namespace {

PartClearance::Result to_result(const Nearest& n, int shape, const std::vector<int>& original) {
  PartClearance::Result r;
  r.distance_mm = n.d;
  r.shape = shape;
  r.triangle = n.tri >= 0 ? original[n.tri] : -1;
  r.on_shape_mm = n.on_shape;
  r.on_part_mm = n.on_part;
  return r;
}

}  // namespace

PartClearance::Result PartClearance::nearest(const CollisionShape& shape,
                                             const Eigen::Isometry3d& world_pose_mm) const {
  if (!world_pose_mm.matrix().allFinite())
    throw InternalError("PartClearance::nearest: the pose of " + shape_label(shape, 0) +
                        " is not finite");
  const PosedShape s = pose_shape(shape, world_pose_mm, shape_label(shape, 0));
  return to_result(impl_->query(s, kInf, -kInf), 0, impl_->original);
}

PartClearance::Result PartClearance::clearance(const std::vector<CollisionShape>& shapes,
                                               const std::vector<Eigen::Isometry3d>& link_frames_mm,
                                               double stop_below_mm) const {
  Result out;
  // every shape posed, with a lower bound on its distance to the whole part (the tree's root)
  std::vector<PosedShape> posed;
  std::vector<std::pair<double, size_t>> order;
  posed.reserve(shapes.size());
  order.reserve(shapes.size());
  for (size_t k = 0; k < shapes.size(); ++k) {
    const CollisionShape& shape = shapes[k];
    if (shape.link < 0 || static_cast<size_t>(shape.link) >= link_frames_mm.size())
      throw InternalError("PartClearance::clearance: " + shape_label(shape, k) + " rides on link " +
                          std::to_string(shape.link) + " of " +
                          std::to_string(link_frames_mm.size()));
    const Eigen::Isometry3d world = link_frames_mm[static_cast<size_t>(shape.link)] * shape.in_link;
    if (!world.matrix().allFinite())
      throw InternalError("PartClearance::clearance: the pose of " + shape_label(shape, k) +
                          " (link " + std::to_string(shape.link) + ") is not finite");
    posed.push_back(pose_shape(shape, world, shape_label(shape, k)));
    order.emplace_back(impl_->bound(posed.back(), 0), k);
  }
  // the nearest-looking shapes first: the ones far from the part are then cut at the root, with
  // no triangle test (a link 400 mm away walked first cost thousands of GJK calls)
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [root_bound, k] : order) {
    // only what beats the shapes so far matters
    if (root_bound > 0.0 && root_bound >= out.distance_mm) break;
    const Nearest n = impl_->query(posed[k], out.distance_mm, stop_below_mm);
    if (n.d < out.distance_mm || (n.d == out.distance_mm && static_cast<int>(k) < out.shape))
      out = to_result(n, static_cast<int>(k), impl_->original);
    if (out.distance_mm < stop_below_mm) break;
  }
  return out;
}

}  // namespace depotwin
