// The firmware baseline planner against closed forms: Marlin's junction deviation speed,
// Klipper's square-corner conversion and minimum cruise ratio, collinear joints at full
// speed, reversals at rest, reachable junction speeds and a single trapezoid's time.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "contract/planner_checks.hpp"
#include "core/error.hpp"
#include "planners/motion/firmware.hpp"
#include "planners/motion/polyline_job.hpp"

namespace depotwin {
namespace {

Trajectory plan_with(const PlannerSpec& spec, const Toolpath& toolpath,
                     const MachineLimits& limits) {
  return make_planner(spec)->plan(toolpath, limits);
}

FirmwareMove move_along(const Vec3& direction, double length, double accel, double speed) {
  FirmwareMove move;
  move.direction = direction.normalized();
  move.length_mm = length;
  move.accel_mm_s2 = accel;
  move.cruise_speed_mm_s = speed;
  move.blend_accel_mm_s2 = Vec3(accel, accel, accel);
  return move;
}

TEST(Firmware, NinetyDegreeJunctionSpeedIsMarlinsFormula) {
  // theta = 90 deg: v^2 = a jd sin 45 / (1 - sin 45)
  const double a = 1000.0, jd = 0.013, s = std::sqrt(0.5);
  const double expected2 = a * jd * s / (1 - s);  // 31.38 (mm/s)^2
  EXPECT_NEAR(junction_speed_squared(Vec3::UnitX(), Vec3::UnitY(), a, jd), expected2, 1e-12);
  // the planner takes the corner of a long L at that speed: the velocity there before the
  // blend turns it is sqrt(expected2) along x
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {20, 0, 0}, {20, 20, 0}}, 50.0);
  const Trajectory plan = plan_with({"firmware", {}, 0}, toolpath, MachineLimits::uniform(100, a));
  ASSERT_EQ(plan.pieces().size(), 2u);
  const double v = std::sqrt(expected2), tau = v / a;  // max_i |dv_i| / a_i = v / a
  const TrajectorySample before = plan.at(plan.pieces()[0].t_end_s - 0.5 * tau - 1e-9);
  EXPECT_NEAR(before.velocity_mm_s.x(), v, 1e-5);
  EXPECT_NEAR(before.velocity_mm_s.y(), 0.0, 1e-9);
  const TrajectorySample after = plan.at(plan.pieces()[1].t_begin_s + 0.5 * tau + 1e-9);
  EXPECT_NEAR(after.velocity_mm_s.x(), 0.0, 1e-9);
  EXPECT_NEAR(after.velocity_mm_s.y(), v, 1e-5);
  // the blend cuts the corner by |dv| tau / 8 = sqrt(2) v tau / 8, less than jd
  double nearest = 1e300;
  for (double t = 0; t < plan.duration_s(); t += 1e-5)
    nearest = std::min(nearest, (plan.at(t).position_mm - Vec3(20, 0, 0)).norm());
  EXPECT_NEAR(nearest, std::sqrt(2.0) * v * tau / 8, 1e-6);
  EXPECT_LT(nearest, jd);
}

// E is tied to the motion: while printing, the commanded flow is |v| / v_des at every instant
// (nominal volume per length), 0 at rest, 1 at the print speed
TEST(Firmware, FlowFollowsTheSpeedAsTheEAxisDoes) {
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {20, 0, 0}, {20, 20, 0}}, 50.0);
  const Trajectory plan =
      plan_with({"firmware", {}, 0}, toolpath, MachineLimits::uniform(100, 1000));
  bool cruised = false;
  for (double t = 0; t <= plan.duration_s(); t += 1e-3) {
    const TrajectorySample sample = plan.at(t);
    if (!sample.depositing) continue;
    EXPECT_NEAR(sample.flow_fraction, sample.velocity_mm_s.norm() / 50.0, 1e-9) << t;
    cruised = cruised || sample.flow_fraction > 1.0 - 1e-9;
  }
  EXPECT_TRUE(cruised);  // it reaches the print speed, and the nominal flow, on the long lines
  EXPECT_NEAR(plan.at(0.0).flow_fraction, 0.0, 1e-9);  // from rest
}

