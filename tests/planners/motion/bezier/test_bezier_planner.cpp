// The bezier planner (Giberti, Sbaglia & Urgo 2017, papers/001) against the paper's numbers,
// closed forms and the project's planner contract.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "bezier_checks.hpp"
#include "core/error.hpp"
#include "core/segment_distance.hpp"
#include "planners/motion/bezier/bezier.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {
namespace {
using namespace bezier_test;

BezierPlanner planner_with(double delta_mm, std::vector<double> weights = {1.0},
                           bool lead_in = false, double period_s = 0.001) {
  BezierSettings settings;
  settings.delta_mm = delta_mm;
  settings.weights = std::move(weights);
  settings.lead_in = lead_in;
  settings.period_s = period_s;
  return BezierPlanner(settings);
}

std::vector<const TrajectoryPiece*> printing_pieces(const Trajectory& trajectory) {
  std::vector<const TrajectoryPiece*> result;
  for (const TrajectoryPiece& piece : trajectory.pieces())
    if (piece.depositing) result.push_back(&piece);
  return result;
}

// limits that never bind, as in the paper's theoretical example (Sec. 4.1)
const MachineLimits kUnbound = MachineLimits::uniform(1000.0, 1e6);

// ---------------------------------------------------------------------------------------
// parameters

TEST(BezierPlanner, DeclaresItsParametersWithRanges) {
  PlannerSpec spec;
  spec.name = "bezier";
  EXPECT_EQ(check_planner_spec(spec), "");
  spec.params["delta"] = {0.3};
  spec.params["weight"] = {1.0, 2.0, 0.5};
  spec.params["period_s"] = {0.0005};
  spec.params["lead_in"] = {1.0};
  EXPECT_EQ(check_planner_spec(spec), "");
  const BezierSettings settings = bezier_settings(spec);
  EXPECT_EQ(settings.delta_mm, 0.3);
  EXPECT_EQ(settings.weights, (std::vector<double>{1.0, 2.0, 0.5}));
  EXPECT_EQ(settings.period_s, 0.0005);
  EXPECT_TRUE(settings.lead_in);
  EXPECT_EQ(settings.merge_mm, 0.01);  // fine chords merged by default
  spec.params["merge"] = {0.0};
  EXPECT_EQ(check_planner_spec(spec), "");
  EXPECT_EQ(bezier_settings(spec).merge_mm, 0.0);
  spec.params["merge"] = {-0.01};
  EXPECT_NE(check_planner_spec(spec).find("'merge'"), std::string::npos);
  spec.params.erase("merge");

  spec.params["delta"] = {0.0};
  EXPECT_NE(check_planner_spec(spec).find("'delta'"), std::string::npos);
  spec.params["delta"] = {0.3};
  spec.params["weight"] = {0.0};
  EXPECT_NE(check_planner_spec(spec).find("'weight'"), std::string::npos);
  spec.params["weight"] = {1.0};
  spec.params["period_s"] = {0.001, 0.002};
  EXPECT_NE(check_planner_spec(spec).find("not a list"), std::string::npos);
  spec.params["period_s"] = {0.001};
  spec.params["lead_in"] = {0.5};
  EXPECT_THROW(make_planner(spec), InputError);
}

TEST(BezierPlanner, WeightListMustMatchTheCornerCount) {
  // the four-point path has two corners
  const Toolpath toolpath = single_path(four_point_path(), 5.0);
  EXPECT_NO_THROW(planner_with(0.5, {2.0}).plan(toolpath, kUnbound));
  EXPECT_NO_THROW(planner_with(0.5, {2.0, 0.5}).plan(toolpath, kUnbound));
  try {
    planner_with(0.5, {1.0, 2.0, 3.0}).plan(toolpath, kUnbound);
    FAIL() << "three weights for two corners";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].key, "planners.bezier.weight");
    EXPECT_NE(e.problems()[0].message.find("2 corners"), std::string::npos);
  }
}

TEST(BezierPlanner, LineTooFastForAnAxisIsAnInputError) {
  const Toolpath toolpath = single_path({Vec3(0, 0, 0), Vec3(10, 0, 0)}, 8.0);
  EXPECT_THROW(planner_with(0.5).plan(toolpath, MachineLimits::uniform(5.0, 100.0)), InputError);
}

