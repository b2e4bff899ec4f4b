// The conformal plots: joints.png (degrees, forbidden bands at the ranges), layers.png (one
// map per layer on a shared colour scale), paths3d.png (paths by layer, travels, tool axes,
// the part's surface): their data, and the PNGs gnuplot draws from it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <set>

#include "conformal_fixture.hpp"
#include "core/error.hpp"
#include "gnuplot_capture.hpp"
#include "plots/plot_data.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"
#include "png_check.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using plots::RunPlot;
using testing_support::make_conformal_fixture;

constexpr double kDeg = 180.0 / M_PI;

std::string output_directory(const std::string& name) {
  const fs::path directory = fs::path(DEPOTWIN_BINARY_DIR) / "test_plots_output" / name;
  fs::remove_all(directory);
  fs::create_directories(directory);
  return directory.string();
}

void expect_run_png(const std::string& path) {
  SCOPED_TRACE(path);
  ASSERT_TRUE(fs::exists(path));
  const std::string bytes = testing_support::read_bytes(path);
  const auto header = testing_support::png_header(bytes);
  ASSERT_TRUE(header.valid);
  EXPECT_EQ(header.width, static_cast<std::uint32_t>(plots::style::kRunPlotWidth_px));
  EXPECT_EQ(header.height, static_cast<std::uint32_t>(plots::style::kRunPlotHeight_px));
  EXPECT_GT(testing_support::pixel_variance(bytes), 100.0);
}

// ---- joints.png ----

TEST(JointPanels, RevoluteJointsInDegreesWithBandsExactlyAtTheRange) {
  const auto f = make_conformal_fixture();
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  ASSERT_EQ(data.joint_panels.size(), 6u);
  for (size_t j = 0; j < 6; ++j) {
    SCOPED_TRACE(j);
    const plots::JointPanel& panel = data.joint_panels[j];
    EXPECT_EQ(panel.name, "j" + std::to_string(j + 1));
    EXPECT_EQ(panel.unit, "deg");
    ASSERT_TRUE(panel.limited);
    EXPECT_DOUBLE_EQ(panel.min, f.joints.min[j] * kDeg);
    EXPECT_DOUBLE_EQ(panel.max, f.joints.max[j] * kDeg);
    // the bands [y_lo, min] and [max, y_hi] are not empty
    EXPECT_LT(panel.y_lo, panel.min);
    EXPECT_GT(panel.y_hi, panel.max);
    // every drawn point is an input sample in degrees, the extremes among them
    double lo = 1e300, hi = -1e300, closest = 1e300;
    for (double q : f.joints.position[j]) {
      lo = std::min(lo, q * kDeg);
      hi = std::max(hi, q * kDeg);
      closest = std::min({closest, q * kDeg - panel.min, panel.max - q * kDeg});
    }
    ASSERT_GT(panel.position.point_count(), 10u);
    double drawn_lo = 1e300, drawn_hi = -1e300;
    for (size_t k = 0; k < panel.position.size(); ++k) {
      if (std::isnan(panel.position.x[k])) continue;
      const size_t sample = static_cast<size_t>(std::lround(panel.position.x[k] / 0.002));
      ASSERT_LT(sample, f.joints.t_s.size());
      EXPECT_DOUBLE_EQ(panel.position.y[k], f.joints.position[j][sample] * kDeg);
      drawn_lo = std::min(drawn_lo, panel.position.y[k]);
      drawn_hi = std::max(drawn_hi, panel.position.y[k]);
    }
    EXPECT_DOUBLE_EQ(drawn_lo, lo);
    EXPECT_DOUBLE_EQ(drawn_hi, hi);
    EXPECT_NEAR(panel.closest_to_limit, closest, 1e-9);
  }
  // j5 comes within 10 degrees of its 120-degree limit
  EXPECT_NEAR(data.joint_panels[4].closest_to_limit, 10.0, 1e-6);
}

