// The data behind the plots: transition bands, decimation, error series, display maps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "plot_fixture.hpp"
#include "plots/plot_data.hpp"
#include "plots/plot_job.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"

namespace depotwin {
namespace {

using plots::Curve;
using plots::TimeInterval;
using testing_support::make_plot_fixture;

size_t count_of(const std::string& text, const std::string& word) {
  size_t count = 0;
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++count;
  return count;
}

TEST(TransitionBands, MatchTheTrajectorysTransitionPiecesExactly) {
  const auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  // start -> 1, (1, 2, 3 joined), 3 -> 4, 4 -> 5, 5 -> end
  ASSERT_EQ(f.expected_transitions.size(), 4u);
  EXPECT_EQ(plots::transition_intervals(f.trajectory), f.expected_transitions);
  // the bands the run plots shade are these
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  EXPECT_EQ(data.transitions, f.expected_transitions);
  const std::string shading = plots::style::transition_shading(data.transitions);
  EXPECT_EQ(count_of(shading, " rect "), 4u);
  EXPECT_NE(plots::style::transition_key_entry(data.transitions), "");
}

TEST(TransitionBands, FromSamplesAgreeWithinOneSamplePeriod) {
  const auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  const auto from_samples = plots::transition_intervals(f.planned);
  ASSERT_EQ(from_samples.size(), f.expected_transitions.size());
  for (size_t i = 0; i < from_samples.size(); ++i) {
    EXPECT_NEAR(from_samples[i].begin_s, f.expected_transitions[i].begin_s, 1e-3 + 1e-12);
    EXPECT_NEAR(from_samples[i].end_s, f.expected_transitions[i].end_s, 1e-3 + 1e-12);
  }
  // without explicit bands the run plots derive them from the planned samples
  auto input = f.input();
  input.transitions.reset();
  EXPECT_EQ(plots::prepare_run_plot_data(input).transitions, from_samples);
}

TEST(TransitionBands, RunWithoutTransitionsShadesNothing) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, true, true);
  ASSERT_TRUE(f.expected_transitions.empty());
  ASSERT_EQ(f.trajectory.pieces().size(), 1u);
  EXPECT_TRUE(plots::transition_intervals(f.trajectory).empty());
  EXPECT_TRUE(plots::transition_intervals(f.planned).empty());
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  EXPECT_TRUE(data.transitions.empty());
  EXPECT_EQ(plots::style::transition_shading(data.transitions), "");
  EXPECT_EQ(plots::style::transition_key_entry(data.transitions), "");
  EXPECT_EQ(data.planned_transition_xy.point_count(), 0u);
}

TEST(TransitionBands, ConsecutiveNonDepositingPiecesMerge) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, false, true);
  // rebuild: transition, transition, print, transition
  std::vector<TrajectoryPiece> pieces;
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(2, 0, 0), d(3, 0, 0), v(1, 0, 0);
  pieces.push_back(testing_support::hermite_piece(0.0, 1.0, a, Vec3::Zero(), b, v, -1, 0));
  pieces.push_back(testing_support::hermite_piece(1.0, 1.0, b, v, c, v, -1, 0));
  pieces.push_back(testing_support::hermite_piece(2.0, 1.0, c, v, d, v, 0, 1.0));
  pieces.push_back(testing_support::hermite_piece(3.0, 0.5, d, v, d, Vec3::Zero(), -1, 0));
  const Trajectory trajectory("synthetic", std::move(pieces));
  const std::vector<TimeInterval> expected = {{0.0, 2.0}, {3.0, 3.5}};
  EXPECT_EQ(plots::transition_intervals(trajectory), expected);
}

TEST(Decimation, KeepsTheExtremaAndTheEnds) {
  // 30 s at 1 ms: a slow sine with one 1-sample spike up and one down
  const size_t n = 30001;
  std::vector<double> y(n);
  for (size_t k = 0; k < n; ++k) y[k] = std::sin(0.001 * k);
  y[12345] = 58.0;
  y[23456] = -7.0;
  const auto kept = plots::decimate_min_max(y, 0, n, 2000);
  EXPECT_LE(kept.size(), 2000u);
  EXPECT_GT(kept.size(), 1000u);
  EXPECT_EQ(kept.front(), 0u);
  EXPECT_EQ(kept.back(), n - 1);
  EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
  EXPECT_TRUE(std::adjacent_find(kept.begin(), kept.end()) == kept.end());
  EXPECT_NE(std::find(kept.begin(), kept.end(), 12345u), kept.end());
  EXPECT_NE(std::find(kept.begin(), kept.end(), 23456u), kept.end());
  // a short range is kept whole
  EXPECT_EQ(plots::decimate_min_max(y, 10, 20, 2000).size(), 10u);
}

