// The depotwin command line as users and outside tools call it: verbs, help, exit status,
// messages naming file/line/key, and nothing half-written on failure.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/pipeline_test_util.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::scenario_path;
using testing_support::write_text;

using Result = testing_support::CliResult;
using testing_support::depotwin;

TEST(Cli, HelpOnEveryVerb) {
  const Result top = depotwin("--help");
  EXPECT_EQ(top.status, 0);
  for (const char* verb : {"run", "compare", "plan", "move", "validate"}) {
    EXPECT_NE(top.output.find(verb), std::string::npos) << verb;
    const Result help = depotwin(std::string(verb) + " --help");
    EXPECT_EQ(help.status, 0) << verb;
    EXPECT_NE(help.output.find("Usage"), std::string::npos) << verb << ": " << help.output;
  }
  EXPECT_EQ(depotwin("").status, 2);  // a verb is required
  EXPECT_EQ(depotwin("fly-to-mars").status, 2);
}

TEST(Cli, MoveOvershootCase) {
  // v0 = 4 towards a target 0.1 mm ahead: overshoot and come back, 0.282405 s
  const Result r = depotwin("move --q0 0 --q1 0.1 --v0 4 --v1 0 --vmax 4 --amax 30");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output);
  EXPECT_NEAR(json["duration_s"].get<double>(), 0.282405, 5e-7);
  ASSERT_EQ(json["axes"].size(), 1u);
  const auto& phases = json["axes"][0]["phases"];
  ASSERT_EQ(phases.size(), 2u);
  EXPECT_DOUBLE_EQ(phases[0]["acceleration"].get<double>(), -30.0);
  EXPECT_NEAR(phases.back()["v_end"].get<double>(), 0.0, 1e-9);
}

TEST(Cli, MoveSynchronisesAxesAndRejectsBadInput) {
  const Result r = depotwin("move --q0 0,0 --q1 0,0.3 --v0 3,0 --v1 3,0 --vmax 4 --amax 30");
  ASSERT_EQ(r.status, 0) << r.output;
  // x (d = 0, v0 = v1 = 3) is blocked on (0, 0.4): the common duration is 0.4 s
  EXPECT_NEAR(nlohmann::json::parse(r.output)["duration_s"].get<double>(), 0.4, 1e-12);
  const Result bad = depotwin("move --q0 0 --q1 1 --v0 5 --vmax 4 --amax 30");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--v0"), std::string::npos) << bad.output;
  EXPECT_EQ(depotwin("move --q0 0,1,2 --q1 1,2 --vmax 4 --amax 30").status, 2);
  EXPECT_EQ(depotwin("move --q0 x --q1 1 --vmax 4 --amax 30").status, 2);
}