TEST(JointPanels, PrismaticJointsInMillimetresAndJointsWithoutARange) {
  plots::JointSeries series;
  series.names = {"x", "y", "z"};
  series.units = {"mm", "mm", "mm"};
  series.min = {-50, -50, 0};
  series.max = {50, 50, 0};  // z: no range
  series.t_s = {0.0, 1.0, 2.0};
  series.position = {{-10, 0, 49}, {0, 5, 0}, {1, 1, 1}};
  const auto f = make_conformal_fixture();
  auto input = f.input();
  input.joints = &series;
  const plots::RunPlotData data = plots::prepare_run_plot_data(input);
  ASSERT_EQ(data.joint_panels.size(), 3u);
  EXPECT_EQ(data.joint_panels[0].unit, "mm");
  EXPECT_EQ(data.joint_panels[0].min, -50.0);
  EXPECT_EQ(data.joint_panels[0].max, 50.0);
  EXPECT_DOUBLE_EQ(data.joint_panels[0].closest_to_limit, 1.0);  // 49 of 50
  EXPECT_DOUBLE_EQ(data.joint_panels[0].position.y[2], 49.0);
  EXPECT_FALSE(data.joint_panels[2].limited);
  EXPECT_TRUE(std::isnan(data.joint_panels[2].closest_to_limit));
  EXPECT_LT(data.joint_panels[2].y_lo, 1.0);
  EXPECT_GT(data.joint_panels[2].y_hi, 1.0);
  // mismatched counts are the caller's bug
  series.min.pop_back();
  EXPECT_THROW(plots::prepare_run_plot_data(input), InternalError);
}