TEST(Decimation, TimeCurveBreaksAtGapsAndKeepsTheSpike) {
  const auto f = make_plot_fixture(testing_support::raster_toolpath(7), 0.5);
  const std::vector<double> error = plots::speed_error_with_gaps(f.simulated);
  double peak = 0.0;
  size_t runs = 0;
  for (size_t k = 0; k < error.size(); ++k) {
    if (std::isfinite(error[k])) peak = std::max(peak, error[k]);
    if (std::isfinite(error[k]) && (k == 0 || !std::isfinite(error[k - 1]))) ++runs;
  }
  ASSERT_EQ(runs, 7u);  // one per raster line
  const Curve curve = plots::time_curve(f.simulated.t_s, error, 2000);
  EXPECT_LE(curve.point_count(), 2000u);
  EXPECT_EQ(curve.size() - curve.point_count(), runs);  // one break after each run
  EXPECT_EQ(*std::max_element(curve.y.begin(), curve.y.end(),
                              [](double a, double b) {
                                return (std::isnan(a) ? -1 : a) < (std::isnan(b) ? -1 : b);
                              }),
            peak);
}

TEST(ErrorSeries, StraightLineAtConstantSpeedHasNoError) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, false, true);
  const auto speed = plots::speed_error_with_gaps(f.planned);
  const auto position = plots::relative_position_error(f.planned, f.toolpath, 10.0);
  ASSERT_EQ(speed.size(), f.planned.size());
  for (size_t k = 0; k < speed.size(); ++k) {
    ASSERT_NEAR(speed[k], 0.0, 1e-9) << k;
    ASSERT_NEAR(position[k], 0.0, 1e-12) << k;
  }
}

TEST(ErrorSeries, GapsExactlyWhereNothingIsDeposited) {
  const auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  const auto speed = plots::speed_error_with_gaps(f.planned);
  const auto position = plots::relative_position_error(f.planned, f.toolpath, 10.0);
  for (size_t k = 0; k < f.planned.size(); ++k) {
    ASSERT_EQ(std::isnan(speed[k]), f.planned.depositing[k] == 0) << k;
    ASSERT_EQ(std::isnan(position[k]), f.planned.depositing[k] == 0) << k;
  }
  // the averaged joint velocities of the joined paths make a speed error, as in Fig. 10(a)
  double peak = 0.0;
  for (double e : speed)
    if (std::isfinite(e)) peak = std::max(peak, e);
  EXPECT_GT(peak, 0.05);
}

TEST(ErrorSeries, FeatureSizeIsThePrintPatternsLargestExtent) {
  // print paths span x 1..9 and y 1..11: 10 mm, start/end (12, 0) not counted
  EXPECT_DOUBLE_EQ(plots::feature_size_mm(testing_support::thompson_like_toolpath()), 10.0);
  Toolpath empty;
  empty.start_mm = Vec3(0, 0, 0);
  empty.end_mm = Vec3(4, 3, 0);
  EXPECT_DOUBLE_EQ(plots::feature_size_mm(empty), 4.0);
  EXPECT_DOUBLE_EQ(plots::feature_size_mm(Toolpath{}), 1.0);
}

TEST(DisplayMap, BlockMaximaCentredOnTheBlock) {
  HeightMap map;
  map.origin_x_mm = 1.0;
  map.origin_y_mm = 2.0;
  map.cell_mm = 0.5;
  map.nx = 4;
  map.ny = 2;
  map.thickness_um = {1, 2, 3, 4, 5, 6, 7, 8};
  const HeightMap out = plots::downsample_for_display(map, 2);
  ASSERT_EQ(out.nx, 2);
  ASSERT_EQ(out.ny, 1);
  EXPECT_DOUBLE_EQ(out.cell_mm, 1.0);
  EXPECT_DOUBLE_EQ(out.origin_x_mm, 1.25);
  EXPECT_DOUBLE_EQ(out.origin_y_mm, 2.25);
  EXPECT_FLOAT_EQ(out.thickness_um[0], 6.0f);
  EXPECT_FLOAT_EQ(out.thickness_um[1], 8.0f);
  // small enough: unchanged
  EXPECT_EQ(plots::downsample_for_display(map, 4).thickness_um, map.thickness_um);
  // 5 cells at most 2 per side: factor 3, the partial edge block is the largest of what is there
  map.nx = 5;
  map.ny = 1;
  map.thickness_um = {3, 3, 3, 9, 7};
  const HeightMap edge = plots::downsample_for_display(map, 2);
  ASSERT_EQ(edge.nx, 2);
  EXPECT_FLOAT_EQ(edge.thickness_um[1], 9.0f);
}

