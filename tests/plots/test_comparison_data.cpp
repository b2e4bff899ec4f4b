// The comparison sheet's data: the zoom window on the thickest spot and its crop, the print
// order's travels and 0-based path numbers, orders comparisons told apart; the target note;
// the shared colour scale.
#include <gtest/gtest.h>

#include "plots/plots.hpp"

namespace depotwin {
namespace {

// a 40 x 20 map of 0.5 mm cells from (-10, 0), zero but for a spot at cell (30, 15)
HeightMap spotted_map(float spot_um) {
  HeightMap map;
  map.origin_x_mm = -10.0;
  map.origin_y_mm = 0.0;
  map.cell_mm = 0.5;
  map.nx = 40;
  map.ny = 20;
  map.thickness_um.assign(800, 1.0f);
  map.thickness_um[15 * 40 + 30] = spot_um;
  return map;
}

TEST(ComparisonZoom, WindowCentresOnTheThickestCellOfAllMaps) {
  const HeightMap a = spotted_map(3.0f), b = spotted_map(5.0f);
  const plots::ZoomWindow w = plots::thickest_spot_window({&a, &b});
  ASSERT_TRUE(w.found);
  EXPECT_FLOAT_EQ(static_cast<float>(w.peak_um), 5.0f);
  EXPECT_DOUBLE_EQ(w.centre_x_mm, -10.0 + 30 * 0.5);
  EXPECT_DOUBLE_EQ(w.centre_y_mm, 15 * 0.5);
  // a side of max(extent / 8, 24 cells) = max(20 / 8, 12) mm, at most the shorter extent
  // (10 mm: the map spans x -10.25 .. 9.75, y -0.25 .. 9.75), kept inside the maps
  EXPECT_DOUBLE_EQ(w.x_hi - w.x_lo, 10.0);
  EXPECT_DOUBLE_EQ(w.x_lo, -0.25);
  EXPECT_DOUBLE_EQ(w.y_lo, -0.25);
  EXPECT_DOUBLE_EQ(w.y_hi, 9.75);
  // the crop: the cells whose centres lie inside, at full resolution
  const HeightMap crop = plots::crop_map(b, w);
  EXPECT_EQ(crop.nx, 20);  // centres x = 0 .. 9.5 mm: cells 20 .. 39
  EXPECT_EQ(crop.nx * crop.ny, static_cast<int>(crop.thickness_um.size()));
  EXPECT_DOUBLE_EQ(crop.origin_x_mm, 0.0);
  EXPECT_FLOAT_EQ(crop.max_value(), 5.0f);
  // nothing deposited: no window
  HeightMap empty = spotted_map(0.0f);
  for (float& v : empty.thickness_um) v = 0.0f;
  EXPECT_FALSE(plots::thickest_spot_window({&empty}).found);
}

// The shared colour scale: the largest peak of all maps, unless that is more than twice the
// median run's 95th percentile of its deposit, where it is topped there so one run's blob
// does not wash the other runs' lines out.
TEST(ComparisonScale, TopIsThePeakUnlessABlobWouldWashTheLinesOut) {
  // even maps (every cell 1 um, one of 1.5 um): the peak
  const HeightMap even = spotted_map(1.0f), slightly = spotted_map(1.5f);
  plots::ComparisonInput input;
  for (const HeightMap* map : {&even, &slightly}) {
    plots::ComparisonColumn column;
    column.thickness = map;
    input.columns.push_back(column);
  }
  plots::SharedThicknessScale scale = plots::shared_thickness_scale(input);
  EXPECT_FALSE(scale.capped);
  EXPECT_DOUBLE_EQ(scale.top_um, 1.5);
  EXPECT_DOUBLE_EQ(scale.peak_um, 1.5);
  // a blob of 50 um over a tenth of the second (more than its 5 %): topped at 2 x the lower
  // run's 95th percentile (1 um), the peak kept for the label
  HeightMap blob = spotted_map(50.0f);
  for (size_t k = 0; k < blob.thickness_um.size(); k += 10) blob.thickness_um[k] = 50.0f;
  input.columns[1].thickness = &blob;
  scale = plots::shared_thickness_scale(input);
  EXPECT_TRUE(scale.capped);
  EXPECT_DOUBLE_EQ(scale.peak_um, 50.0);
  EXPECT_DOUBLE_EQ(scale.top_um, plots::kSharedScaleCap * 1.0);
  // with a third, even run the median run is an even one: the same top
  input.columns.push_back(input.columns[0]);
  EXPECT_DOUBLE_EQ(plots::shared_thickness_scale(input).top_um, scale.top_um);
  // with two of the three blobbed the median run is blobbed: the blob's 95th percentile
  input.columns[0].thickness = &blob;
  EXPECT_DOUBLE_EQ(plots::shared_thickness_scale(input).top_um, 50.0);
  // one map, lines of 1 um beside a spot 200 times thicker (a dwell): the lines below 1 % of
  // the peak still make the percentile, so the scale is topped at 2 um, not left at the spot
  HeightMap dwell = spotted_map(200.0f);
  plots::ComparisonInput alone;
  alone.columns.resize(1);
  alone.columns[0].thickness = &dwell;
  scale = plots::shared_thickness_scale(alone);
  EXPECT_TRUE(scale.capped);
  EXPECT_DOUBLE_EQ(scale.top_um, plots::kSharedScaleCap * 1.0);
  EXPECT_DOUBLE_EQ(scale.peak_um, 200.0);
  // nothing deposited: 1 um
  HeightMap empty = spotted_map(0.0f);
  for (float& v : empty.thickness_um) v = 0.0f;
  plots::ComparisonInput none;
  none.columns.resize(1);
  none.columns[0].thickness = &empty;
  scale = plots::shared_thickness_scale(none);
  EXPECT_FALSE(scale.capped);
  EXPECT_DOUBLE_EQ(scale.top_um, 1.0);
}

// Two runs whose grids cover different extents, drawn on shared axes: each is padded with zero
// cells to the joint extent, on its own lattice, so neither leaves a white strip.
TEST(ComparisonMaps, PaddedWithZerosToTheSharedExtent) {
  const HeightMap map = spotted_map(5.0f);  // cells -10 .. 9.5 (edges -10.25 .. 9.75), y 0 .. 9.5
  const HeightMap padded = plots::pad_to_extent(map, -11.25, 9.75, -0.25, 10.75);
  EXPECT_EQ(padded.nx, 42);  // two more cells on the left
  EXPECT_EQ(padded.ny, 22);  // two more on top
  EXPECT_DOUBLE_EQ(padded.origin_x_mm, -11.0);
  EXPECT_DOUBLE_EQ(padded.origin_y_mm, 0.0);
  EXPECT_DOUBLE_EQ(padded.cell_mm, 0.5);
  EXPECT_EQ(padded.at(0, 0), 0.0f);  // new cells: nothing deposited
  EXPECT_EQ(padded.at(41, 21), 0.0f);
  EXPECT_EQ(padded.at(2 + 30, 15), 5.0f);  // the old cells where they were
  EXPECT_EQ(padded.at(2, 0), 1.0f);
  // already covering: unchanged
  EXPECT_EQ(plots::pad_to_extent(map, -10.25, 9.75, -0.25, 9.75).thickness_um, map.thickness_um);
}

// The peaks shown side by side in one fixed format: three significant digits of the largest.
TEST(ComparisonMaps, PeaksInOneFixedFormat) {
  EXPECT_EQ(plots::fixed_text(2000.0, 2000.0), "2000");
  EXPECT_EQ(plots::fixed_text(1034.4, 2000.0), "1034");
  EXPECT_EQ(plots::fixed_text(360.2, 360.2), "360");
  EXPECT_EQ(plots::fixed_text(12.345, 12.345), "12.3");
  EXPECT_EQ(plots::fixed_text(9.8, 12.345), "9.8");
  EXPECT_EQ(plots::fixed_text(1.5, 2.0), "1.50");
}

TEST(ComparisonTravels, PathsNumberedFromZeroInPrintOrder) {
  // print path 1 along y = 0, travel, print path 0 along y = 2 (printed second)
  MotionSamples s;
  for (int k = 0; k <= 10; ++k) s.push_back(0.1 * k, Vec3(k, 0, 0), Vec3(10, 0, 0), true, 1, 10);
  for (int k = 1; k < 5; ++k)
    s.push_back(1.0 + 0.1 * k, Vec3(10, 0.5 * k, 0), Vec3(0, 5, 0), false, -1, 0);
  for (int k = 0; k <= 10; ++k)
    s.push_back(1.5 + 0.1 * k, Vec3(10 - k, 2, 0), Vec3(-10, 0, 0), true, 0, 10);
  plots::ComparisonColumn column;
  plots::set_travels(column, s);
  ASSERT_EQ(column.path_labels.size(), 2u);
  EXPECT_EQ(column.path_labels[0].path, 1);
  EXPECT_DOUBLE_EQ(column.path_labels[0].x_mm, 5.0);
  EXPECT_EQ(column.path_labels[1].path, 0);
  EXPECT_DOUBLE_EQ(column.path_labels[1].y_mm, 2.0);
  EXPECT_GT(column.travel_xy.point_count(), 0u);
  EXPECT_GT(column.print_xy.point_count(), 0u);

  std::vector<plots::ComparisonColumn> columns(2);
  columns[0].order = columns[1].order = "as_given";
  EXPECT_FALSE(plots::is_orders_comparison(columns));
  columns[1].order = "nearest_neighbor";
  EXPECT_TRUE(plots::is_orders_comparison(columns));
}

// extrusion's 0.2 mm layer and 0.45 mm bead: 0.45 x 0.2 / (0.1125 sqrt(2 pi)) = 319 um
TEST(ThicknessProfile, TargetNoteSaysWhereTheTargetComesFrom) {
  const std::string extrusion =
      plots::target_thickness_note(true, 319.15, 10.0, 0.1125, 0.0, 0.45, 0.2);
  EXPECT_EQ(extrusion,
            "target 319 µm = w h / (σ √(2π)) = 1.60 h: a w × h = 0.45 × 0.2 mm bead as a "
            "Gaussian, σ = w/4");
  const std::string aerosol = plots::target_thickness_note(false, 2.0, 3.0, 0.1, 1.504, 0, 0);
  EXPECT_EQ(aerosol,
            "target 2 µm: a straight line's centreline peak Q / (v σ √(2π)), Q = 1.5 mm³/s, "
            "v = 3 mm/s, σ = 0.1 mm");
}

}  // namespace
}  // namespace depotwin
