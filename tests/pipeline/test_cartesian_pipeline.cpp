// The cartesian machine end to end (issue 14): a three-layer G-code print read from the file,
// planned, simulated on the gantry's three servos, extruded layer on layer and scored per layer.
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "pipeline/job_check.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "pipeline/quiet_settings.hpp"
#include "pipeline/run.hpp"
#include "scenario/scenario.hpp"

namespace depotwin {
namespace {

using testing_support::fresh_directory;
using testing_support::quiet;
using testing_support::write_text;

// a 10 mm square (centred on the bed) printed three times, 0.2 mm apart, at 20 mm/s, with
// absolute E; the layer changes are travels (no E)
std::string square_layers_gcode() {
  std::string text = "; three layers of a 10 mm square\nG21\nG90\nM82\nG92 E0\n";
  double e = 0.0;
  for (int layer = 0; layer < 3; ++layer) {
    text += "G1 Z" + std::to_string(0.2 * (layer + 1)) + " F600\n";
    text += "G0 X-5 Y-5 F3000\n";
    const char* corners[4] = {"X5 Y-5", "X5 Y5", "X-5 Y5", "X-5 Y-5"};
    for (int k = 0; k < 4; ++k) {
      e += 0.4;
      text += std::string("G1 ") + corners[k] + " E" + std::to_string(e) +
              (k == 0 ? " F1200" : "") + "\n";
    }
  }
  return text;
}

class CartesianPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string dir = fresh_directory("cartesian_pipeline");
    write_text(dir, "square.gcode", square_layers_gcode());
    const std::string scenario = write_text(dir, "square.yaml", R"(name: cartesian_square
machine: cartesian
limits: {v_max: 100, a_max: 1000}
process: {type: extrusion, bead_width_mm: 0.4, layer_height_mm: 0.2}
toolpath:
  gcode: square.gcode
planners: [lspb_mtt]
)");
    job_ = new PreparedJob(prepare_job(load_scenario(scenario)));
    run_ = new SimulatedRun(simulate_job(*job_, job_->scenario.planners.front(), quiet()));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete job_;
  }
  static PreparedJob* job_;
  static SimulatedRun* run_;
};
PreparedJob* CartesianPipeline::job_ = nullptr;
SimulatedRun* CartesianPipeline::run_ = nullptr;

// three layers of one closed square each, starting (by default) at the file's first point and
// ending above it on the top layer (not by a move down through the layers)
TEST_F(CartesianPipeline, ReadsThreeLayersAndStartsAtTheFirstPoint) {
  const Toolpath& toolpath = job_->toolpath;
  ASSERT_EQ(toolpath.paths.size(), 3u);
  EXPECT_EQ(toolpath.layer_count(), 3);
  for (int layer = 0; layer < 3; ++layer) {
    EXPECT_EQ(toolpath.paths[layer].layer, layer);
    EXPECT_NEAR(toolpath.paths[layer].length_mm(), 40.0, 1e-9);
    EXPECT_NEAR(toolpath.paths[layer].points.front().z(), 0.2 * (layer + 1), 1e-9);
  }
  EXPECT_LT((toolpath.start_mm - Vec3(-5, -5, 0.2)).norm(), 1e-9);
  EXPECT_LT((toolpath.end_mm - Vec3(-5, -5, 0.6)).norm(), 1e-9);
  // `auto` says which rule it chose, in metrics.json's warnings
  ASSERT_FALSE(run_->report.warnings.empty());
  EXPECT_NE(run_->report.warnings.front().find("toolpath.gcode: auto chose e"), std::string::npos)
      << run_->report.warnings.front();
}

// the deposit stacks: the stacked field is the sum of the layers', its volume the extruded
// volume (3 x 40 mm x 0.4 mm x 0.2 mm = 9.6 mm^3), and mid-edge it is three beads high
TEST_F(CartesianPipeline, LayersStackToTheExtrudedVolume) {
  const LayeredDeposit& deposit = *run_->deposit;
  ASSERT_EQ(deposit.layer_count(), 3);
  double layer_sum_mm3 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double volume_mm3 = deposit.layer_normal_field(k).total_volume_mm3();
    EXPECT_NEAR(volume_mm3, 3.2, 0.01 * 3.2) << "layer " << k;
    layer_sum_mm3 += volume_mm3;
  }
  EXPECT_NEAR(deposit.field().total_volume_mm3(), layer_sum_mm3, 1e-9 * layer_sum_mm3);
  EXPECT_NEAR(deposit.account().emitted_mm3, 9.6, 0.01 * 9.6);
  // a straight bead's centreline peak is 1.60 h = 0.319 mm (README, thickness_profile.png),
  // 0.309 mm at the nearest cell centre (a quarter sigma off the line): three of them
  double stacked_mm = deposit.field().thickness_mm_at(0.0, -5.0);
  double layers_mm = 0.0;
  for (int k = 0; k < 3; ++k) layers_mm += deposit.layer_normal_field(k).thickness_mm_at(0.0, -5.0);
  EXPECT_NEAR(stacked_mm, layers_mm, 1e-9);
  EXPECT_NEAR(stacked_mm, 3 * 0.309, 0.03);
}

