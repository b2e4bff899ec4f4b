// `uniform` on curves given as fine chords (a slicer's or CAM system's output): the chords
// merged within half the tolerance (merge_fine_edges), the sharp corners kept, and a chorded
// circle printed at its print speed within the tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "contract/planner_checks.hpp"
#include "core/segment_distance.hpp"
#include "metrics/motion_metrics.hpp"
#include "planners/motion/plan_figure.hpp"
#include "planners/motion/polyline_job.hpp"
#include "planners/motion/process_context.hpp"
#include "planners/motion/uniform/path_plan.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

namespace depotwin {
namespace {

// a closed circle of radius r about the origin at z = 0.2 in `chords` chords, from angle 0
std::vector<Vec3> chorded_circle(double r, int chords) {
  std::vector<Vec3> points;
  for (int k = 0; k <= chords; ++k) {
    const double angle = 2.0 * kPi * k / chords;
    points.emplace_back(r * std::cos(angle), r * std::sin(angle), 0.2);
  }
  return points;
}

// A chain of three paths: a circle of 0.1 mm chords with noise of 2 um, then (joined) a sharp
// square corner of fine edges at another speed, then a zig-zag of 0.2 mm teeth. Every point of
// the given chain lies within its merged edge's error of that edge, the errors within the
// bound; the kept points are the given ones (ends, path and speed changes, the square's
// corners among them) with their path and point indices.
TEST(MergeFineEdges, DroppedPointsLieWithinTheirEdgesError) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> noise(-0.002, 0.002);
  Toolpath toolpath;
  PrintPath circle, square, zigzag;
  for (Vec3 p : chorded_circle(10.0, 628))
    circle.points.push_back(p + Vec3(noise(rng), noise(rng), 0));
  circle.points.back() = Vec3(10, 0, 0.2);
  circle.speed_mm_s = 40.0;
  square.speed_mm_s = 20.0;
  for (int k = 0; k <= 100; ++k) square.points.emplace_back(10.0 + 0.1 * k, 0.0, 0.2);
  for (int k = 1; k <= 100; ++k) square.points.emplace_back(20.0, 0.1 * k, 0.2);
  zigzag.speed_mm_s = 20.0;
  for (int k = 0; k <= 40; ++k)
    zigzag.points.emplace_back(20.0 - 0.1 * k, 10.0 + 0.2 * (k % 2), 0.2);
  for (PrintPath* path : {&circle, &square, &zigzag}) {
    path->source_index = static_cast<int>(toolpath.paths.size());
    toolpath.paths.push_back(*path);
  }
  const std::vector<PrintChain> chains = print_chains(toolpath);
  ASSERT_EQ(chains.size(), 1u);
  const PrintChain& given = chains.front();
  const double max_error = 0.025;
  const MergedChain merged = merge_fine_edges(given, max_error);
  const PrintChain& chain = merged.chain;
  ASSERT_EQ(chain.edges(), merged.edge_error_mm.size());
  ASSERT_EQ(chain.edge_speed_mm_s.size(), chain.edges());
  ASSERT_EQ(chain.point_path.size(), chain.points.size());
  EXPECT_LT(chain.points.size(), given.points.size() / 4) << "the fine chords merge";
  // the kept points, in order, among the given ones
  size_t g = 0;
  for (size_t i = 0; i < chain.points.size(); ++i) {
    while (g < given.points.size() && given.points[g] != chain.points[i]) ++g;
    ASSERT_LT(g, given.points.size()) << "kept point " << i << " is not a given one in order";
    EXPECT_EQ(chain.point_path[i], given.point_path[g]);
    EXPECT_EQ(chain.point_index[i], given.point_index[g]);
    if (i + 1 < chain.points.size()) {
      // every given point up to the next kept one within the edge's error of it
      size_t next = g + 1;
      double farthest = 0.0;
      while (given.points[next] != chain.points[i + 1]) {
        farthest = std::max(farthest, point_segment_distance(given.points[next], chain.points[i],
                                                             chain.points[i + 1]));
        EXPECT_EQ(given.edge_path[next], chain.edge_path[i]) << "merged across a path";
        ++next;
      }
      EXPECT_EQ(given.edge_speed_mm_s[g], chain.edge_speed_mm_s[i]);
      EXPECT_EQ(given.edge_path[g], chain.edge_path[i]);
      EXPECT_NEAR(merged.edge_error_mm[i], farthest, 1e-12) << "edge " << i;
      EXPECT_LE(merged.edge_error_mm[i], max_error);
    }
  }
  EXPECT_EQ(chain.points.front(), given.points.front());
  EXPECT_EQ(chain.points.back(), given.points.back());
  // the square's corner (20, 0) and the path ends are kept; the zig-zag's teeth (0.2 mm) too
  const auto kept = [&](const Vec3& p) {
    for (const Vec3& q : chain.points)
      if ((q - p).norm() < 1e-12) return true;
    return false;
  };
  EXPECT_TRUE(kept(Vec3(10, 0, 0.2)));
  EXPECT_TRUE(kept(Vec3(20, 0, 0.2)));
  EXPECT_TRUE(kept(Vec3(20, 10, 0.2)));
  for (const Vec3& p : toolpath.paths[2].points) EXPECT_TRUE(kept(p)) << p.transpose();
}

// A polyline whose every point is farther from the chord past it than the bound, reversals,
// and the points where the tool turns, stay as given.
TEST(MergeFineEdges, LeavesCoarseChainsAndTurningToolsAlone) {
  const std::vector<Vec3> coarse = chorded_circle(10.0, 24);  // sagitta 0.086 mm > 0.025
  const PrintChain chain = print_chains(polyline_job(coarse, 20.0)).front();
  const MergedChain merged = merge_fine_edges(chain, 0.025);
  EXPECT_EQ(merged.chain.points, chain.points);
  for (const double error : merged.edge_error_mm) EXPECT_EQ(error, 0.0);

  // a reversal within the bound (out 0.02 mm and back) is not folded into a zero-length edge,
  // nor a step back along the line
  const PrintChain reversal =
      print_chains(polyline_job({Vec3(0, 0, 0), Vec3(0.02, 0, 0), Vec3(0, 0, 0), Vec3(5, 0, 0),
                                 Vec3(4.99, 0, 0), Vec3(10, 0, 0)},
                                20.0))
          .front();
  EXPECT_EQ(merge_fine_edges(reversal, 0.025).chain.points, reversal.points);

  // a tool turning at every point (its axis tilted by the point's angle): nothing merged
  Toolpath oriented = polyline_job(chorded_circle(10.0, 600), 20.0);
  PrintPath& turning = oriented.paths[0];
  for (const Vec3& p : turning.points)
    turning.normals.push_back(Vec3(0.1 * p.x(), 0.1 * p.y(), 1.0).normalized());
  const PrintChain with_normals = print_chains(oriented).front();
  ASSERT_TRUE(with_normals.oriented);
  EXPECT_EQ(merge_fine_edges(with_normals, 0.025).chain.points, with_normals.points);
}

// A merged edge runs in none of its edges' directions: chords zig-zagging 0.02 mm off x, at
// the speed x allows along each (v_max / cos 1.15 deg), merged into edges along x would need
// more than v_max on x. With the limits, they are merged only where the speed fits.
TEST(MergeFineEdges, MergedEdgesKeepThePrintSpeedWithinTheAxisLimits) {
  std::vector<Vec3> zig;
  for (int k = 0; k <= 20; ++k) zig.emplace_back(k, (k % 2) * 0.02, 0.0);
  const double speed = 100.0 * std::hypot(1.0, 0.02);  // 100 mm/s on x along each chord
  const PrintChain chain = print_chains(polyline_job(zig, speed)).front();
  EXPECT_LT(merge_fine_edges(chain, 0.025).chain.points.size(), chain.points.size());
  const TcpLimits tight = MachineLimits::uniform(100.0, 1000.0);
  EXPECT_EQ(merge_fine_edges(chain, 0.025, &tight).chain.points, chain.points);
  const TcpLimits loose = MachineLimits::uniform(101.0, 1000.0);
  EXPECT_EQ(merge_fine_edges(chain, 0.025, &loose).chain.points,
            merge_fine_edges(chain, 0.025).chain.points);
  // the planner merges under its limits: the job is planned, where the merged edges along x
  // refused it ("needs 100.02 mm/s on axis x")
  EXPECT_NO_THROW(UniformPlanner{UniformSettings{}}.plan_in_context(
      polyline_job(zig, speed), MachineLimits::uniform(100.0, 1000.0),
      process_context(ProcessType::extrusion)));
}

// The arm's planar jobs carry a roll per point (arm_posture.cpp), one roll all along: its fine
// chords merge as on a stage, the orientations of the kept points kept; a roll that changes
// keeps the points where it does. (Left alone, a 90 deg corner between two 1e-4 mm edges was
// decided on a window of 2e-4 mm: a crawl at 0.012 mm/s.)
TEST(MergeFineEdges, ChainsWithOneOrientationMergeAsWithout) {
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5.0001, 0, 0),
                                    Vec3(5.0001, 0.0001, 0), Vec3(5.0001, 5, 0)};
  Toolpath toolpath = polyline_job(points, 3.0);
  const PrintChain plain = print_chains(toolpath).front();
  const MergedChain plain_merged = merge_fine_edges(plain, 0.025);
  ASSERT_EQ(plain_merged.chain.points.size(), 3u);
  EXPECT_EQ(plain_merged.chain.points[1], points[3]);

  toolpath.paths[0].rolls.assign(points.size(), 0.3);
  const PrintChain rolled = print_chains(toolpath).front();
  ASSERT_TRUE(rolled.oriented);
  const MergedChain rolled_merged = merge_fine_edges(rolled, 0.025);
  EXPECT_TRUE(rolled_merged.chain.oriented);
  EXPECT_EQ(rolled_merged.chain.points, plain_merged.chain.points);
  EXPECT_EQ(rolled_merged.edge_error_mm, plain_merged.edge_error_mm);
  for (const ToolOrientation& o : rolled_merged.chain.orientations) EXPECT_EQ(o.roll_rad, 0.3);

  // the roll turns over the second edge: both its ends are kept, the rest merges
  toolpath.paths[0].rolls = {0.3, 0.3, 0.5, 0.5, 0.5};
  const MergedChain turned = merge_fine_edges(print_chains(toolpath).front(), 0.025);
  EXPECT_EQ(turned.chain.points, (std::vector<Vec3>{points[0], points[1], points[2], points[4]}));
  std::vector<double> rolls;
  for (const ToolOrientation& o : turned.chain.orientations) rolls.push_back(o.roll_rad);
  EXPECT_EQ(rolls, (std::vector<double>{0.3, 0.3, 0.5, 0.5}));
}

