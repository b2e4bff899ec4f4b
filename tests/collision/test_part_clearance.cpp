// Clearance between convex machine shapes and a non-convex part (collision/part_clearance.hpp):
// closed-form gaps above a plate and inside a U channel (where the part's convex hull, which is
// what MuJoCo would collide, says the tool is in the part), contact, several shapes on several
// links, inside a closed part, and the tree walk against every triangle on its own.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "collision/part_clearance.hpp"
#include "core/error.hpp"

namespace depotwin {
namespace {

using Type = CollisionShape::Type;
constexpr double kTol = 1e-6;  // mm

CollisionShape make_shape(Type type, Vec3 size, int link = 0,
                          Eigen::Isometry3d in_link = Eigen::Isometry3d::Identity()) {
  CollisionShape s;
  s.type = type;
  s.size_mm = size;
  s.link = link;
  s.in_link = in_link;
  return s;
}

Eigen::Isometry3d pose(const Vec3& at,
                       const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = rotation;
  p.translation() = at;
  return p;
}

Eigen::Matrix3d rotation(double angle, Vec3 axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// the square [-half, half]^2 at z = 0 in n x n cells, normals +z (an open surface)
TriangleMesh plate(int n, double half) {
  TriangleMesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      m.vertices.emplace_back(-half + 2 * half * i / n, -half + 2 * half * j / n, 0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + n + 1;
      m.triangles.push_back({a, b, b + 1});
      m.triangles.push_back({a, b + 1, a + 1});
    }
  return m;
}

// a prism: the polygon `profile` (x, z), counter-clockwise, extruded over y in [-half_y, half_y];
// `caps` triangulates the profile (indices into it, counter-clockwise)
TriangleMesh prism(const std::vector<Eigen::Vector2d>& profile,
                   const std::vector<std::array<int, 3>>& caps, double half_y) {
  TriangleMesh m;
  const int n = static_cast<int>(profile.size());
  for (double y : {-half_y, half_y})
    for (const auto& p : profile) m.vertices.emplace_back(p.x(), y, p.y());
  // counter-clockwise in (x, z) has the normal -y: the cap at -half_y as is, the other reversed
  for (const auto& t : caps) {
    m.triangles.push_back({t[0], t[1], t[2]});
    m.triangles.push_back({n + t[0], n + t[2], n + t[1]});
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, n + j, j});
    m.triangles.push_back({i, n + i, n + j});
  }
  return m;
}

// a U channel along y: floor z in [0, floor], walls x in [-outer, -groove] and [groove, outer] up
// to z = height; the groove x in (-groove, groove), z > floor is open at the top
struct Channel {
  double outer = 30, groove = 10, floor = 5, height = 40, half_y = 50;
  TriangleMesh mesh() const {
    const std::vector<Eigen::Vector2d> profile{{-outer, 0},       {outer, 0},      {outer, height},
                                               {groove, height},  {groove, floor}, {-groove, floor},
                                               {-groove, height}, {-outer, height}};
    // the floor slab and the two walls, each a convex quadrilateral
    const std::vector<std::array<int, 3>> caps{{0, 1, 4}, {0, 4, 5}, {1, 2, 3},
                                               {1, 3, 4}, {5, 6, 7}, {5, 7, 0}};
    return prism(profile, caps, half_y);
  }
};

TriangleMesh cube(double half) {
  const std::vector<Eigen::Vector2d> square{
      {-half, -half}, {half, -half}, {half, half}, {-half, half}};
  return prism(square, {{0, 1, 2}, {0, 2, 3}}, half);
}

void expect_consistent(const PartClearance::Result& r) {
  ASSERT_GT(r.distance_mm, 0);
  EXPECT_NEAR((r.on_shape_mm - r.on_part_mm).norm(), r.distance_mm, kTol);
}

TEST(PartClearance, SphereInAConcaveChannelIsClearWhereTheHullSaysItIsInside) {
  const Channel ch;
  const TriangleMesh mesh = ch.mesh();
  ASSERT_GT(mesh.signed_volume_mm3(), 0);
  const PartClearance part(mesh);
  EXPECT_TRUE(part.closed());
  EXPECT_EQ(part.triangle_count(), mesh.triangle_count());

  // in the groove, 1.5 mm right of its middle: the right wall is nearest
  const double r = 6;
  const Vec3 c(1.5, 3, 20);
  const auto sphere = make_shape(Type::sphere, Vec3(r, 0, 0));
  const auto res = part.nearest(sphere, pose(c));
  const double wall = ch.groove - c.x() - r, floor = c.z() - ch.floor - r;  // 2.5, 9
  EXPECT_NEAR(res.distance_mm, std::min(wall, floor), kTol);
  EXPECT_NEAR(res.distance_mm, 2.5, kTol);
  EXPECT_TRUE(res.on_part_mm.isApprox(Vec3(ch.groove, c.y(), c.z()), 1e-9));
  EXPECT_TRUE(res.on_shape_mm.isApprox(Vec3(c.x() + r, c.y(), c.z()), 1e-9));
  expect_consistent(res);

  // the convex hull is the box [-outer, outer] x [-half_y, half_y] x [0, height]: it holds the
  // sphere's centre, so a hull-based check has the sphere 26 mm deep in the part
  const double hull_depth = std::min({ch.outer - std::abs(c.x()), ch.half_y - std::abs(c.y()),
                                      c.z(), ch.height - c.z()}) +
                            r;
  EXPECT_NEAR(hull_depth, 26, 1e-12);
  EXPECT_LT(-hull_depth, 0);

  // lower: the floor is nearest (9 - 6 = 3 mm above it at z = 14)
  const auto low = part.nearest(sphere, pose(Vec3(0, 0, 14)));
  EXPECT_NEAR(low.distance_mm, 3, kTol);
  EXPECT_NEAR(low.on_part_mm.z(), ch.floor, 1e-9);
  // a capsule lying along the groove: 10 - 4 = 6 mm from both walls, 14 - 5 - 4 = 5 from the floor
  const auto capsule = make_shape(Type::capsule, Vec3(4, 20, 0));
  const auto along = part.nearest(capsule, pose(Vec3(0, 0, 14), rotation(kPi / 2, Vec3::UnitX())));
  EXPECT_NEAR(along.distance_mm, 5, kTol);
}

TEST(PartClearance, ShapesAboveAPlateMatchTheAnalyticGap) {
  const PartClearance part(plate(10, 100));
  EXPECT_FALSE(part.closed());
  const std::vector<Eigen::Matrix3d> rotations{
      Eigen::Matrix3d::Identity(),        rotation(0.7, Vec3::UnitX()),
      rotation(kPi / 2, Vec3::UnitY()),   rotation(1.1, Vec3(1, 2, 0.5)),
      rotation(-2.3, Vec3(-0.3, 0.4, 1)), rotation(0.05, Vec3(1, 1, 0))};
  const Vec3 at(3.3, -4.1, 30);
  for (const auto& R : rotations) {
    const Vec3 z = R.row(2);  // z components of the shape's axes
    struct Case {
      CollisionShape shape;
      double gap;
    };
    const std::vector<Case> cases{
        {make_shape(Type::sphere, Vec3(2, 0, 0)), at.z() - 2},
        {make_shape(Type::capsule, Vec3(2, 9, 0)), at.z() - 9 * std::abs(z[2]) - 2},
        {make_shape(Type::cylinder, Vec3(2, 9, 0)),
         at.z() - 9 * std::abs(z[2]) - 2 * std::sqrt(1 - z[2] * z[2])},
        {make_shape(Type::box, Vec3(3, 5, 7)),
         at.z() - 3 * std::abs(z[0]) - 5 * std::abs(z[1]) - 7 * std::abs(z[2])},
    };
    for (const auto& c : cases) {
      SCOPED_TRACE(::testing::Message() << "type " << static_cast<int>(c.shape.type) << ", R =\n"
                                        << R);
      const auto res = part.nearest(c.shape, pose(at, R));
      EXPECT_NEAR(res.distance_mm, c.gap, kTol);
      EXPECT_NEAR(part.distance(c.shape, pose(at, R)), c.gap, kTol);
      EXPECT_NEAR(res.on_part_mm.z(), 0, 1e-9);
      EXPECT_NEAR(res.on_shape_mm.z(), c.gap, kTol);
      expect_consistent(res);
    }
  }
}

TEST(PartClearance, ShapesPushedIntoThePartReportContact) {
  const PartClearance part(plate(10, 100));
  // a sphere 1 mm through: -1 exactly, its deepest point 1 mm below the plate
  const auto sphere = part.nearest(make_shape(Type::sphere, Vec3(2, 0, 0)), pose(Vec3(1, 2, 1)));
  EXPECT_NEAR(sphere.distance_mm, -1, 1e-12);
  EXPECT_NEAR(sphere.on_shape_mm.z(), -1, 1e-12);
  EXPECT_NEAR(sphere.on_part_mm.z(), 0, 1e-12);
  // a capsule lying 0.5 mm through (its core clear): -0.5 exactly
  const auto lying = part.nearest(make_shape(Type::capsule, Vec3(2, 10, 0)),
                                  pose(Vec3(0, 0, 1.5), rotation(kPi / 2, Vec3::UnitX())));
  EXPECT_NEAR(lying.distance_mm, -0.5, 1e-12);
  // a capsule standing through the plate: at least its radius deep
  EXPECT_LE(part.distance(make_shape(Type::capsule, Vec3(2, 10, 0)), pose(Vec3(0, 0, 3))), -2);
  // a box and a cylinder 1 mm through (FCL's MPR depth)
  const double box = part.distance(make_shape(Type::box, Vec3(3, 3, 3)), pose(Vec3(5, 5, 2)));
  EXPECT_LT(box, 0);
  EXPECT_NEAR(box, -1, 1e-6);
  EXPECT_LT(part.distance(make_shape(Type::cylinder, Vec3(3, 5, 0)), pose(Vec3(5, 5, 4))), 0);
  // touching counts as contact
  EXPECT_NEAR(part.distance(make_shape(Type::box, Vec3(3, 3, 3)), pose(Vec3(5, 5, 3))), 0, 1e-9);

  // among several shapes, the one in the part is reported
  const std::vector<CollisionShape> shapes{make_shape(Type::sphere, Vec3(2, 0, 0)),
                                           make_shape(Type::box, Vec3(3, 3, 3), 1),
                                           make_shape(Type::capsule, Vec3(1, 4, 0), 2)};
  const std::vector<Eigen::Isometry3d> frames{pose(Vec3(0, 0, 10)), pose(Vec3(20, 0, 2.5)),
                                              pose(Vec3(-20, 0, 8))};
  const auto res = part.clearance(shapes, frames);
  EXPECT_EQ(res.shape, 1);
  EXPECT_LE(res.distance_mm, 0);
}

TEST(PartClearance, SeveralShapesOnSeveralLinksGiveTheMinimumAndItsIndex) {
  const PartClearance part(plate(10, 100));
  // link frames: translated and turned; shapes offset in their links
  const std::vector<Eigen::Isometry3d> frames{
      pose(Vec3(0, 0, 40), rotation(0.3, Vec3::UnitZ())), pose(Vec3(10, -5, 20)),
      pose(Vec3(-10, 5, 30), rotation(kPi, Vec3::UnitX()))};  // link 2 upside down
  const std::vector<CollisionShape> shapes{
      // link 0, 10 mm above its origin: 50 - 3 = 47
      make_shape(Type::sphere, Vec3(3, 0, 0), 0, pose(Vec3(0, 0, 10))),
      // link 1, vertical capsule 4 mm above its origin: 24 - 6 - 1 = 17
      make_shape(Type::capsule, Vec3(1, 6, 0), 1, pose(Vec3(0, 0, 4))),
      // link 2 (upside down), box 8 mm along the link's -z: 30 + 8 - 2 = 36
      make_shape(Type::box, Vec3(2, 2, 2), 2, pose(Vec3(0, 0, -8))),
      // link 1 again, horizontal cylinder 6 mm below its origin: 14 - 1.5 = 12.5 (the minimum)
      make_shape(Type::cylinder, Vec3(1.5, 5, 0), 1,
                 pose(Vec3(0, 0, -6), rotation(kPi / 2, Vec3::UnitY())))};
  const auto res = part.clearance(shapes, frames);
  EXPECT_EQ(res.shape, 3);
  EXPECT_NEAR(res.distance_mm, 12.5, kTol);
  expect_consistent(res);
  const std::vector<double> each{47, 17, 36, 12.5};
  for (size_t k = 0; k < shapes.size(); ++k) {
    const Eigen::Isometry3d world = frames[shapes[k].link] * shapes[k].in_link;
    EXPECT_NEAR(part.distance(shapes[k], world), each[k], kTol) << "shape " << k;
  }
  // the first shape is far: the minimum wins over the order
  std::vector<CollisionShape> reversed(shapes.rbegin(), shapes.rend());
  EXPECT_EQ(part.clearance(reversed, frames).shape, 0);

  // early-out: below 40, the query may stop at the first shape closer than that
  const auto early = part.clearance(shapes, frames, 40);
  EXPECT_LT(early.distance_mm, 40);
  ASSERT_GE(early.shape, 1);  // shape 0 (47) is not below 40; any of the others is
  EXPECT_GE(early.distance_mm, each[early.shape] - kTol);  // a real distance of that shape
  // a threshold nothing beats gives the exact minimum
  EXPECT_NEAR(part.clearance(shapes, frames, 5).distance_mm, 12.5, kTol);

  // no shapes: nothing near
  const auto none = part.clearance({}, frames);
  EXPECT_EQ(none.shape, -1);
  EXPECT_EQ(none.distance_mm, std::numeric_limits<double>::infinity());
}

TEST(PartClearance, InsideAClosedPartIsNegativeOutsideAnOpenOneIsNot) {
  const TriangleMesh box_mesh = cube(10);
  ASSERT_GT(box_mesh.signed_volume_mm3(), 0);
  const PartClearance solid(box_mesh);
  ASSERT_TRUE(solid.closed());
  const auto sphere = make_shape(Type::sphere, Vec3(3, 0, 0));
  // centre 8 mm from the face x = 10: it must travel 8 + 3 to be out
  const auto in = solid.nearest(sphere, pose(Vec3(2, 1, -1)));
  EXPECT_NEAR(in.distance_mm, -11, 1e-12);
  EXPECT_NEAR(in.on_part_mm.x(), 10, 1e-12);
  // outside the same cube: the plain gap
  EXPECT_NEAR(solid.distance(sphere, pose(Vec3(15, 1, -1))), 2, 1e-12);
  // a box inside: gap 10 - 2 - 5 = 3 to the face z = 10, plus its height 2 * 2
  EXPECT_NEAR(solid.distance(make_shape(Type::box, Vec3(1, 1, 2)), pose(Vec3(1, 0, 5))), -7, kTol);
  // inside, pruned by a nearer shape outside: still found and reported
  const std::vector<CollisionShape> shapes{make_shape(Type::sphere, Vec3(1, 0, 0), 0),
                                           make_shape(Type::sphere, Vec3(1, 0, 0), 1)};
  const auto res = solid.clearance(shapes, {pose(Vec3(0, 0, 12)), pose(Vec3(0, 0, 0))});
  EXPECT_EQ(res.shape, 1);
  EXPECT_NEAR(res.distance_mm, -11, 1e-12);

  // the plate is open: below it is as far as above it
  const PartClearance sheet(plate(4, 20));
  EXPECT_NEAR(sheet.distance(sphere, pose(Vec3(1, 1, -5))), 2, 1e-12);
}

// every pose against the whole part agrees with the minimum over its triangles one by one (the
// tree walk prunes nothing it should not), from several threads at once
TEST(PartClearance, TreeWalkMatchesEveryTriangleAloneAndIsThreadSafe) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> bump(-3, 3), unit(-1, 1), place(-25, 25), height(-2, 15);
  TriangleMesh terrain = plate(12, 30);
  for (auto& v : terrain.vertices) v.z() = bump(rng);
  const PartClearance part(terrain);
  std::vector<PartClearance> one_by_one;
  for (const auto& t : terrain.triangles) {
    TriangleMesh single;
    for (int k : t) single.vertices.push_back(terrain.vertices[k]);
    single.triangles.push_back({0, 1, 2});
    one_by_one.emplace_back(single);
  }
  const std::vector<CollisionShape> kinds{
      make_shape(Type::sphere, Vec3(2.5, 0, 0)), make_shape(Type::capsule, Vec3(1.5, 6, 0)),
      make_shape(Type::cylinder, Vec3(2, 4, 0)), make_shape(Type::box, Vec3(1, 3, 5))};
  struct Query {
    CollisionShape shape;
    Eigen::Isometry3d pose;
  };
  std::vector<Query> queries;
  for (int i = 0; i < 24; ++i)
    for (const auto& shape : kinds)
      queries.push_back(
          {shape, pose(Vec3(place(rng), place(rng), height(rng)),
                       rotation(3 * unit(rng), Vec3(unit(rng), unit(rng), unit(rng))))});
  std::vector<double> expected;
  int contacts = 0;
  for (const auto& q : queries) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& tri : one_by_one) best = std::min(best, tri.distance(q.shape, q.pose));
    expected.push_back(best);
    contacts += best <= 0;
    const auto res = part.nearest(q.shape, q.pose);
    EXPECT_NEAR(res.distance_mm, best, 1e-9);
    ASSERT_GE(res.triangle, 0);
    EXPECT_NEAR(one_by_one[res.triangle].distance(q.shape, q.pose), res.distance_mm, 1e-9);
  }
  EXPECT_GT(contacts, 5);  // both regimes are exercised
  EXPECT_LT(contacts, static_cast<int>(queries.size()) - 5);

  std::vector<std::vector<double>> seen(4, std::vector<double>(queries.size()));
  std::vector<std::thread> threads;
  for (size_t t = 0; t < seen.size(); ++t)
    threads.emplace_back([&, t] {
      for (size_t i = 0; i < queries.size(); ++i)
        seen[t][i] = part.distance(queries[i].shape, queries[i].pose);
    });
  for (auto& th : threads) th.join();
  for (const auto& s : seen)
    for (size_t i = 0; i < queries.size(); ++i) EXPECT_NEAR(s[i], expected[i], 1e-9);
}