TEST(Cli, ValidateReportsEveryProblemWithFileLineAndKey) {
  EXPECT_EQ(depotwin("validate " + scenario_path("thompson_fig7.yaml")).status, 0);
  const std::string dir = fresh_directory("cli_validate");
  const std::string path = write_text(dir, "bad.yaml",
                                      "name: bad\n"
                                      "limits: {v_max: -4, a_max: 30}\n"
                                      "toolpath:\n"
                                      "  speed: 3\n"
                                      "  segments:\n"
                                      "    - [[0, 0], [0, 0]]\n"
                                      "colour: blue\n");
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find(path + ":2: limits.v_max"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path + ":6: toolpath.segments[0]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path + ":7: colour"), std::string::npos) << r.output;
}

TEST(Cli, PlanWritesMetricsAndTrajectory) {
  const std::string dir = fresh_directory("cli_plan");
  const Result r =
      depotwin("plan " + scenario_path("thompson_fig7.yaml") + " --planner lspb_mtt --out " + dir);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto metrics =
      nlohmann::json::parse(testing_support::read_text(dir + "/lspb_mtt/metrics.json"));
  for (const char* key :
       {"scenario", "planner", "time_s", "planned_velocity_error", "path_error_mm", "warnings"})
    EXPECT_TRUE(metrics.contains(key)) << key;
  const std::string csv = testing_support::read_text(dir + "/lspb_mtt/trajectory.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "t,x,y,z,vx,vy,vz,speed,depositing,segment,desired_speed");
  // 1 ms samples over the whole plan
  const double total = metrics["time_s"]["total"].get<double>();
  EXPECT_NEAR(std::count(csv.begin(), csv.end(), '\n') - 1, std::floor(total * 1000) + 2, 1.0);
  EXPECT_FALSE(fs::exists(dir + "/stop_and_go"));
}

// a scenario with a broken piece, run end to end: exit 2, a clear message, no output folder
void expect_bad_run(const std::string& name, const std::string& scenario_text,
                    const std::string& message, const std::string& extra_file = "",
                    const std::string& extra_text = "") {
  const std::string dir = fresh_directory("cli_bad_" + name);
  if (!extra_file.empty()) write_text(dir, extra_file, extra_text);
  const std::string path = write_text(dir, "scenario.yaml", scenario_text);
  const std::string out = dir + "/results";
  const Result r = depotwin("run " + path + " --no-render --quiet --out " + out);
  EXPECT_EQ(r.status, 2) << name << ": " << r.output;
  EXPECT_NE(r.output.find(message), std::string::npos) << name << ": " << r.output;
  EXPECT_FALSE(fs::exists(out)) << name << ": output folder left behind";
  // nothing staged either
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

std::string scenario_with_machine(const std::string& machine,
                                  const std::string& segment = "[[0, 0], [5, 0]]") {
  return "name: bad\nmachine: " + machine +
         "\nlimits: {v_max: 4, a_max: 30}\ntoolpath:\n  speed: 3\n  segments:\n    - " + segment +
         "\n";
}

TEST(Cli, BadRunsExitWithStatusTwoAndLeaveNothingBehind) {
  expect_bad_run("unknown_machine", scenario_with_machine("warp_stage"), "machine");
  expect_bad_run("missing_mjcf", scenario_with_machine("missing.xml"), "missing.xml");
  expect_bad_run("malformed_mjcf", scenario_with_machine("broken.xml"), "broken.xml", "broken.xml",
                 "<mujoco><worldbody><body name='x'></mujoco>");
  // a Cartesian stage model without the `nozzle` site
  std::string model =
      testing_support::read_text(std::string(DEPOTWIN_MODELS_DIR) + "/xy_stage.xml");
  const size_t site = model.find("name=\"nozzle\"");
  ASSERT_NE(site, std::string::npos);
  model.replace(site, 13, "name=\"nozzle_renamed\"");
  expect_bad_run("no_nozzle", scenario_with_machine("no_nozzle.xml"), "nozzle", "no_nozzle.xml",
                 model);
  // a print segment beyond the +-50 mm travel
  expect_bad_run("outside_travel", scenario_with_machine("xy_stage", "[[0, 0], [80, 0]]"),
                 "travel");
}

TEST(Cli, RunAndCompareWriteResults) {
  const std::string dir = fresh_directory("cli_compare");
  const Result r =
      depotwin("compare " + scenario_path("thompson_fig7.yaml") +
               " --no-render --quiet --orders as_given,nearest_neighbor+two_opt --out " + dir);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/as_given/metrics.json"));
  EXPECT_TRUE(fs::exists(dir + "/nearest_neighbor+two_opt/metrics.json"));
  const auto table = nlohmann::json::parse(testing_support::read_text(dir + "/comparison.json"));
  ASSERT_EQ(table["runs"].size(), 2u);
  const auto& reordered = table["runs"][1]["metrics"]["order"];
  EXPECT_EQ(reordered["method"], "nearest_neighbor");
  EXPECT_EQ(reordered["refine"], "two_opt");
  // the sequencer's objective never beats its own lower bound
  EXPECT_GE(reordered["cost_s"].get<double>(), reordered["lower_bound_s"].get<double>());
}

// ---------------------------------------------------------------------------------------
// the 6-DOF arm: a toolpath it cannot print is refused with file:line: key and the point

// scenarios/shembekar_beam.stl (the 65 x 14 mm arch centred on the origin) placed at `offset`
// and hatched every 4 mm along x: line k at y = -6 + 4 k, point i at x = -32 + 4 i (before the
// offset). The `surface:` key is on line 7.
std::string arm_beam_scenario(const std::string& offset, const std::string& extra = "") {
  return "name: arm_bad\n"
         "machine: arm6\n"
         "limits: {v_max: 200, a_max: 2000}\n"
         "process: {type: extrusion, bead_width_mm: 0.5, layer_height_mm: 0.5, tau_s: 0.02}\n"
         "toolpath:\n"
         "  speed: 30\n"
         "  surface:\n"
         "    file: " +
         scenario_path("shembekar_beam.stl") +
         "\n"
         "    offset: " +
         offset +
         "\n"
         "    hatch_mm: 4\n"
         "    angles: [0]\n"
         "planners: [conformal]\n" +
         extra;
}

// 600 mm beyond the work origin: 960 mm in front of the robot's base, far out of its reach
TEST(Cli, ArmPointOutOfReachIsNamed) {
  const std::string dir = fresh_directory("cli_arm_reach");
  const std::string path = write_text(dir, "reach.yaml", arm_beam_scenario("[600, 0, 0]"));
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  const std::string where = path + ":7: toolpath.surface: ";
  // the job's start above the part, and the points of the hatch by layer, line and point
  EXPECT_NE(r.output.find(where + "the start (600.000, 0.000, "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(where + "layer 0, line 0, point 0 (568.000, -6.000, "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(where + "layer 0, line 1, point 16 (632.000, -2.000, "),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(") mm is out of the arm's reach for every roll and branch of arm6"),
            std::string::npos)
      << r.output;
  // `run` refuses it the same way and leaves nothing behind
  expect_bad_run("arm_out_of_reach", arm_beam_scenario("[600, 0, 0]"), "is out of the arm's reach");
}

// every posture's wrist centre is closer than 1000 mm to the joint-1 axis: all singular
TEST(Cli, ArmSingularPointIsNamed) {
  const std::string dir = fresh_directory("cli_arm_singular");
  const std::string path = write_text(
      dir, "singular.yaml", arm_beam_scenario("[0, 0, 0]", "arm: {min_wrist_offset_mm: 1000}\n"));
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(
      r.output.find(path + ":7: toolpath.surface: layer 0, line 0, point 0 (-32.000, -6.000, "),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(") mm is at a singularity for every roll and branch of arm6"),
            std::string::npos)
      << r.output;
  // the same scenario without the demand is fine
  const std::string fine = write_text(dir, "fine.yaml", arm_beam_scenario("[0, 0, 0]"));
  const Result ok = depotwin("validate " + fine);
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("machine arm6, 4 print paths"), std::string::npos) << ok.output;
}

// `arm:` on a machine without a wrist
TEST(Cli, ArmSettingsOnAPlanarMachineAreRefused) {
  const std::string dir = fresh_directory("cli_arm_planar");
  const std::string path =
      write_text(dir, "planar.yaml", scenario_with_machine("xy_stage") + "arm: {roll: fixed}\n");
  const Result r = depotwin("validate " + path);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(path + ":8: arm: applies to machine arm6 (a 6-DOF arm), not to xy_stage"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace depotwin