TEST(JointSeries, FromARecordedRun) {
  RecordedRun run;
  run.joint_count = 2;
  run.joint_names = {"a", "b"};
  run.t_s = {0.0, 0.5, 1.0};
  run.joint_position = {0.1, 10.0, 0.2, 20.0, 0.3, 30.0};  // step-major
  std::vector<JointLimit> limits(2);
  limits[0].min = -1.0, limits[0].max = 1.0;
  limits[1].min = 0.0, limits[1].max = 100.0;
  const plots::JointSeries series = plots::joint_series(run, limits, {true, false});
  EXPECT_EQ(series.names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(series.units, (std::vector<std::string>{"rad", "mm"}));
  EXPECT_EQ(series.t_s, run.t_s);
  EXPECT_EQ(series.position[0], (std::vector<double>{0.1, 0.2, 0.3}));
  EXPECT_EQ(series.position[1], (std::vector<double>{10.0, 20.0, 30.0}));
  EXPECT_EQ(series.min, (std::vector<double>{-1.0, 0.0}));
  EXPECT_EQ(series.max, (std::vector<double>{1.0, 100.0}));
  EXPECT_THROW(plots::joint_series(run, limits, {true}), InternalError);
}

// ---- layers.png ----

TEST(LayerPanels, OneMapPerLayerOnASharedScaleWithItsOwnPaths) {
  const auto f = make_conformal_fixture(2);
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  ASSERT_EQ(data.layer_panels.size(), 2u);
  EXPECT_EQ(data.layer_count, 2);
  EXPECT_EQ(data.layer_panels[0].title, "layer 0 (0°)");
  EXPECT_EQ(data.layer_panels[1].title, "layer 1 (90°)");
  // each map reduced to at most 200 cells a side (a panel is small), and the shared colour
  // range the thickest of the maps drawn (layer 1: 5 um peak)
  double peak = 0.0;
  for (const auto& panel : data.layer_panels) {
    const HeightMap expected =
        plots::downsample_for_display(f.layer_maps[static_cast<size_t>(panel.layer)], 200);
    EXPECT_EQ(panel.map.nx, expected.nx);
    EXPECT_EQ(panel.map.ny, expected.ny);
    EXPECT_EQ(panel.map.thickness_um, expected.thickness_um);
    EXPECT_LE(std::max(panel.map.nx, panel.map.ny), 200);
    peak = std::max(peak, static_cast<double>(panel.map.max_value()));
  }
  // (the maps are max-pooled: the thickest cell survives the reduction exactly)
  EXPECT_DOUBLE_EQ(data.layer_scale.peak_um, peak);
  EXPECT_EQ(data.layer_scale.peak_um, data.layer_panels[1].map.max_value());
  EXPECT_EQ(data.layer_scale.peak_um, f.layer_maps[1].max_value());
  // even lines: the scale is not topped
  EXPECT_FALSE(data.layer_scale.capped);
  EXPECT_DOUBLE_EQ(data.layer_scale.top_um, peak);
  // each panel carries its own layer's paths only
  for (const auto& panel : data.layer_panels) {
    size_t points = 0;
    for (const PrintPath& path : f.toolpath.paths)
      if (path.layer == panel.layer) points += path.points.size();
    EXPECT_EQ(panel.paths.point_count(), points);
  }
  // one extent for all panels, covering maps and paths
  EXPECT_LE(data.layers_x_lo, -0.5 * f.length_mm);
  EXPECT_GE(data.layers_x_hi, 0.5 * f.length_mm);
  // without angles: "layer k"
  auto input = f.input();
  input.layer_angles_deg = {0.0, NAN};
  const plots::RunPlotData no_angle = plots::prepare_run_plot_data(input);
  EXPECT_EQ(no_angle.layer_panels[1].title, "layer 1");
}

// A blob where the layers start (six times the beads' height, as a G-code job's first extrusion
// leaves) tops the colour scale near the beads, not at the blob, and the plot says so; the
// beads then take the middle of the scale instead of its dark end.
TEST(LayerPanels, ABlobWhereTheLayersStartDoesNotWashTheBeadsOut) {
  auto f = make_conformal_fixture(2);
  HeightMap& first = f.layer_maps[0];
  for (int iy = 0; iy < 4; ++iy)
    for (int ix = 0; ix < 4; ++ix)
      first.thickness_um[static_cast<size_t>(iy) * first.nx + ix] = 30.0f;
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  EXPECT_TRUE(data.layer_scale.capped);
  EXPECT_DOUBLE_EQ(data.layer_scale.peak_um, 30.0);
  // 2 x the lower layer's 95th percentile (about its 4 um bead), far below the blob's 30 um
  EXPECT_GE(data.layer_scale.top_um, 4.0);
  EXPECT_LE(data.layer_scale.top_um, 2 * 5.0);
  // the colour bar's range and the note under the panels
  const auto capture = testing_support::capturing_gnuplot(output_directory("layers_blob_tool"));
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  plots::render_run_plots(f.input(), output_directory("layers_blob"), {RunPlot::layers}, options);
  const std::string script = capture.script();
  EXPECT_NE(script.find(plots::format("set cbrange [0:%.9g]", data.layer_scale.top_um)),
            std::string::npos);
  EXPECT_NE(script.find("colour scale topped at 2 × the median layer''s 95th percentile"),
            std::string::npos);
}

TEST(LayerPanels, ManyLayersShowEightEvenlyChosen) {
  auto f = make_conformal_fixture(2);
  // 20 layers: the two maps repeated, the fourth left empty
  std::vector<const HeightMap*> maps;
  for (int k = 0; k < 20; ++k) maps.push_back(&f.layer_maps[static_cast<size_t>(k % 2)]);
  HeightMap empty;
  maps[3] = &empty;
  auto input = f.input();
  input.layer_maps = maps;
  input.layer_angles_deg = {};
  const plots::RunPlotData data = plots::prepare_run_plot_data(input);
  EXPECT_EQ(data.layer_count, 20);
  std::vector<int> shown;
  for (const auto& panel : data.layer_panels) shown.push_back(panel.layer);
  EXPECT_EQ(shown, (std::vector<int>{0, 3, 5, 8, 11, 14, 16, 19}));
  EXPECT_EQ(data.layer_panels[1].map.nx, 0);  // layer 3: nothing deposited
  EXPECT_EQ(data.layer_panels[1].title, "layer 3");
}

// ---- paths3d.png ----

TEST(Paths3d, PathsByLayerTravelsAndToolAxesOfTheStatedLength) {
  const auto f = make_conformal_fixture(2);
  const plots::RunPlotData data = plots::prepare_run_plot_data(f.input());
  ASSERT_EQ(data.layer_paths.size(), 2u);
  // each layer's curve: points of that layer's paths only, every path's ends among them
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    std::set<std::array<double, 3>> layer_points;
    size_t paths = 0;
    for (const PrintPath& path : f.toolpath.paths) {
      if (path.layer != k) continue;
      ++paths;
      for (const Vec3& p : path.points) layer_points.insert({p.x(), p.y(), p.z()});
    }
    const plots::Curve3& c = data.layer_paths[static_cast<size_t>(k)];
    size_t breaks = 0;
    for (size_t i = 0; i < c.size(); ++i) {
      if (std::isnan(c.x[i])) {
        ++breaks;
        continue;
      }
      EXPECT_TRUE(layer_points.count({c.x[i], c.y[i], c.z[i]})) << i;
    }
    EXPECT_EQ(breaks, paths);  // one line per path
  }
  // travels: the plan where not depositing (lifted over the part between paths)
  EXPECT_GT(data.travels.point_count(), 10u);
  double travel_top = -1e300;
  for (double z : data.travels.z)
    if (!std::isnan(z)) travel_top = std::max(travel_top, z);
  EXPECT_NEAR(travel_top, 15.0, 1e-9);  // start and end
  // tool axes: from a path point along that point's tool axis, tool_axis_length_mm long
  double x_lo = 1e300, x_hi = -1e300;  // the paths' extent: about 39 mm in x
  for (const PrintPath& path : f.toolpath.paths)
    for (const Vec3& p : path.points) x_lo = std::min(x_lo, p.x()), x_hi = std::max(x_hi, p.x());
  EXPECT_NEAR(data.tool_axis_length_mm, 0.08 * (x_hi - x_lo), 1e-9);  // 8 % of it
  const plots::Curve3& axes = data.tool_axes;
  ASSERT_EQ(axes.size() % 3, 0u);
  const size_t segments = axes.size() / 3;
  EXPECT_GT(segments, 20u);
  EXPECT_LE(segments, plots::PlotOptions{}.max_tool_axes);
  for (size_t s = 0; s < segments; ++s) {
    const Vec3 a(axes.x[3 * s], axes.y[3 * s], axes.z[3 * s]);
    const Vec3 b(axes.x[3 * s + 1], axes.y[3 * s + 1], axes.z[3 * s + 1]);
    EXPECT_TRUE(std::isnan(axes.x[3 * s + 2]));
    bool found = false;
    for (const PrintPath& path : f.toolpath.paths)
      for (size_t i = 0; i < path.points.size() && !found; ++i)
        if (path.points[i] == a) {
          found = true;
          EXPECT_LT((b - (a + data.tool_axis_length_mm * path.tool_axis(i))).norm(), 1e-12);
        }
    EXPECT_TRUE(found) << s;
    EXPECT_NEAR((b - a).norm(), data.tool_axis_length_mm, 1e-9);
  }
  // tilted by alpha = 0.5 away from vertical where the arch slopes
  double largest_tilt = 0.0;
  for (size_t s = 0; s < segments; ++s)
    largest_tilt = std::max(largest_tilt, std::abs(axes.x[3 * s + 1] - axes.x[3 * s]));
  EXPECT_GT(largest_tilt, 0.1 * data.tool_axis_length_mm);
  // the part: its upward faces only, decimated to at most max_part_triangles
  EXPECT_FALSE(data.part_surface.empty());
  EXPECT_LE(data.part_surface.triangle_count(), plots::PlotOptions{}.max_part_triangles);
  for (size_t t = 0; t < data.part_surface.triangle_count(); ++t)
    EXPECT_GT(data.part_surface.facet_normal(t).z(), 0.0);
}