// A bead one cell wide on a map reduced eightfold (a thin line on a large map) keeps its full
// height: averaged, it would fade to an eighth and vanish into the zero colour.
TEST(DisplayMap, AOneCellLineKeepsItsPeak) {
  HeightMap map;
  map.cell_mm = 0.05;
  map.nx = 800;
  map.ny = 16;
  map.thickness_um.assign(static_cast<size_t>(map.nx) * map.ny, 0.0f);
  for (int ix = 0; ix < map.nx; ++ix)
    map.thickness_um[static_cast<size_t>(5) * map.nx + ix] = 320.0f;
  const HeightMap out = plots::downsample_for_display(map, 100);
  ASSERT_EQ(out.nx, 100);
  ASSERT_EQ(out.ny, 2);
  EXPECT_FLOAT_EQ(out.max_value(), 320.0f);
  for (int ix = 0; ix < out.nx; ++ix) {
    EXPECT_FLOAT_EQ(out.at(ix, 0), 320.0f);  // the block holding the line
    EXPECT_FLOAT_EQ(out.at(ix, 1), 0.0f);    // nothing spills into the next
  }
}

TEST(DataText, FixedFormatWithBlankLinesAtBreaks) {
  Curve curve;
  curve.add(0.1, 2.0);
  curve.add(1.0 / 3.0, -1e-7);
  curve.add_break();
  curve.add_break();  // doubled breaks collapse
  curve.add(5.0, 1e6);
  EXPECT_EQ(plots::format_curve(curve), "0.1 2\n0.333333333 -1e-07\n\n5 1000000\n");
}

// A long thin job (100 x 2 mm) is framed at least a third as wide as long, about its middle,
// so that its plan views are not strips of a few pixels; a square one keeps its padding only
TEST(PlanRanges, ALongThinJobIsFramedAtLeastAThirdAsWideAsLong) {
  plots::Range x, y;
  x.add(-50.0), x.add(50.0);
  y.add(-1.0), y.add(1.0);
  const plots::PlanRanges thin = plots::plan_ranges(x, y, 0.05, 0.5);
  EXPECT_DOUBLE_EQ(thin.x_lo, -55.0);
  EXPECT_DOUBLE_EQ(thin.x_hi, 55.0);
  EXPECT_NEAR(thin.y_hi - thin.y_lo, 110.0 * plots::kMinPlanAspect, 1e-9);
  EXPECT_NEAR(thin.y_lo + thin.y_hi, 0.0, 1e-9);
  plots::Range square;
  square.add(0.0), square.add(10.0);
  const plots::PlanRanges even = plots::plan_ranges(square, square, 0.05, 0.5);
  EXPECT_DOUBLE_EQ(even.x_lo, -0.5);
  EXPECT_DOUBLE_EQ(even.y_hi, 10.5);
}

// A half circle of radius 10 (one arc edge from (10, 0) to (-10, 0) about the centre) is
// labelled at the top of the arc, (0, 10), not at the middle of its chord; a straight
// two-edge path of 4 mm then 6 mm at 5 mm along it.
TEST(PathLabels, EachPathIsNumberedHalfwayAlongItsLength) {
  Toolpath toolpath;
  PrintPath arc;
  arc.points = {Vec3(10, 0, 0), Vec3(-10, 0, 0)};
  arc.arcs = {EdgeArc{Vec3::Zero(), Vec3::UnitZ(), M_PI}};
  PrintPath corner;
  corner.points = {Vec3(0, 0, 1), Vec3(4, 0, 1), Vec3(4, 6, 1)};
  toolpath.paths = {arc, corner};
  const std::vector<plots::PathLabel> labels = plots::halfway_path_labels(toolpath);
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].path, 0);
  EXPECT_NEAR(labels[0].x_mm, 0.0, 1e-9);
  EXPECT_NEAR(labels[0].y_mm, 10.0, 1e-9);
  EXPECT_EQ(labels[1].path, 1);
  EXPECT_NEAR(labels[1].x_mm, 4.0, 1e-9);
  EXPECT_NEAR(labels[1].y_mm, 1.0, 1e-9);
}

