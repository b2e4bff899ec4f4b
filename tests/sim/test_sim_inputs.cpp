// Bad models, bad settings and bad trajectories end as InputError naming the file and the
// element; a diverging simulation ends as InternalError; a fatal MuJoCo error exits with 1.
#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>

#include "core/error.hpp"
#include "kinematics/xy_stage.hpp"
#include "scratch_folder.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace depotwin {
namespace {

using testing_util::small_xy_model;
using testing_util::straight_print;
using testing_util::xy_stage_model;

// an inline MJCF written to a temporary file
std::string write_model(const std::string& name, const std::string& xml) {
  const std::string path = testing_support::scratch_file(name + ".xml");
  std::ofstream(path) << xml;
  return path;
}

// the InputError's text when constructing a Simulation on `path`, "" when none is thrown
std::string load_problem(const std::string& path, const SimSettings& settings = {}) {
  const auto machine = make_xy_stage();
  try {
    Simulation simulation(path, *machine, settings);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

const Trajectory& short_print() {
  static const Trajectory trajectory =
      straight_print(Vec3(0, 0, 0), Vec3(1, 0, 0), 3.0, 1.0, MachineLimits::uniform(4, 30))
          .trajectory;
  return trajectory;
}

TEST(SimInputs, TheSmallModelLoadsAndRunsWithoutAShutter) {
  const auto machine = make_xy_stage();
  Simulation simulation(write_model("small", small_xy_model()), *machine);
  EXPECT_FALSE(simulation.has_shutter());
  EXPECT_DOUBLE_EQ(simulation.shutter_time_s(), 0.0);
  const RecordedRun run = simulation.run(short_print());
  // without a shutter the open fraction is the depositing command itself
  long printing = 0;
  for (size_t k = 0; k < run.size(); ++k) {
    EXPECT_EQ(run.open_fraction[k], run.deposit_command[k] ? 1.0f : 0.0f);
    printing += run.deposit_command[k];
  }
  EXPECT_GT(printing, 300);
}

TEST(SimInputs, MissingModelFile) {
  const std::string problem = load_problem("/nonexistent/depotwin/model.xml");
  EXPECT_NE(problem.find("/nonexistent/depotwin/model.xml"), std::string::npos) << problem;
  EXPECT_NE(problem.find("does not exist"), std::string::npos) << problem;
}

TEST(SimInputs, MalformedXmlNamesTheLine) {
  const std::string path = write_model(
      "malformed", "<mujoco>\n<worldbody>\n<geom size='1' bogus='2'/>\n</worldbody>\n</mujoco>\n");
  const auto machine = make_xy_stage();
  try {
    Simulation simulation(path, *machine);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u);
    EXPECT_EQ(error.problems()[0].file, path);
    EXPECT_EQ(error.problems()[0].line, 3);
    EXPECT_NE(std::string(error.what()).find("bogus"), std::string::npos) << error.what();
  }
  const std::string unclosed = load_problem(write_model("unclosed", "<mujoco><worldbody>"));
  EXPECT_NE(unclosed.find("model"), std::string::npos) << unclosed;
}

TEST(SimInputs, MissingNamedElements) {
  const std::string no_nozzle = load_problem(write_model("no_nozzle", small_xy_model("nozzle")));
  EXPECT_NE(no_nozzle.find("site nozzle"), std::string::npos) << no_nozzle;
  const std::string no_substrate =
      load_problem(write_model("no_substrate", small_xy_model("substrate")));
  EXPECT_NE(no_substrate.find("body substrate"), std::string::npos) << no_substrate;
  const std::string no_joint = load_problem(write_model("no_joint", small_xy_model("y_joint")));
  EXPECT_NE(no_joint.find("joint y"), std::string::npos) << no_joint;
  const std::string no_actuator =
      load_problem(write_model("no_actuator", small_xy_model("y_actuator")));
  EXPECT_NE(no_actuator.find("actuator y"), std::string::npos) << no_actuator;
}

TEST(SimInputs, ActuatorMustBeAPositionServo) {
  const std::string motor = load_problem(
      write_model("motor", small_xy_model("", "<motor name=\"y\" joint=\"y\" gear=\"1\"/>")));
  EXPECT_NE(motor.find("actuator y"), std::string::npos) << motor;
  EXPECT_NE(motor.find("position servo"), std::string::npos) << motor;
  const std::string geared = load_problem(write_model(
      "geared", small_xy_model("", "<position name=\"y\" joint=\"y\" kp=\"7e4\" gear=\"2\"/>")));
  EXPECT_NE(geared.find("position servo"), std::string::npos) << geared;
  // <position> itself is accepted
  EXPECT_EQ(load_problem(write_model(
                "position", small_xy_model("", "<position name=\"y\" joint=\"y\" kp=\"7e4\"/>"))),
            "");
}

TEST(SimInputs, JointRangeNarrowerThanTheTravel) {
  std::string xml = small_xy_model();
  const std::string wide = "axis=\"1 0 0\" range=\"-0.06 0.06\"";
  xml.replace(xml.find(wide), wide.size(), "axis=\"1 0 0\" range=\"-0.04 0.06\"");
  const std::string problem = load_problem(write_model("narrow", xml));
  EXPECT_NE(problem.find("joint x"), std::string::npos) << problem;
  EXPECT_NE(problem.find("narrower"), std::string::npos) << problem;
}

TEST(SimInputs, BadSettings) {
  SimSettings settings;
  settings.timestep_s = 0.0;
  EXPECT_NE(load_problem(xy_stage_model(), settings).find("timestep_s"), std::string::npos);
  settings = SimSettings{};
  settings.control_period_s = 0.0015;
  EXPECT_NE(load_problem(xy_stage_model(), settings).find("whole number"), std::string::npos);
  settings = SimSettings{};
  settings.control_period_s = -1.0;
  EXPECT_NE(load_problem(xy_stage_model(), settings).find("control_period_s"), std::string::npos);
  // a coarser physics step than the controller period: the controller runs every step
  settings = SimSettings{};
  settings.timestep_s = 0.002;
  EXPECT_EQ(load_problem(xy_stage_model(), settings), "");
  settings = SimSettings{};
  settings.kp_scale = -1.0;
  EXPECT_NE(load_problem(xy_stage_model(), settings).find("kp_scale"), std::string::npos);
  settings = SimSettings{};
  settings.settle_s = std::nan("");
  EXPECT_NE(load_problem(xy_stage_model(), settings).find("settle_s"), std::string::npos);
}

TEST(SimInputs, TrajectoryOutsideTheTravelNamesTimeAndJoint) {
  // from TCP x = 45 mm printing 10 mm towards +x: the x carriage would pass -50 mm
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(45, 0, 0), Vec3(1, 0, 0), 3.0, 10.0, MachineLimits::uniform(4, 30));
  Simulation simulation(xy_stage_model(), *machine);
  long calls = 0;
  try {
    simulation.run(print.trajectory, [&](const StepState&, const StepState&) { ++calls; });
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    const std::string text = error.what();
    EXPECT_NE(text.find("trajectory"), std::string::npos) << text;
    EXPECT_NE(text.find("joint x"), std::string::npos) << text;
    EXPECT_NE(text.find("at t = "), std::string::npos) << text;
    EXPECT_NE(text.find(" s (printing path 0): "), std::string::npos) << text;
    // the first sample beyond the travel: TCP x passes 50 mm during the print at 3 mm/s
    const double print_start_x = print.trajectory.at(print.print_begin_s).position_mm.x();
    const double expected_t = print.print_begin_s + (50.0 - print_start_x) / 3.0;
    const double reported_t = std::stod(text.substr(text.find("at t = ") + 7));
    EXPECT_NEAR(reported_t, expected_t, 0.002) << text;
  }
  // checked before anything is simulated
  EXPECT_EQ(calls, 0);
  // an empty trajectory is bad input too
  EXPECT_THROW(simulation.run(Trajectory()), InputError);
}

// a divergence is the user's to fix (their model, the step, the gains, the plan): an InputError
// on `sim` naming what to change, with MuJoCo's own warning
TEST(SimInputs, DivergenceIsReportedAsWhatTheUserCanChange) {
  // absurd unlimited servo gains at a 1 ms step: explicit integration blows up
  const std::string path =
      write_model("unstable", small_xy_model("",
                                             "<general name=\"y\" joint=\"y\" gainprm=\"1e13\" "
                                             "biastype=\"affine\" biasprm=\"0 -1e13 0\"/>",
                                             "gainprm=\"1e13\" biasprm=\"0 -1e13 0\""));
  const auto machine = make_xy_stage();
  Simulation simulation(path, *machine);
  try {
    simulation.run(short_print());
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u);
    const Problem& problem = error.problems().front();
    EXPECT_EQ(problem.key, "sim");
    for (const char* words :
         {"MuJoCo warning in the simulation at t =", "lower sim.timestep_s", "sim.kp_scale 1"})
      EXPECT_NE(problem.message.find(words), std::string::npos) << problem.message;
  }
}

TEST(SimInputsDeathTest, FatalMujocoErrorExitsWithStatusOne) {
  EXPECT_EXIT(
      {
        install_mujoco_handlers();
        mju_error("deliberate failure");
      },
      ::testing::ExitedWithCode(kExitInternal), "MuJoCo: deliberate failure");
}

}  // namespace
}  // namespace depotwin