// A circle of radius 10 mm in 200 chords of 0.31 mm, or 3000 of 0.021 mm, at 50 mm/s under
// 1000 mm/s^2 and 1e5 mm/s^3 per axis: the clothoid pair a corner needs at that speed is 0.4 mm
// long, more than a chord. Blended one chord at a time, an aerosol stage looped 179 of the 199
// corners (38 s); merged within half the tolerance, every corner is blended at print speed:
// the circle is printed in its length over its speed (1.257 s) to 1 % (1.255 s), within the
// tolerance of the given chords (0.020 and 0.025 mm). An extruder, from rest to rest, takes at
// most 1.3 x what the same length of straight line takes (1.58 and 1.57 s against 1.48 s;
// 6.1 s, 4.1 x, for the 3000 chords before).
TEST(UniformPlanner, ChordedCircleIsPrintedAtItsPrintSpeed) {
  const MachineLimits limits = MachineLimits::uniform(100.0, 1000.0);
  const double speed = 50.0, radius = 10.0;
  const auto printing_s = [](const Trajectory& plan) {
    double t = 0.0;
    for (const TrajectoryPiece& piece : plan.pieces())
      if (piece.depositing) t += piece.t_end_s - piece.t_begin_s;
    return t;
  };
  for (const int chords : {200, 3000}) {
    const Toolpath toolpath = polyline_job(chorded_circle(radius, chords), speed);
    const double length = chords * 2.0 * radius * std::sin(kPi / chords);
    const UniformPlanner planner{UniformSettings{}};
    // aerosol: entered and left at print speed
    const Trajectory aerosol =
        planner.plan_in_context(toolpath, limits, process_context(ProcessType::aerosol));
    for (const PlanDecision& decision : aerosol.decisions()) {
      EXPECT_EQ(decision.choice, "blend") << chords << " chords, point " << decision.point_index;
      for (const PlanFigure& figure : decision.figures) {
        if (figure.name == "speed_mm_s") {
          EXPECT_NEAR(figure.value, speed, 1e-9);
        }
      }
    }
    EXPECT_FALSE(aerosol.decisions().empty());
    EXPECT_NEAR(printing_s(aerosol), length / speed, 0.01 * length / speed) << chords;
    EXPECT_LE(path_error(sample_trajectory(aerosol, 1e-4), toolpath).max_mm,
              UniformSettings{}.tolerance_mm)
        << chords;
    // extrusion: from rest to rest, against a straight line of the same length
    const Trajectory extrusion =
        planner.plan_in_context(toolpath, limits, process_context(ProcessType::extrusion));
    const Trajectory line =
        planner.plan_in_context(polyline_job({Vec3(0, 0, 0.2), Vec3(length, 0, 0.2)}, speed),
                                limits, process_context(ProcessType::extrusion));
    EXPECT_LE(printing_s(extrusion), 1.3 * printing_s(line))
        << chords << " chords: " << printing_s(extrusion) << " s, line " << printing_s(line);
    EXPECT_LE(path_error(sample_trajectory(extrusion, 1e-4), toolpath).max_mm,
              UniformSettings{}.tolerance_mm)
        << chords;
  }
}

