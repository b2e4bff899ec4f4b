// Deposition metrics: target region geometry, end zones, thickness statistics and the
// material split, on hand-built fields with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "deposition/deposition_metrics.hpp"
#include "deposition_test_util.hpp"

namespace depotwin {
namespace {

constexpr double kCell = 0.025;

// brute-force distance from a point to a polyline (xy)
double distance_to_polyline(const PrintPath& path, double x, double y) {
  double best = 1e300;
  for (size_t k = 0; k + 1 < path.points.size(); ++k) {
    const Eigen::Vector2d a = path.points[k].head<2>(), b = path.points[k + 1].head<2>();
    const Eigen::Vector2d p(x, y);
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (a + t * (b - a))).norm());
  }
  return best;
}

// the row-interval rasteriser finds exactly the lattice points within r of the path
TEST(TargetRegion, MatchesBruteForceOnAPolylineWithCorners) {
  Toolpath toolpath;
  PrintPath path;
  path.points = {Vec3(0.013, 0.021, 0), Vec3(1.511, 0.402, 0), Vec3(0.9, 1.7, 0),
                 Vec3(0.9, 2.3, 0)};
  toolpath.paths.push_back(path);
  const double width = 0.4, r = 0.2;
  const TargetRegion region(toolpath, width, kCell);
  size_t expected = 0;
  size_t mismatches = 0;
  for (int iy = -20; iy <= 110; ++iy) {
    for (int ix = -20; ix <= 80; ++ix) {
      const double d = distance_to_polyline(path, ix * kCell, iy * kCell);
      if (std::abs(d - r) < 1e-9) continue;  // on the boundary: either answer is fine
      const bool inside = d < r;
      expected += inside ? 1 : 0;
      mismatches += inside != region.in_target(ix, iy) ? 1 : 0;
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_GT(expected, 1000u);
}

// straight on-lattice line: target = 17 rows x (401 columns + caps), stats = 17 x 385
TEST(TargetRegion, EndZonesRemoveOneHalfWidthAtEachEnd) {
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 10.0, 0.0, 3.0);
  const TargetRegion region(toolpath, 0.4, kCell);
  size_t stats_cells = 0, band_cells = 0;
  for (int iy = -10; iy <= 10; ++iy) {
    for (int ix = -10; ix <= 410; ++ix) {
      stats_cells += region.in_stats(ix, iy) ? 1 : 0;
      band_cells += (region.in_target(ix, iy) && ix >= 0 && ix <= 400) ? 1 : 0;
    }
  }
  EXPECT_EQ(band_cells, 17u * 401u);
  EXPECT_EQ(stats_cells, 17u * 385u);
  // the caps: lattice points with i >= 1 and i^2 + j^2 <= 64, twice
  size_t cap = 0;
  for (int i = 1; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j) cap += (i * i + j * j <= 64) ? 1 : 0;
  EXPECT_EQ(region.target_cells(), 17u * 401u + 2 * cap);
}

// a cell's share of the band: its 8 x 8 sub-points within r (a row exactly r from the line:
// half); two bands that touch fill their shared row, two that overlap count once
TEST(TargetRegion, ACellSharesInTheBandByItsSubPointsAndBandsCountOnce) {
  const TargetRegion one(test::straight_toolpath(0.0, 0.0, 10.0, 0.0, 3.0), 0.4, kCell);
  EXPECT_EQ(one.weight(40, 0), 1.0);
  EXPECT_EQ(one.weight(40, 7), 1.0);
  EXPECT_EQ(one.weight(40, 8), 0.5);
  EXPECT_EQ(one.weight(40, 9), 0.0);
  EXPECT_EQ(one.weight(40, -8), 0.5);
  // half a cell off: the band covers 16 rows whole
  const TargetRegion off(test::straight_toolpath(0.0, 0.5 * kCell, 10.0, 0.5 * kCell, 3.0), 0.4,
                         kCell);
  EXPECT_EQ(off.weight(40, 8), 1.0);
  EXPECT_EQ(off.weight(40, 9), 0.0);
  EXPECT_EQ(off.weight(40, -7), 1.0);
  EXPECT_EQ(off.weight(40, -8), 0.0);
  for (const double second_y : {0.4, 0.1}) {
    Toolpath two = test::straight_toolpath(0.0, 0.0, 10.0, 0.0, 3.0);
    two.paths.push_back(test::straight_toolpath(0.0, second_y, 10.0, second_y, 3.0).paths[0]);
    const TargetRegion both(two, 0.4, kCell);
    EXPECT_EQ(both.weight(40, 8), 1.0) << second_y;
    EXPECT_EQ(both.weight(40, -8), 0.5) << second_y;
  }
}

// known field: 1 um below the centreline, 2 um on and above it, a gap of zero cells inside
// the band (its two outer rows on either side kept)
TEST(ThicknessStats, MeanCvMinMaxOfAKnownField) {
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 10.0, 0.0, 3.0);
  ThicknessField field(kCell);
  for (int iy = -8; iy <= 8; ++iy)
    for (int ix = -8; ix <= 408; ++ix)
      if (!(ix >= 100 && ix < 105 && std::abs(iy) < 7))
        field.add_to_cell(ix, iy, iy < 0 ? 1e-3 : 2e-3);
  const TargetRegion region(toolpath, 0.4, kCell);
  const ThicknessStats stats = thickness_stats(field, region, toolpath);
  ASSERT_EQ(stats.cells, 17u * 385u);
  // per stats column: 8 cells of 1 um, 9 of 2 um, the two exactly r from the centreline (rows
  // -8 and 8) half in the band: weights 7.5 of 1 um and 8.5 of 2 um (their inner halves read
  // between rows of the same value); 5 columns empty but for rows -8, -7, 7 and 8
  const double n = 16.0 * 385.0;
  const double sum = 380.0 * (7.5 * 1.0 + 8.5 * 2.0) + 5.0 * (1.5 * 1.0 + 1.5 * 2.0);
  const double squares = 380.0 * (7.5 * 1.0 + 8.5 * 4.0) + 5.0 * (1.5 * 1.0 + 1.5 * 4.0);
  const double mean = sum / n;
  EXPECT_NEAR(stats.mean_um, mean, 1e-9);
  EXPECT_NEAR(stats.cv, std::sqrt(squares / n - mean * mean) / mean, 1e-9);
  EXPECT_NEAR(stats.min_rel, 0.0, 1e-12);
  EXPECT_NEAR(stats.max_rel, 2.0 / mean, 1e-9);
  // centreline (row 0 = 2 um) sampled on cell centres: 380 of 385 samples at 2 um
  ASSERT_EQ(stats.line_samples, 385u);
  const double line_mean = 2.0 * 380.0 / 385.0;
  const double line_sq = 4.0 * 380.0 / 385.0;
  EXPECT_NEAR(stats.line_cv, std::sqrt(line_sq - line_mean * line_mean) / line_mean, 1e-9);
}