TEST(PartClearance, BadInputIsRefused) {
  EXPECT_THROW(PartClearance{TriangleMesh{}}, InputError);
  TriangleMesh nan_vertex = plate(2, 10);
  nan_vertex.vertices[3].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(PartClearance{nan_vertex}, InputError);
  TriangleMesh inf_vertex = plate(2, 10);
  inf_vertex.vertices[0].z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(PartClearance{inf_vertex}, InputError);
  TriangleMesh bad_index = plate(2, 10);
  bad_index.triangles[1][2] = 99;
  EXPECT_THROW(PartClearance{bad_index}, InputError);
  TriangleMesh flat;  // one triangle without area
  flat.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  flat.triangles = {{0, 1, 2}};
  EXPECT_THROW(PartClearance{flat}, InputError);

  const PartClearance part(plate(2, 10));
  EXPECT_THROW(part.distance(make_shape(Type::sphere, Vec3(0, 0, 0)), pose(Vec3(0, 0, 5))),
               InputError);
  EXPECT_THROW(part.distance(make_shape(Type::box, Vec3(1, -1, 1)), pose(Vec3(0, 0, 5))),
               InputError);
  EXPECT_THROW(part.distance(make_shape(Type::cylinder, Vec3(1, 0, 0)), pose(Vec3(0, 0, 5))),
               InputError);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(part.distance(make_shape(Type::capsule, Vec3(1, nan, 0)), pose(Vec3(0, 0, 5))),
               InputError);
  EXPECT_THROW(part.clearance({make_shape(Type::sphere, Vec3(1, 0, 0), 2)}, {pose(Vec3::Zero())}),
               InternalError);
  EXPECT_THROW(part.clearance({make_shape(Type::sphere, Vec3(1, 0, 0))}, {pose(Vec3(nan, 0, 0))}),
               InternalError);
}

}  // namespace
}  // namespace depotwin