// ---------------------------------------------------------------------------------------
// the paper's measurements

// Sec. 4.1 / Fig. 4: four points, two curves, 5, 10 and 20 mm/s, delta 0.45 mm (the value of
// the paper's application, Sec. 6.2), T_s = 1 ms. The paper reports at most 0.14, 0.27 and
// 0.22 % speed variation over the central part (and "always smaller than 0.3 %") without
// giving its points. Measured where the variation is largest: both corners of
// four_point_path turn by 135 degrees, the sharpest of these tests.
//
// At 5 and 10 mm/s the variation there is below the paper's figures. At 20 mm/s no plan at
// constant speed can be: the measure is the chord between samples over T_s, and a chord of
// s = v T_s = 0.02 mm across the blend's apex, of curvature kappa = cos(phi/2) / (delta
// sin^2(phi/2)) = 14.0 / mm (legs delta, phi = 45 degrees between them), falls short of its
// arc by (kappa s)^2 / 24 = 0.33 %, above the paper's 0.22 %: the paper's corners must have
// been gentler. There the variation is at least that geometric shortfall, and at most the
// paper's 10 mm/s figure carried to twice the step by the update's (v T)^2 law
// (SpeedVariationGrowsWithTheSquareOfTheStep): 4 x 0.27 = 1.08 %. On 90-degree corners
// (apex curvature 3.1 / mm) all three figures hold.
TEST(BezierPlanner, SpeedVariationOnAFourPointPathIsBelowThePapers) {
  struct Case {
    double speed_mm_s, paper_rel;
  };
  const Case paper[] = {{5.0, 0.0014}, {10.0, 0.0027}, {20.0, 0.0022}};
  const double delta_mm = 0.45, period_s = 0.001;
  // the apex curvature of a blend whose legs meet at phi (180 degrees minus the turn)
  const auto apex_curvature = [&](double turn_deg) {
    const double half_phi = deg_to_rad(180.0 - turn_deg) / 2.0;
    return std::cos(half_phi) / (delta_mm * std::sin(half_phi) * std::sin(half_phi));
  };
  const auto measure = [&](const std::vector<Vec3>& points, double speed) {
    double length_mm = 0.0;
    for (size_t i = 0; i + 1 < points.size(); ++i) length_mm += (points[i + 1] - points[i]).norm();
    const Trajectory trajectory = planner_with(delta_mm).plan(single_path(points, speed), kUnbound);
    EXPECT_TRUE(trajectory.warnings().empty());
    const auto pieces = printing_pieces(trajectory);
    EXPECT_EQ(pieces.size(), 1u);
    const SpeedVariation variation = speed_variation(sampled(*pieces[0]), speed);
    // the central part is nearly the whole path (ramps of v/a are a few samples)
    EXPECT_GT(variation.central_samples, 0.98 * length_mm / speed / period_s);
    return variation.max_rel;
  };

  double at_10 = 0.0;
  for (const Case& c : paper) {
    const double sharp = measure(four_point_path(), c.speed_mm_s);
    const double step_mm = c.speed_mm_s * period_s;
    const double shortfall = std::pow(apex_curvature(135.0) * step_mm, 2) / 24.0;
    std::printf(
        "[ speed variation, 135-degree corners ] %4.0f mm/s: %.4f %% (paper %.2f %%, "
        "chord shortfall at the apex %.4f %%)\n",
        c.speed_mm_s, 100 * sharp, 100 * c.paper_rel, 100 * shortfall);
    EXPECT_GE(sharp, shortfall) << c.speed_mm_s << " mm/s";
    if (shortfall < c.paper_rel) {
      EXPECT_LT(sharp, c.paper_rel) << c.speed_mm_s << " mm/s";
    } else {
      EXPECT_LT(sharp, 4.0 * paper[1].paper_rel) << c.speed_mm_s << " mm/s";
    }
    if (c.speed_mm_s == 10.0) at_10 = sharp;
  }
  EXPECT_GT(at_10, 0.5 * paper[1].paper_rel);  // the sharp corners are a real test at 10 mm/s
  // the three figures on 90-degree corners
  for (const Case& c : paper) {
    const double right =
        measure({Vec3(0, 0, 0), Vec3(30, 0, 0), Vec3(30, 20, 0), Vec3(60, 20, 0)}, c.speed_mm_s);
    std::printf("[ speed variation, 90-degree corners ] %4.0f mm/s: %.4f %% (paper %.2f %%)\n",
                c.speed_mm_s, 100 * right, 100 * c.paper_rel);
    EXPECT_LT(right, c.paper_rel) << c.speed_mm_s << " mm/s";
  }
}