TEST(Firmware, KlipperSquareCornerVelocityIsTheNinetyDegreeSpeed) {
  // jd = scv^2 (sqrt 2 - 1) / accel
  EXPECT_NEAR(klipper_junction_deviation(5.0, 1000.0), 25.0 * (std::sqrt(2.0) - 1) / 1000.0, 1e-15);
  FirmwareSettings klipper;
  klipper.mode = FirmwareMode::klipper;
  klipper.minimum_cruise_ratio = 0.0;
  const std::vector<FirmwareMove> moves{move_along(Vec3::UnitX(), 20, 1000, 50),
                                        move_along(Vec3::UnitY(), 20, 1000, 50)};
  const FirmwareProfile profile =
      firmware_lookahead(moves, klipper, klipper_junction_deviation(5.0, 1000.0));
  EXPECT_NEAR(profile.junction_speed_mm_s[1], 5.0, 1e-12);
  // through the planner, square_corner_velocity 7 at max_accel 1000: the corner at 7 mm/s
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {20, 0, 0}, {20, 20, 0}}, 50.0);
  const PlannerSpec spec{"firmware",
                         {{"square_corner_velocity", {7.0}}, {"minimum_cruise_ratio", {0.0}}},
                         0,
                         {{"mode", "klipper"}}};
  const Trajectory plan = plan_with(spec, toolpath, MachineLimits::uniform(100, 1000));
  const TrajectorySample before = plan.at(plan.pieces()[0].t_end_s - 0.5 * 7.0 / 1000 - 1e-9);
  EXPECT_NEAR(before.velocity_mm_s.x(), 7.0, 1e-5);
}

// Marlin's classic jerk: a 90 deg corner at 50 mm/s stops x and starts y, a jump of 50 each,
// scaled to the jerk; 20 then 100 mm/s along x jumps by 80, scaled to 20 * 8 / 80 = 2 mm/s,
// and both moves' safe speed (the jerk, 8) is taken instead
TEST(Firmware, ClassicJerkBoundsEachAxisJump) {
  FirmwareSettings classic;
  classic.classic_jerk_mm_s[0] = classic.classic_jerk_mm_s[1] = 8.0;
  classic.classic_jerk_mm_s[2] = 0.3;
  classic.classic_jerk_mm_s[3] = 5.0;
  ASSERT_TRUE(classic.uses_classic_jerk());
  const FirmwareMove x_fast = move_along(Vec3::UnitX(), 20, 1000, 50);
  const FirmwareMove y_fast = move_along(Vec3::UnitY(), 20, 1000, 50);
  const FirmwareMove x_slow = move_along(Vec3::UnitX(), 20, 1000, 20);
  const FirmwareMove x_faster = move_along(Vec3::UnitX(), 20, 1000, 100);
  EXPECT_DOUBLE_EQ(classic_jerk_junction_speed(x_fast, y_fast, classic.classic_jerk_mm_s), 8.0);
  EXPECT_DOUBLE_EQ(classic_jerk_junction_speed(x_slow, x_faster, classic.classic_jerk_mm_s), 8.0);
  // a 45 deg turn: y starts at 50 cos 45 = 35.4, the largest jump (x's is 14.6), so v = 50 * 8 /
  // 35.4 = 8 sqrt 2; the x move's safe speed, 8, is below 0.99 v, so v stays
  const FirmwareMove diagonal = move_along(Vec3(1, 1, 0), 20, 1000, 50);
  EXPECT_NEAR(classic_jerk_junction_speed(x_fast, diagonal, classic.classic_jerk_mm_s),
              8.0 * std::sqrt(2.0), 1e-12);
  // the look-ahead corners by it, and the planner with `classic_jerk` takes the L's corner at 8
  const FirmwareProfile profile = firmware_lookahead({x_fast, y_fast}, classic, 0.013);
  EXPECT_NEAR(profile.junction_speed_mm_s[1], 8.0, 1e-12);
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {20, 0, 0}, {20, 20, 0}}, 50.0);
  const Trajectory plan = plan_with({"firmware", {{"classic_jerk", {8.0}}}, 0}, toolpath,
                                    MachineLimits::uniform(100, 1000));
  const TrajectorySample before = plan.at(plan.pieces()[0].t_end_s - 0.5 * 8.0 / 1000 - 1e-9);
  EXPECT_NEAR(before.velocity_mm_s.x(), 8.0, 1e-5);
  EXPECT_NEAR(before.velocity_mm_s.y(), 0.0, 1e-9);
}