// A job that ends where it started (the arm returns to its start): the end's square is drawn
// first and the start's ring over it, so both markers show. And the shorter horizontal axis
// (the arch's width beside its length) gets three ticks or more, not a lone "0".
TEST(Paths3d, StartRingDrawnOverACoincidentEndAndThreeTicksOnEachAxis) {
  auto f = make_conformal_fixture(2);
  f.toolpath.end_mm = f.toolpath.start_mm;
  const auto capture = testing_support::capturing_gnuplot(output_directory("paths3d_tool"));
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  const auto result = plots::render_run_plots(f.input(), output_directory("paths3d_same_ends"),
                                              {RunPlot::paths3d}, options);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  const std::string section = testing_support::png_section(capture.script(), "paths3d.png");
  const std::vector<std::string> elements = testing_support::plot_elements(section);
  size_t start = elements.size(), end = elements.size();
  for (size_t e = 0; e < elements.size(); ++e) {
    if (testing_support::key_title(elements[e]) == "start") start = e;
    if (testing_support::key_title(elements[e]) == "end") end = e;
  }
  ASSERT_LT(start, elements.size()) << section;
  ASSERT_LT(end, elements.size()) << section;
  EXPECT_GT(start, end);                                        // drawn over it
  EXPECT_NE(elements[start].find("pt 6 "), std::string::npos);  // an open ring
  // the ticks on x and y
  for (const char* axis : {"x", "y"}) {
    SCOPED_TRACE(axis);
    std::smatch range, tics;
    ASSERT_TRUE(std::regex_search(
        section, range,
        std::regex(std::string("set ") + axis + "range \\[([-0-9.e+]+):([-0-9.e+]+)\\]")));
    ASSERT_TRUE(std::regex_search(section, tics,
                                  std::regex(std::string("set ") + axis + "tics ([-0-9.e+]+)")));
    EXPECT_GE(plots::tick_count(std::stod(range[1]), std::stod(range[2]), std::stod(tics[1])), 3);
  }
}