// The variation comes from the 2nd-order Taylor update, so it grows with the square of the
// step v T_s: doubling the speed quadruples it (shown on sharp 135-degree corners, where it
// is largest).
TEST(BezierPlanner, SpeedVariationGrowsWithTheSquareOfTheStep) {
  std::vector<double> variations;
  for (double speed : {5.0, 10.0, 20.0}) {
    const Trajectory trajectory =
        planner_with(0.45).plan(single_path(four_point_path(), speed), kUnbound);
    const auto pieces = printing_pieces(trajectory);
    variations.push_back(speed_variation(sampled(*pieces[0]), speed).max_rel);
    std::printf("[ speed variation, 135-degree corners ] %4.0f mm/s: %.4f %%\n", speed,
                100 * variations.back());
  }
  EXPECT_NEAR(variations[1] / variations[0], 4.0, 0.4);
  EXPECT_NEAR(variations[2] / variations[1], 4.0, 0.4);
  // a finer sample period gives the same quadratic gain
  const Trajectory fine =
      planner_with(0.45, {1.0}, false, 0.0005).plan(single_path(four_point_path(), 20.0), kUnbound);
  const double fine_variation = speed_variation(sampled(*printing_pieces(fine)[0]), 20.0).max_rel;
  EXPECT_NEAR(variations[2] / fine_variation, 4.0, 0.4);
}

// ---------------------------------------------------------------------------------------
// geometry

TEST(BezierPlanner, PathStaysOnTheLinesOrWithinDeltaOfACorner) {
  const double delta = 0.8;
  const std::vector<Vec3> points = four_point_path();
  const Trajectory trajectory = planner_with(delta).plan(single_path(points, 10.0), kUnbound);
  const SampledMotion& motion = sampled(*printing_pieces(trajectory)[0]);
  double farthest = 0.0;
  for (const Vec3& p : motion.position_mm) {
    const double off = distance_to_polyline(p, points);
    farthest = std::max(farthest, off);
    if (off < 1e-9) continue;
    const double to_corner = std::min((p - points[1]).norm(), (p - points[2]).norm());
    EXPECT_LE(to_corner, delta + 1e-12);
  }
  // the farthest point is the apex of a corner (both turn by 135 degrees): at
  // delta sin(turn/2) / 2 from the corner, i.e. delta sin(turn/2) cos(turn/2) / 2 from the
  // lines. The distance has a kink there (slope sin(turn/2) per mm of arc); the nearest
  // sample is at most half a step v T away.
  const double half = deg_to_rad(135.0) / 2;
  const double apex = delta * std::sin(half) * std::cos(half) / 2;
  EXPECT_LE(farthest, apex + 1e-12);
  EXPECT_GE(farthest, apex - std::sin(half) * 10.0 * 0.001 / 2);
}

TEST(BezierPlanner, PerCornerWeightsPullOnlyTheirCorner) {
  const std::vector<Vec3> points = four_point_path();
  auto nearest = [&](const Trajectory& t, const Vec3& corner) {
    double d = 1e300;
    for (const Vec3& p : sampled(*printing_pieces(t)[0]).position_mm)
      d = std::min(d, (p - corner).norm());
    return d;
  };
  const Trajectory plain = planner_with(0.8).plan(single_path(points, 5.0), kUnbound);
  const Trajectory pulled = planner_with(0.8, {1.0, 10.0}).plan(single_path(points, 5.0), kUnbound);
  EXPECT_NEAR(nearest(pulled, points[1]), nearest(plain, points[1]), 1e-9);
  EXPECT_LT(nearest(pulled, points[2]), 0.25 * nearest(plain, points[2]));
}

