// Every plot function writes its PNG: right pixel size, not blank, no gnuplot warnings,
// byte-identical on a second run; a missing gnuplot is the named error.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>

#include "gnuplot_capture.hpp"
#include "plot_fixture.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"
#include "png_check.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using plots::RunPlot;
using testing_support::make_plot_fixture;

// a fresh directory per test under the build tree (kept afterwards, to look at the images)
std::string output_directory(const std::string& name) {
  const fs::path directory = fs::path(DEPOTWIN_BINARY_DIR) / "test_plots_output" / name;
  fs::remove_all(directory);
  fs::create_directories(directory);
  return directory.string();
}

std::vector<std::string> entries(const std::string& directory) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(directory))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void expect_png(const std::string& path, std::uint32_t width, std::uint32_t height) {
  SCOPED_TRACE(path);
  ASSERT_TRUE(fs::exists(path));
  const std::string bytes = testing_support::read_bytes(path);
  const auto header = testing_support::png_header(bytes);
  ASSERT_TRUE(header.valid);
  EXPECT_EQ(header.width, width);
  EXPECT_EQ(header.height, height);
  // a white page with a few lines already has a variance of several hundred grey levels^2
  EXPECT_GT(testing_support::pixel_variance(bytes), 100.0);
}

// the part of the gnuplot script that draws `plot` of `input`, rendered into directory/plot
// through a stand-in that captures the job
std::string drawn_section(const plots::RunPlotInput& input, const std::string& directory,
                          RunPlot plot) {
  const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  plots::render_run_plots(input, directory + "/plot", {plot}, options);
  return testing_support::png_section(capture.script(), plots::file_name(plot));
}

const std::vector<RunPlot> kAllRunPlots = {RunPlot::path, RunPlot::axes, RunPlot::errors,
                                           RunPlot::thickness_profile, RunPlot::thickness};

class EachRunPlot : public ::testing::TestWithParam<RunPlot> {};

TEST_P(EachRunPlot, WritesItsFileAlone) {
  const auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  const std::string name = plots::file_name(GetParam());
  const std::string directory = output_directory("single_" + name.substr(0, name.size() - 4));
  const plots::PlotResult result = plots::render_run_plots(f.input(), directory, {GetParam()});
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files, std::vector<std::string>{directory + "/" + name});
  expect_png(result.files[0], plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);
  // nothing else left behind: no temporary directory, no data files
  EXPECT_EQ(entries(directory), std::vector<std::string>{name});
}

INSTANTIATE_TEST_SUITE_P(Plots, EachRunPlot, ::testing::ValuesIn(kAllRunPlots),
                         [](const auto& info) {
                           const std::string name = plots::file_name(info.param);
                           return name.substr(0, name.size() - 4);
                         });

TEST(RunPlots, AllFiveInOneCallAndByteIdenticalTwice) {
  const auto f = make_plot_fixture(testing_support::raster_toolpath(7), 0.5);
  const auto input = f.input("raster / synthetic");
  EXPECT_EQ(plots::available_plots(input), kAllRunPlots);
  const std::string first = output_directory("all_first"), second = output_directory("all_second");
  const auto a = plots::render_run_plots(input, first);
  const auto b = plots::render_run_plots(input, second);
  ASSERT_EQ(a.files.size(), 5u);
  EXPECT_TRUE(a.warnings.empty()) << a.warnings.front();
  for (size_t i = 0; i < a.files.size(); ++i) {
    expect_png(a.files[i], plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);
    EXPECT_EQ(testing_support::read_bytes(a.files[i]), testing_support::read_bytes(b.files[i]))
        << a.files[i];
  }
}