TEST(Curve3, BreaksAreTwoBlankLinesSoThatSplotDoesNotJoinLinesIntoAGrid) {
  plots::Curve3 c;
  c.add(Vec3(1, 2, 3));
  c.add(Vec3(4, 5, 6));
  c.add_break();
  c.add_break();  // no doubled breaks
  c.add(Vec3(7, 8, 9.5));
  EXPECT_EQ(c.point_count(), 3u);
  EXPECT_EQ(plots::format_curve3(c), "1 2 3\n4 5 6\n\n\n7 8 9.5\n");
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.25)};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_EQ(plots::format_triangles(mesh), "0 0 0\n1 0 0\n0 1 0.25\n\n");
}

TEST(DisplaySurface, KeepsUpwardFacesAndDecimatesOnTheSurface) {
  const auto f = make_conformal_fixture(1);
  const TriangleMesh fine = testing_support::arch_mesh(f, 0.1);  // 96 000 top triangles
  const TriangleMesh shown = plots::display_surface(fine, 2000);
  EXPECT_LE(shown.triangle_count(), 2000u);
  EXPECT_GT(shown.triangle_count(), 1000u);
  // every vertex lies on the arch (a vertex of the fine mesh's top)
  for (const Vec3& v : shown.vertices) EXPECT_NEAR(v.z(), f.z(v.x()), 1e-9);
  // it still covers the footprint
  Vec3 lo, hi;
  shown.bounds(lo, hi);
  EXPECT_NEAR(lo.x(), -20.0, 0.5);
  EXPECT_NEAR(hi.x(), 20.0, 0.5);
  EXPECT_NEAR(lo.y(), -6.0, 0.5);
  EXPECT_NEAR(hi.y(), 6.0, 0.5);
  // small enough already: the upward faces as they are
  const TriangleMesh coarse = testing_support::arch_mesh(f, 1.0);
  EXPECT_EQ(plots::display_surface(coarse, 2000).triangle_count(), 2u * 40u * 12u);
}

// A box's twelve triangles wound outward, corners lo and hi.
TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh box;
  for (int i = 0; i < 8; ++i)
    box.vertices.push_back(
        Vec3(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()));
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return box;
}

// A flat square patch at height z, wound facing up or down.
TriangleMesh square_patch(double half_mm, double z, bool facing_up) {
  TriangleMesh patch;
  patch.vertices = {Vec3(-half_mm, -half_mm, z), Vec3(half_mm, -half_mm, z),
                    Vec3(half_mm, half_mm, z), Vec3(-half_mm, half_mm, z)};
  patch.triangles = facing_up ? std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}}
                              : std::vector<std::array<int, 3>>{{0, 2, 1}, {0, 3, 2}};
  return patch;
}