TEST(BezierPlanner, ClipsTheFilletWhenCornersAreCloserThanTwoDelta) {
  // the middle line is 0.6 mm long: both corners get delta = 0.3 mm and a warning
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 0.6, 0),
                                    Vec3(20, 0.6, 0)};
  const Toolpath toolpath = single_path(points, 5.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 2000.0);
  const Trajectory trajectory = planner_with(0.5).plan(toolpath, limits);
  int clipped = 0;
  for (const std::string& w : trajectory.warnings())
    if (w.find("clipped from 0.5 to 0.3") != std::string::npos) ++clipped;
  EXPECT_EQ(clipped, 2);
  for (const Vec3& p : sampled(*printing_pieces(trajectory)[0]).position_mm) {
    if (distance_to_polyline(p, points) < 1e-9) continue;
    EXPECT_LE(std::min((p - points[1]).norm(), (p - points[2]).norm()), 0.3 + 1e-12);
  }
  expect_contract(trajectory, toolpath, limits, 0.3);
}

TEST(BezierPlanner, StopsAtAnExactReversal) {
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(4, 0, 0)};
  const Toolpath toolpath = single_path(points, 5.0);
  const MachineLimits limits = MachineLimits::uniform(20.0, 200.0);
  const Trajectory trajectory = planner_with(0.5).plan(toolpath, limits);
  ASSERT_EQ(trajectory.warnings().size(), 1u);
  EXPECT_NE(trajectory.warnings()[0].find("corner 1: reverses direction"), std::string::npos);
  bool at_corner_at_rest = false;
  const SampledMotion& motion = sampled(*printing_pieces(trajectory)[0]);
  for (size_t k = 0; k < motion.position_mm.size(); ++k)
    at_corner_at_rest |=
        (motion.position_mm[k] - points[1]).norm() < 1e-12 && motion.velocity_mm_s[k].norm() == 0.0;
  EXPECT_TRUE(at_corner_at_rest);
  expect_contract(trajectory, toolpath, limits, 0.0);
}

// ---------------------------------------------------------------------------------------
// limits

TEST(BezierPlanner, SlowsBlendsThatWouldExceedAnAxisAccelerationAndNamesThem) {
  // 20 mm/s through 90-degree corners with delta 0.45 needs 20^2 sqrt(2) / 0.45 / sqrt(2)
  // = 889 mm/s^2 per axis at the apex: with 500 mm/s^2 both blends slow down, with
  // trapezoidal ramps on the lines around them
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(30, 0, 0), Vec3(30, 20, 0),
                                    Vec3(60, 20, 0)};
  const Toolpath toolpath = single_path(points, 20.0);
  const MachineLimits limits = MachineLimits::uniform(50.0, 500.0);
  const Trajectory trajectory = planner_with(0.45).plan(toolpath, limits);
  int slowed = 0;
  for (const std::string& w : trajectory.warnings()) {
    if (w.find("path 0 corner 1: blend slowed") != std::string::npos) ++slowed;
    if (w.find("path 0 corner 2: blend slowed") != std::string::npos) ++slowed;
  }
  EXPECT_EQ(slowed, 2);
  expect_contract(trajectory, toolpath, limits, 0.45);
  // the limit is used, not wasted: the sampled peak comes close to a_max
  const SamplePeaks peaks = sample_peaks(sampled(*printing_pieces(trajectory)[0]));
  EXPECT_GT(peaks.accel.maxCoeff(), 0.9 * 500.0);
}

TEST(BezierPlanner, SlowsBlendsForAxisVelocity) {
  // both lines need 0.8 * 10 = 8 mm/s per axis, but the blend's tangent swings through the
  // x axis (10 mm/s on x at the apex): with v_max = 9 the blend slows to 9 mm/s
  const double s = 0.6, c = 0.8;
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(20 * c, 20 * s, 0), Vec3(40 * c, 0, 0)};
  const Toolpath toolpath = single_path(points, 10.0);
  const MachineLimits limits = MachineLimits::uniform(9.0, 5000.0);
  const Trajectory trajectory = planner_with(1.0).plan(toolpath, limits);
  ASSERT_FALSE(trajectory.warnings().empty());
  EXPECT_NE(trajectory.warnings()[0].find("v_max of axis x"), std::string::npos);
  expect_contract(trajectory, toolpath, limits, 1.0);
  const SamplePeaks peaks = sample_peaks(sampled(*printing_pieces(trajectory)[0]));
  EXPECT_NEAR(peaks.velocity.x(), 9.0, 0.01);
}