// path.png of three stacked layers of one line and a line beside them: the layers' numbers,
// which were drawn at one point over one another, share one label "0–2"; the fourth line
// keeps its own, "3".
TEST(RunPlots, StackedLayersShareOnePathNumberLabel) {
  Toolpath toolpath = testing_support::raster_toolpath(1);
  for (int layer = 1; layer <= 2; ++layer) {
    PrintPath path = testing_support::line(0, 0, 10, 0);
    for (Vec3& point : path.points) point.z() = 0.2 * layer;
    path.layer = layer;
    toolpath.paths.push_back(path);
  }
  toolpath.paths.push_back(testing_support::line(0, 5, 10, 5));
  const auto f = make_plot_fixture(toolpath, 0.5, false);
  const std::string directory = output_directory("stacked_layer_labels");
  const std::string section = drawn_section(f.input(), directory, RunPlot::path);
  const std::regex label_command(R"re(set label (\d+) "([^"]*)" at ([-\d.e]+),([-\d.e]+))re");
  std::vector<std::string> texts;
  for (std::sregex_iterator it(section.begin(), section.end(), label_command), end; it != end; ++it)
    texts.push_back((*it)[2].str() + " at " + (*it)[3].str() + "," + (*it)[4].str());
  EXPECT_EQ(texts, (std::vector<std::string>{"0–2 at 5,0", "3 at 5,5"})) << section;
}

// thickness.png draws the print paths over a map they leave legible (7 lines 1 mm apart) and
// leaves them off one they would hide (60 lines 0.2 mm apart), the key saying so
TEST(RunPlots, ThePrintPathsAreLeftOffAMapTheyWouldHide) {
  for (const int lines : {7, 60}) {
    SCOPED_TRACE(lines);
    const double spacing_mm = lines == 7 ? 1.0 : 0.2;
    Toolpath toolpath;
    for (int i = 0; i < lines; ++i)
      toolpath.paths.push_back(i % 2 == 0
                                   ? testing_support::line(0, i * spacing_mm, 10, i * spacing_mm)
                                   : testing_support::line(10, i * spacing_mm, 0, i * spacing_mm));
    toolpath.start_mm = toolpath.paths.front().front();
    toolpath.end_mm = toolpath.paths.back().back();
    const auto f = make_plot_fixture(toolpath, 0.2);
    const std::string directory = output_directory("overlay_" + std::to_string(lines));
    const std::string section = drawn_section(f.input(), directory, RunPlot::thickness);
    const bool drawn = section.find("thickness_map_paths.dat") != std::string::npos;
    const bool said = section.find("print paths: too dense to draw") != std::string::npos;
    EXPECT_EQ(drawn, lines == 7) << section;
    EXPECT_EQ(said, lines == 60) << section;
  }
}

TEST(RunPlots, PlanOnlyRunWithoutThickness) {
  auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5, false);
  auto input = f.input("plan only");
  input.thickness = nullptr;
  input.profiles.clear();
  const std::vector<RunPlot> expected = {RunPlot::path, RunPlot::axes, RunPlot::errors};
  EXPECT_EQ(plots::available_plots(input), expected);
  const std::string directory = output_directory("plan_only");
  const auto result = plots::render_run_plots(input, directory);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 3u);
  for (const auto& file : result.files)
    expect_png(file, plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);
  // asking for a thickness plot without a map is the caller's bug
  EXPECT_THROW(plots::render_run_plots(input, directory, {RunPlot::thickness}), InternalError);
}

TEST(RunPlots, NoTransitionRunRendersCleanly) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, true, true);
  const std::string directory = output_directory("no_transitions");
  const auto result = plots::render_run_plots(f.input("single line"), directory);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 5u);
  for (const auto& file : result.files)
    expect_png(file, plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);
}

TEST(RunPlots, NothingDepositedStillRendersEveryFrame) {
  Toolpath toolpath;  // a move from start to end, no print path
  toolpath.end_mm = Vec3(5, 3, 0);
  const auto f = make_plot_fixture(toolpath, 2.0);
  ASSERT_EQ(f.expected_transitions.size(), 1u);
  auto input = f.input("no print paths");
  input.thickness = nullptr;
  input.profiles.clear();
  const plots::RunPlotData data = plots::prepare_run_plot_data(input);
  EXPECT_EQ(data.planned_speed_error_pct.point_count(), 0u);
  EXPECT_EQ(data.planned_print_xy.point_count(), 0u);
  const std::string directory = output_directory("nothing_deposited");
  const auto result = plots::render_run_plots(input, directory);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 3u);
  for (const auto& file : result.files)
    expect_png(file, plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);
}