TEST(DisplaySurface, ShowsTheSideSeenFromAboveWhicheverWayItIsWound) {
  // a closed box: its top alone (the underside lies under it)
  const TriangleMesh box = box_mesh(Vec3(-5, -5, 0), Vec3(5, 5, 4));
  const TriangleMesh shown_box = plots::display_surface(box, 2000);
  ASSERT_EQ(shown_box.triangle_count(), 2u);
  for (size_t t = 0; t < 2; ++t) {
    EXPECT_NEAR(shown_box.facet_normal(t).z(), 1.0, 1e-12);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(shown_box.vertices[shown_box.triangles[t][c]].z(), 4.0);
  }
  // an open patch wound facing down is seen on its back: both triangles, turned to face up
  const TriangleMesh shown_patch = plots::display_surface(square_patch(5, 1, false), 2000);
  ASSERT_EQ(shown_patch.triangle_count(), 2u);
  for (size_t t = 0; t < 2; ++t) EXPECT_NEAR(shown_patch.facet_normal(t).z(), 1.0, 1e-12);
  // a patch wound facing down under a roof wound facing up: the roof alone
  TriangleMesh roofed = square_patch(8, 10, true);
  const TriangleMesh under = square_patch(3, 2, false);
  for (const auto& triangle : under.triangles)
    roofed.triangles.push_back({triangle[0] + 4, triangle[1] + 4, triangle[2] + 4});
  roofed.vertices.insert(roofed.vertices.end(), under.vertices.begin(), under.vertices.end());
  const TriangleMesh shown_roofed = plots::display_surface(roofed, 2000);
  ASSERT_EQ(shown_roofed.triangle_count(), 2u);
  for (const Vec3& v : shown_roofed.vertices) EXPECT_EQ(v.z(), 10.0);
  // a band that turns over halfway: half wound up, half down, none under the other; every
  // triangle is shown, facing up
  TriangleMesh band;
  for (int i = 0; i <= 20; ++i)
    for (int side = 0; side < 2; ++side) band.vertices.push_back(Vec3(i, side * 4.0, 0.1 * i));
  for (int i = 0; i < 20; ++i) {
    const int a = 2 * i, b = 2 * i + 2, c = 2 * i + 3, d = 2 * i + 1;
    if (i < 10) {
      band.triangles.push_back({a, b, c});
      band.triangles.push_back({a, c, d});
    } else {
      band.triangles.push_back({a, c, b});
      band.triangles.push_back({a, d, c});
    }
  }
  const TriangleMesh shown_band = plots::display_surface(band, 2000);
  ASSERT_EQ(shown_band.triangle_count(), 40u);
  for (size_t t = 0; t < 40; ++t) EXPECT_GT(shown_band.facet_normal(t).z(), 0.9);
}

// ---- availability and the PNGs ----

TEST(ConformalPlots, AvailableOnlyWithTheirInputs) {
  const auto f = make_conformal_fixture(2);
  auto input = f.input();
  const std::vector<RunPlot> all = {RunPlot::path,   RunPlot::axes,   RunPlot::errors,
                                    RunPlot::joints, RunPlot::layers, RunPlot::paths3d};
  EXPECT_EQ(plots::available_plots(input), all);
  input.joints = nullptr;
  input.layer_maps.clear();
  input.part = nullptr;
  // the toolpath alone is conformal (tool axes, two layers)
  EXPECT_EQ(
      plots::available_plots(input),
      (std::vector<RunPlot>{RunPlot::path, RunPlot::axes, RunPlot::errors, RunPlot::paths3d}));
  EXPECT_THROW(
      plots::render_run_plots(input, output_directory("conformal_missing"), {RunPlot::joints}),
      InternalError);
}