// Fig. 11a: constant speed makes the acceleration peak in the curves. On a Cartesian stage
// the peak is the blend's v^2 kappa at the apex: 5^2 * sqrt(2) / 0.45 mm/s^2 for 90 degrees.
TEST(BezierPlanner, AccelerationPeaksAtTheBlendApexWithVSquaredKappa) {
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(40, 0, 0), Vec3(40, 30, 0), Vec3(0, 30, 0)};
  const double v = 5.0, delta = 0.45;
  const MachineLimits limits = MachineLimits::uniform(100.0, 1000.0);
  const Trajectory trajectory = planner_with(delta).plan(single_path(points, v), limits);
  const SampledMotion& motion = sampled(*printing_pieces(trajectory)[0]);
  double peak = 0.0;
  size_t peak_at = 0;
  const double h2 = motion.period_s * motion.period_s;
  // skip the start and end ramps (a_max along a line), look at the constant-speed part
  for (size_t k = 60; k + 60 < motion.position_mm.size(); ++k) {
    const Vec3 a =
        (motion.position_mm[k + 1] - 2 * motion.position_mm[k] + motion.position_mm[k - 1]) / h2;
    if (a.norm() > peak) peak = a.norm(), peak_at = k;
  }
  EXPECT_NEAR(peak, v * v * std::sqrt(2.0) / delta, 0.005 * v * v * std::sqrt(2.0) / delta);
  const Vec3& p = motion.position_mm[peak_at];
  EXPECT_LT(std::min((p - points[1]).norm(), (p - points[2]).norm()), delta);
  std::printf("[ Fig. 11a ] peak |a| %.2f mm/s^2 at (%.3f, %.3f), v^2 kappa = %.2f\n", peak, p.x(),
              p.y(), v * v * std::sqrt(2.0) / delta);
}

// ---------------------------------------------------------------------------------------
// the planner contract

TEST(BezierPlanner, PrintPathsStartAndEndAtRestAtTheirEnds) {
  const std::vector<Vec3> points = four_point_path();
  const Trajectory trajectory = planner_with(0.5).plan(single_path(points, 10.0), kUnbound);
  const SampledMotion& motion = sampled(*printing_pieces(trajectory)[0]);
  EXPECT_EQ(motion.position_mm.front(), points.front());
  EXPECT_EQ(motion.position_mm.back(), points.back());
  EXPECT_EQ(motion.velocity_mm_s.front().norm(), 0.0);
  EXPECT_EQ(motion.velocity_mm_s.back().norm(), 0.0);
}

TEST(BezierPlanner, MeetsTheContractOnRandomSegments) {
  // the lead's contract instances (Ganganath et al.), with the scenario example's limits
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    RandomSegmentsSpec spec;
    spec.count = 8;
    spec.seed = seed;
    const Toolpath toolpath = make_random_segments(spec);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
    const Trajectory trajectory = planner_with(0.5).plan(toolpath, limits);
    SCOPED_TRACE("seed " + std::to_string(seed));
    expect_contract(trajectory, toolpath, limits, 0.5);
  }
}

TEST(BezierPlanner, MeetsTheContractOnRandomPolylines) {
  // 3-D polylines with sharp turns, reversals and short edges; tight limits; with and
  // without lead-in, at two sample periods
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    const Toolpath toolpath = random_polylines(seed, 5);
    for (const MachineLimits& limits :
         {MachineLimits::uniform(25.0, 300.0), MachineLimits::uniform(60.0, 3000.0)}) {
      const bool lead_in = seed % 2 == 0;
      const double period = seed < 3 ? 0.001 : 0.004;
      SCOPED_TRACE("seed " + std::to_string(seed));
      const Trajectory trajectory =
          planner_with(0.5, {1.0}, lead_in, period).plan(toolpath, limits);
      expect_contract(trajectory, toolpath, limits, 0.5);
    }
  }
}

