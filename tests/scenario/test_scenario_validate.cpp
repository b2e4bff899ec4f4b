// Validation lists every problem in one run: a bad value for one key does not hide the speed
// checks, every over-speed segment is reported, and what the machine makes of the paths
// (travel, joint limits, speeds under its mapped limits, a jerk limit a planner ignores) comes
// with the same file, line and dotted key as the loader's own problems.
#include <gtest/gtest.h>

#include "scenario/scenario_test_util.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using testing_scenario::expect_problem;
using Validate = testing_scenario::ScenarioFiles;

// a bad value elsewhere in the file, even in `limits`, leaves the speed checks on
TEST_F(Validate, ABadValueDoesNotHideTheSpeedChecks) {
  const std::vector<Problem> problems = problems_of(R"(
limits: {v_max: 4, a_max: abc}
process: {sigma_mm: -1}
toolpath:
  speed: 5
  segments:
    - [[0, 0], [10, 0]]
)");
  const std::string file = scenario_path();
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, file, "limits.a_max", 1, "expected a number");
  expect_problem(problems, file, "process.sigma_mm", 2, "must be in [0.001, 100], got -1");
  expect_problem(problems, file, "toolpath.segments[0]", 6,
                 "print speed 5 mm/s needs 5 mm/s on x, above limits v_max 4");
}

