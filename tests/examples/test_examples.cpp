// The example outputs: every scenario in scenarios/ produces every plot through the CLI
// (right pixel size, not blank), and a job without transitions draws no shaded band.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/job.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "pipeline/run.hpp"
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
void expect_every_plot(const std::string& run_directory, int scene_width_px, int scene_height_px) {
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

class EveryScenario : public ::testing::TestWithParam<std::string> {};

// one planner per scenario (the first it lists) keeps this fast
TEST_P(EveryScenario, ProducesEveryPlot) {
  const std::string stem = GetParam();
  const std::string path = scenario_path(stem + ".yaml");
  const Scenario scenario = load_scenario(path);
  ASSERT_FALSE(scenario.planners.empty()) << path;
  const std::string planner = scenario.planners.front().run_label();
  const std::string out = fresh_directory("examples_" + stem);
  const Result run = depotwin("run " + quoted(path) + " --planner " + planner + " --out " +
                              quoted(out) + " --quiet");
  ASSERT_EQ(run.status, 0) << run.output;
  expect_every_plot(out + "/" + planner, scenario.outputs.image_width,
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
  expect_every_plot(out + "/stop_and_go", 640, 480);
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
