// The job's size before anything is allocated (pipeline/job_check.hpp): the lower bound on a
// job's duration before planning against its closed form, the planned estimate against the
// plan itself, --max-memory's sizes, and a long segments list read apart giving the scenario
// yaml-cpp would.
#include <gtest/gtest.h>

#include <cmath>

#include "pipeline/job_check.hpp"
#include "pipeline_test_util.hpp"
#include "scenario/lifted_list.hpp"

namespace depotwin {
namespace {

using testing_support::fresh_directory;
using testing_support::write_text;

TEST(MemorySize, UnitsArePowersOf1024) {
  const double gib = 1024.0 * 1024.0 * 1024.0;
  EXPECT_EQ(parse_memory_size("8G"), 8 * gib);
  EXPECT_EQ(parse_memory_size("512M"), 512 * 1024.0 * 1024.0);
  EXPECT_EQ(parse_memory_size("1.5GiB"), 1.5 * gib);
  EXPECT_EQ(parse_memory_size("2gb"), 2 * gib);
  EXPECT_EQ(parse_memory_size("1T"), 1024 * gib);
  EXPECT_EQ(parse_memory_size("1073741824"), gib);
  EXPECT_EQ(kDefaultMaxMemoryBytes, 8 * gib);
  EXPECT_EQ(format_bytes(6.6 * gib), "6.6 GB");
  EXPECT_EQ(format_bytes(512 * 1024.0 * 1024.0), "512 MB");
  // the bounds in the same units, 1 MiB and 1 EiB (they were 1e6 and 1e18 bytes: 1048575T,
  // under 1 EiB, was refused and 1000000 bytes taken), and a size beyond a PiB read in TB
  EXPECT_EQ(parse_memory_size("1M"), 1024.0 * 1024.0);
  EXPECT_EQ(parse_memory_size("1048576T"), 1024.0 * 1024.0 * 1024 * gib);
  EXPECT_EQ(parse_memory_size("1048575T"), 1048575 * 1024 * gib);
  for (const char* outside : {"1048575", "1000000", "1048577T"})
    EXPECT_THROW(parse_memory_size(outside), InputError) << outside;
  EXPECT_EQ(format_bytes(1048575 * 1024 * gib), "1048575 TB");
  // beyond the largest budget (a job at 1e-300 mm/s needs 1e+46 bytes) the figure is still
  // a figure with its unit: in full it was 47 digits, and the buffer cut off the " TB"
  EXPECT_EQ(format_bytes(2048576.0 * 1024 * gib), "2.05e+06 TB");
  EXPECT_EQ(format_bytes(1e46), "9.09e+33 TB");
}

TEST(MemorySize, NonsenseIsAnInputErrorNamingTheOption) {
  for (const char* text : {"lots", "", "0", "-1G", "1K", "8Q", "nan", "1e300G"}) {
    try {
      parse_memory_size(text);
      ADD_FAILURE() << "'" << text << "' accepted";
    } catch (const InputError& error) {
      ASSERT_EQ(error.problems().size(), 1u);
      EXPECT_EQ(error.problems()[0].key, "--max-memory") << text;
    }
  }
}

// one 10 mm segment along x at 2 mm/s, a_max 4 mm/s^2 on x: 5 s of printing and, to reach
// 2 mm/s from rest and to leave it, 2 / 4 = 0.5 s each way: at least 6 s
TEST(JobEstimate, BeforePlanningIsTheClosedFormLowerBound) {
  const std::string dir = fresh_directory("job_estimate");
  const Scenario scenario =
      load_scenario(write_text(dir, "one.yaml", R"(limits: {v_max: 5, a_max: 4}
toolpath:
  speed: 2
  segments:
    - [[0, 0], [10, 0]]
sim: {timestep_s: 0.0005, settle_s: 1}
)"));
  const RunEstimate run = estimate_before_planning(scenario, true);
  EXPECT_DOUBLE_EQ(run.print_s, 5.0);
  EXPECT_DOUBLE_EQ(run.duration_s, 6.0);
  // (6 s + 1 s settling) / 0.5 ms
  EXPECT_DOUBLE_EQ(run.steps, 14000.0);
  EXPECT_DOUBLE_EQ(run.samples, 6002.0);  // every ms of the motion, both ends
  EXPECT_GT(run.cells, 0.0);
  // a bound: the plans take longer
  std::vector<RunEstimate> planned;
  const PreparedJob job = prepare_checked_job(
      scenario, {PlannerSpec{"lspb_mtt", {}, 0}, PlannerSpec{"stop_and_go", {}, 0}}, JobBudget{},
      true, false, &planned);
  ASSERT_EQ(planned.size(), 2u);
  for (const RunEstimate& plan : planned) {
    EXPECT_GE(plan.duration_s, run.duration_s) << plan.label;
    // the planned estimate is the plan's own duration
    EXPECT_DOUBLE_EQ(plan.duration_s,
                     plan_trajectory(job, PlannerSpec{plan.label, {}, 0}).duration_s());
    EXPECT_DOUBLE_EQ(plan.steps, std::ceil((plan.duration_s + 1.0) / 0.0005)) << plan.label;
  }
}

// the plans made while the job is checked are kept, one per planner, and plan_job takes them:
// the same plan as planning again (uniform, which predicts the deposit, and a paper planner),
// a spec differing only in its label shares its plan, other parameters do not
TEST(JobEstimate, CheckedPlansAreKeptAndEqualAFreshPlan) {
  const std::string dir = fresh_directory("job_checked_plans");
  const Scenario scenario =
      load_scenario(write_text(dir, "vee.yaml", R"(limits: {v_max: 20, a_max: 200}
toolpath:
  speed: 5
  polylines:
    - [[0, 0], [6, 0], [1, 3]]
)"));
  const PlannerSpec uniform{"uniform", {}, 0};
  PlannerSpec relabelled = uniform;
  relabelled.label = "uniform_again";
  const PlannerSpec lspb{"lspb_mtt", {}, 0};
  const PreparedJob job =
      prepare_checked_job(scenario, {uniform, relabelled, lspb}, JobBudget{}, true, false);
  ASSERT_EQ(job.checked_plans.size(), 2u);
  EXPECT_EQ(job.checked_plan(relabelled), job.checked_plan(uniform));
  PlannerSpec other = uniform;
  other.params["tolerance_mm"] = {0.02};
  EXPECT_EQ(job.checked_plan(other), nullptr);
  for (const PlannerSpec& spec : {uniform, lspb}) {
    const Trajectory fresh = plan_trajectory(job, spec);
    const PlannedRun run = plan_job(job, spec);
    ASSERT_EQ(run.trajectory.duration_s(), fresh.duration_s()) << spec.name;
    ASSERT_EQ(run.trajectory.decisions().size(), fresh.decisions().size()) << spec.name;
    // sample by sample, to the bit
    for (double t = 0.0; t < fresh.duration_s(); t += 0.01) {
      const TrajectorySample a = run.trajectory.at(t);
      const TrajectorySample b = fresh.at(t);
      ASSERT_EQ(a.position_mm, b.position_mm) << spec.name << " t = " << t;
      ASSERT_EQ(a.velocity_mm_s, b.velocity_mm_s) << spec.name << " t = " << t;
    }
  }
}

// the lower bound refuses a job far beyond the steps allowed before any planning, at the key
// that drives it; raising sim.max_steps lets it through that check
TEST(JobEstimate, TheStepLimitIsTheScenariosToRaise) {
  const std::string dir = fresh_directory("job_steps");
  const std::string slow = R"(toolpath:
  speed: 0.001
  segments:
    - [[0, 0], [10, 0]]
planners: [lspb_mtt]
)";
  try {
    check_scenario(write_text(dir, "slow.yaml", slow), JobBudget{});
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u) << error.what();
    EXPECT_EQ(error.problems()[0].key, "toolpath.speed");
    EXPECT_EQ(error.problems()[0].line, 2);
    // 10 mm at 1 um/s: 1e4 s, 1e7 steps at 1 ms, with the ramps just above: whole numbers,
    // which three digits would show as equal ("1e+07 ..., more than ... 1e+07")
    const std::string& message = error.problems()[0].message;
    EXPECT_NE(message.find(" physics steps, more than sim.max_steps = 10000000: "),
              std::string::npos)
        << error.what();
    EXPECT_EQ(message.find("1e+07"), std::string::npos) << error.what();
  }
  JobBudget budget;
  budget.max_memory_bytes = 1e15;
  EXPECT_NO_THROW(
      check_scenario(write_text(dir, "raised.yaml", slow + "sim: {max_steps: 2e7}\n"), budget));
}

// a G-code job too large for the memory allowed names the key that prints fewer of its
// layers (three here; one selected: no such hint, it prints one layer)
TEST(JobEstimate, ALargeGcodeJobIsToldToPrintFewerLayers) {
  const std::string dir = fresh_directory("job_layers");
  std::string gcode = "G21\nG90\nM83\n";
  for (int layer = 0; layer < 3; ++layer)
    gcode += "G0 X0 Y0 Z" + std::to_string(0.2 * (layer + 1)) +
             "\nG1 X20 Y0 E1 F600\nG1 X20 Y20 E1\nG1 X0 Y20 E1\nG1 X0 Y0 E1\n";
  write_text(dir, "square.gcode", gcode);
  const std::string head = "machine: cartesian\nprocess: {type: extrusion}\ntoolpath:\n";
  JobBudget budget;
  budget.max_memory_bytes = 1e6;
  try {
    check_scenario(write_text(dir, "all.yaml", head + "  gcode: square.gcode\n"), budget);
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u) << error.what();
    EXPECT_NE(error.problems()[0].message.find(
                  "print fewer of its 3 layers (toolpath.gcode.layers: [from, to])"),
              std::string::npos)
        << error.what();
  }
  try {
    check_scenario(
        write_text(dir, "one.yaml", head + "  gcode: {file: square.gcode, layers: [1, 1]}\n"),
        budget);
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    ASSERT_EQ(error.problems().size(), 1u) << error.what();
    EXPECT_EQ(error.problems()[0].message.find("fewer of its"), std::string::npos) << error.what();
    EXPECT_NE(error.problems()[0].message.find("more than --max-memory"), std::string::npos)
        << error.what();
  }
}

// a long segments list read apart (scenario/lifted_list.hpp) gives the scenario and the
// problems yaml-cpp gives: the same list with a comment in it goes through yaml-cpp
TEST(LiftedSegments, GiveTheSameScenarioAndProblemsAsYamlCpp) {
  const std::string dir = fresh_directory("lifted_segments");
  std::string list;
  for (int i = 0; i < 300; ++i) {
    const double x = -40.0 + 0.25 * i, y = (i % 7) * 5.0 - 15.0;
    list += "    - [[" + std::to_string(x) + ", " + std::to_string(y) + "], [" +
            std::to_string(x + 0.1) + ", " + std::to_string(y + 2.0) + "]]\n";
  }
  // problems among them: a zero-length one, a repeat, one beyond the travel, too fast
  list +=
      "    - [[1, 1], [1, 1]]\n    - [[-40, -15], [-39.9, -13]]\n    - [[0, 0], [60, 0]]\n"
      "    - [[5, 5], [5.5, 5, 0]]";
  const std::string head =
      "name: lifted\nlimits: {v_max: 2, a_max: 30}\ntoolpath:\n  speed: 3\n"
      "  segments:\n";
  const std::string tail = "planners: [lspb_mtt, teleport]\n";
  // (a comment after an entry keeps the list with yaml-cpp, every line where it was)
  const std::string lifted = write_text(dir, "lifted.yaml", head + list + "\n" + tail);
  const std::string parsed =
      write_text(dir, "parsed.yaml", head + list + "  # yaml-cpp's\n" + tail);
  // the first is read apart, the second by yaml-cpp
  std::string lifted_text = head + list + "\n" + tail,
              parsed_text = testing_support::read_text(parsed);
  const auto apart = scenario_detail::lift_segments(lifted_text);
  ASSERT_TRUE(apart.has_value());
  EXPECT_EQ(apart->segments.size(), 304u);
  EXPECT_EQ(apart->key_line, 5);
  EXPECT_FALSE(scenario_detail::lift_segments(parsed_text).has_value());
  const ScenarioReading a = read_scenario(lifted);
  const ScenarioReading b = read_scenario(parsed);
  ASSERT_EQ(a.scenario.toolpath.paths.size(), 304u);
  ASSERT_EQ(b.scenario.toolpath.paths.size(), 304u);
  for (size_t i = 0; i < a.scenario.toolpath.paths.size(); ++i) {
    EXPECT_EQ(a.scenario.toolpath.paths[i].points, b.scenario.toolpath.paths[i].points) << i;
    EXPECT_EQ(a.scenario.toolpath.paths[i].speed_mm_s, b.scenario.toolpath.paths[i].speed_mm_s);
    EXPECT_EQ(a.scenario.path_sources[i].key, b.scenario.path_sources[i].key);
    EXPECT_EQ(a.scenario.path_sources[i].point_lines, b.scenario.path_sources[i].point_lines);
  }
  // the same problems at the same lines (the planners' line after the list too), but for
  // the file's name
  ASSERT_EQ(a.problems.size(), b.problems.size());
  ASSERT_GE(a.problems.size(), 5u);
  for (size_t i = 0; i < a.problems.size(); ++i) {
    EXPECT_EQ(a.problems[i].line, b.problems[i].line) << a.problems[i].str();
    EXPECT_EQ(a.problems[i].key, b.problems[i].key) << a.problems[i].str();
    EXPECT_EQ(a.problems[i].message, b.problems[i].message);
  }
  EXPECT_EQ(a.problems.back().key, "planners[1]");
  EXPECT_EQ(a.problems.back().line, 5 + 304 + 1);
}

}  // namespace
}  // namespace depotwin