// A Gaussian line's cross-section, t = exp(-y^2 / 2 sigma^2) sampled at the cell centres
// (sigma = 0.1 mm, r = 0.2 mm = 2 sigma), laid on the lattice and between its rows: the mean,
// cv and overspray are the band's closed forms wherever the line falls. Before, a line on
// the lattice counted the two rows exactly r away whole (a band of r + h/2): its mean read
// 4.7 % low, its cv 9.5 % high and its overspray 27 % low against the closed forms.
TEST(ThicknessStats, AGaussianLineScoresAlikeWhereverItFallsOnTheLattice) {
  const double sigma = 0.1, r = 0.2;
  // over the band |y| <= r: mean of t, mean of t^2, and the share of t outside it
  const double mean_t =
      sigma * std::sqrt(2.0 * M_PI) * std::erf(r / (sigma * std::sqrt(2.0))) / (2.0 * r);
  const double mean_t2 = sigma * std::sqrt(M_PI) * std::erf(r / sigma) / (2.0 * r);
  const double cv = std::sqrt(mean_t2 / (mean_t * mean_t) - 1.0);
  const double overspray = 1.0 - std::erf(r / (sigma * std::sqrt(2.0)));
  std::vector<double> means, cvs, oversprays;
  for (const double offset : {0.0, 0.25 * kCell, 0.5 * kCell, 0.75 * kCell}) {
    SCOPED_TRACE(offset);
    const Toolpath toolpath = test::straight_toolpath(0.0, offset, 10.0, offset, 3.0);
    ThicknessField field(kCell);
    double landed = 0.0;
    for (int iy = -40; iy <= 40; ++iy) {
      const double y = iy * kCell - offset;
      const double t = 1e-3 * std::exp(-y * y / (2.0 * sigma * sigma));
      for (int ix = 0; ix <= 400; ++ix) field.add_to_cell(ix, iy, t);
      landed += 401.0 * t;
    }
    MaterialAccount account;
    account.emitted_mm3 = account.landed_mm3 = landed * kCell * kCell;
    const DepositionMetrics metrics = evaluate_deposition(field, toolpath, 2.0 * r, account);
    // (cell-centre samples of a smooth profile: the mean within 0.2 % of the integral, the cv
    // within 0.5 %, the overspray within 1.5 %)
    EXPECT_NEAR(metrics.thickness.mean_um, mean_t, 2e-3 * mean_t);
    EXPECT_NEAR(metrics.thickness.cv, cv, 5e-3 * cv);
    EXPECT_NEAR(metrics.material.overspray_mm3 / account.emitted_mm3, overspray,
                1.5e-2 * overspray);
    means.push_back(metrics.thickness.mean_um);
    cvs.push_back(metrics.thickness.cv);
    oversprays.push_back(metrics.material.overspray_mm3 / account.emitted_mm3);
  }
  // and alike wherever the line falls: within 0.2 % of one another
  for (const std::vector<double>* scores : {&means, &cvs, &oversprays}) {
    const auto [lo, hi] = std::minmax_element(scores->begin(), scores->end());
    EXPECT_LT(*hi - *lo, 2e-3 * *hi);
  }
}

