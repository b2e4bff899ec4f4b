// The example outputs: every scenario in scenarios/ produces every plot through the CLI, each
// drawn from that run's data (what gnuplot was given, captured, against the scenario's paths
// and the run's metrics.json; the plots' colours in the pixels), and a job without
// transitions draws no shaded band.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "metrics/motion_metrics.hpp"
#include "pipeline/job.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "pipeline/run.hpp"
#include "plots/gnuplot_capture.hpp"
#include "plots/plots.hpp"
#include "plots/png_check.hpp"
#include "plots/style.hpp"
#include "scenario/scenario.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::pixel_variance;
using testing_support::png_header;
using testing_support::read_bytes;
using testing_support::scenario_path;
using testing_support::write_text;

using Result = testing_support::CliResult;
using testing_support::depotwin;

std::string quoted(const std::string& path) {
  return "'" + path + "'";
}

// the scenario files shipped in scenarios/, sorted
std::vector<std::string> scenario_stems() {
  std::vector<std::string> stems;
  for (const auto& entry : fs::directory_iterator(DEPOTWIN_SCENARIOS_DIR))
    if (entry.path().extension() == ".yaml") stems.push_back(entry.path().stem().string());
  std::sort(stems.begin(), stems.end());
  return stems;
}

// every image of a rendered run has its pixel size and is not blank
void expect_every_plot_size(const std::string& run_directory, int scene_width_px,
                            int scene_height_px) {
  struct Expected {
    const char* file;
    int width_px, height_px;
  };
  const Expected expected[] = {
      {"path.png", plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px},
      {"axes.png", plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px},
      {"errors.png", plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px},
      {"thickness_profile.png", plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px},
      {"thickness.png", plots::style::kRunPlotWidth_px, plots::style::kRunPlotHeight_px},
      {"scene.png", scene_width_px, scene_height_px},
  };
  for (const Expected& e : expected) {
    const std::string path = run_directory + "/" + e.file;
    ASSERT_TRUE(fs::exists(path)) << path;
    const std::string bytes = read_bytes(path);
    const auto header = png_header(bytes);
    ASSERT_TRUE(header.valid) << path;
    EXPECT_EQ(header.width, static_cast<std::uint32_t>(e.width_px)) << path;
    EXPECT_EQ(header.height, static_cast<std::uint32_t>(e.height_px)) << path;
    EXPECT_GT(pixel_variance(bytes), 0.0) << path << " is blank or does not decode";
  }
}

// the built CLI with a folder put first on PATH (where a stand-in gnuplot waits)
Result depotwin_with_path(const std::string& bin_directory, const std::string& arguments) {
  const std::string command = "PATH=" + quoted(bin_directory) + ":\"$PATH\" " +
                              std::string(DEPOTWIN_BINARY_DIR) + "/depotwin " + arguments + " 2>&1";
  Result result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// the pixels of a PNG, RGB rows top to bottom, and its width
struct Pixels {
  std::vector<unsigned char> rgb;
  int width = 0, height = 0;
  // pixels within `tolerance` (per channel, 0..255) of the colour "#rrggbb", in rows
  // [row_lo, row_hi)
  long count(const std::string& hex, int tolerance, int row_lo = 0, int row_hi = -1) const {
    const int target[3] = {std::stoi(hex.substr(1, 2), nullptr, 16),
                           std::stoi(hex.substr(3, 2), nullptr, 16),
                           std::stoi(hex.substr(5, 2), nullptr, 16)};
    long n = 0;
    const size_t end = 3 * static_cast<size_t>(width) * (row_hi < 0 ? height : row_hi);
    for (size_t i = 3 * static_cast<size_t>(width) * row_lo; i < end; i += 3) {
      int difference = 0;
      for (int c = 0; c < 3; ++c)
        difference = std::max(difference, std::abs(rgb[i + c] - target[c]));
      n += difference <= tolerance;
    }
    return n;
  }
};
Pixels read_pixels(const std::string& path) {
  Pixels p;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &p.width, &p.height, &channels, 3);
  if (data == nullptr) return p;
  p.rgb.assign(data, data + 3 * static_cast<size_t>(p.width) * p.height);
  stbi_image_free(data);
  return p;
}

