// The binned distance to a polyline (metrics/polyline_distance.hpp) is distance_to_polyline
// to the bit: on slicer-like polylines (spirals, zig-zags, arcs of many chords, a spiral
// rising through layers that overlap in (x, y)), on degenerate ones (repeated points,
// vertical segments, one long segment among short ones, few segments), for points on, near
// and far from them, and for points that are not finite.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "metrics/motion_metrics.hpp"
#include "metrics/polyline_distance.hpp"

namespace depotwin {
namespace {

std::vector<Vec3> spiral(int points, double turns, double rise_per_turn) {
  std::vector<Vec3> out;
  for (int k = 0; k < points; ++k) {
    const double a = 2.0 * M_PI * turns * k / points;
    const double r = 20.0 - 15.0 * k / points;
    out.emplace_back(r * std::cos(a), r * std::sin(a), rise_per_turn * a / (2.0 * M_PI));
  }
  return out;
}

std::vector<Vec3> zigzag(int lines, double length, double step) {
  std::vector<Vec3> out;
  for (int k = 0; k < lines; ++k) {
    const double y = k * step;
    out.emplace_back(k % 2 ? length : 0.0, y, 0.2);
    out.emplace_back(k % 2 ? 0.0 : length, y, 0.2);
  }
  return out;
}

std::vector<Vec3> random_walk(int points, std::mt19937_64& random) {
  std::uniform_real_distribution<double> step(-2.0, 2.0);
  std::vector<Vec3> out{Vec3(100.0, -50.0, 3.0)};
  for (int k = 1; k < points; ++k) {
    Vec3 next = out.back() + Vec3(step(random), step(random), 0.1 * step(random));
    if (k % 17 == 0) next = out.back();                            // a repeated point
    if (k % 29 == 0) next = out.back() + Vec3(0.0, 0.0, 1.0);      // vertical
    if (k % 101 == 0) next = out.back() + Vec3(60.0, -45.0, 0.0);  // one long segment
    out.push_back(next);
  }
  return out;
}

// every query point's binned distance equals the plain loop's, exactly
void expect_exact(const std::vector<Vec3>& polyline, const std::string& name,
                  std::mt19937_64& random) {
  Vec3 lo = polyline.front(), hi = polyline.front();
  for (const Vec3& p : polyline) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 span = (hi - lo).cwiseMax(Vec3::Constant(1.0));
  std::uniform_real_distribution<double> unit(0.0, 1.0), noise(-0.05, 0.05);
  std::uniform_int_distribution<std::size_t> vertex(0, polyline.size() - 1);
  const PolylineDistance distance(polyline);
  std::vector<Vec3> queries;
  for (int n = 0; n < 3000; ++n) {
    // near a vertex (as a path's samples are), anywhere in the box and around it, far away
    queries.push_back(polyline[vertex(random)] + Vec3(noise(random), noise(random), noise(random)));
    queries.push_back(lo - 0.5 * span +
                      2.0 * Vec3(unit(random), unit(random), unit(random)).cwiseProduct(span));
  }
  queries.push_back(polyline.front());
  queries.push_back(lo + Vec3(1e6, -3e5, 10.0));
  queries.push_back(Vec3(1e300, 0.0, 0.0));
  for (const Vec3& q : queries)
    ASSERT_EQ(distance(q), distance_to_polyline(q, polyline))
        << name << " at (" << q.x() << ", " << q.y() << ", " << q.z() << ")";
  // not finite: what the plain loop gives (a NaN coordinate is never nearer than infinity)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Vec3& q :
       {Vec3(nan, 0.0, 0.0), Vec3(0.0, std::numeric_limits<double>::infinity(), 0.0)}) {
    const double plain = distance_to_polyline(q, polyline);
    const double binned = distance(q);
    EXPECT_TRUE(binned == plain || (std::isnan(binned) && std::isnan(plain))) << name;
  }
}

TEST(PolylineDistance, EqualsThePlainLoopOnEveryShape) {
  std::mt19937_64 random(3);
  expect_exact(spiral(4000, 12.0, 0.0), "flat spiral", random);
  expect_exact(spiral(6000, 30.0, 0.2), "vase spiral (turns overlap in x, y)", random);
  expect_exact(zigzag(60, 20.0, 0.45), "zigzag", random);
  expect_exact(random_walk(5000, random), "random walk", random);
  // a circle of 0.01 mm chords, and a straight line of many collinear points
  std::vector<Vec3> circle, line;
  for (int k = 0; k <= 6283; ++k) circle.emplace_back(std::cos(k * 1e-3), std::sin(k * 1e-3), 0.0);
  for (int k = 0; k < 500; ++k) line.emplace_back(0.1 * k, 0.0, 0.0);
  expect_exact(circle, "circle", random);
  expect_exact(line, "straight line", random);
  // few segments (every one visited), a single point, all points equal, vertical only
  expect_exact({Vec3(0, 0, 0), Vec3(3, 4, 0), Vec3(3, 0, 1)}, "three points", random);
  expect_exact({Vec3(1, 2, 3)}, "one point", random);
  expect_exact(std::vector<Vec3>(100, Vec3(1, 2, 3)), "one point repeated", random);
  std::vector<Vec3> column;
  for (int k = 0; k < 100; ++k) column.emplace_back(5.0, 5.0, 0.1 * k);
  expect_exact(column, "vertical column", random);
  // a box too small to divide into cells, and one of coordinates near a kilometre
  std::vector<Vec3> tiny, far;
  for (int k = 0; k < 100; ++k) {
    tiny.emplace_back(1e-320 * (k % 3), 0.0, 0.0);
    far.emplace_back(1e6 + std::cos(0.1 * k), -1e6 + std::sin(0.1 * k), 0.0);
  }
  expect_exact(tiny, "subnormal box", random);
  expect_exact(far, "far from the origin", random);
}

TEST(PolylineDistance, EmptyPolylineIsInfinitelyFar) {
  const std::vector<Vec3> none;
  EXPECT_EQ(PolylineDistance(none)(Vec3(1, 2, 3)), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace depotwin