// A 4 mm circle of 0.2 mm chords at 50 mm/s (625 mm/s^2 on the true circle, 1000 allowed),
// its corners each its own (no arc runs: as one, the circle keeps the print speed,
// test_uniform_arc.cpp): merged, its corners' clothoid pairs cannot keep that speed within the
// tolerance, and taken
// one at a time an aerosol stage looped 27 of its 31 corners (6.25 s, against lspb_mtt's
// 0.74 s). The whole chain at the one speed all its corners' largest blends take (about 42.5
// mm/s) lays an even line 1.18 x the target: predicted 8.6 mm of misplaced line in 0.59 s,
// against the corners' own choices' 7.8 mm in 6.0 s, so at time_weight 0.2 it is taken. The
// decision and every corner report it; the printed speed is that speed throughout, the
// desired speed still the print speed; its error is the closed form (print speed / speed - 1)
// (1 + erf(w / (2 sqrt 2 sigma))) x the merged chain's length. A 2 mm circle would print 1.87 x
// thick at one speed: its corners keep their own choices. Extrusion, whose flow follows the
// speed, never takes it.
TEST(UniformPlanner, SmallAerosolCircleIsPrintedAtOneConstantSpeed) {
  const MachineLimits limits = MachineLimits::uniform(100.0, 1000.0);
  const double print_speed = 50.0, radius = 4.0;
  const int chords = 126;
  const Toolpath toolpath = polyline_job(chorded_circle(radius, chords), print_speed);
  const double length = chords * 2.0 * radius * std::sin(kPi / chords);
  // (its corners one by one: as one arc run it keeps the print speed, test_uniform_arc.cpp)
  UniformSettings settings;
  settings.arc_runs = false;
  const UniformPlanner planner{settings};
  const PlanningContext aerosol = process_context(ProcessType::aerosol);
  const Trajectory plan = planner.plan_in_context(toolpath, limits, aerosol);

  // one path decision, and every corner at its speed
  double speed = 0.0;
  int path_decisions = 0, corners = 0;
  for (const PlanDecision& decision : plan.decisions()) {
    if (decision.kind != "path") continue;
    ++path_decisions;
    EXPECT_EQ(decision.choice, "constant_speed");
    speed = figure(decision, "constant_speed_mm_s");
    EXPECT_EQ(figure(decision, "print_speed_mm_s"), print_speed);
    // cheaper by the planner's own cost
    EXPECT_LT(figure(decision, "constant_speed_error_mm") +
                  settings.time_weight_mm_s * figure(decision, "constant_speed_time_s"),
              figure(decision, "corners_error_mm") +
                  settings.time_weight_mm_s * figure(decision, "corners_time_s"));
    // the even line's error (its length the merged chords', shorter than the given by less
    // than 0.2 %)
    const double band_share = std::erf(0.5 * aerosol.process->resolved_line_width_mm() /
                                       (std::sqrt(2.0) * aerosol.process->footprint_sigma_mm()));
    EXPECT_NEAR(figure(decision, "constant_speed_error_mm"),
                (print_speed / speed - 1.0) * (1.0 + band_share) * length,
                0.002 * figure(decision, "constant_speed_error_mm"));
  }
  ASSERT_EQ(path_decisions, 1);
  ASSERT_GT(speed, 0.5 * print_speed);
  ASSERT_LT(speed, print_speed);
  for (const PlanDecision& decision : plan.decisions()) {
    if (decision.kind != "corner") continue;
    ++corners;
    EXPECT_EQ(decision.choice, "constant_speed") << "point " << decision.point_index;
    EXPECT_NEAR(figure(decision, "speed_mm_s"), speed, 1e-9 * speed);
  }
  EXPECT_GT(corners, 20);
  // printed at that speed throughout, its length over that speed, within the tolerance
  const MotionSamples samples = sample_trajectory(plan, 1e-4);
  double printing_s = 0.0;
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!samples.depositing[k]) continue;
    // (a blend's samples interpolated: to 1e-5)
    EXPECT_NEAR(samples.velocity_mm_s[k].norm(), speed, 1e-5 * speed) << "t " << samples.t_s[k];
    EXPECT_EQ(samples.desired_speed_mm_s[k], print_speed);
  }
  for (const TrajectoryPiece& piece : plan.pieces())
    if (piece.depositing) printing_s += piece.t_end_s - piece.t_begin_s;
  EXPECT_NEAR(printing_s, length / speed, 0.01 * length / speed);
  EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm);

  // a 2 mm circle: its corners' own choices, some of them loops
  const Trajectory small =
      planner.plan_in_context(polyline_job(chorded_circle(2.0, 64), print_speed), limits, aerosol);
  int loops = 0;
  for (const PlanDecision& decision : small.decisions()) {
    EXPECT_EQ(decision.kind, "corner");
    loops += decision.choice == "loop" ? 1 : 0;
  }
  EXPECT_GT(loops, 0);
  // extrusion: never
  const Trajectory extrusion =
      planner.plan_in_context(toolpath, limits, process_context(ProcessType::extrusion));
  for (const PlanDecision& decision : extrusion.decisions()) {
    EXPECT_EQ(decision.kind, "corner");
    EXPECT_NE(decision.choice, "constant_speed");
  }
}