TEST(Firmware, CollinearMovesNeverSlowAtTheJoints) {
  // 30 mm in three collinear moves at 50 mm/s, a = 1000: one trapezoid, d / v + v / a
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {10, 0, 0}, {17, 0, 0}, {30, 0, 0}}, 50.0);
  for (const char* mode : {"marlin", "klipper"}) {
    SCOPED_TRACE(mode);
    const Trajectory plan = plan_with({"firmware", {}, 0, {{"mode", mode}}}, toolpath,
                                      MachineLimits::uniform(100, 1000));
    EXPECT_NEAR(plan.duration_s(), 30.0 / 50.0 + 50.0 / 1000.0, 1e-12);
    for (size_t k = 1; k < plan.pieces().size(); ++k)
      EXPECT_NEAR(plan.at(plan.pieces()[k].t_begin_s).velocity_mm_s.x(), 50.0, 1e-9);
  }
}

TEST(Firmware, AReversalStops) {
  EXPECT_EQ(junction_speed_squared(Vec3::UnitX(), -Vec3::UnitX(), 1000, 0.013), 0.0);
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {10, 0, 0}, {0, 0, 0}}, 50.0);
  const Trajectory plan =
      plan_with({"firmware", {}, 0}, toolpath, MachineLimits::uniform(100, 1000));
  ASSERT_EQ(plan.pieces().size(), 2u);
  EXPECT_NEAR(plan.at(plan.pieces()[1].t_begin_s).velocity_mm_s.norm(), 0.0, 1e-12);
  // two rest-to-rest trapezoids of 10 mm
  EXPECT_NEAR(plan.duration_s(), 2 * (10.0 / 50.0 + 50.0 / 1000.0), 1e-12);
}

TEST(Firmware, JunctionSpeedsAreReachableFromNeighbours) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> heading(0, 2 * kPi), length(0.05, 5.0);
  std::vector<FirmwareMove> moves;
  for (int k = 0; k < 200; ++k) {
    const double h = heading(rng);
    moves.push_back(move_along(Vec3(std::cos(h), std::sin(h), 0), length(rng), 1500, 80));
  }
  for (const FirmwareMode mode : {FirmwareMode::marlin, FirmwareMode::klipper}) {
    FirmwareSettings settings;
    settings.mode = mode;
    const FirmwareProfile profile = firmware_lookahead(moves, settings, 0.05);
    const auto& v = profile.junction_speed_mm_s;
    EXPECT_EQ(v.front(), 0.0);
    EXPECT_EQ(v.back(), 0.0);
    for (size_t k = 0; k < moves.size(); ++k) {
      // v_{k+1}^2 <= v_k^2 + 2 a d and back, and within the cruise speed
      const double reach = 2 * moves[k].accel_mm_s2 * moves[k].length_mm;
      EXPECT_LE(v[k + 1] * v[k + 1], v[k] * v[k] + reach + 1e-9) << "move " << k;
      EXPECT_LE(v[k] * v[k], v[k + 1] * v[k + 1] + reach + 1e-9) << "move " << k;
      EXPECT_LE(v[k], profile.cruise_speed_mm_s[k] + 1e-12);
      if (k > 0) {
        const double jd2 =
            junction_speed_squared(moves[k - 1].direction, moves[k].direction, 1500, 0.05);
        EXPECT_LE(v[k] * v[k], jd2 + 1e-9) << "junction " << k;
      }
    }
  }
}