// thickness_profile.png's key, read from the script gnuplot ran: the two reference lines
// (target, centreline mean) and the profiles; `expected` titles per profile element ("" for
// notitle) and whether they share one colour. Each profile's data file holds that line's
// profile, point for point (the fixture's profiles are below the decimation budget).
void expect_profile_key(const testing_support::PlotFixture& fixture,
                        const plots::RunPlotInput& input, const std::string& name,
                        const std::vector<std::string>& expected, bool one_colour) {
  SCOPED_TRACE(name);
  const std::string directory = output_directory(name);
  const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  const auto result =
      plots::render_run_plots(input, directory + "/plot", {RunPlot::thickness_profile}, options);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 1u);
  expect_png(result.files[0], plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px);

  const std::vector<std::string> elements = testing_support::plot_elements(
      testing_support::png_section(capture.script(), "thickness_profile.png"));
  ASSERT_EQ(elements.size(), 2 + expected.size()) << capture.script();
  EXPECT_EQ(testing_support::key_title(elements[0]), "target 10 µm");
  EXPECT_EQ(testing_support::key_title(elements[1]).rfind("centreline mean ", 0), 0u);
  std::vector<std::string> titles, colours;
  for (size_t e = 2; e < elements.size(); ++e) {
    titles.push_back(testing_support::key_title(elements[e]));
    colours.push_back(testing_support::line_colour(elements[e]));
    // the data: the profile it names, every point
    const std::string file = testing_support::data_file_name(elements[e]);
    ASSERT_EQ(file.rfind("profile_", 0), 0u) << elements[e];
    const size_t index = std::stoul(file.substr(8));
    ASSERT_LT(index, fixture.profiles.size());
    const auto& profile = fixture.profiles[index];
    const auto rows = testing_support::read_rows(capture.folder + "/" + file);
    ASSERT_EQ(rows.size(), profile.arc_length_mm.size()) << file;
    for (size_t k = 0; k < rows.size(); ++k) {
      ASSERT_EQ(rows[k].size(), 2u);
      EXPECT_NEAR(rows[k][0], profile.arc_length_mm[k], 1e-6) << file << " row " << k;
      EXPECT_NEAR(rows[k][1], profile.thickness_um[k], 1e-5 * profile.thickness_um[k] + 1e-9)
          << file << " row " << k;
    }
  }
  EXPECT_EQ(titles, expected);
  const std::set<std::string> distinct(colours.begin(), colours.end());
  EXPECT_EQ(distinct.size(), one_colour ? 1u : colours.size());
  EXPECT_EQ(distinct.count(""), 0u);
}

// Past eight lines the profiles share one colour and one key entry, "paths first-last", not
// one entry each (that would fill the key and hide the plot); eight or fewer get an entry
// and a colour each. The shared entry stays when the first line has no profile (it goes on
// the first line drawn, naming the paths drawn).
TEST(RunPlots, ManyLinesShareOneProfileKeyEntry) {
  const auto many = make_plot_fixture(testing_support::raster_toolpath(12), 0.3, false);
  std::vector<std::string> shared(12, "");
  shared[0] = "paths 0-11";
  expect_profile_key(many, many.input("12 lines"), "many_lines", shared, true);

  const auto few = make_plot_fixture(testing_support::raster_toolpath(8), 0.3, false);
  std::vector<std::string> each;
  for (int i = 0; i < 8; ++i) each.push_back("path " + std::to_string(i));
  expect_profile_key(few, few.input("8 lines"), "eight_lines", each, false);

  // nine lines drawn of ten, the first without a profile
  auto gap = make_plot_fixture(testing_support::raster_toolpath(10), 0.3, false);
  gap.profiles[0].arc_length_mm.clear();
  gap.profiles[0].thickness_um.clear();
  std::vector<std::string> after_gap(9, "");
  after_gap[0] = "paths 1-9";
  expect_profile_key(gap, gap.input("10 lines, the first empty"), "first_line_empty", after_gap,
                     true);
}