TEST(ThicknessStats, UniformFieldHasZeroSpread) {
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 5.0, 0.0, 3.0);
  ThicknessField field(kCell);
  for (int iy = -20; iy <= 20; ++iy)
    for (int ix = -20; ix <= 220; ++ix) field.add_to_cell(ix, iy, 1.5e-3);
  const DepositionMetrics metrics = evaluate_deposition(field, toolpath, 0.4, MaterialAccount{});
  EXPECT_NEAR(metrics.thickness.mean_um, 1.5, 1e-12);
  EXPECT_NEAR(metrics.thickness.cv, 0.0, 1e-12);
  EXPECT_NEAR(metrics.thickness.line_cv, 0.0, 1e-12);
  EXPECT_NEAR(metrics.thickness.min_rel, 1.0, 1e-12);
  EXPECT_NEAR(metrics.thickness.max_rel, 1.0, 1e-12);
  // a line narrower than a cell, between two rows of cell centres (line width 0.8 h): no cell
  // centre lies in its band, yet cells share in it (before: every score 0)
  const Toolpath narrow = test::straight_toolpath(0.0, 0.5 * kCell, 5.0, 0.5 * kCell, 3.0);
  const DepositionMetrics between = evaluate_deposition(field, narrow, 0.8 * kCell, {});
  EXPECT_GT(between.thickness.cells, 0u);
  EXPECT_NEAR(between.thickness.mean_um, 1.5, 1e-12);
  EXPECT_NEAR(between.thickness.cv, 0.0, 1e-12);
  EXPECT_NEAR(between.thickness.min_rel, 1.0, 1e-12);
  EXPECT_NEAR(between.thickness.max_rel, 1.0, 1e-12);
}

// on_target / overspray by cell, captured and emitted from the account
TEST(MaterialSplit, SplitsLandedMaterialByTargetRegion) {
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 5.0, 0.0, 3.0);
  ThicknessField field(kCell);
  field.add_to_cell(40, 0, 2.0);  // on the centreline
  // a 3 x 3 block of 3 across the band's edge: row 7 inside, row 8 exactly half a width away
  // (half of each cell in the band, and half its material: the field is even across it),
  // row 9 outside
  for (int ix = 39; ix <= 41; ++ix)
    for (int iy = 7; iy <= 9; ++iy) field.add_to_cell(ix, iy, 3.0);
  field.add_to_cell(-300, 0, 7.0);  // far away
  const double area = kCell * kCell;
  MaterialAccount account;
  account.landed_mm3 = 36.0 * area;
  account.captured_mm3 = 3.0 * area;
  account.emitted_mm3 = 39.0 * area;
  account.closed_time_s = 0.25;
  const MaterialSplit split = evaluate_deposition(field, toolpath, 0.4, account).material;
  EXPECT_NEAR(split.on_target_mm3, (2.0 + 9.0 + 4.5) * area, 1e-12);
  EXPECT_NEAR(split.overspray_mm3, (4.5 + 9.0 + 7.0) * area, 1e-12);
  EXPECT_DOUBLE_EQ(split.captured_mm3, 3.0 * area);
  EXPECT_DOUBLE_EQ(split.emitted_mm3, 39.0 * area);
  EXPECT_NEAR(split.fraction, 23.5 / 39.0, 1e-12);
  EXPECT_DOUBLE_EQ(split.closed_time_s, 0.25);
}

// a field of the known one's pattern scaled to denormal thicknesses (a flow of 1e-320 mm3/s)
// keeps its spread: the squares of the differences once underflowed to a cv of 0
TEST(ThicknessStats, ATinyFieldKeepsItsSpread) {
  const Toolpath toolpath = test::straight_toolpath(0.0, 0.0, 10.0, 0.0, 3.0);
  ThicknessField field(kCell), tiny(kCell);
  for (int iy = -8; iy <= 8; ++iy)
    for (int ix = -8; ix <= 408; ++ix) {
      field.add_to_cell(ix, iy, iy < 0 ? 1e-3 : 2e-3);
      tiny.add_to_cell(ix, iy, iy < 0 ? 1e-310 : 2e-310);
    }
  const TargetRegion region(toolpath, 0.4, kCell);
  const ThicknessStats stats = thickness_stats(field, region, toolpath);
  const ThicknessStats tiny_stats = thickness_stats(tiny, region, toolpath);
  ASSERT_GT(stats.cv, 0.3);
  EXPECT_NEAR(tiny_stats.cv, stats.cv, 1e-6 * stats.cv);
  EXPECT_NEAR(tiny_stats.min_rel, stats.min_rel, 1e-6);
  EXPECT_NEAR(tiny_stats.max_rel, stats.max_rel, 1e-6);
}

TEST(ThicknessStats, EmptyToolpathGivesZeros) {
  ThicknessField field(kCell);
  field.add_to_cell(0, 0, 1.0);
  const DepositionMetrics metrics = evaluate_deposition(field, Toolpath{}, 0.4, MaterialAccount{});
  EXPECT_EQ(metrics.thickness.cells, 0u);
  EXPECT_EQ(metrics.thickness.mean_um, 0.0);
  EXPECT_EQ(metrics.thickness.line_cv, 0.0);
  EXPECT_EQ(metrics.material.fraction, 0.0);
}

}  // namespace
}  // namespace depotwin