TEST(BezierPlanner, JoinedPathsAreSeparatedByAnEmptyTransition) {
  // the second path starts where the first ends: both stop there (each path starts and
  // ends at rest) and the transition between them takes no time
  Toolpath toolpath = single_path(four_point_path(), 5.0);
  PrintPath second;
  second.points = {Vec3(40, 20, 0), Vec3(40, 40, 0), Vec3(0, 40, 0)};
  second.speed_mm_s = 8.0;
  second.source_index = 1;
  toolpath.paths.push_back(second);
  const MachineLimits limits = MachineLimits::uniform(50.0, 500.0);
  const Trajectory trajectory = planner_with(0.5).plan(toolpath, limits);
  ASSERT_EQ(trajectory.pieces().size(), 5u);
  EXPECT_EQ(trajectory.pieces()[2].path_index, -1);
  EXPECT_EQ(trajectory.pieces()[2].t_end_s, trajectory.pieces()[2].t_begin_s);
  expect_contract(trajectory, toolpath, limits, 0.5);
}

TEST(BezierPlanner, SameInputSamePlan) {
  const Toolpath toolpath = random_polylines(9, 3);
  const MachineLimits limits = MachineLimits::uniform(25.0, 300.0);
  const Trajectory a = planner_with(0.5).plan(toolpath, limits);
  const Trajectory b = planner_with(0.5).plan(toolpath, limits);
  ASSERT_EQ(a.pieces().size(), b.pieces().size());
  EXPECT_EQ(a.duration_s(), b.duration_s());
  for (size_t i = 0; i < a.pieces().size(); ++i) {
    if (!std::holds_alternative<SampledMotion>(a.pieces()[i].motion)) continue;
    EXPECT_EQ(sampled(a.pieces()[i]).position_mm, sampled(b.pieces()[i]).position_mm);
  }
}

// ---------------------------------------------------------------------------------------
// lead-in / lead-out

TEST(BezierPlanner, LeadInPrintsOnlyAtFullSpeed) {
  const std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(30, 0, 0), Vec3(30, 20, 0),
                                    Vec3(60, 20, 0)};
  const double v = 10.0, period = 0.001;
  const Toolpath toolpath = single_path(points, v);
  const MachineLimits limits = MachineLimits::uniform(50.0, 1000.0);
  const Trajectory trajectory = planner_with(0.45, {1.0}, true, period).plan(toolpath, limits);
  const auto pieces = printing_pieces(trajectory);
  ASSERT_EQ(pieces.size(), 1u);
  const SampledMotion& motion = sampled(*pieces[0]);
  // printing starts exactly at P_0 and stops within one step past P_n, at full speed throughout
  EXPECT_LT((motion.position_mm.front() - points.front()).norm(), 1e-12);
  const Vec3 past_end = motion.position_mm.back() - points.back();
  EXPECT_GE(past_end.x(), 0.0);
  EXPECT_LT(past_end.norm(), v * period + 1e-12);
  for (const Vec3& velocity : motion.velocity_mm_s) EXPECT_NEAR(velocity.norm(), v, 1e-9 * v);
  // ramps are separate, material-off pieces on the extensions of the first and last line
  int ramps = 0;
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    if (piece.depositing || !std::holds_alternative<SampledMotion>(piece.motion)) continue;
    ++ramps;
    for (const Vec3& p : sampled(piece).position_mm)
      EXPECT_TRUE(p.x() <= 1e-12 || p.x() >= 60.0 - 1e-12) << p.transpose();
  }
  EXPECT_EQ(ramps, 2);
  expect_contract(trajectory, toolpath, limits, 0.45);
}

// A vertex that goes straight on is no corner (no blend): a 10 mm line given as 101 points
// every 0.1 mm plans exactly as the 2-point line, at print speed, without warnings. Before,
// each vertex got a blend clipped to 0.05 mm, the lines between them had length 0, and the
// constant-speed blends held the speed reached on the first 0.05 mm: 1.616 mm/s.
TEST(BezierPlanner, CollinearPointsPlanAsOneLine) {
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  BezierSettings settings;  // delta 0.5 mm, T_s 1 ms
  const BezierPlanner planner(settings);
  std::vector<Vec3> fine;
  for (int i = 0; i <= 100; ++i) fine.push_back(Vec3(-5.0 + 0.1 * i, 0.0, 0.0));
  const Toolpath fine_path = single_path(fine, 3.0);
  const Trajectory two = planner.plan(single_path({Vec3(-5, 0, 0), Vec3(5, 0, 0)}, 3.0), limits);
  const Trajectory many = planner.plan(fine_path, limits);
  EXPECT_TRUE(many.warnings().empty());
  EXPECT_NEAR(many.duration_s(), two.duration_s(), 1e-9);
  EXPECT_NEAR(many.depositing_time_s(), two.depositing_time_s(), 1e-9);
  double peak = 0.0;
  for (const TrajectoryPiece& piece : many.pieces())
    if (piece.depositing)
      for (const Vec3& v : sampled(piece).velocity_mm_s) peak = std::max(peak, v.norm());
  EXPECT_NEAR(peak, 3.0, 1e-9);
  expect_contract(many, fine_path, limits, 0.5);
  // a straight run counts as one line for the fillet room of the corner after it: no clip
  std::vector<Vec3> bent = fine;
  bent.push_back(Vec3(5.0, 10.0, 0.0));
  const Trajectory corner = planner.plan(single_path(bent, 3.0), limits);
  for (const std::string& w : corner.warnings())
    EXPECT_EQ(w.find("clipped"), std::string::npos) << w;
}

