// The speed and path error statistics (docs/ARCHITECTURE.md, "Metrics") on hand-made samples
// whose answers are closed forms: a constant error, an error that steps between two values, a
// sinusoidal ripple (max A, rms A / sqrt 2, 95th percentile A sin(0.95 pi / 2)), a constant
// offset beside a polyline and a sinusoidal wobble across a line; and what counts (only
// depositing samples with a desired speed, each measured against its own path).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "core/types.hpp"
#include "metrics/motion_metrics.hpp"

namespace depotwin {
namespace {

constexpr double kPeriod_s = 1e-4;

// samples every kPeriod_s over [0, duration_s] of a nozzle printing path `path` at the desired
// speed: position(t) and velocity(t) given, depositing throughout
MotionSamples printing(double duration_s, double desired_mm_s,
                       const std::function<Vec3(double)>& position,
                       const std::function<Vec3(double)>& velocity, int path = 0) {
  MotionSamples s;
  const long n = std::lround(duration_s / kPeriod_s);
  for (long k = 0; k <= n; ++k) {
    const double t = k * kPeriod_s;
    s.push_back(t, position(t), velocity(t), true, path, desired_mm_s);
  }
  return s;
}

Toolpath one_path(std::vector<Vec3> points) {
  Toolpath toolpath;
  PrintPath path;
  path.points = std::move(points);
  path.speed_mm_s = 3.0;
  toolpath.paths.push_back(path);
  return toolpath;
}

// 10 % too fast everywhere: every statistic is 0.1, all the length is over 1 %
TEST(VelocityError, ConstantOverspeedIsTheSameEverywhere) {
  const MotionSamples s = printing(
      2.0, 3.0, [](double t) { return Vec3(3.3 * t, 0, 0); },
      [](double) { return Vec3(0, 3.3, 0); });  // the direction does not matter, |v| does
  const VelocityErrorStats e = velocity_error(s);
  EXPECT_NEAR(e.max_rel, 0.1, 1e-12);
  EXPECT_NEAR(e.rms_rel, 0.1, 1e-12);
  EXPECT_NEAR(e.p95_rel, 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(e.frac_len_over_1pct, 1.0);
  for (double r : relative_speed_error(s)) EXPECT_NEAR(r, 0.1, 1e-12);
}

// first second 2 % too fast, next three seconds 0.5 % too slow: time-weighted rms
// sqrt((1 x 0.02^2 + 3 x 0.005^2) / 4); 75 % of the time at 0.5 %, so the 95th percentile is
// 2 %; the length over 1 % is the fast part's: 1.02 x 1 / (1.02 x 1 + 0.995 x 3)
TEST(VelocityError, TwoLevelsGiveTheirTimeWeightedStatistics) {
  const double v = 3.0;
  const auto speed = [v](double t) { return t < 1.0 ? 1.02 * v : 0.995 * v; };
  const MotionSamples s = printing(
      4.0, v, [](double) { return Vec3::Zero(); }, [&](double t) { return Vec3(speed(t), 0, 0); });
  const VelocityErrorStats e = velocity_error(s);
  EXPECT_NEAR(e.max_rel, 0.02, 1e-12);
  EXPECT_NEAR(e.rms_rel, std::sqrt((0.02 * 0.02 + 3 * 0.005 * 0.005) / 4.0), 1e-6);
  EXPECT_NEAR(e.p95_rel, 0.02, 1e-12);
  EXPECT_NEAR(e.frac_len_over_1pct, 1.02 / (1.02 + 0.995 * 3), 1e-4);
  // with 97 % of the time at 0.5 %, the 95th percentile is 0.5 %
  const auto mostly_slow = [v](double t) { return t < 0.03 ? 1.02 * v : 0.995 * v; };
  const MotionSamples slow = printing(
      1.0, v, [](double) { return Vec3::Zero(); },
      [&](double t) { return Vec3(mostly_slow(t), 0, 0); });
  EXPECT_NEAR(velocity_error(slow).p95_rel, 0.005, 1e-12);
}

// |v| = v (1 + A sin(2 pi f t)) over whole periods: e = A |sin|, so max A, rms A / sqrt 2, and
// since the time with |sin| <= x is (2 / pi) arcsin x, the 95th percentile is A sin(0.95 pi/2);
// the length over 1 % (A = 5 %): where |sin| > 0.2, weighted by the speed, whose ripple
// cancels over the symmetric set: 1 - (2 / pi) arcsin 0.2
TEST(VelocityError, SinusoidalRippleGivesItsClosedForms) {
  const double v = 5.0, amplitude = 0.05, frequency_hz = 2.0;
  const auto speed = [&](double t) {
    return v * (1.0 + amplitude * std::sin(2.0 * kPi * frequency_hz * t));
  };
  const MotionSamples s = printing(
      3.0, v, [](double) { return Vec3::Zero(); }, [&](double t) { return Vec3(0, 0, speed(t)); });
  const VelocityErrorStats e = velocity_error(s);
  EXPECT_NEAR(e.max_rel, amplitude, 1e-9);
  EXPECT_NEAR(e.rms_rel, amplitude / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(e.p95_rel, amplitude * std::sin(0.95 * kPi / 2.0), 1e-5);
  // (each of the 24 crossings of |sin| = 0.2 falls between two samples: at most 24 x 1e-4 s
  // of the 3 s either way)
  EXPECT_NEAR(e.frac_len_over_1pct, 1.0 - 2.0 / kPi * std::asin(0.2), 8e-4);
}

// only depositing samples with a desired speed count: travel moves at any speed and depositing
// samples without a desired speed are left out
TEST(VelocityError, OnlyPrintedSamplesWithADesiredSpeedCount) {
  MotionSamples s;
  for (int k = 0; k <= 100; ++k) {
    const double t = k * 0.01;
    const bool travel = k < 30;
    const bool no_target = k >= 90;
    s.push_back(t, Vec3::Zero(), Vec3(travel ? 40.0 : 3.03, 0, 0), !travel, travel ? -1 : 0,
                travel || no_target ? 0.0 : 3.0);
  }
  const VelocityErrorStats e = velocity_error(s);
  EXPECT_NEAR(e.max_rel, 0.01, 1e-12);
  EXPECT_NEAR(e.rms_rel, 0.01, 1e-12);
  const std::vector<double> r = relative_speed_error(s);
  EXPECT_EQ(r[0], 0.0);
  EXPECT_EQ(r[95], 0.0);
  EXPECT_NEAR(r[50], 0.01, 1e-12);
  // no printed sample at all: zeros
  MotionSamples travel_only;
  travel_only.push_back(0.0, Vec3::Zero(), Vec3(5, 0, 0), false, -1, 0.0);
  travel_only.push_back(0.1, Vec3(0.5, 0, 0), Vec3(5, 0, 0), false, -1, 0.0);
  const VelocityErrorStats none = velocity_error(travel_only);
  EXPECT_EQ(none.max_rel, 0.0);
  EXPECT_EQ(none.rms_rel, 0.0);
  EXPECT_EQ(none.frac_len_over_1pct, 0.0);
}

// a nozzle 0.05 mm to the left of an L-shaped path all along it (inside the corner it is
// 0.05 mm from both legs): max = rms = 0.05 mm
TEST(PathError, ConstantOffsetBesideAPolyline) {
  const Toolpath toolpath = one_path({Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 10, 0)});
  const double offset = 0.05;
  // along the first leg at y = +0.05 up to x = 9.95, then along the second at x = 9.95
  const auto position = [&](double t) {
    const double s = 3.0 * t;  // arc length along the offset path
    return s <= 9.95 ? Vec3(s, offset, 0) : Vec3(10.0 - offset, offset + (s - 9.95), 0);
  };
  const MotionSamples s =
      printing((9.95 + 9.95) / 3.0, 3.0, position, [](double) { return Vec3(3, 0, 0); });
  const PathErrorStats e = path_error(s, toolpath);
  EXPECT_NEAR(e.max_mm, offset, 1e-12);
  EXPECT_NEAR(e.rms_mm, offset, 1e-12);
}

// y = A sin(2 pi x / lambda) across a straight line, x at constant speed over whole waves:
// max A, time-weighted rms A / sqrt 2
TEST(PathError, SinusoidalWobbleAcrossALine) {
  const Toolpath toolpath = one_path({Vec3(-1, 0, 0), Vec3(11, 0, 0)});
  const double amplitude = 0.02, wavelength = 2.5, speed = 2.0;
  const auto position = [&](double t) {
    const double x = speed * t;
    return Vec3(x, amplitude * std::sin(2.0 * kPi * x / wavelength), 0);
  };
  const MotionSamples s =
      printing(10.0 / speed, speed, position, [&](double) { return Vec3(speed, 0, 0); });
  const PathErrorStats e = path_error(s, toolpath);
  EXPECT_NEAR(e.max_mm, amplitude, 1e-9);
  EXPECT_NEAR(e.rms_mm, amplitude / std::sqrt(2.0), 1e-7);
}

// each sample is measured against the path it prints, not the nearest one; transitions and
// samples naming no path of the toolpath are left out
TEST(PathError, EachSampleAgainstItsOwnPath) {
  Toolpath toolpath = one_path({Vec3(0, 0, 0), Vec3(10, 0, 0)});
  toolpath.paths.push_back(one_path({Vec3(0, 1, 0), Vec3(10, 1, 0)}).paths[0]);
  MotionSamples s;
  // printing path 0 while on path 1's line: 1 mm off; travelling far away: not counted
  s.push_back(0.0, Vec3(5, 1, 0), Vec3(3, 0, 0), true, 0, 3.0);
  s.push_back(0.1, Vec3(5.3, 1, 0), Vec3(3, 0, 0), true, 0, 3.0);
  s.push_back(0.2, Vec3(50, 50, 0), Vec3(3, 0, 0), false, -1, 0.0);
  s.push_back(0.3, Vec3(50, 60, 0), Vec3(3, 0, 0), true, 7, 3.0);  // no such path
  const PathErrorStats e = path_error(s, toolpath);
  EXPECT_DOUBLE_EQ(e.max_mm, 1.0);
  EXPECT_DOUBLE_EQ(e.rms_mm, 1.0);
}

// distances to a polyline: perpendicular inside a segment, to the end point beyond it, to the
// nearer leg near a corner, to the point itself for a one-point polyline
TEST(DistanceToPolyline, ClosedForms) {
  const std::vector<Vec3> l_shape = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(4, 3, 0)};
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(2, -1.5, 0), l_shape), 1.5);
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(-3, 4, 0), l_shape), 5.0);  // beyond the start
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(7, 7, 0), l_shape), 5.0);   // beyond the end
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(3, 1, 0), l_shape), 1.0);   // inside the corner
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(2, 0, 2), l_shape), 2.0);   // above it (3-D)
  EXPECT_DOUBLE_EQ(distance_to_polyline(Vec3(5, 3, 0), {Vec3(1, 0, 0)}), 5.0);
}

}  // namespace
}  // namespace depotwin