// the element of `elements` with this key title
const std::string* titled(const std::vector<std::string>& elements, const std::string& title) {
  for (const std::string& e : elements)
    if (testing_support::key_title(e) == title) return &e;
  return nullptr;
}

// the rows of the data file an element plots, from the captured job
std::vector<std::vector<double>> element_rows(const testing_support::GnuplotCapture& capture,
                                              const std::string& element) {
  return testing_support::read_rows(capture.folder + "/" +
                                    testing_support::data_file_name(element));
}

// thickness.csv read back: its cell size, and the sum and peak of its cells (µm)
struct ThicknessCsv {
  double cell_mm = 0.0;
  double sum_um = 0.0;
  double peak_um = 0.0;
};
ThicknessCsv read_thickness_csv(const std::string& path) {
  ThicknessCsv csv;
  std::istringstream in(read_bytes(path));
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) {
      const std::size_t at = line.find("cell_mm=");
      if (at != std::string::npos) csv.cell_mm = std::stod(line.substr(at + 8));
      continue;
    }
    if (header) {  // the columns' x
      header = false;
      continue;
    }
    std::istringstream row(line);
    std::string cell;
    std::getline(row, cell, ',');  // the row's y
    while (std::getline(row, cell, ',')) {
      const double value = std::stod(cell);
      csv.sum_um += value;
      csv.peak_um = std::max(csv.peak_um, value);
    }
  }
  return csv;
}