// The key under thickness_profile.png holds two rows of three entries above the notes; eight
// lines and the two references (ten entries) would cover the notes there, so they go in one
// column right of the plot, and the notes stay clear.
TEST(RunPlots, AProfileKeyOfTenEntriesGoesBesideThePlotNotOverTheNotes) {
  for (int lines : {3, 8}) {
    SCOPED_TRACE(lines);
    const auto f = make_plot_fixture(testing_support::raster_toolpath(lines), 0.3, false);
    const std::string directory = output_directory("profile_key_" + std::to_string(lines));
    const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
    plots::PlotOptions options;
    options.gnuplot = capture.program;
    const auto result = plots::render_run_plots(f.input(), directory + "/plot",
                                                {RunPlot::thickness_profile}, options);
    EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
    const std::string section =
        testing_support::png_section(capture.script(), "thickness_profile.png");
    const bool beside =
        section.find("set key at screen 0.985,0.90 right top vertical") != std::string::npos;
    const bool below =
        section.find("set key at screen 0.5,0.235 center top horizontal") != std::string::npos;
    EXPECT_EQ(beside, lines == 8) << section;
    EXPECT_EQ(below, lines == 3) << section;
  }
}

// the numbers of the section's `set <command> [a:b]` or `set <command> a`, in order
std::vector<double> set_numbers(const std::string& section, const std::string& command) {
  std::smatch match;
  const std::regex pattern("set " + command + " \\[?([-0-9.e+]+)(?::([-0-9.e+]+)\\])?");
  if (!std::regex_search(section, match, pattern)) return {};
  std::vector<double> numbers = {std::stod(match[1])};
  if (match[2].matched) numbers.push_back(std::stod(match[2]));
  return numbers;
}

// A wide, short deposit (three 10 mm lines 1 mm apart): the one step the longer x axis gets
// would leave y (about 3 mm) a single tick; every axis of the map gets at least three.
TEST(RunPlots, EveryThicknessMapAxisHasAtLeastThreeTicks) {
  const auto f = make_plot_fixture(testing_support::raster_toolpath(3), 0.3, false);
  const std::string directory = output_directory("short_axis_ticks");
  const std::string section = drawn_section(f.input(), directory, RunPlot::thickness);
  for (const char* axis : {"x", "y"}) {
    SCOPED_TRACE(axis);
    const std::vector<double> range = set_numbers(section, axis + std::string("range"));
    const std::vector<double> step = set_numbers(section, axis + std::string("tics"));
    ASSERT_EQ(range.size(), 2u) << section;
    ASSERT_EQ(step.size(), 1u) << section;
    EXPECT_GE(plots::tick_count(range[0], range[1], step[0]), 3);
  }
}

// thickness.png of a job several times as wide as high (two 30 mm lines 2 mm apart) and thin
// (tick labels like 0.25): the colour bar's label stays inside the image (it ran past the right
// edge, "thickness (µm" cut)
TEST(RunPlots, AWideThicknessMapKeepsItsColourBarLabelInside) {
  Toolpath toolpath;
  toolpath.paths = {testing_support::line(0, 0, 30, 0), testing_support::line(30, 2, 0, 2)};
  toolpath.start_mm = toolpath.paths.front().front();
  toolpath.end_mm = toolpath.paths.back().back();
  auto f = make_plot_fixture(toolpath, 0.3, false);
  ASSERT_GE(f.thickness.nx, 3 * f.thickness.ny);
  // a thin deposit, peak 0.285 um: the colour bar's tick labels are four characters wide
  for (float& um : f.thickness.thickness_um) um *= 0.0285f;
  const std::string directory = output_directory("wide_thickness");
  const plots::PlotResult result =
      plots::render_run_plots(f.input(), directory, {RunPlot::thickness});
  ASSERT_EQ(result.files.size(), 1u);
  const std::string bytes = testing_support::read_bytes(result.files[0]);
  EXPECT_TRUE(testing_support::right_edge_blank(bytes, 4)) << result.files[0];
}