// thickness_profile.png's lines: each path read on its own layer's deposit, one bead high
// (0.309 mm at the nearest cell centre, as above), never the stack of three under it
TEST_F(CartesianPipeline, EachLineProfileIsItsOwnLayersBead) {
  const std::vector<plots::LineProfile> profiles =
      centreline_profiles(*run_->deposit, job_->toolpath);
  ASSERT_EQ(profiles.size(), 3u);
  for (size_t i = 0; i < profiles.size(); ++i) {
    const plots::LineProfile& profile = profiles[i];
    ASSERT_GT(profile.thickness_um.size(), 100u);
    // an eighth of the 40 mm: the first edge's middle, 5 mm from either corner
    const double mid_um = profile.thickness_um[profile.thickness_um.size() / 8];
    EXPECT_GT(mid_um, 0.8 * 309.0) << "path " << i;
    EXPECT_LT(mid_um, 1.2 * 319.0) << "path " << i;
  }
}

// metrics per layer and overall; the gantry follows the plan: its path error is the plan's own
// (lspb_mtt rounds each 90 degree corner by 0.05 mm at 20 mm/s) plus at most 5 um of tracking
TEST_F(CartesianPipeline, ScoresEachLayerAndTracksThePath) {
  const MetricsReport& report = run_->report;
  ASSERT_EQ(report.layers.size(), 3u);
  for (const LayerReport& layer : report.layers) {
    EXPECT_EQ(layer.paths, 1);
    EXPECT_NEAR(layer.print_length_mm, 40.0, 1e-6);
    ASSERT_TRUE(layer.path_error.has_value());
    EXPECT_LT(layer.path_error->max_mm, layer.planned_path_error.max_mm + 0.005);
  }
  ASSERT_TRUE(report.path_error.has_value());
  EXPECT_LT(report.path_error->max_mm, report.planned_path_error.max_mm + 0.005);
}

// a plan that leaves the travel (lspb_mtt's flying transition from an intro line ending at the
// bed's edge, x = 100, overshoots it by about 0.013 mm) is refused at the planner's entry in
// the scenario, by name: file, line and key, not a bare "trajectory"
TEST(CartesianPlanOutsideTravel, IsNamedAtThePlannersEntry) {
  const std::string dir = fresh_directory("cartesian_plan_outside_travel");
  const std::string scenario = write_text(dir, "edge.yaml", R"(name: edge
machine: cartesian
limits: {v_max: 200, a_max: 1250}
process: {type: extrusion, bead_width_mm: 0.45, layer_height_mm: 0.2}
toolpath:
  speed: 16.6667
  polylines:
    - [[60, -3, 0.2], [100, -3, 0.2]]
    - [[20, 20, 0.2], [40, 20, 0.2]]
planners: [lspb_mtt]
)");
  const auto expect_named = [&](const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    const Problem& problem = e.problems()[0];
    EXPECT_EQ(problem.file, scenario);
    EXPECT_EQ(problem.line, 10);
    EXPECT_EQ(problem.key, "planners");
    const std::string& message = problem.message;
    EXPECT_EQ(message.rfind("the lspb_mtt plan at t = ", 0), 0u) << message;
    EXPECT_NE(message.find(" s (in a transition the planner added): the cartesian machine's x "
                           "axis at 100.01 mm is outside its travel [-100, 100] mm, by 0.01"),
              std::string::npos)
        << message;
  };
  // as the simulation solves the plan's poses
  const Scenario loaded = load_scenario(scenario);
  const PreparedJob job = prepare_job(loaded);
  try {
    simulate_job(job, job.scenario.planners.front(), quiet());
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    expect_named(e);
  }
  // and the same, word for word, by validate's checks, which solve the plans' poses (validate
  // used to pass the file)
  try {
    prepare_checked_job(loaded, loaded.planners, JobBudget{}, true, false, nullptr, true);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    expect_named(e);
  }
  // run's checks leave the poses to the simulation (above); a plan alone (`depotwin plan`) is
  // not simulated: neither refuses it before
  EXPECT_NO_THROW(prepare_checked_job(loaded, loaded.planners, JobBudget{}, true, false));
  EXPECT_NO_THROW(prepare_checked_job(loaded, loaded.planners, JobBudget{}, false, false));
}

}  // namespace
}  // namespace depotwin