TEST(BezierPlanner, FineChordsAreMergedWithinMerge) {
  // a circle of radius 10 mm in 0.05 mm chords (a slicer's or CAM's curve), at 10 mm/s
  const double radius = 10.0, speed = 10.0;
  const MachineLimits limits = MachineLimits::uniform(40.0, 500.0);
  const auto circle = [&](int chords) {
    std::vector<Vec3> points;
    for (int k = 0; k <= chords; ++k) {
      const double angle = 2.0 * kPi * k / chords;
      points.push_back(Vec3(radius * std::cos(angle), radius * std::sin(angle), 0.0));
    }
    return points;
  };
  const int fine_chords = 1257;  // 0.0500 mm each
  const Toolpath fine = single_path(circle(fine_chords), speed);
  const BezierPlanner merging(BezierSettings{});  // merge 0.01 mm
  const Trajectory merged = merging.plan(fine, limits);
  expect_contract(merged, fine, limits, 0.5);

  // printed as fast as the same circle in 1 mm chords, which need no merging
  const Trajectory coarse = merging.plan(single_path(circle(63), speed), limits);
  EXPECT_LT(merged.depositing_time_s(), 1.01 * coarse.depositing_time_s());

  // every sample within the merge distance plus a blend's deviation from its merged corner:
  // a chord of sagitta 0.01 mm turns by at most theta = 2 acos(1 - 0.01 / R) at its ends, and
  // a blend of fillet delta <= 0.5 mm passes delta sin(theta / 2) / 2 inside its corner
  const double theta = 2.0 * std::acos(1.0 - 0.01 / radius);
  const double bound = 0.01 + 0.5 * std::sin(0.5 * theta) / 2.0;
  double farthest = 0.0;
  for (const TrajectoryPiece& piece : merged.pieces()) {
    if (!piece.depositing) continue;
    for (const Vec3& p : sampled(piece).position_mm) {
      double nearest = std::numeric_limits<double>::infinity();
      const double angle = std::atan2(p.y(), p.x());
      const int k = static_cast<int>(std::floor(angle / (2.0 * kPi) * fine_chords + fine_chords));
      for (int j = k - 2; j <= k + 2; ++j) {  // the chords around the sample's angle
        const int e = ((j % fine_chords) + fine_chords) % fine_chords;
        nearest = std::min(nearest, point_segment_distance(p, fine.paths[0].points[e],
                                                           fine.paths[0].points[e + 1]));
      }
      farthest = std::max(farthest, nearest);
    }
  }
  EXPECT_LE(farthest, bound);
  EXPECT_GT(farthest, 1e-3);  // the blends do cut inside

  // merge 0 keeps every chord: the fillets clipped to 0.025 mm leave no room to ramp
  BezierSettings every_point;
  every_point.merge_mm = 0.0;
  const Trajectory unmerged = BezierPlanner(every_point).plan(fine, limits);
  EXPECT_GT(unmerged.depositing_time_s(), 2.0 * merged.depositing_time_s());
  // as does a weight per corner (each corner keeps its own)
  BezierSettings weighted;
  weighted.weights.assign(fine_chords - 1, 1.0);
  EXPECT_DOUBLE_EQ(BezierPlanner(weighted).plan(fine, limits).duration_s(), unmerged.duration_s());
}

}  // namespace
}  // namespace depotwin