// thickness.png of a deposit with a blob 20 times its lines (layers stacked where they start):
// its colour scale is topped at 2 x the map's 95th percentile, as comparison.png's and
// layers.png's are, and says so over the map; an even deposit's reaches its own peak
TEST(RunPlots, AThicknessMapsScaleIsToppedOverABlob) {
  auto f = make_plot_fixture(testing_support::raster_toolpath(3), 0.3, false);
  const double peak_um = f.thickness.max_value();
  const std::string directory = output_directory("thickness_blob");
  const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  plots::render_run_plots(f.input(), directory + "/even", {RunPlot::thickness}, options);
  const std::string even = testing_support::png_section(capture.script(), "thickness.png");
  EXPECT_NE(even.find(plots::format("set cbrange [0:%.9g]", peak_um)), std::string::npos) << even;
  EXPECT_EQ(even.find("colour scale topped"), std::string::npos);

  for (int iy = 0; iy < 3; ++iy)
    for (int ix = 0; ix < 3; ++ix)
      f.thickness.thickness_um[static_cast<size_t>(iy) * f.thickness.nx + ix] =
          static_cast<float>(20 * peak_um);
  const plots::SharedThicknessScale scale = plots::capped_thickness_scale({&f.thickness});
  ASSERT_TRUE(scale.capped);
  EXPECT_LE(scale.top_um, 2.0 * peak_um);
  const auto blob_capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture-2");
  options.gnuplot = blob_capture.program;
  plots::render_run_plots(f.input(), directory + "/blob", {RunPlot::thickness}, options);
  const std::string blob = testing_support::png_section(blob_capture.script(), "thickness.png");
  EXPECT_NE(blob.find(plots::format("set cbrange [0:%.9g]", scale.top_um)), std::string::npos)
      << blob;
  EXPECT_NE(blob.find("colour scale topped at 2 × the 95th percentile"), std::string::npos) << blob;
}

// errors.png with tiny position errors (a fixture whose lines are followed to within
// micrometres: ticks like "0.0002"): the left margin leaves room for the widest tick label and
// the two-line y label beside it, so the label is not pushed past the image's edge.
TEST(RunPlots, ErrorsMarginFitsTheWidestTickLabelAndTheLabel) {
  EXPECT_EQ(plots::widest_tick_label(0, 0.027, 0.005), 5u);  // "0.005" .. "0.025"
  EXPECT_EQ(plots::widest_tick_label(0, 7.5e-5, 2e-5), 5u);  // "2e-05"
  EXPECT_EQ(plots::widest_tick_label(0, 0.3, 0.1), 3u);      // "0.1" (not 0.30000000000000004)
  auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.5);
  f.simulated = f.planned;  // the plan, 20 nm off the path: 2e-4 % of 10 mm
  for (Vec3& p : f.simulated.position_mm) p.y() += 2e-5;
  const std::string directory = output_directory("errors_tiny");
  const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  const auto result =
      plots::render_run_plots(f.input(), directory + "/plot", {RunPlot::errors}, options);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  const std::string section = testing_support::png_section(capture.script(), "errors.png");
  // the lower panel: the last margin, range and step set
  std::smatch match;
  const std::regex panel(
      "set lmargin at screen ([0-9.]+)\n[^]*?set yrange \\[0:([-0-9.e+]+)\\]"
      "\nset ytics ([-0-9.e+]+)");
  std::string rest = section;
  double left = 0, top = 0, step = 0;
  while (std::regex_search(rest, match, panel)) {
    left = std::stod(match[1]), top = std::stod(match[2]), step = std::stod(match[3]);
    rest = match.suffix();
  }
  ASSERT_GT(step, 0.0) << section;
  const size_t widest = plots::widest_tick_label(0, top, step);
  EXPECT_GE(widest, 5u);  // the case the margin must grow for
  // 7.5 px a character, two label lines of 17 px and a few px of gaps
  EXPECT_GE(left * plots::style::kRunPlotWidth_px, widest * 7.5 + 2 * 17 + 10);
  EXPECT_NE(section.find("set ylabel \"(b) position error\\n(% of 10 mm)\""), std::string::npos)
      << section;
}