TEST(ConformalPlots, WritesTheThreePngs) {
  const auto f = make_conformal_fixture(2);
  const std::string directory = output_directory("conformal");
  const auto result = plots::render_run_plots(f.input(), directory,
                                              {RunPlot::joints, RunPlot::layers, RunPlot::paths3d});
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 3u);
  EXPECT_EQ(result.files[0], directory + "/joints.png");
  EXPECT_EQ(result.files[1], directory + "/layers.png");
  EXPECT_EQ(result.files[2], directory + "/paths3d.png");
  for (const auto& file : result.files) expect_run_png(file);
}

TEST(ConformalPlots, AllPlotsOfAConformalRunByteIdenticalTwice) {
  const auto f = make_conformal_fixture(2);
  const std::string first = output_directory("conformal_all_first");
  const std::string second = output_directory("conformal_all_second");
  const auto a = plots::render_run_plots(f.input(), first);
  const auto b = plots::render_run_plots(f.input(), second);
  EXPECT_TRUE(a.warnings.empty()) << a.warnings.front();
  ASSERT_EQ(a.files.size(), 6u);
  for (size_t i = 0; i < a.files.size(); ++i) {
    expect_run_png(a.files[i]);
    EXPECT_EQ(testing_support::read_bytes(a.files[i]), testing_support::read_bytes(b.files[i]));
  }
}

TEST(ConformalPlots, ManyLayersAndAThreeJointMachine) {
  const auto f = make_conformal_fixture(12, 2.0);
  plots::JointSeries series;
  series.names = {"x", "y", "z"};
  series.units = {"mm", "mm", "mm"};
  series.min = {-30, -30, -5};
  series.max = {30, 30, 25};
  for (size_t k = 0; k < f.planned.size(); k += 10) {
    series.t_s.push_back(f.planned.t_s[k]);
    series.position.resize(3);
    for (int a = 0; a < 3; ++a) series.position[a].push_back(f.planned.position_mm[k][a]);
  }
  auto input = f.input("arch / 12 layers");
  input.joints = &series;
  const std::string directory = output_directory("conformal_many_layers");
  const auto result = plots::render_run_plots(input, directory,
                                              {RunPlot::joints, RunPlot::layers, RunPlot::paths3d});
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 3u);
  for (const auto& file : result.files) expect_run_png(file);
}

// the fixture turned by 90 degrees about z: the arch runs along y (tall layer panels, the 3-D
// view from the other side)
TEST(ConformalPlots, APartLongerInY) {
  auto f = make_conformal_fixture(3);
  auto turn = [](const Vec3& p) { return Vec3(-p.y(), p.x(), p.z()); };
  for (Vec3& v : f.part.vertices) v = turn(v);
  for (PrintPath& path : f.toolpath.paths) {
    for (Vec3& p : path.points) p = turn(p);
    for (Vec3& n : path.normals) n = turn(n);
  }
  f.toolpath.start_mm = turn(f.toolpath.start_mm);
  f.toolpath.end_mm = turn(f.toolpath.end_mm);
  for (size_t k = 0; k < f.planned.size(); ++k) {
    f.planned.position_mm[k] = turn(f.planned.position_mm[k]);
    f.planned.velocity_mm_s[k] = turn(f.planned.velocity_mm_s[k]);
  }
  for (HeightMap& map : f.layer_maps) {  // (x, y) -> (-y, x): row iy of the map is column -iy
    HeightMap turned;
    turned.cell_mm = map.cell_mm;
    turned.nx = map.ny;
    turned.ny = map.nx;
    turned.origin_x_mm = -(map.origin_y_mm + (map.ny - 1) * map.cell_mm);
    turned.origin_y_mm = map.origin_x_mm;
    turned.thickness_um.resize(map.thickness_um.size());
    for (int iy = 0; iy < map.ny; ++iy)
      for (int ix = 0; ix < map.nx; ++ix)
        turned.thickness_um[static_cast<size_t>(ix) * turned.nx + (map.ny - 1 - iy)] =
            map.at(ix, iy);
    map = std::move(turned);
  }
  const std::string directory = output_directory("conformal_along_y");
  const auto result = plots::render_run_plots(f.input("arch along y"), directory,
                                              {RunPlot::layers, RunPlot::paths3d});
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  for (const auto& file : result.files) expect_run_png(file);
}

}  // namespace
}  // namespace depotwin