// Every plot of a run shows this run's data, read from what gnuplot was given (the script and
// its data files, captured) and from the pixels:
// - path.png: the planned printing path, every point of it within the plan's path error
//   (metrics.json) of the scenario's own print paths; the simulated path, start and end; the
//   planned path's colour in the picture;
// - axes.png and errors.png: their curves span the job's time (metrics.json time_s.total), the
//   errors at least its print time; the planned speed error never exceeds metrics.json's
//   planned maximum;
// - thickness_profile.png: a profile of the deposit and the target line;
// - thickness.png: the deposit map (thickness.csv's block maxima: its peak, at least its
//   volume; thickness.csv's volume is the material that landed, metrics.json on_target +
//   overspray), under the scenario's print paths; the palette's top colour (the map's
//   thickest cell) in the picture;
// - scene.png: the colour bar's bottom and top colours.
void expect_every_plot(const std::string& run_directory,
                       const testing_support::GnuplotCapture& capture, const Scenario& scenario,
                       int scene_width_px, int scene_height_px) {
  expect_every_plot_size(run_directory, scene_width_px, scene_height_px);
  const nlohmann::json metrics =
      nlohmann::json::parse(testing_support::read_bytes(run_directory + "/metrics.json"));
  const std::string script = capture.script();
  ASSERT_FALSE(script.empty()) << "no gnuplot job captured";
  const auto elements_of = [&](const char* png) {
    return testing_support::plot_elements(testing_support::png_section(script, png));
  };
  // the scenario's print paths in x-y (arcs followed within 0.1 um)
  std::vector<std::vector<Vec3>> print_paths;
  for (const PrintPath& path : scenario.toolpath.paths) {
    std::vector<Vec3> points;
    for (const Vec3& p : (path.has_arcs() ? path.chorded(1e-4) : path).points)
      points.push_back(Vec3(p.x(), p.y(), 0.0));
    print_paths.push_back(points);
  }
  const auto distance_to_paths = [&](double x, double y) {
    double nearest_mm = 1e9;
    for (const auto& path : print_paths)
      nearest_mm = std::min(nearest_mm, distance_to_polyline(Vec3(x, y, 0), path));
    return nearest_mm;
  };
  ASSERT_FALSE(print_paths.empty());

  // path.png
  {
    SCOPED_TRACE("path.png");
    const auto elements = elements_of("path.png");
    for (const char* title : {"planned: printing", "simulated", "start", "end"})
      EXPECT_NE(titled(elements, title), nullptr) << title;
    const std::string* printing = titled(elements, "planned: printing");
    ASSERT_NE(printing, nullptr);
    const auto rows = element_rows(capture, *printing);
    ASSERT_GT(rows.size(), 10u);
    const double tolerance_mm = metrics["planned_path_error_mm"]["max"].get<double>() * 1.01 + 1e-3;
    double farthest_mm = 0.0;
    for (const auto& row : rows)
      farthest_mm = std::max(farthest_mm, distance_to_paths(row[0], row[1]));
    EXPECT_LE(farthest_mm, tolerance_mm);
    EXPECT_GT(read_pixels(run_directory + "/path.png").count(plots::style::kPlannedColour, 8), 100);
  }

  // axes.png and errors.png: the job's whole time
  const double total_s = metrics["time_s"]["total"].get<double>();
  for (const char* png : {"axes.png", "errors.png"}) {
    SCOPED_TRACE(png);
    const auto elements = elements_of(png);
    size_t curves = 0;
    double t_lo = 1e9, t_hi = -1e9;
    for (const std::string& element : elements) {
      if (testing_support::data_file_name(element).empty()) continue;
      ++curves;
      for (const auto& row : element_rows(capture, element)) {
        t_lo = std::min(t_lo, row[0]);
        t_hi = std::max(t_hi, row[0]);
      }
    }
    EXPECT_GE(curves, 2u);
    EXPECT_GE(t_lo, 0.0);
    EXPECT_LE(t_hi, total_s + 0.01);
    // the axes from start to end; the errors where material is on, at least the print time
    if (std::string(png) == "axes.png") {
      EXPECT_LT(t_lo, 0.01 * total_s);
      EXPECT_GT(t_hi, 0.99 * total_s);
    } else {
      EXPECT_GE(t_hi - t_lo, 0.99 * metrics["time_s"]["print"].get<double>());
    }
  }
  {
    const auto elements = elements_of("errors.png");
    const std::string* planned = titled(elements, "planned");
    ASSERT_NE(planned, nullptr);
    double largest_pct = 0.0;
    for (const auto& row : element_rows(capture, *planned))
      largest_pct = std::max(largest_pct, row[1]);
    EXPECT_LE(
        largest_pct,
        100.0 * metrics["planned_velocity_error"]["max_rel"].get<double>() * (1 + 1e-6) + 1e-6);
  }

  // thickness_profile.png
  {
    SCOPED_TRACE("thickness_profile.png");
    const auto elements = elements_of("thickness_profile.png");
    size_t profiles = 0;
    for (const std::string& element : elements)
      if (testing_support::data_file_name(element).rfind("profile_", 0) == 0) {
        ++profiles;
        EXPECT_FALSE(element_rows(capture, element).empty()) << element;
      }
    EXPECT_GE(profiles, 1u);
    EXPECT_LE(profiles, print_paths.size());
    bool target = false;
    for (const std::string& element : elements)
      target = target || testing_support::key_title(element).rfind("target ", 0) == 0;
    EXPECT_TRUE(target);
  }

  // thickness.png: the map's volume and the print paths over it
  {
    SCOPED_TRACE("thickness.png");
    const auto elements = elements_of("thickness.png");
    ASSERT_GE(elements.size(), 2u);
    std::smatch match;
    ASSERT_TRUE(std::regex_search(elements[0], match,
                                  std::regex("array=\\((\\d+),(\\d+)\\) dx=([-0-9.eE+]+)")))
        << elements[0];
    const size_t nx = std::stoul(match[1]), ny = std::stoul(match[2]);
    const double cell_mm = std::stod(match[3]);
    const std::string map =
        read_bytes(capture.folder + "/" + testing_support::data_file_name(elements[0]));
    ASSERT_EQ(map.size(), 4 * nx * ny);
    double shown_sum_um = 0.0, shown_peak_um = 0.0;
    for (size_t k = 0; k < nx * ny; ++k) {
      float value = 0.0f;
      std::memcpy(&value, map.data() + 4 * k, 4);
      shown_sum_um += value;
      shown_peak_um = std::max(shown_peak_um, static_cast<double>(value));
    }
    // the deposit at full resolution (thickness.csv): its volume is what landed, and the map
    // shown (block maxima, so that a thin bead keeps its colour) has its peak and at least
    // its volume
    const ThicknessCsv field = read_thickness_csv(run_directory + "/thickness.csv");
    ASSERT_GT(field.cell_mm, 0.0);
    const double landed_mm3 = metrics["material_mm3"]["on_target"].get<double>() +
                              metrics["material_mm3"]["overspray"].get<double>();
    // (on a part the map is the thickness along the normal: not a vertical volume)
    if (scenario.toolpath.layer_count() == 1 && !scenario.surface) {
      EXPECT_NEAR(1e-3 * field.sum_um * field.cell_mm * field.cell_mm, landed_mm3,
                  0.01 * landed_mm3);
    }
    EXPECT_NEAR(shown_peak_um, field.peak_um, 1e-3 * field.peak_um + 1e-3);
    EXPECT_GE(shown_sum_um * cell_mm * cell_mm,
              (1.0 - 1e-4) * field.sum_um * field.cell_mm * field.cell_mm);
    // the overlay: on the scenario's paths, through both ends of every one; left off a map it
    // would hide (a dense hatch), the key saying so
    ASSERT_TRUE(std::regex_search(elements[0], match,
                                  std::regex("origin=\\(([-0-9.eE+]+),([-0-9.eE+]+)\\)")))
        << elements[0];
    const double x_lo = std::stod(match[1]) - 0.5 * cell_mm;
    const double y_lo = std::stod(match[2]) - 0.5 * cell_mm;
    const std::string* overlay = titled(elements, "print path");
    if (plots::paths_crowd_window(scenario.toolpath, x_lo, x_lo + nx * cell_mm, y_lo,
                                  y_lo + ny * cell_mm)) {
      EXPECT_EQ(overlay, nullptr);
      EXPECT_NE(titled(elements, "print paths: too dense to draw over the map"), nullptr);
    } else {
      ASSERT_NE(overlay, nullptr);
      const auto overlay_rows = element_rows(capture, *overlay);
      for (const auto& row : overlay_rows) EXPECT_LT(distance_to_paths(row[0], row[1]), 1e-4);
      for (const auto& path : print_paths)
        for (const Vec3& end : {path.front(), path.back()}) {
          double nearest_mm = 1e9;
          for (const auto& row : overlay_rows)
            nearest_mm = std::min(nearest_mm, std::hypot(row[0] - end.x(), row[1] - end.y()));
          EXPECT_LT(nearest_mm, 1e-4);
        }
    }
    EXPECT_GT(read_pixels(run_directory + "/thickness.png").count("#fde725", 12), 0);
  }

  // scene.png: the colour bar
  {
    const Pixels scene = read_pixels(run_directory + "/scene.png");
    EXPECT_GT(scene.count("#440154", 6, scene.height * 3 / 4), 10) << "scene.png";
    EXPECT_GT(scene.count("#fde725", 6, scene.height * 3 / 4), 10) << "scene.png";
  }
}