// The tick step: the shared one when it gives three ticks, else the largest finer 1-2-5 step
// that does (giberti_fig3's 65 x 85 mm map: 20 mm, not 50 with only "0" on each axis)
TEST(Ticks, AShortAxisGetsAFinerStepWithThreeTicks) {
  EXPECT_DOUBLE_EQ(plots::round_step_up(85.0 / 4), 50.0);
  EXPECT_EQ(plots::tick_count(-30, 35, 50), 1);
  EXPECT_DOUBLE_EQ(plots::axis_tick_step(-30, 35, 50), 20.0);
  EXPECT_DOUBLE_EQ(plots::axis_tick_step(-40, 45, 50), 20.0);
  // an L's 3 mm leg beside its 10 mm one: 2 mm (0, 2, 4)
  EXPECT_DOUBLE_EQ(plots::axis_tick_step(-0.8, 4.3, 5), 2.0);
  // enough already: unchanged
  EXPECT_DOUBLE_EQ(plots::axis_tick_step(0, 100, 20), 20.0);
  EXPECT_EQ(plots::tick_count(-6, 7, plots::axis_tick_step(-6, 7, 10)), 3);
}

TEST(Comparison, OneColumnPerPlannerOnASharedScale) {
  const auto a = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  const auto b = make_plot_fixture(testing_support::thompson_like_toolpath(), 3.0);
  // a thinner second map: the shared colour range is set by the thicker one
  HeightMap thinner = b.thickness;
  for (float& v : thinner.thickness_um) v *= 0.5f;
  plots::ComparisonInput input;
  input.title = "fixture";
  input.toolpath = &a.toolpath;
  for (int c = 0; c < 3; ++c) {
    const auto& f = c == 0 ? a : b;
    plots::ComparisonColumn column;
    column.planner = c == 0 ? "lspb_mtt" : c == 1 ? "slow_transitions" : "plan_only";
    column.thickness = c == 0 ? &a.thickness : c == 1 ? &thinner : nullptr;
    plots::set_speed_error(column, c == 2 ? f.planned : f.simulated);
    column.transitions = plots::transition_intervals(f.trajectory);
    const VelocityErrorStats stats = velocity_error(c == 2 ? f.planned : f.simulated);
    column.max_speed_error_rel = stats.max_rel;
    column.rms_speed_error_rel = stats.rms_rel;
    if (c < 2) column.thickness_cv = 0.1 * (c + 1), column.waste_fraction = 0.2;
    column.total_time_s = f.trajectory.duration_s();
    input.columns.push_back(column);
  }
  // (its top: that peak, or 2 x the deposit's 95th percentile where lower; see
  // test_comparison_data.cpp)
  const plots::SharedThicknessScale scale = plots::shared_thickness_scale(input);
  EXPECT_FLOAT_EQ(static_cast<float>(scale.peak_um), a.thickness.max_value());
  EXPECT_LE(scale.top_um, scale.peak_um);
  EXPECT_EQ(scale.capped, scale.top_um < scale.peak_um);
  const std::string directory = output_directory("comparison");
  const auto result = plots::render_comparison(input, directory + "/comparison.png");
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  ASSERT_EQ(result.files.size(), 1u);
  expect_png(result.files[0], 3 * plots::style::kComparisonColumnWidth_px,
             plots::style::kComparisonHeight_px);
  EXPECT_EQ(entries(directory), std::vector<std::string>{"comparison.png"});
}