TEST(Firmware, SingleTrapezoidTime) {
  const MachineLimits limits = MachineLimits::uniform(100, 1000);
  // trapezoid: d / v + v / a
  EXPECT_NEAR(plan_with({"firmware", {}, 0}, polyline_job({{0, 0, 0}, {10, 0, 0}}, 50), limits)
                  .duration_s(),
              10.0 / 50 + 50.0 / 1000, 1e-12);
  // triangle: 2 sqrt(d / a)
  EXPECT_NEAR(
      plan_with({"firmware", {}, 0}, polyline_job({{0, 0, 0}, {1, 0, 0}}, 50), limits).duration_s(),
      2 * std::sqrt(1.0 / 1000), 1e-12);
  // along a diagonal the move's acceleration is a / |u_y| (no axis beyond a): 3-4-5
  EXPECT_NEAR(
      plan_with({"firmware", {}, 0}, polyline_job({{0, 0, 0}, {3, 4, 0}}, 50), limits).duration_s(),
      5.0 / 50 + 50.0 / (1000 / 0.8), 1e-12);
  // Klipper's max_accel is the same in every direction (default: the x and y axes' smaller
  // a_max): the diagonal takes a, not a / |u_y|
  EXPECT_NEAR(plan_with({"firmware", {}, 0, {{"mode", "klipper"}}},
                        polyline_job({{0, 0, 0}, {3, 4, 0}}, 50), limits)
                  .duration_s(),
              5.0 / 50 + 50.0 / 1000, 1e-12);
  // Klipper's minimum_cruise_ratio 0.5: a 1.5 mm move cruises 0.75 mm (its docs' example) at
  // sqrt(a d / 2)
  const Trajectory klipper = plan_with({"firmware", {}, 0, {{"mode", "klipper"}}},
                                       polyline_job({{0, 0, 0}, {1.5, 0, 0}}, 50), limits);
  const double peak = std::sqrt(1000 * 1.5 / 2);
  EXPECT_NEAR(klipper.duration_s(), 2 * peak / 1000 + 0.75 / peak, 1e-12);
  // the older max_accel_to_decel = 500 at max_accel 1000 is the same ratio
  const Trajectory older =
      plan_with({"firmware", {{"max_accel_to_decel", {500.0}}}, 0, {{"mode", "klipper"}}},
                polyline_job({{0, 0, 0}, {1.5, 0, 0}}, 50), limits);
  EXPECT_NEAR(older.duration_s(), klipper.duration_s(), 1e-12);
  // max_velocity and max_accel cap the limits' own; a max_velocity below the print speed is
  // said in the plan's warnings
  const Trajectory capped =
      plan_with({"firmware", {{"max_velocity", {20.0}}, {"max_accel", {400.0}}}, 0},
                polyline_job({{0, 0, 0}, {10, 0, 0}}, 50), limits);
  EXPECT_NEAR(capped.duration_s(), 10.0 / 20 + 20.0 / 400, 1e-12);
  ASSERT_EQ(capped.warnings().size(), 1u);
  EXPECT_EQ(capped.warnings()[0],
            "max_velocity 20 mm/s is below the print speed of 1 of 1 segments (up to 50 mm/s): "
            "they print at most at 20 mm/s");
  EXPECT_TRUE(plan_with({"firmware", {{"max_velocity", {60.0}}}, 0},
                        polyline_job({{0, 0, 0}, {10, 0, 0}}, 50), limits)
                  .warnings()
                  .empty());
}

TEST(Firmware, ZigZagKeepsTheContract) {
  // a 0.4 mm-pitch infill zig-zag: blends at every corner, material on throughout
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i) {
    const double x0 = i % 2 == 0 ? 0.0 : 10.0;
    points.emplace_back(x0, 0.4 * i, 0);
    points.emplace_back(10.0 - x0, 0.4 * i, 0);
  }
  const Toolpath toolpath = polyline_job(points, 40);
  const MachineLimits limits = MachineLimits::uniform(100, 1500);
  for (const char* mode : {"marlin", "klipper"}) {
    SCOPED_TRACE(mode);
    const Trajectory plan = plan_with({"firmware", {}, 0, {{"mode", mode}}}, toolpath, limits);
    testing_support::expect_contract(plan, toolpath, limits);
    for (const TrajectoryPiece& piece : plan.pieces()) EXPECT_TRUE(piece.depositing);
  }
}

