// The shutter: the blade reference (pure) and the simulated blade on the XY stage.
// Invariant (sim/shutter.hpp): opening over [t1 - T, t1], closing over [t2 - T, t2], so the
// closed time equals the planned transition time.
#include <gtest/gtest.h>

#include <cmath>

#include "kinematics/xy_stage.hpp"
#include "sim/shutter.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace depotwin {
namespace {

using testing_util::straight_print;
using testing_util::xy_stage_model;

// a trajectory that only carries depositing flags (motion at rest)
Trajectory flags_only(const std::vector<std::pair<double, bool>>& pieces) {
  std::vector<TrajectoryPiece> list;
  double t = 0.0;
  for (const auto& [duration, depositing] : pieces) {
    TrajectoryPiece piece;
    piece.t_begin_s = t;
    piece.t_end_s = t + duration;
    piece.depositing = depositing;
    piece.path_index = depositing ? 0 : -1;
    piece.motion = PhaseMotion{};
    list.push_back(piece);
    t += duration;
  }
  return Trajectory("flags", list);
}

TEST(ShutterReference, RampsAcrossTheBlockingTravelBeforeEachEdge) {
  // print over [1, 2] s; T = 20 ms, overtravel 0.5
  const Trajectory trajectory = flags_only({{1.0, false}, {1.0, true}, {1.0, false}});
  const ShutterReference reference(trajectory, 0.02, 0.5);
  double r = 0.0, rate = 0.0;
  // at rest, closed: -e
  reference.at(0.5, r, rate);
  EXPECT_DOUBLE_EQ(r, -0.5);
  EXPECT_DOUBLE_EQ(rate, 0.0);
  // the lead-in starts at t1 - (1 + e) T = 0.97 s; at 0.975: window [0.965, 1.005]
  reference.at(0.975, r, rate);
  EXPECT_NEAR(r, -0.25, 1e-12);
  EXPECT_DOUBLE_EQ(rate, 50.0);
  // blocking travel crossed over [t1 - T, t1]
  EXPECT_NEAR(reference.open_fraction(0.98), 0.0, 1e-12);
  EXPECT_NEAR(reference.open_fraction(0.99), 0.5, 1e-12);
  EXPECT_NEAR(reference.open_fraction(1.0), 1.0, 1e-12);
  reference.at(1.5, r, rate);
  EXPECT_NEAR(r, 1.5, 1e-12);
  // closing over [t2 - T, t2]
  EXPECT_NEAR(reference.open_fraction(1.98), 1.0, 1e-12);
  EXPECT_NEAR(reference.open_fraction(1.99), 0.5, 1e-12);
  EXPECT_NEAR(reference.open_fraction(2.0), 0.0, 1e-12);
  reference.at(1.995, r, rate);
  EXPECT_DOUBLE_EQ(rate, -50.0);
}

TEST(ShutterReference, OpenIntegralEqualsTheDepositingTime) {
  // two prints (0.4 s and 0.25 s) with a 0.3 s gap, touching depositing pieces merged
  const Trajectory trajectory = flags_only(
      {{0.2, false}, {0.15, true}, {0.25, true}, {0.3, false}, {0.25, true}, {0.3, false}});
  const ShutterReference reference(trajectory, 0.02, 0.5);
  ASSERT_EQ(reference.depositing_intervals().size(), 2u);
  EXPECT_NEAR(reference.depositing_intervals()[0].second, 0.6, 1e-12);
  // the open fraction is piecewise linear with corners on this grid: trapezoids are exact
  const double h = 1e-4;
  double integral = 0.0;
  for (int k = 0; k < 14500; ++k)
    integral += 0.5 * h * (reference.open_fraction(k * h) + reference.open_fraction((k + 1) * h));
  EXPECT_NEAR(integral, trajectory.depositing_time_s(), 1e-9);
}

TEST(ShutterReference, AGapShorterThanTheBladeTimePlusOvertravelClosesPartly) {
  // in a gap g < (1 + e) T the blade turns back early: least open fraction 1 + e - g / T
  for (const double gap_s : {0.01, 0.02, 0.025, 0.03}) {
    const Trajectory trajectory =
        flags_only({{0.2, false}, {0.2, true}, {gap_s, false}, {0.2, true}, {0.2, false}});
    const ShutterReference reference(trajectory, 0.02, 0.5);
    double least = 1.0;
    for (int k = 0; k <= 1000; ++k)
      least = std::min(least, reference.open_fraction(0.35 + k * 1e-4));
    EXPECT_NEAR(least, std::clamp(1.5 - gap_s / 0.02, 0.0, 1.0), 1e-9) << "gap " << gap_s;
  }
}

TEST(ShutterGeometry, OpenFractionIsLinearOverTheTravel) {
  ShutterGeometry geometry;
  geometry.closed_angle_rad = 0.0;
  geometry.open_angle_rad = deg_to_rad(60.0);
  EXPECT_DOUBLE_EQ(shutter_open_fraction(deg_to_rad(-30.0), geometry), 0.0);
  EXPECT_DOUBLE_EQ(shutter_open_fraction(0.0, geometry), 0.0);
  EXPECT_NEAR(shutter_open_fraction(deg_to_rad(15.0), geometry), 0.25, 1e-12);
  EXPECT_NEAR(shutter_open_fraction(deg_to_rad(45.0), geometry), 0.75, 1e-12);
  EXPECT_DOUBLE_EQ(shutter_open_fraction(deg_to_rad(90.0), geometry), 1.0);
}

// the simulated blade over a straight print [t1, t2]
struct BladeRun {
  RecordedRun run;
  double t1 = 0.0, t2 = 0.0, blade_s = 0.0;
};

BladeRun blade_run(double shutter_time_s) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(-3, 2, 0), Vec3(1, -1, 0), 3.0, 4.0, MachineLimits::uniform(4.0, 30.0));
  SimSettings settings;
  settings.settle_s = 0.1;
  settings.shutter_time_s = shutter_time_s;
  Simulation simulation(xy_stage_model(), *machine, settings);
  EXPECT_TRUE(simulation.has_shutter());
  BladeRun result{simulation.run(print.trajectory), print.print_begin_s, print.print_end_s,
                  simulation.shutter_time_s()};
  return result;
}

