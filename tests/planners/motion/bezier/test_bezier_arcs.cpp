// The bezier planner on exact arcs (G-code G2/G3): a circular arc is the rational quadratic
// Bezier with weight cos(sweep / 2), so the planner traverses it exactly, on the circle, at
// constant speed; an arc it cannot take that way (at a path's end, not tangent, a helix) is
// chorded within the toolpath's chord tolerance.
#include <gtest/gtest.h>

#include <cmath>

#include "bezier_checks.hpp"
#include "planners/motion/bezier/bezier.hpp"
#include "planners/motion/bezier/bezier_curve.hpp"

namespace depotwin {
namespace {
using namespace bezier_test;

BezierPlanner planner(double delta_mm = 0.5) {
  BezierSettings settings;
  settings.delta_mm = delta_mm;
  return BezierPlanner(settings);
}

// a line along x, a quarter circle of radius 3 turning left (G3 about +z), a line along y
PrintPath line_arc_line(double radius_mm = 3.0) {
  PrintPath path;
  path.points = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10 + radius_mm, radius_mm, 0),
                 Vec3(10 + radius_mm, 15, 0)};
  path.arcs.resize(3);
  path.arcs[1].center_mm = Vec3(10, radius_mm, 0);
  path.arcs[1].axis = Vec3::UnitZ();
  path.arcs[1].sweep_rad = kPi / 2;
  path.speed_mm_s = 10.0;
  return path;
}

Toolpath toolpath_of(const PrintPath& path) {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-5, -5, 0);
  toolpath.end_mm = Vec3(20, 20, 0);
  toolpath.paths = {path};
  toolpath.chord_tolerance_mm = 0.01;
  return toolpath;
}

// the printing samples' positions and velocities
void printing_samples(const Trajectory& plan, std::vector<Vec3>& positions,
                      std::vector<Vec3>& velocities) {
  for (const TrajectoryPiece& piece : plan.pieces()) {
    if (!piece.depositing) continue;
    const SampledMotion& motion = sampled(piece);
    positions.insert(positions.end(), motion.position_mm.begin(), motion.position_mm.end());
    velocities.insert(velocities.end(), motion.velocity_mm_s.begin(), motion.velocity_mm_s.end());
  }
}

TEST(BezierArcs, ARationalQuadraticWithWeightCosHalfSweepIsTheCircle) {
  // 90 degrees of radius 3 about (10, 3): every point at distance 3 from the centre
  BezierBlend arc;
  arc.entry_mm = Vec3(10, 0, 0);
  arc.exit_mm = Vec3(13, 3, 0);
  arc.corner_mm = Vec3(13, 0, 0);  // the tangents' intersection
  arc.weight = std::cos(kPi / 4);
  for (double u = 0.0; u <= 1.0; u += 0.05)
    EXPECT_NEAR((arc.point(u) - Vec3(10, 3, 0)).norm(), 3.0, 1e-12) << u;
  EXPECT_NEAR(arc.arc_length_mm(), 1.5 * kPi, 1e-9);
}

TEST(BezierArcs, AnArcBetweenTangentLinesIsFlownOnTheCircleAtPrintSpeed) {
  const Toolpath toolpath = toolpath_of(line_arc_line());
  const Trajectory plan =
      planner().plan(toolpath, TcpLimits(MachineLimits::uniform(100.0, 1000.0)));
  std::vector<Vec3> positions, velocities;
  printing_samples(plan, positions, velocities);
  ASSERT_GT(positions.size(), 100u);
  // on the arc (the quarter turn's samples) the nozzle is on the circle, not on a chord
  int on_arc = 0;
  for (size_t k = 0; k < positions.size(); ++k) {
    const Vec3& p = positions[k];
    if (p.x() <= 10.0 + 1e-9 || p.y() >= 3.0 - 1e-9) continue;  // the lines
    ++on_arc;
    EXPECT_NEAR((p - Vec3(10, 3, 0)).norm(), 3.0, 1e-9) << k;
    // at the print speed (10 mm/s: 0.1 m/s^2 centripetal on 3 mm, far within the limits)
    EXPECT_NEAR(velocities[k].norm(), 10.0, 10.0 * 1e-3) << k;
  }
  // 4.71 mm at 10 mm/s, sampled every ms
  EXPECT_GT(on_arc, 460);
  // the printed length is the exact one: lines of 10 and 12 mm and the arc's 1.5 pi
  double length_mm = 0.0;
  for (size_t k = 1; k < positions.size(); ++k)
    length_mm += (positions[k] - positions[k - 1]).norm();
  EXPECT_NEAR(length_mm, 22.0 + 1.5 * kPi, 1e-3);
  // no warning: nothing slowed, nothing chorded
  EXPECT_TRUE(plan.warnings().empty());
}