// Numbers whose points lie within the merge distance of a drawn label share it, listed
// ascending once each, runs of three or more as a range; others get their own label, at their
// own point; too many labels draw none.
TEST(PathLabels, NumbersThatWouldCoverOneAnotherShareOneLabel) {
  // three stacked layers at one spot (one of them a second run of path 1), then path 5 there
  // too, paths 3 and 4 side by side elsewhere, path 6 just outside the first spot's reach
  const std::vector<plots::PathLabel> labels = {{10.0, 10.0, 0}, {10.0, 10.0, 1}, {10.0, 10.2, 2},
                                                {10.0, 10.0, 1}, {30.0, 0.0, 3},  {30.3, 0.0, 4},
                                                {10.4, 10.0, 5}, {10.0, 10.6, 6}};
  const std::vector<plots::DrawnLabel> drawn = plots::drawn_path_labels(labels, 0.5, 40);
  ASSERT_EQ(drawn.size(), 3u);
  EXPECT_EQ(drawn[0].text, "0–2, 5");
  EXPECT_EQ(drawn[0].x_mm, 10.0);
  EXPECT_EQ(drawn[0].y_mm, 10.0);
  EXPECT_EQ(drawn[1].text, "3, 4");
  EXPECT_EQ(drawn[1].x_mm, 30.0);
  EXPECT_EQ(drawn[2].text, "6");
  EXPECT_EQ(drawn[2].y_mm, 10.6);
  // three labels are one more than two
  EXPECT_EQ(plots::drawn_path_labels(labels, 0.5, 3).size(), 3u);
  EXPECT_TRUE(plots::drawn_path_labels(labels, 0.5, 2).empty());
  // a merge distance of 0: only numbers at the very same point share a label (0 and 1)
  const std::vector<plots::DrawnLabel> apart = plots::drawn_path_labels(labels, 0.0, 40);
  ASSERT_EQ(apart.size(), 6u);
  EXPECT_EQ(apart[0].text, "0, 1");
}

// A slicer's infill (lines 0.3 mm apart over 40 mm: 0.75 of a 0.4 mm cell) crowds its map,
// the same lines 4 mm apart do not, nor does a zoom of 5 mm on the dense ones (30 cells between
// lines); an outline never does, however many layers repeat it; concentric full circles
// 0.3 mm apart, each one arc edge that starts where it ends, crowd it as the lines do.
TEST(PathOverlay, PrintPathsCrowdAMapWhereTheyWouldHideIt) {
  const auto raster = [](double spacing_mm) {
    Toolpath toolpath;
    for (double y = 0.0; y <= 40.0; y += spacing_mm)
      toolpath.paths.push_back(testing_support::line(0, y, 40, y));
    return toolpath;
  };
  EXPECT_TRUE(plots::paths_crowd_window(raster(0.3), 0, 40, 0, 40));
  EXPECT_FALSE(plots::paths_crowd_window(raster(4.0), 0, 40, 0, 40));
  EXPECT_FALSE(plots::paths_crowd_window(raster(0.3), 10, 15, 10, 15));
  Toolpath outline;
  for (int layer = 0; layer < 50; ++layer) {
    PrintPath square;
    for (const auto& [x, y] : {std::pair{0, 0}, {40, 0}, {40, 40}, {0, 40}, {0, 0}})
      square.points.push_back(Vec3(x, y, 0.2 * layer));
    outline.paths.push_back(square);
  }
  EXPECT_FALSE(plots::paths_crowd_window(outline, 0, 40, 0, 40));
  Toolpath circles;
  for (double r = 0.3; r <= 20.0; r += 0.3) {
    PrintPath circle;
    circle.points = {Vec3(20 + r, 20, 0), Vec3(20 + r, 20, 0)};
    circle.arcs = {EdgeArc{Vec3(20, 20, 0), Vec3::UnitZ(), 2 * M_PI}};
    circles.paths.push_back(circle);
  }
  EXPECT_TRUE(plots::paths_crowd_window(circles, 0, 40, 0, 40));
}

}  // namespace
}  // namespace depotwin