// A one-run sheet is one column (460 px) wide: the footer caption (about 120 characters,
// some 900 px on one line) is wrapped to lines that fit it, not cut off at both sides, and the
// sheet grows by the extra line.
TEST(Comparison, OneRunSheetWrapsItsFooterCaption) {
  EXPECT_EQ(plots::wrap_text("aa bb cc dd", 5), (std::vector<std::string>{"aa bb", "cc dd"}));
  EXPECT_EQ(plots::wrap_text("µµµ µµ", 6), (std::vector<std::string>{"µµµ µµ"}));  // characters
  EXPECT_EQ(plots::wrap_text("toolongword a", 4), (std::vector<std::string>{"toolongword", "a"}));

  const auto f = make_plot_fixture(testing_support::thompson_like_toolpath(), 1.5);
  plots::ComparisonInput input;
  input.title = "one run";
  input.toolpath = &f.toolpath;
  plots::ComparisonColumn column;
  column.planner = "bezier";
  column.thickness = &f.thickness;
  plots::set_speed_error(column, f.simulated);
  input.columns.push_back(column);
  const std::string directory = output_directory("comparison_one_run");
  const auto capture = testing_support::capturing_gnuplot(directory, "gnuplot-capture");
  plots::PlotOptions options;
  options.gnuplot = capture.program;
  const auto result = plots::render_comparison(input, directory + "/comparison.png", options);
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  const std::string script = capture.script();
  std::smatch match;
  ASSERT_TRUE(std::regex_search(script, match, std::regex("set label 900 \"([^\"]*)\""))) << script;
  const std::string caption = match[1];
  EXPECT_NE(caption.find("grey bands: transitions"), std::string::npos);
  EXPECT_NE(caption.find("thickest spot"), std::string::npos);
  // the maps' dashed overlay is named (it has no key of its own)
  EXPECT_NE(caption.find("dashed: the print paths"), std::string::npos);
  // lines split by gnuplot's \n, each at most the column's width at 8 px a character
  size_t lines = 0, start = 0;
  while (true) {
    const size_t end = caption.find("\\n", start);
    const std::string line = caption.substr(start, end == std::string::npos ? end : end - start);
    EXPECT_LE(line.size() * 8, static_cast<size_t>(plots::style::kComparisonColumnWidth_px))
        << line;
    ++lines;
    if (end == std::string::npos) break;
    start = end + 2;
  }
  EXPECT_GE(lines, 2u);
  expect_png(directory + "/comparison.png", plots::style::kComparisonColumnWidth_px,
             plots::style::kComparisonHeight_px + 17 * (lines - 1));
}

TEST(Gnuplot, MissingToolIsANamedInternalError) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, false, true);
  const std::string directory = output_directory("missing_gnuplot");
  plots::PlotOptions options;
  options.gnuplot = "depotwin-no-such-gnuplot";
  try {
    plots::render_run_plots(f.input(), directory, {}, options);
    FAIL() << "expected GnuplotNotFound";
  } catch (const InternalError& error) {  // exit status 1
    EXPECT_STREQ(
        error.what(),
        "gnuplot not found: install the Debian package gnuplot-nox (scripts/setup.sh does)");
  }
  options.gnuplot = "/nonexistent/bin/gnuplot";
  EXPECT_THROW(plots::render_run_plots(f.input(), directory, {}, options), plots::GnuplotNotFound);
  EXPECT_TRUE(entries(directory).empty());
}

TEST(Gnuplot, FailingToolLeavesNoPartialOutput) {
  const auto f = make_plot_fixture(testing_support::single_line_toolpath(), 1.0, false, true);
  const std::string directory = output_directory("failing_gnuplot");
  plots::PlotOptions options;
  options.gnuplot = "false";  // found on PATH, exits 1
  EXPECT_THROW(plots::render_run_plots(f.input(), directory, {}, options), InternalError);
  EXPECT_TRUE(entries(directory).empty());
}

}  // namespace
}  // namespace depotwin