// an axis whose own v_max is bad is left out; the other axes are still checked
TEST_F(Validate, AnAxisWithABadLimitIsSkippedTheOthersAreChecked) {
  const std::vector<Problem> problems = problems_of(R"(
limits: {v_max: 4, x: {v_max: -2}}
toolpath:
  speed: 5
  segments:
    - [[0, 0], [10, 0]]
    - [[0, 5], [0, 15]]
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.x.v_max", 1, "must be in [1e-06, 1e+06]");
  expect_problem(problems, scenario_path(), "toolpath.segments[1]", 6,
                 "print speed 5 mm/s needs 5 mm/s on y, above limits v_max 4");
}

// every over-speed segment of a polyline, each at the line of its end point (0-based names)
TEST_F(Validate, EveryOverSpeedSegmentOfAPolylineIsReported) {
  const std::vector<Problem> problems = problems_of(R"(
limits: {v_max: 4, a_max: 30}
toolpath:
  speed: 5
  polylines:
    - - [0, 0]
      - [10, 0]
      - [13, 4]
      - [0, 4]
)");
  // the diagonal needs 3 and 4 mm/s: within the limits
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  EXPECT_EQ(problems[0].str(), scenario_path() +
                                   ":6: toolpath.polylines[0]: segment 0 (points 0 and 1): print "
                                   "speed 5 mm/s needs 5 mm/s on x, above limits v_max 4 (lower "
                                   "the speed or raise the limit)");
  EXPECT_EQ(problems[1].line, 8);
  EXPECT_NE(problems[1].message.find("segment 2 (points 2 and 3)"), std::string::npos)
      << problems[1].message;
}

// a point outside the travel: its dotted key and line, the point's 0-based index
TEST_F(Validate, UnreachablePointsNameTheirKeyAndLine) {
  const std::vector<Problem> problems = problems_of(R"(
machine: xy_stage
toolpath:
  speed: 3
  start: [0, 60]
  segments:
    - [[0, 0], [10, 0]]
    - [[0, 0],
       [60, 0]]
)");
  const std::string file = scenario_path();
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  expect_problem(problems, file, "toolpath.start", 4,
                 "(0, 60, 0) mm is not reachable by xy_stage: joint y at -60 mm is outside its "
                 "travel [-50, 50] mm");
  expect_problem(problems, file, "toolpath.segments[1]", 8,
                 "point 1 (60, 0, 0) mm is not reachable by xy_stage");
  // the end defaults to the start: named as the default, at the toolpath's line
  expect_problem(problems, file, "toolpath.end", 2, "(the default) (0, 60, 0) mm");
  // and where the paths lie: moved 30 mm in -x (their centre onto the stage's), every path
  // point is within the stage's travel [-50, 50]
  expect_problem(problems, file, "toolpath.offset", 2,
                 "the print paths span x 0 to 60, y 0, z 0 mm; moved by (-30, 0, 0) mm every "
                 "point is within xy_stage's reach: add that to toolpath.offset");
}

// the loader's problems and the machine's in one list, in line order
TEST_F(Validate, LoaderAndMachineProblemsInOneList) {
  const std::vector<Problem> problems = problems_of(R"(
machine: linear_delta
limits: {v_max: 40, a_max: 300, joint: {v_max: 100, a_max: 1000, j_max: 5}}
sim: {kp_scale: 0}
toolpath:
  speed: 3
  polylines:
    - [[0, 0], [500, 0]]
)");
  const std::string file = scenario_path();
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  expect_problem(problems, file, "limits.joint", 2, "a carriage j_max is not supported");
  expect_problem(problems, file, "sim.kp_scale", 3, "must be in [0.1, 10], got 0");
  expect_problem(problems, file, "toolpath.polylines[0]", 7,
                 "point 1 (500, 0, 0) mm is not reachable by linear_delta");
  // 500 mm long: no move brings it within the delta's reach
  expect_problem(problems, file, "toolpath.offset", 4,
                 "the print paths span x 0 to 500, y 0, z 0 mm; even centred on linear_delta's "
                 "workspace (moved by (-250, 0, 37.5) mm) some are out of its reach");
  for (std::size_t i = 1; i < problems.size(); ++i)
    EXPECT_LE(problems[i - 1].line, problems[i].line);
}

// a print speed within the user's limits but above what the delta's carriages allow over the
// segment: the machine's mapped limit, named as such
TEST_F(Validate, SpeedAboveTheMachinesMappedLimitsIsReported) {
  const std::vector<Problem> problems = problems_of(R"(
machine: linear_delta
limits: {v_max: 400, a_max: 3000, joint: {v_max: 20, a_max: 1000}}
toolpath:
  speed: 100
  segments:
    - [[0, 0], [20, 0]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.segments[0]", 6,
                 "linear_delta's joint limits mapped over this segment; limits v_max is 400");
}

// a joint jerk limit on the XY stage becomes the TCP's, which every planner honours; on the
// linear delta it is refused at the limits, not at a planner
TEST_F(Validate, AJointJerkLimitInForceIsHonouredOrRefusedByTheMachine) {
  const std::vector<Problem> stage = problems_of(R"(
limits: {joint: {v_max: 200, a_max: 2000, j_max: 1000}}
toolpath: {speed: 3, segments: [[[0, 0], [10, 0]]]}
planners: [lspb_mtt, bezier, firmware, conformal]
)");
  EXPECT_TRUE(stage.empty()) << dump(stage);
  const std::vector<Problem> delta = problems_of(R"(
machine: linear_delta
limits: {v_max: 400, a_max: 3000, joint: {v_max: 200, a_max: 3000, j_max: 1000}}
toolpath: {speed: 3, segments: [[[0, 0], [10, 0]]]}
planners: [bezier]
)");
  ASSERT_EQ(delta.size(), 1u) << dump(delta);
  EXPECT_NE(delta.front().message.find("j_max"), std::string::npos) << dump(delta);
}

// a 0/1 switch takes whole numbers only (was refused only when planning)
TEST_F(Validate, APlannerSwitchTakesWholeNumbers) {
  const std::vector<Problem> problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [10, 0]]]}
planners:
  - {name: bezier, lead_in: 0.5}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "planners[0].lead_in", 3,
                 "must be a whole number in [0, 1]");
}

// where each path came from is kept for later messages (posture, planners)
TEST_F(Validate, PathSourcesAreKept) {
  const Scenario s = load_scenario(write("ok.yaml", R"(
toolpath:
  speed: 3
  start: [-5, -5]
  polylines:
    - [[0, 0], [5, 0]]
    - {points: [[0, 2],
                [5, 2]], speed: 2}
)"));
  ASSERT_EQ(s.path_sources.size(), 2u);
  EXPECT_EQ(s.path_sources[1].key, "toolpath.polylines[1]");
  EXPECT_EQ(s.path_sources[1].point_lines, (std::vector<int>{6, 7}));
  EXPECT_EQ(s.start_line, 3);
  EXPECT_EQ(s.end_line, 0);
  EXPECT_EQ(path_point_problem(s, 1, 1, "is here").str(),
            s.file + ":7: toolpath.polylines[1]: point 1 is here");
}

}  // namespace
}  // namespace depotwin