// ---------------------------------------------------------------------------------------
// S_CURVE_ACCELERATION under a jerk limit

// Marlin's quintic Bezier speed shape: 0 to 1 with zero slope and curvature at both ends,
// peak slope 15/8 at the middle, peak |curvature| 10 / sqrt(3) at (1 -+ 1/sqrt(3)) / 2
TEST(FirmwareSCurve, BezierShapeClosedForms) {
  EXPECT_EQ(s_curve_shape(0.0), 0.0);
  EXPECT_NEAR(s_curve_shape(1.0), 1.0, 1e-15);
  EXPECT_NEAR(s_curve_shape(0.5), 0.5, 1e-15);
  EXPECT_NEAR(s_curve_shape_integral(1.0), 0.5, 1e-15);       // mean speed (v0 + v1) / 2
  EXPECT_NEAR(s_curve_shape_integral(0.5), 5.0 / 64, 1e-15);  // the corner cut 5 |dv| tau / 64
  double slope = 0.0, curvature = 0.0;
  const double dx = 1e-5;
  for (double x = dx; x < 1.0; x += dx) {
    slope = std::max(slope, (s_curve_shape(x + dx) - s_curve_shape(x - dx)) / (2 * dx));
    curvature = std::max(
        curvature,
        std::abs(s_curve_shape(x + dx) - 2 * s_curve_shape(x) + s_curve_shape(x - dx)) / (dx * dx));
  }
  EXPECT_NEAR(slope, kSCurvePeakAccel, 1e-8);
  EXPECT_NEAR(curvature, kSCurvePeakJerk, 1e-4);
  // a 30 mm/s change at a = 1000, j = 200000: the acceleration binds (15/8 30 / 1000 / 0.97),
  // at j = 2000 the jerk does (sqrt(10 / sqrt(3) 30 / 2000 / 0.97))
  EXPECT_NEAR(s_curve_ramp_time(30, 1000, 200000), 1.875 * 30 / 970, 1e-15);
  EXPECT_NEAR(s_curve_ramp_time(-30, 1000, 2000), std::sqrt(kSCurvePeakJerk * 30 / 1940), 1e-15);
  EXPECT_EQ(s_curve_ramp_time(0, 1000, 2000), 0.0);
  EXPECT_EQ(s_curve_ramp_time(1e-6, 1000, 2000), kSCurveMinTime_s);
}

// a single move rest to rest: two Bezier ramps and a cruise, (v / 2) T + d_cruise / v + (v / 2) T
TEST(FirmwareSCurve, SingleMoveTimeIsTwoBezierRampsAndACruise) {
  for (const double jerk : {20000.0, 500000.0}) {
    SCOPED_TRACE(jerk);
    const MachineLimits limits = MachineLimits::uniform(100, 1000, jerk);
    const double T = s_curve_ramp_time(50, 1000, jerk);
    const Trajectory plan =
        plan_with({"firmware", {}, 0}, polyline_job({{0, 0, 0}, {10, 0, 0}}, 50), limits);
    EXPECT_NEAR(plan.duration_s(), 2 * T + (10.0 - 50 * T) / 50, 1e-12);
    // half-way through the ramp the speed is half the peak
    EXPECT_NEAR(plan.at(0.5 * T).velocity_mm_s.x(), 25.0, 1e-4);
    testing_support::expect_finite_difference_limits(plan, limits, 0.01);
    // the peaks 15/8 v / T and 10/sqrt(3) v / T^2: one of them at 97 % of its limit
    const auto peaks = testing_support::finite_difference_peaks(plan, limits);
    EXPECT_NEAR(peaks.accel_ratio[0], kSCurvePeakAccel * 50 / T / 1000, 2e-3);
    EXPECT_NEAR(peaks.jerk_ratio[0], kSCurvePeakJerk * 50 / (T * T) / jerk, 2e-3);
    EXPECT_NEAR(std::max(peaks.accel_ratio[0], peaks.jerk_ratio[0]), kSCurveLimitShare, 2e-3);
  }
}