TEST(Shutter, ClosedTimeEqualsTheRunMinusThePrintAndTheBladeIsOpenWhilePrinting) {
  const BladeRun blade = blade_run(0.0);  // the model's own time
  const RecordedRun& run = blade.run;
  EXPECT_DOUBLE_EQ(blade.blade_s, 0.02);
  // integral of (1 - open fraction) over the whole run (trapezoids on the step grid)
  double closed_s = 0.0;
  for (size_t k = 0; k + 1 < run.size(); ++k)
    closed_s +=
        0.5 * run.timestep_s * ((1.0 - run.open_fraction[k]) + (1.0 - run.open_fraction[k + 1]));
  const double run_s = run.t_s.back();
  std::printf("closed time %.6f s, run %.6f s - print %.6f s = %.6f s\n", closed_s, run_s,
              blade.t2 - blade.t1, run_s - (blade.t2 - blade.t1));
  EXPECT_NEAR(closed_s, run_s - (blade.t2 - blade.t1), 1e-3);

  // fully open from the first printed point until the closing ramp [t2 - T, t2];
  // fully closed before the opening ramp [t1 - T, t1] and after t2
  int open_violations = 0, closed_violations = 0;
  for (size_t k = 0; k < run.size(); ++k) {
    const double t = run.t_s[k];
    if (t >= blade.t1 && t <= blade.t2 - blade.blade_s && run.open_fraction[k] != 1.0f)
      ++open_violations;
    if ((t <= blade.t1 - blade.blade_s || t >= blade.t2) && run.open_fraction[k] != 0.0f)
      ++closed_violations;
  }
  EXPECT_EQ(open_violations, 0);
  EXPECT_EQ(closed_violations, 0);
  // half open in the middle of each ramp (the blade follows its ramp to a few percent)
  const size_t opening_mid = static_cast<size_t>(std::lround((blade.t1 - 0.01) / run.timestep_s));
  const size_t closing_mid = static_cast<size_t>(std::lround((blade.t2 - 0.01) / run.timestep_s));
  const double opening_expected = 1.0 - (blade.t1 - run.t_s[opening_mid]) / 0.02;
  const double closing_expected = (blade.t2 - run.t_s[closing_mid]) / 0.02;
  EXPECT_NEAR(run.open_fraction[opening_mid], opening_expected, 0.03);
  EXPECT_NEAR(run.open_fraction[closing_mid], closing_expected, 0.03);
}

TEST(Shutter, ASlowerBladeFromTheSettingsKeepsTheInvariant) {
  const BladeRun blade = blade_run(0.05);
  const RecordedRun& run = blade.run;
  EXPECT_DOUBLE_EQ(blade.blade_s, 0.05);
  double closed_s = 0.0;
  for (size_t k = 0; k + 1 < run.size(); ++k)
    closed_s +=
        0.5 * run.timestep_s * ((1.0 - run.open_fraction[k]) + (1.0 - run.open_fraction[k + 1]));
  EXPECT_NEAR(closed_s, run.t_s.back() - (blade.t2 - blade.t1), 1e-3);
  // 25 ms before printing the 50 ms ramp is half way
  const size_t k = static_cast<size_t>(std::lround((blade.t1 - 0.025) / run.timestep_s));
  EXPECT_NEAR(run.open_fraction[k], 1.0 - (blade.t1 - run.t_s[k]) / 0.05, 0.03);
}

}  // namespace
}  // namespace depotwin