// Random print jobs (seeded): 1-4 paths, joined or apart, of up to 60 edges from 0.1 um to
// 10 mm, gently curving, reversing, turning at random, nearly straight or circling; print
// speeds from 0.5 to 99 mm/s, tolerances from 1 um to 3 mm, accelerations from 10 to 20 000
// mm/s^2, aerosol and extrusion. Every plan is finite and keeps to its tolerance of the given
// polylines (merged, blended or looped), sampled every 0.2 ms, and every axis' speed and
// acceleration within its limits by finite differences on the controller's grid.
TEST(UniformPlanner, RandomJobsStayWithinTheTolerance) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double steps[] = {1e-4, 0.003, 0.02, 0.3, 2.0, 10.0};
  const double speeds[] = {0.5, 3.0, 20.0, 50.0, 99.0};
  const double tolerances[] = {0.001, 0.05, 0.5, 3.0};
  const double accelerations[] = {10.0, 1000.0, 20000.0};
  for (int trial = 0; trial < 30; ++trial) {
    Toolpath toolpath;
    Vec3 p(unit(rng) * 40 - 20, unit(rng) * 40 - 20, 0);
    const int paths = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < paths; ++k) {
      PrintPath path;
      path.speed_mm_s = speeds[rng() % 5];
      if (rng() % 3 != 0) p = Vec3(unit(rng) * 40 - 20, unit(rng) * 40 - 20, 0);
      path.points.push_back(p);
      const int edges = 1 + static_cast<int>(rng() % 60);
      const int shape = static_cast<int>(rng() % 5);
      double heading = unit(rng) * 2 * kPi;
      for (int i = 0; i < edges; ++i) {
        const double step = steps[rng() % 6];
        if (shape == 0) heading += (unit(rng) - 0.5) * 0.1;         // a gentle curve
        if (shape == 1) heading += kPi + (unit(rng) - 0.5) * 1e-3;  // nearly reversing
        if (shape == 2) heading += (unit(rng) - 0.5) * 6.0;         // anywhere
        if (shape == 3) heading += 1e-7;                            // nearly straight
        if (shape == 4) heading += 0.05;                            // circling
        Vec3 q = p + step * Vec3(std::cos(heading), std::sin(heading), 0);
        q.x() = std::clamp(q.x(), -40.0, 40.0);
        q.y() = std::clamp(q.y(), -40.0, 40.0);
        if ((q - p).norm() < 1e-5) continue;
        path.points.push_back(q);
        p = q;
      }
      if (path.points.size() < 2) {
        path.points.push_back(p + Vec3(1, 0, 0));
        p = path.points.back();
      }
      path.source_index = k;
      toolpath.paths.push_back(path);
    }
    toolpath.start_mm = toolpath.end_mm = Vec3::Zero();
    UniformSettings settings;
    settings.tolerance_mm = tolerances[rng() % 4];
    const MachineLimits limits = MachineLimits::uniform(100.0, accelerations[rng() % 3]);
    const ProcessType process = trial % 2 == 0 ? ProcessType::extrusion : ProcessType::aerosol;
    const Trajectory plan =
        UniformPlanner{settings}.plan_in_context(toolpath, limits, process_context(process));
    const MotionSamples samples = sample_trajectory(plan, 2e-4);
    for (size_t k = 0; k < samples.size(); ++k)
      ASSERT_TRUE(samples.position_mm[k].allFinite() && samples.velocity_mm_s[k].allFinite())
          << "trial " << trial << " sample " << k;
    EXPECT_LE(path_error(samples, toolpath).max_mm, settings.tolerance_mm * (1 + 1e-9))
        << "trial " << trial << ", tolerance " << settings.tolerance_mm;
    // (1e-5: one job, at 10 mm/s^2, peaks 1.2e-6 above its limit on the grid, 598 s into its
    // 885 s plan, on a transition whose law is at its limit to the last digit: the grid's times
    // are rounded to ulp(598 s) = 1.1e-13 s, 1.1e-11 mm at its 98 mm/s, and d2p / h^2 turns that
    // into 1e-5 mm/s^2. Traced on the plan sampled as here, every 1 ms.)
    const testing_support::FiniteDifferencePeaks peaks =
        testing_support::finite_difference_peaks(plan, limits);
    EXPECT_LE(peaks.max_speed_ratio(), 1.0 + 1e-5) << "trial " << trial;
    EXPECT_LE(peaks.max_accel_ratio(), 1.0 + 1e-5) << "trial " << trial;
  }
}

