// Batched deposition (step_batch.hpp): consecutive steps put down as one quadrature must
// give the same map as every step on its own, keep material exact, read complete through
// field(), and stay deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "deposition/process.hpp"
#include "deposition_test_util.hpp"

namespace depotwin {
namespace {

using test::drive;

constexpr double kSigma = 0.1;
constexpr double kCell = 0.025;  // sigma / 4

DepositionSettings aerosol_settings(double batch_length_sigmas) {
  DepositionSettings settings;
  settings.type = ProcessType::aerosol;
  settings.sigma_mm = kSigma;
  settings.batch_length_sigmas = batch_length_sigmas;
  return settings;
}

auto no_command = [](double) { return 0.0; };

std::string scientific(double value) {
  std::ostringstream out;
  out << std::scientific << std::setprecision(3) << value;
  return out.str();
}

// largest cell difference relative to the unbatched map's peak
double relative_difference(const Process& batched, const Process& unbatched) {
  return test::max_abs_difference(batched.field(), unbatched.field()) /
         test::max_value(unbatched.field());
}

// accelerating from rest along a spiral (curvature rising), the shutter opening and closing
// over 20 ms ramps that start inside a step, then re-opening half way and closing again
auto spiral_position = [](double t) {
  const double angle = 1.5 * t * t;  // angular acceleration 3 rad/s^2 from rest
  const double radius = 2.0 - 0.8 * t;
  return Vec3(radius * std::cos(angle), radius * std::sin(angle), 0.0);
};
auto spiral_open = [](double t) {
  auto ramp = [t](double t0) { return std::min(1.0, std::max(0.0, (t - t0) / 0.02)); };
  return ramp(0.1003) - ramp(0.7007) + 0.5 * ramp(0.9004) - 0.5 * ramp(1.3001);
};

// the acceptance: batched and unbatched agree to 1e-4 of the peak on a curved,
// accelerating motion with shutter ramps, and both land exactly what was emitted
TEST(Batching, AgreesWithUnbatchedOnCurvedAcceleratingMotionWithShutterRamps) {
  AerosolProcess batched(aerosol_settings(1.0), kCell);
  AerosolProcess unbatched(aerosol_settings(0.0), kCell);
  drive(batched, 0.0, 1.5, 1e-3, spiral_position, spiral_open, no_command, no_command);
  drive(unbatched, 0.0, 1.5, 1e-3, spiral_position, spiral_open, no_command, no_command);

  const double relative = relative_difference(batched, unbatched);
  RecordProperty("max_rel_diff_batched_vs_unbatched", scientific(relative));
  EXPECT_LT(relative, 1e-4);

  // material: the same account, and each field holds exactly what landed
  EXPECT_EQ(batched.account().landed_mm3, unbatched.account().landed_mm3);
  EXPECT_EQ(batched.account().captured_mm3, unbatched.account().captured_mm3);
  const double landed = batched.account().landed_mm3;
  EXPECT_NEAR(batched.field().total_volume_mm3(), landed, 1e-12 * landed);
  EXPECT_NEAR(unbatched.field().total_volume_mm3(), landed, 1e-12 * landed);

  // it did batch: ~1300 steps with material, at most one box per sigma of path (plus
  // splits at the ramps' kinks), far fewer boxes than steps
  const StepBatch::Stats& stats = batched.batch_stats();
  RecordProperty("quadratures", std::to_string(stats.quadratures));
  RecordProperty("single_steps", std::to_string(stats.single_steps));
  RecordProperty("splits", std::to_string(stats.splits));
  EXPECT_GT(stats.steps, 1000);
  EXPECT_LT(stats.quadratures + stats.single_steps, stats.steps / 5);
  EXPECT_EQ(unbatched.batch_stats().single_steps, unbatched.batch_stats().steps);
}

// sharp 90 degree corners (a square at 3 mm/s, the velocity turning within one step):
// the moment check must split the batches that straddle a corner
TEST(Batching, AgreesWithUnbatchedAtSharpCorners) {
  auto square = [](double t) {
    const double s = 3.0 * t;  // arc length, 1 mm sides
    const double side = std::floor(s);
    const double f = s - side;
    switch (static_cast<int>(side) % 4) {
      case 0:
        return Vec3(f, 0.0, 0.0);
      case 1:
        return Vec3(1.0, f, 0.0);
      case 2:
        return Vec3(1.0 - f, 1.0, 0.0);
      default:
        return Vec3(0.0, 1.0 - f, 0.0);
    }
  };
  auto always_open = [](double) { return 1.0; };
  AerosolProcess batched(aerosol_settings(1.0), kCell);
  AerosolProcess unbatched(aerosol_settings(0.0), kCell);
  // 1.3 s: corners at s = 1, 2, 3 mm fall inside steps (t = 1/3 s, 2/3 s, 1 s)
  drive(batched, 0.0, 1.3, 1e-3, square, always_open, no_command, no_command);
  drive(unbatched, 0.0, 1.3, 1e-3, square, always_open, no_command, no_command);
  const double relative = relative_difference(batched, unbatched);
  RecordProperty("max_rel_diff_batched_vs_unbatched", scientific(relative));
  EXPECT_LT(relative, 1e-4);
  EXPECT_GT(batched.batch_stats().splits, 0);
}

// extrusion: a lagging flow, the command switching on and off while moving, a speed change
TEST(Batching, AgreesWithUnbatchedForExtrusionLag) {
  DepositionSettings settings;
  settings.type = ProcessType::extrusion;
  settings.tau_s = 0.05;
  auto position = [](double t) {
    const double x = t < 1.0 ? 5.0 * t : 5.0 + 2.0 * (t - 1.0);  // 5 mm/s, then 2 mm/s
    return Vec3(x, 0.3 * std::sin(x), 0.0);
  };
  auto command = [](double t) { return (t > 0.2 && t < 0.8) || t > 1.1 ? 1.0 : 0.0; };
  auto speed = [](double t) { return t < 1.0 ? 5.0 : 2.0; };
  auto closed = [](double) { return 0.0; };
  settings.batch_length_sigmas = 1.0;
  ExtrusionProcess batched(settings, 0.0);
  settings.batch_length_sigmas = 0.0;
  ExtrusionProcess unbatched(settings, 0.0);
  drive(batched, 0.0, 1.6, 1e-3, position, closed, command, speed);
  drive(unbatched, 0.0, 1.6, 1e-3, position, closed, command, speed);
  const double relative = relative_difference(batched, unbatched);
  RecordProperty("max_rel_diff_batched_vs_unbatched", scientific(relative));
  EXPECT_LT(relative, 1e-4);
  const double landed = batched.account().landed_mm3;
  EXPECT_NEAR(batched.field().total_volume_mm3(), landed, 1e-12 * landed);
  EXPECT_LT(batched.batch_stats().quadratures, batched.batch_stats().steps / 5);
}

// a tight circle (radius 3 sigma) at chords of `step_sigmas` sigma, the shutter closing and
// reopening part way: the curvature keeps the moments of a batch apart, so batches halve
// down to single steps (as on a prediction's slowed blend)
void drive_tight_circle(Process& process, double step_sigmas) {
  const double radius_mm = 3.0 * kSigma, speed_mm_s = 3.0;
  const double dt = step_sigmas * kSigma / speed_mm_s;
  auto circle = [&](double t) {
    const double angle = speed_mm_s * t / radius_mm;
    return Vec3(radius_mm * std::cos(angle), radius_mm * std::sin(angle), 0.0);
  };
  auto open = [&](double t) {
    const double u = t / (60 * dt);
    return std::clamp(std::abs(u - 0.5) * 8.0 - 0.5, 0.0, 1.0);
  };
  drive(process, 0.0, 60 * dt, dt, circle, open, no_command, no_command);
}

// paired steps (the corner predictions' quadrature): where a failed batch comes down to two
// short steps they go down in one 4-node call, 2 nodes per chord, within 5.6e-6 of a step's
// peak of the exact chords; the map agrees with every step on its own, holds exactly what
// landed, and takes fewer footprint calls than unpaired batching of the same steps
TEST(Batching, PairedStepsAgreeWithUnbatchedInFewerCalls) {
  AerosolProcess paired(aerosol_settings(2.0), kCell);
  paired.pair_short_steps(true);
  AerosolProcess unpaired(aerosol_settings(2.0), kCell);
  AerosolProcess unbatched(aerosol_settings(0.0), kCell);
  drive_tight_circle(paired, 0.25);
  drive_tight_circle(unpaired, 0.25);
  drive_tight_circle(unbatched, 0.25);

  const double relative = relative_difference(paired, unbatched);
  RecordProperty("max_rel_diff_paired_vs_unbatched", scientific(relative));
  RecordProperty("max_rel_diff_unpaired_vs_unbatched",
                 scientific(relative_difference(unpaired, unbatched)));
  EXPECT_LT(relative, 1e-5);
  const double landed = paired.account().landed_mm3;
  EXPECT_EQ(landed, unbatched.account().landed_mm3);
  EXPECT_NEAR(paired.field().total_volume_mm3(), landed, 1e-12 * landed);

  // a footprint call per quadrature, per single step, per pair
  const auto calls = [](const StepBatch::Stats& s) {
    return s.quadratures + s.single_steps + s.paired_steps / 2;
  };
  const StepBatch::Stats& stats = paired.batch_stats();
  RecordProperty("paired_steps", std::to_string(stats.paired_steps));
  RecordProperty("calls_paired", std::to_string(calls(stats)));
  RecordProperty("calls_unpaired", std::to_string(calls(unpaired.batch_stats())));
  EXPECT_GT(stats.paired_steps, 0);
  EXPECT_EQ(unpaired.batch_stats().paired_steps, 0);
  EXPECT_LT(calls(stats), calls(unpaired.batch_stats()));
}

// steps longer than kPairChordSigmas (0.3) are never paired: at 0.4 sigma a step the halved
// batches come down to single steps, each deposited exactly on its own
TEST(Batching, LongStepsAreNotPaired) {
  AerosolProcess paired(aerosol_settings(2.0), kCell);
  paired.pair_short_steps(true);
  AerosolProcess unbatched(aerosol_settings(0.0), kCell);
  drive_tight_circle(paired, 0.4);
  drive_tight_circle(unbatched, 0.4);
  EXPECT_EQ(paired.batch_stats().paired_steps, 0);
  EXPECT_GT(paired.batch_stats().single_steps, 0);
  EXPECT_LT(relative_difference(paired, unbatched), 1e-4);
}

// field() puts the pending steps down before it answers: a read after any step is
// complete, and flush() makes no further change
TEST(Batching, FieldReadsAreCompleteWhilePending) {
  AerosolProcess process(aerosol_settings(1.0), kCell);
  auto position = [](double t) { return Vec3(3.0 * t, 0.0, 0.0); };
  auto always_open = [](double) { return 1.0; };
  drive(process, 0.0, 0.0137, 1e-3, position, always_open, no_command, no_command);
  EXPECT_GT(process.batch_stats().steps, 0);  // 14 steps of 3 um: still one pending batch
  const double landed = process.account().landed_mm3;
  EXPECT_NEAR(landed, process.nozzle_flow_mm3_s() * 0.014, 1e-15);
  EXPECT_NEAR(process.field().total_volume_mm3(), landed, 1e-12 * landed);
  const double peak_after_read = test::max_value(process.field());
  process.flush();
  EXPECT_EQ(test::max_value(process.field()), peak_after_read);
}

// same steps -> identical field, bit for bit; reading the field midway only moves batch
// boundaries, within the batching tolerance
TEST(Batching, DeterministicAndReadPatternOnlyMovesBoundaries) {
  AerosolProcess first(aerosol_settings(1.0), kCell);
  AerosolProcess second(aerosol_settings(1.0), kCell);
  AerosolProcess read_midway(aerosol_settings(1.0), kCell);
  drive(first, 0.0, 1.5, 1e-3, spiral_position, spiral_open, no_command, no_command);
  drive(second, 0.0, 1.5, 1e-3, spiral_position, spiral_open, no_command, no_command);
  EXPECT_EQ(test::max_abs_difference(first.field(), second.field()), 0.0);

  drive(read_midway, 0.0, 0.7, 1e-3, spiral_position, spiral_open, no_command, no_command);
  EXPECT_GT(read_midway.field().total_volume_mm3(), 0.0);
  drive(read_midway, 0.7, 1.5, 1e-3, spiral_position, spiral_open, no_command, no_command);
  EXPECT_LT(relative_difference(read_midway, first), 1e-4);
}

// the footprint is continuous in the node position, also where a cell crosses the
// truncation radius (5 sigma): there it carries half the Gaussian's value (the taper's
// midpoint) on either side, where a hard cut would jump by the whole exp(-12.5)
TEST(Footprint, ContinuousInNodePositionAtTheTruncationRadius) {
  GaussianFootprint footprint(kSigma, kCell, 5.0);
  ThicknessField inside(kCell), outside(kCell);
  const double edge_mm = 5.0 * kSigma;  // cell 0 sits exactly 5 sigma from a node here
  const FootprintNode near_node{edge_mm - 1e-9, 0.0, 1e-3};
  const FootprintNode far_node{edge_mm + 1e-9, 0.0, 1e-3};
  footprint.deposit_nodes(inside, &near_node, 1);
  footprint.deposit_nodes(outside, &far_node, 1);
  const double peak = test::max_value(inside);
  EXPECT_LT(test::max_abs_difference(inside, outside) / peak, 1e-7);
  EXPECT_NEAR(inside.cell_thickness_mm(0, 0) / peak, 0.5 * std::exp(-12.5), 1e-3 * std::exp(-12.5));
  // nothing from 5.25 sigma on (cell -1 is that far from the far node), and exactly the
  // node's volume
  EXPECT_EQ(outside.cell_thickness_mm(-1, 0), 0.0);
  EXPECT_LT(inside.cell_thickness_mm(-1, 0) / peak, 1e-20);
  EXPECT_NEAR(inside.total_volume_mm3(), 1e-3, 1e-15);
}

// a field limited to a region (ThicknessField::limit_writes): its cells hold exactly what an
// unlimited field's do, every other cell nothing; a deposit wholly outside touches no tile
TEST(Footprint, WriteRegionKeepsItsCellsExactAndSkipsTheRest) {
  GaussianFootprint footprint(kSigma, kCell, 5.0, 2.0);
  ThicknessField everywhere(kCell), limited(kCell);
  // a band of rows 3..10, each from a column that moves with the row (a slanted strip)
  ThicknessField::WriteRegion region;
  region.iy_lo = 3;
  for (int iy = 3; iy <= 10; ++iy) region.spans.push_back({iy - 8, iy + 2});
  region.spans[4] = {1, 0};  // row 7: no cell
  limited.limit_writes(region);
  // 1-, 3- and 4-node groups across the band and beside it
  const FootprintNode nodes[4] = {
      {0.05, 0.12, 1e-3}, {0.07, 0.15, 2e-3}, {0.09, 0.19, 1e-3}, {0.11, 0.21, 5e-4}};
  for (const int count : {1, 3, 4}) {
    footprint.deposit_nodes(everywhere, nodes, count);
    footprint.deposit_nodes(limited, nodes, count);
  }
  int inside = 0;
  for (int iy = -30; iy <= 40; ++iy)
    for (int ix = -40; ix <= 40; ++ix) {
      const bool in_region = iy >= 3 && iy <= 10 && ix >= region.spans[iy - 3].first &&
                             ix <= region.spans[iy - 3].second;
      if (in_region) {
        ++inside;
        ASSERT_EQ(limited.cell_thickness_mm(ix, iy), everywhere.cell_thickness_mm(ix, iy))
            << ix << ", " << iy;
        EXPECT_GT(limited.cell_thickness_mm(ix, iy), 0.0) << ix << ", " << iy;
      } else {
        ASSERT_EQ(limited.cell_thickness_mm(ix, iy), 0.0) << ix << ", " << iy;
      }
    }
  EXPECT_EQ(inside, 7 * 11);
  // (so it holds only part of the material)
  EXPECT_GT(limited.total_volume_mm3(), 0.0);
  EXPECT_LT(limited.total_volume_mm3(), 0.9 * everywhere.total_volume_mm3());
  // nodes 2 mm away: their box misses the band, no tile is made
  const size_t tiles = limited.allocated_tiles();
  const FootprintNode far_node{2.0, 2.0, 1e-3};
  footprint.deposit_nodes(limited, &far_node, 1);
  EXPECT_EQ(limited.allocated_tiles(), tiles);
  // writing everywhere again: the far node lands whole
  limited.write_everywhere();
  footprint.deposit_nodes(limited, &far_node, 1);
  EXPECT_GT(limited.allocated_tiles(), tiles);
}

TEST(Batching, BadBatchLengthIsInputError) {
  EXPECT_THROW(make_process(aerosol_settings(-1.0)), InputError);
  EXPECT_THROW(make_process(aerosol_settings(3.0)), InputError);
}

}  // namespace
}  // namespace depotwin