// The 90 deg corner of an L under j_max: Marlin's junction speed, the blend's velocity turns by
// the Bezier shape over tau (acceleration and jerk both within the limits), the corner is cut
// by 5 |dv| tau / 64
TEST(FirmwareSCurve, CornerBlendIsJerkLimited) {
  const double a = 1000.0, j = 30000.0, jd = 0.013, s = std::sqrt(0.5);
  const MachineLimits limits = MachineLimits::uniform(100, a, j);
  const Toolpath toolpath = polyline_job({{0, 0, 0}, {20, 0, 0}, {20, 20, 0}}, 50.0);
  const Trajectory plan = plan_with({"firmware", {}, 0}, toolpath, limits);
  ASSERT_EQ(plan.pieces().size(), 2u);
  const double v = std::sqrt(a * jd * s / (1 - s));
  // per axis |dv_i| = v: tau = max(15/8 v / a, sqrt(10/sqrt 3 v / j), 8 ms) / share
  const double tau =
      std::max({kSCurvePeakAccel * v / (kSCurveLimitShare * a),
                std::sqrt(kSCurvePeakJerk * v / (kSCurveLimitShare * j)), kSCurveMinTime_s});
  // (the samples' cubic interpolation is within 1e-4 mm/s of the Bezier shape)
  const TrajectorySample before = plan.at(plan.pieces()[0].t_end_s - 0.5 * tau - 1e-9);
  EXPECT_NEAR(before.velocity_mm_s.x(), v, 1e-4);
  EXPECT_NEAR(before.velocity_mm_s.y(), 0.0, 1e-4);
  const TrajectorySample after = plan.at(plan.pieces()[1].t_begin_s + 0.5 * tau + 1e-9);
  EXPECT_NEAR(after.velocity_mm_s.x(), 0.0, 1e-4);
  EXPECT_NEAR(after.velocity_mm_s.y(), v, 1e-4);
  double nearest = 1e300;
  for (double t = 0; t < plan.duration_s(); t += 1e-5)
    nearest = std::min(nearest, (plan.at(t).position_mm - Vec3(20, 0, 0)).norm());
  EXPECT_NEAR(nearest, std::sqrt(2.0) * v * tau * 5 / 64, 1e-6);
  testing_support::expect_contract(plan, toolpath, limits);
  testing_support::expect_finite_difference_limits(plan, limits, 0.01);
}

// Random toolpaths (isolated segments and chains, travels between them) and a fine zig-zag, both
// modes: every 1 ms sample within v_max, a_max and j_max by finite differences, the contract
// kept, never faster than without the jerk limit
TEST(FirmwareSCurve, RandomToolpathsStayWithinTheJerkLimit) {
  double worst = 0.0;
  for (const char* mode : {"marlin", "klipper"}) {
    const auto planner = make_planner({"firmware", {}, 0, {{"mode", mode}}});
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      SCOPED_TRACE(testing::Message() << mode << " seed " << seed);
      const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
      for (const double jerk : {200.0, 3000.0}) {
        const MachineLimits limits = MachineLimits::uniform(4.0, 30.0, jerk);
        const Trajectory plan = planner->plan(toolpath, limits);
        testing_support::expect_contract(plan, toolpath, limits);
        testing_support::expect_finite_difference_limits(plan, limits, 0.01);
        worst = std::max(worst,
                         testing_support::finite_difference_peaks(plan, limits).max_jerk_ratio());
        const Trajectory free = planner->plan(toolpath, MachineLimits::uniform(4.0, 30.0));
        EXPECT_GE(plan.duration_s(), free.duration_s() - 1e-9);
      }
      if (HasFatalFailure()) return;
    }
  }
  std::printf("firmware: largest finite-difference jerk / j_max on random toolpaths: %.4f\n",
              worst);
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i) {
    const double x0 = i % 2 == 0 ? 0.0 : 10.0;
    points.emplace_back(x0, 0.4 * i, 0);
    points.emplace_back(10.0 - x0, 0.4 * i, 0);
  }
  const Toolpath zigzag = polyline_job(points, 40);
  const MachineLimits limits = MachineLimits::uniform(100, 1500, 20000);
  const Trajectory plan = plan_with({"firmware", {}, 0}, zigzag, limits);
  testing_support::expect_contract(plan, zigzag, limits);
  testing_support::expect_finite_difference_limits(plan, limits, 0.01);
}