// Two cases the random jobs above found (a wider run of them), each a curved ramp across two
// joined paths, extrusion:
// - a 2 mm line at 50 mm/s joined to a 0.1 um edge turning 29 deg, at 10 mm/s^2 and a 0.5 mm
//   tolerance: the ramp to rest passes the turn's blend (halves of 2 nm, capped at 2 um/s).
//   Judged at its cap, that blend no longer rules the ramp out, so the ramp's check must land
//   on it however fast the law first runs: a blend passed between two checks is checked at
//   its middle. Without that, 1.9 x the acceleration limit at the turn.
// - collinear edges along x = -40 (a random walk clamped at the box), a path at 99 mm/s joined
//   to one at 50 mm/s, 1 um tolerance: each ramp section is its own piece from the time the law
//   reaches its start, so no sample of the second path is labelled with the first (which put
//   samples 2.9 um past the first path's end, against its own polyline).
// Each keeps its limits on the controller's grid and its tolerance of its own path.
TEST(UniformPlanner, CurvedRampsAcrossJoinedPathsKeepLimitsAndTheirOwnPaths) {
  struct Case {
    double a_max_mm_s2, tolerance_mm, speeds[2];
    std::vector<Vec3> first, second;
  };
  const std::vector<Case> cases = {
      {10.0,
       0.5,
       {50.0, 50.0},
       {Vec3(-1.1409277849645865, 1.5951741983550456, 0),
        Vec3(-3.0879857029845343, 1.1380467939306056, 0)},
       {Vec3(-3.0879857029845343, 1.1380467939306056, 0),
        Vec3(-3.0880820301063459, 1.1380736469677428, 0)}},
      {1000.0,
       0.001,
       {99.0, 50.0},
       {Vec3(-40, 13.887798941033363, 0), Vec3(-40, 13.980162669199636, 0),
        Vec3(-40, 13.98019345709951, 0), Vec3(-40, 13.986351035171559, 0),
        Vec3(-40, 14.602108652091385, 0), Vec3(-40, 14.602139439962716, 0)},
       {Vec3(-40, 14.602139439962716, 0), Vec3(-40, 14.68507175728675, 0),
        Vec3(-40, 14.75569582494721, 0), Vec3(-40, 14.813697874435329, 0),
        Vec3(-40, 14.858820214326972, 0), Vec3(-40, 14.890862375153743, 0)}}};
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE("case " + std::to_string(c));
    const Case& job = cases[c];
    Toolpath toolpath;
    for (int k = 0; k < 2; ++k) {
      PrintPath path;
      path.points = k == 0 ? job.first : job.second;
      path.speed_mm_s = job.speeds[k];
      path.source_index = k;
      toolpath.paths.push_back(path);
    }
    toolpath.start_mm = toolpath.end_mm = Vec3::Zero();
    UniformSettings settings;
    settings.tolerance_mm = job.tolerance_mm;
    const MachineLimits limits = MachineLimits::uniform(100.0, job.a_max_mm_s2);
    const Trajectory plan = UniformPlanner{settings}.plan_in_context(
        toolpath, limits, process_context(ProcessType::extrusion));
    const testing_support::FiniteDifferencePeaks peaks =
        testing_support::finite_difference_peaks(plan, limits);
    EXPECT_LE(peaks.max_accel_ratio(), 1.0 + 1e-6);
    EXPECT_LE(peaks.max_speed_ratio(), 1.0 + 1e-6);
    EXPECT_LE(path_error(sample_trajectory(plan, 1e-4), toolpath).max_mm,
              job.tolerance_mm * (1 + 1e-9));
  }
}

}  // namespace
}  // namespace depotwin