TEST(BezierArcs, ATightArcIsSlowedByTheAxesAccelerationNotChorded) {
  // radius 0.1 mm at 10 mm/s needs 1000 mm/s^2 centripetal; the axes allow 200
  const Toolpath toolpath = toolpath_of(line_arc_line(0.1));
  const Trajectory plan = planner().plan(toolpath, TcpLimits(MachineLimits::uniform(100.0, 200.0)));
  std::vector<Vec3> positions, velocities;
  printing_samples(plan, positions, velocities);
  double slowest_on_arc = 1e9;
  for (size_t k = 0; k < positions.size(); ++k) {
    const Vec3& p = positions[k];
    if (p.x() <= 10.0 + 1e-9 || p.y() >= 0.1 - 1e-9) continue;
    EXPECT_NEAR((p - Vec3(10, 0.1, 0)).norm(), 0.1, 1e-9);
    slowest_on_arc = std::min(slowest_on_arc, velocities[k].norm());
  }
  // v^2 / r within a_max on the arc (sqrt(200 * 0.1) = 4.47 mm/s)
  EXPECT_LE(slowest_on_arc, std::sqrt(200.0 * 0.1) * (1.0 + 1e-6));
  EXPECT_GT(slowest_on_arc, 0.5 * std::sqrt(200.0 * 0.1));
  ASSERT_FALSE(plan.warnings().empty());
  EXPECT_NE(plan.warnings().front().find("arc from point 1: blend slowed"), std::string::npos)
      << plan.warnings().front();
}

TEST(BezierArcs, AnArcAtAPathsEndOrNotTangentIsChordedWithinTheTolerance) {
  // the same arc, but the line after it leaves at 45 degrees: no longer tangent
  PrintPath path = line_arc_line();
  path.points[3] = Vec3(20, 10, 0);
  Toolpath toolpath = toolpath_of(path);
  toolpath.chord_tolerance_mm = 0.05;
  const Trajectory plan =
      planner(0.01).plan(toolpath, TcpLimits(MachineLimits::uniform(100.0, 1000.0)));
  std::vector<Vec3> positions, velocities;
  printing_samples(plan, positions, velocities);
  // the samples between the arc's ends lie on its chords: inside the circle, within the
  // chord tolerance (plus the small corner blends between chords)
  double deepest_mm = 0.0;
  for (const Vec3& p : positions) {
    if (p.x() <= 10.0 + 1e-9 || p.y() >= 3.0 - 1e-9 || p.x() >= 13.0) continue;
    const double inside_mm = 3.0 - (p - Vec3(10, 3, 0)).norm();
    EXPECT_GT(inside_mm, -1e-9);
    deepest_mm = std::max(deepest_mm, inside_mm);
  }
  EXPECT_GT(deepest_mm, 0.01);  // really chorded: the chords' sagitta shows
  EXPECT_LT(deepest_mm, 0.05 + 0.01);
  // a path that ends on its arc is chorded too (bezier starts and ends at rest on a line)
  PrintPath ends_on_arc = line_arc_line();
  ends_on_arc.points.pop_back();
  ends_on_arc.arcs.pop_back();
  const Trajectory plan2 =
      planner().plan(toolpath_of(ends_on_arc), TcpLimits(MachineLimits::uniform(100.0, 1000.0)));
  positions.clear();
  velocities.clear();
  printing_samples(plan2, positions, velocities);
  EXPECT_LT((positions.back() - Vec3(13, 3, 0)).norm(), 1e-9);
}

TEST(BezierArcs, ConsecutiveArcsAndAFullCircleKeepTheirExactLength) {
  // line, a half circle of radius 2 split in two quarter arcs, a full circle back to the
  // same point (tangent there), then a line on: every arc exact
  PrintPath path;
  path.points = {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(7, 2, 0), Vec3(7, 2, 0), Vec3(7, 12, 0)};
  path.arcs.resize(4);
  for (int e : {1}) {
    path.arcs[e].center_mm = Vec3(5, 2, 0);
    path.arcs[e].axis = Vec3::UnitZ();
    path.arcs[e].sweep_rad = kPi / 2;
  }
  path.arcs[2].center_mm = Vec3(5, 2, 0);
  path.arcs[2].axis = Vec3::UnitZ();
  path.arcs[2].sweep_rad = 2 * kPi;
  path.speed_mm_s = 5.0;
  const Trajectory plan =
      planner().plan(toolpath_of(path), TcpLimits(MachineLimits::uniform(100.0, 1000.0)));
  std::vector<Vec3> positions, velocities;
  printing_samples(plan, positions, velocities);
  double length_mm = 0.0;
  for (size_t k = 1; k < positions.size(); ++k)
    length_mm += (positions[k] - positions[k - 1]).norm();
  EXPECT_NEAR(length_mm, 5.0 + 0.5 * kPi * 2.0 + 2.0 * kPi * 2.0 + 10.0, 2e-3);
  for (const Vec3& p : positions) {
    if (p.x() > 5.0 + 1e-9 && p.y() < 2.0 + 1e-9) {
      EXPECT_NEAR((p - Vec3(5, 2, 0)).norm(), 2.0, 1e-9);
    }
  }
}

}  // namespace
}  // namespace depotwin