class EveryScenario : public ::testing::TestWithParam<std::string> {};

// one planner per scenario (the first it lists) keeps this fast
TEST_P(EveryScenario, ProducesEveryPlot) {
  const std::string stem = GetParam();
  const std::string path = scenario_path(stem + ".yaml");
  const Scenario scenario = load_scenario(path);
  ASSERT_FALSE(scenario.planners.empty()) << path;
  const std::string planner = scenario.planners.front().run_label();
  const std::string out = fresh_directory("examples_" + stem);
  const auto capture = testing_support::capturing_gnuplot(out);
  const Result run = depotwin_with_path(out, "run " + quoted(path) + " --planner " + planner +
                                                 " --out " + quoted(out + "/runs") + " --quiet");
  ASSERT_EQ(run.status, 0) << run.output;
  expect_every_plot(out + "/runs/" + planner, capture, scenario, scenario.outputs.image_width,
                    scenario.outputs.image_height);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, EveryScenario, ::testing::ValuesIn(scenario_stems()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

// the transition bands the run plots of a scenario shade, from the data behind axes.png and
// errors.png (built as the pipeline builds it)
std::vector<plots::TimeInterval> shaded_bands(const std::string& path, double& total_s) {
  const Scenario scenario = load_scenario(path);
  const PreparedJob job = prepare_job(scenario);
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  const SimulatedRun run = simulate_job(job, scenario.planners.front(), settings);
  plots::RunPlotInput input;
  input.title = scenario.name;
  input.toolpath = &job.toolpath;
  input.planned = &run.planned_at_steps;
  input.simulated = &run.simulated;
  input.transitions = plots::transition_intervals(run.plan.trajectory);
  total_s = run.plan.trajectory.duration_s();
  return plots::prepare_run_plot_data(input).transitions;
}

// one print line from the start point to the end point, printed stop-and-go (from rest at the
// line's start to rest at its end; lspb_mtt would run up to print speed before the line, a
// transition): material on the whole job, so the axes and error plots shade nothing (and
// their script has no band and no key entry)
TEST(NoTransitions, SingleLineShadesNothing) {
  const std::string dir = fresh_directory("examples_single_line");
  const std::string path = write_text(dir, "single_line.yaml", R"(name: single_line
machine: xy_stage
limits: {v_max: 4, a_max: 30}
process: {type: aerosol}
toolpath:
  speed: 3
  start: [0, 0]
  end: [8, 0]
  segments:
    - [[0, 0], [8, 0]]
order: as_given
planners: [stop_and_go]
)");
  double total_s = 0.0;
  const auto bands = shaded_bands(path, total_s);
  EXPECT_TRUE(bands.empty()) << bands.size() << " bands, first " << bands.front().begin_s << " - "
                             << bands.front().end_s << " s";
  EXPECT_EQ(plots::style::transition_shading(bands), "");
  EXPECT_EQ(plots::style::transition_key_entry(bands), "");
  // 8 mm at 3 mm/s plus the ramps at a_max 30 mm/s^2: 8/3 + 3/30 s (trapezoid from and to rest)
  EXPECT_NEAR(total_s, 8.0 / 3.0 + 3.0 / 30.0, 1e-6);

  // and the CLI still draws every plot for it
  const std::string out = dir + "/out";
  const Result run = depotwin("run " + quoted(path) + " --out " + quoted(out) + " --quiet");
  ASSERT_EQ(run.status, 0) << run.output;
  expect_every_plot_size(out + "/stop_and_go", 640, 480);
}

// the control: Thompson & Yoon's Fig. 7 has four transitions (start -> line 1, line 3 -> 4,
// 4 -> 5, 5 -> end; lines 1-3 are connected), the first from t = 0, the last to the job end
TEST(NoTransitions, Fig7ShadesFourBands) {
  double total_s = 0.0;
  const auto bands = shaded_bands(scenario_path("thompson_fig7.yaml"), total_s);
  ASSERT_EQ(bands.size(), 4u);
  EXPECT_EQ(bands.front().begin_s, 0.0);
  EXPECT_NEAR(bands.back().end_s, total_s, 1e-9);
  for (const auto& band : bands) EXPECT_LT(band.begin_s, band.end_s);
  EXPECT_NE(plots::style::transition_shading(bands), "");
}

}  // namespace
}  // namespace depotwin