// A slicer's perimeter: a 10 mm circle of 0.25 mm chords at 30 mm/s under j_max 30000, where
// the ramps, not the junctions, bound the speeds. The look-ahead's bisection for the highest
// speed a ramp reaches once moved the ramp's lower end with it, so the passes lowered speeds
// that fitted and never settled (an internal error after 10000 sweeps on every such perimeter).
TEST(FirmwareSCurve, ShortChordPerimeterSettles) {
  std::vector<Vec3> points;
  const int chords = 251;  // 2 pi 10 / 0.25
  for (int i = 0; i <= chords; ++i) {
    const double angle = 2.0 * kPi * i / chords;
    points.emplace_back(10.0 * std::cos(angle), 10.0 * std::sin(angle), 0.0);
  }
  const Toolpath circle = polyline_job(points, 30.0);
  const MachineLimits limits = MachineLimits::uniform(200, 1500, 30000);
  for (const char* mode : {"marlin", "klipper"}) {
    SCOPED_TRACE(mode);
    const Trajectory plan = plan_with({"firmware", {}, 0, {{"mode", mode}}}, circle, limits);
    testing_support::expect_contract(plan, circle, limits);
    testing_support::expect_finite_difference_limits(plan, limits, 0.01);
    // the speed builds up over many chords (the passes settled on speeds above what stopping
    // at every junction allows), below the print speed, and never faster than without j_max
    const double mean_speed = 2.0 * kPi * 10.0 / plan.duration_s();
    EXPECT_GT(mean_speed, 5.0);
    EXPECT_LT(mean_speed, 30.0);
    const Trajectory free =
        plan_with({"firmware", {}, 0, {{"mode", mode}}}, circle, MachineLimits::uniform(200, 1500));
    EXPECT_GE(plan.duration_s(), free.duration_s() - 1e-9);
  }
}

TEST(Firmware, ParametersOfTheOtherFirmwareAreRefused) {
  EXPECT_EQ(check_planner_spec({"firmware", {{"junction_deviation_mm", {0.02}}}, 0}), "");
  EXPECT_NE(check_planner_spec({"firmware", {}, 0, {{"mode", "grbl"}}}).find("marlin | klipper"),
            std::string::npos);
  EXPECT_THROW(make_planner({"firmware", {{"square_corner_velocity", {5.0}}}, 0}), InputError);
  EXPECT_THROW(
      make_planner({"firmware", {{"junction_deviation_mm", {0.02}}}, 0, {{"mode", "klipper"}}}),
      InputError);
  EXPECT_THROW(make_planner({"firmware", {{"classic_jerk", {8.0}}}, 0, {{"mode", "klipper"}}}),
               InputError);
  EXPECT_THROW(
      make_planner({"firmware", {{"classic_jerk", {8.0}}, {"junction_deviation_mm", {0.02}}}, 0}),
      InputError);
  EXPECT_THROW(make_planner({"firmware",
                             {{"minimum_cruise_ratio", {0.3}}, {"max_accel_to_decel", {500.0}}},
                             0,
                             {{"mode", "klipper"}}}),
               InputError);
}

}  // namespace
}  // namespace depotwin
