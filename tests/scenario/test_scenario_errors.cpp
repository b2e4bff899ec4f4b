// Bad scenario files: each problem names the file, the 1-based line and the dotted key,
// and says what is wrong; every problem of a file is reported, not only the first.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "scenario/scenario.hpp"
#include "scenario_test_util.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using testing_scenario::expect_problem;
using ScenarioErrors = testing_scenario::ScenarioFiles;

TEST_F(ScenarioErrors, UnknownTopLevelKey) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
colour: red
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "colour", 2,
                 "unknown key (expected one of: name, machine");
}

TEST_F(ScenarioErrors, UnknownNestedKey) {
  const auto problems = problems_of(R"(
limits:
  v_max: 4
  x: {v_max: 3, a_maxx: 30}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.x.a_maxx", 3,
                 "unknown key (expected one of: v_max, a_max, j_max)");
}

TEST_F(ScenarioErrors, TextWhereANumberIsExpected) {
  const auto problems = problems_of(R"(
toolpath:
  speed: fast
  segments: [[[0, 0], [1, 0]]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.speed", 2, "expected a number, got 'fast'");
}

TEST_F(ScenarioErrors, QuotedNumberIsText) {
  const auto problems = problems_of(R"(
toolpath:
  speed: "3"
  segments: [[[0, 0], [1, 0]]]
)");
  expect_problem(problems, scenario_path(), "toolpath.speed", 2, "without quotes");
}

TEST_F(ScenarioErrors, MapWhereAListIsExpected) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners: {name: lspb_mtt}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "planners", 2, "expected a list of planners");
}

TEST_F(ScenarioErrors, NegativeLimit) {
  const auto problems = problems_of(R"(
limits: {v_max: -4, a_max: 30}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.v_max", 1, "must be in [1e-06, 1e+06], got -4");
}

TEST_F(ScenarioErrors, ZeroLimit) {
  const auto problems = problems_of(R"(
limits:
  v_max: 4
  a_max: 0
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.a_max", 3, "must be in [1e-06, 1e+09], got 0");
}

TEST_F(ScenarioErrors, NanAndInfiniteLimits) {
  const auto problems = problems_of(R"(
limits:
  v_max: .nan
  a_max: 30
  j_max: -.inf
  z: {a_max: nan}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.v_max", 2, "must be a finite number, got .nan");
  expect_problem(problems, scenario_path(), "limits.j_max", 4,
                 "must be a finite number, got -.inf");
  expect_problem(problems, scenario_path(), "limits.z.a_max", 5, "must be a finite number");
}

// a number nearer 0 than a double holds reads as 0: a range that refuses 0 shows it as written
// (it said "got 0" of `v_max: 3e-400`); 0 written so is 0 (j_max 0: no jerk limit)
TEST_F(ScenarioErrors, ANumberTooNearZeroIsShownAsWritten) {
  const auto problems = problems_of(R"(
limits: {v_max: 3e-400, a_max: -0.5e-330, j_max: 0e-999}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.v_max", 1,
                 "must be in [1e-06, 1e+06], got 3e-400 (nearer 0 than a double holds: 0)");
  expect_problem(problems, scenario_path(), "limits.a_max", 1,
                 "must be in [1e-06, 1e+09], got -0.5e-330 (nearer 0 than a double holds: 0)");
}

// the arm's roll step divides 360: one that does not is named at its own line and key
TEST_F(ScenarioErrors, ARollStepThatDoesNotDivide360IsNamedAtItsKey) {
  const auto problems = problems_of(R"(
machine: arm6
arm:
  roll: optimized
  roll_step_deg: 7
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "arm.roll_step_deg", 4,
                 "must divide 360 into a whole number of steps (5, 7.5, 10, 15, 30, ...), got 7");
  EXPECT_TRUE(problems_of("machine: arm6\narm: {roll_step_deg: 7.5}\ntoolpath: {speed: 3, "
                          "segments: [[[0, 0], [1, 0]]]}\n")
                  .empty());
}

TEST_F(ScenarioErrors, JointLimitsNeedVelocityAndAcceleration) {
  const auto problems = problems_of(R"(
limits: {joint: {v_max: 200}}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits.joint", 1, "missing a_max");
}

TEST_F(ScenarioErrors, ZeroLengthSegment) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  segments:
    - [[2, 2], [8, 2]]
    - [[8, 2], [8, 2]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.segments[1]", 5,
                 "zero length: both points are (8, 2, 0)");
}

TEST_F(ScenarioErrors, ZeroLengthSegmentInAPolyline) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  polylines:
    - [[0, 0], [1, 0], [1, 0], [2, 0]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.polylines[0]", 4,
                 "segment 1 (points 1 and 2) has zero length");
}

// 5 mm/s along (3, 4) needs 5 * 4/5 = 4 mm/s on y, above a y limit of 3.9
TEST_F(ScenarioErrors, PrintSpeedAboveWhatTheLimitsAllow) {
  const auto problems = problems_of(R"(
limits: {v_max: 3.9, a_max: 30, x: {v_max: 10}}
toolpath:
  speed: 5
  segments:
    - [[0, 0], [1, 0]]
    - [[0, 0], [3, 4]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.segments[1]", 6,
                 "print speed 5 mm/s needs 4 mm/s on y, above limits v_max 3.9");
}

// past 20 segments over speed, one line says how many more: after the 20 listed, where the
// last of them is (the problems are sorted by line), not first
TEST_F(ScenarioErrors, TheSegmentsOverSpeedBeyondTheListedAreCountedAfterThem) {
  std::string yaml =
      "\nlimits: {v_max: 3.9, a_max: 30, x: {v_max: 10}}\ntoolpath:\n  speed: 5\n"
      "  segments:\n";
  for (int i = 0; i < 25; ++i)
    yaml += "    - [[0, " + std::to_string(i) + "], [3, " + std::to_string(i + 4) + "]]\n";
  const auto problems = problems_of(yaml);
  ASSERT_EQ(problems.size(), 21u) << dump(problems);
  EXPECT_EQ(problems[19].key, "toolpath.segments[19]") << dump(problems);
  EXPECT_EQ(problems[20].str(), scenario_path() +
                                    ":24: toolpath.segments[19]: ... and 5 more print segments "
                                    "above the speed limits (the first 20 are listed)")
      << dump(problems);
}

TEST_F(ScenarioErrors, MissingFile) {
  const std::string path = (dir_ / "no_such.yaml").string();
  const auto problems = validate_scenario_file(path);
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].file, path);
  EXPECT_EQ(problems[0].str(), path + ": scenario file not found");
  EXPECT_THROW(load_scenario(path), InputError);
}

// a directory or a FIFO (which a read would wait on for ever) is named, not opened
TEST_F(ScenarioErrors, ScenarioPathThatIsNotARegularFile) {
  const std::string fifo = (dir_ / "pipe.yaml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto problems = validate_scenario_file(fifo);
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].str(), fifo + ": scenario file is not a regular file");
  problems = validate_scenario_file(dir_.string());
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].str(), dir_.string() + ": scenario file is a directory, not a file");
}

TEST_F(ScenarioErrors, MalformedYaml) {
  const auto problems = problems_of(R"(
name: broken
toolpath:
  speed: 3
  segments: [[[0, 0], [1, 0]]
order: as_given
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].file, scenario_path());
  EXPECT_EQ(problems[0].line, 5) << problems[0].str();
  EXPECT_NE(problems[0].message.find("malformed YAML"), std::string::npos);
}

// yaml-cpp stops a parse nested hundreds of levels deep with "bad file": said as it is
TEST_F(ScenarioErrors, YamlNestedTooDeepSaysSo) {
  const auto problems = problems_of("name: deep\ntoolpath: " + std::string(1000, '[') +
                                    std::string(1000, ']') + "\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2) << problems[0].str();
  EXPECT_EQ(problems[0].message,
            "malformed YAML: lists or maps nested hundreds of levels deep (a "
            "scenario nests a few)");
}

TEST_F(ScenarioErrors, UnknownPlanner) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners:
  - lspb_mtt
  - warp_drive
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "planners[1]", 4,
                 "unknown planner 'warp_drive' (known: lspb_mtt, stop_and_go");
}

TEST_F(ScenarioErrors, UnknownPlannerParameter) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners:
  - name: lspb_mtt
    smoothness: 0.3
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "planners[0].smoothness", 4,
                 "planner 'lspb_mtt' has no parameter 'smoothness'");
}

TEST_F(ScenarioErrors, PlannerParameterMustBeNumbers) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners:
  - {name: lspb_mtt, delta: [0.1, big]}
  - {delta: 0.3}
  - stop_and_go
  - stop_and_go
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "planners[0].delta[1]", 3,
                 "expected a number, got 'big'");
  expect_problem(problems, scenario_path(), "planners[1]", 4, "missing name");
  expect_problem(problems, scenario_path(), "planners[3]", 6, "listed twice");
}

TEST_F(ScenarioErrors, UnknownOrderMethod) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
order: shortest_first
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "order", 2,
                 "unknown sequencer 'shortest_first' (expected as_given, random, nearest_neighbor, "
                 "christofides");
}

TEST_F(ScenarioErrors, BadOrderMapFields) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
order:
  method: christofides+five_opt
  refine: two_opt
  cost_model: euclid
  seed: -1
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "order.method", 3, "unknown sequencer");
  expect_problem(problems, scenario_path(), "order.cost_model", 5,
                 "unknown cost model 'euclid' (expected machine, along_line)");
  expect_problem(problems, scenario_path(), "order.seed", 6, "whole number >= 0");
}

// a seed is a whole number however written (1.0, 1e3, as every whole-number key reads it);
// anything else is echoed as written
TEST_F(ScenarioErrors, SeedsAreWholeNumbersHoweverWritten) {
  for (const auto& [text, seed] : std::vector<std::pair<std::string, std::uint64_t>>{
           {"1.0", 1}, {"1e3", 1000}, {"18446744073709551615", 18446744073709551615u}}) {
    const Scenario s = load_scenario(write("seed.yaml",
                                           "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n"
                                           "order: {method: random, seed: " +
                                               text + "}\n"));
    EXPECT_EQ(s.order.seed, seed) << text;
  }
  const auto problems = problems_of(
      "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\norder: {method: random, seed: 1.5}\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "order.seed", 2,
                 "expected a whole number >= 0 (a random seed), got 1.5");
}

TEST_F(ScenarioErrors, RefinementTwice) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
order: {method: two_opt, refine: three_opt}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "order.refine", 2, "already implies refine two_opt");
}

TEST_F(ScenarioErrors, TwoToolpathKindsAtOnce) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  segments: [[[0, 0], [1, 0]]]
  polylines: [[[0, 0], [1, 0], [1, 1]]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.polylines", 4,
                 "exactly one of segments, polylines, gcode, random_segments");
}

TEST_F(ScenarioErrors, NoToolpathKind) {
  const auto problems = problems_of(R"(
name: empty
toolpath:
  speed: 3
  start: [0, 0]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath", 2, "no print paths");
}

TEST_F(ScenarioErrors, NoToolpathAtAll) {
  const auto problems = problems_of("name: nothing_to_print\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath", 1, "missing");
}

TEST_F(ScenarioErrors, PointWithOneCoordinate) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  start: [0, 0, 0, 1]
  segments:
    - [[0, 0], [5]]
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.start", 3,
                 "expected a point [x, y] or [x, y, z] in mm, got a list of 4 numbers");
  expect_problem(problems, scenario_path(), "toolpath.segments[0][1]", 5, "got a list of 1 number");
}

TEST_F(ScenarioErrors, SegmentWithThreePoints) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  segments: [[[0, 0], [1, 0], [2, 0]]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.segments[0]", 3,
                 "got a list of 3 points (use polylines for more)");
}

TEST_F(ScenarioErrors, PolylineWithOnePointAndMissingSpeed) {
  const auto problems = problems_of(R"(
toolpath:
  polylines:
    - {points: [[0, 0]], speed: 2}
    - [[0, 0], [1, 0]]
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.polylines[0].points", 3,
                 "needs at least 2 points, got 1");
  expect_problem(problems, scenario_path(), "toolpath.polylines[1]", 4, "no print speed");
}

TEST_F(ScenarioErrors, SegmentsWithoutSpeed) {
  const auto problems = problems_of(R"(
toolpath:
  segments: [[[0, 0], [1, 0]], [[1, 1], [2, 2]]]
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.speed", 2, "missing");
}

TEST_F(ScenarioErrors, BadGcodeLine) {
  write("job.gcode", R"(
G90
G1 X1 Y0 E1 F120
G1 Xabc Y2 E2
G1 X3 Y3 E3
)");
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  gcode: job.gcode
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, (dir_ / "job.gcode").string(), "toolpath.gcode", 3,
                 "malformed word 'Xabc'");
}

TEST_F(ScenarioErrors, GcodeInTheBedsFrameIsToldTheOffset) {
  // a slicer's square in its bed's frame (x 120 to 180, y 100 to 160 mm) on the cartesian
  // printer, which centres on (0, 0) with x and y in [-100, 100]: the summary names the move
  // that centres it, and with that offset the scenario is clean
  write("bed.gcode",
        "G90\nM83\nG1 X120 Y100 Z0.2 F3000\nG1 X180 Y100 E1 F1800\nG1 X180 Y160 E1\n"
        "G1 X120 Y160 E1\n");
  // the scenario with a toolpath line after `gcode:` (an offset, or nothing)
  const auto problems_with = [&](const std::string& offset_line) {
    return problems_of(
        "machine: cartesian\nlimits: {v_max: 100, a_max: 1000}\ntoolpath:\n"
        "  gcode: bed.gcode\n" +
        offset_line);
  };
  const auto problems = problems_with("");
  ASSERT_FALSE(problems.empty());
  expect_problem(problems, scenario_path(), "toolpath.offset", 3,
                 "the print paths span x 120 to 180, y 100 to 160, z 0.2 mm; moved by (-150, "
                 "-130, 0) mm every point is within cartesian's reach: add that to "
                 "toolpath.offset (a slicer's file lies in its bed's frame, from 0;");
  const auto moved = problems_with("  offset: [-150, -130]\n");
  EXPECT_TRUE(moved.empty()) << dump(moved);
  // given an offset that is not enough, the summary is at its line and counts from it
  const auto short_move = problems_with("  offset: [-50, -50]\n");
  expect_problem(short_move, scenario_path(), "toolpath.offset", 5,
                 "the print paths span x 70 to 130, y 50 to 110, z 0.2 mm; moved by (-100, -80, "
                 "0) mm");
}

TEST_F(ScenarioErrors, GcodePrintSpeedAboveLimits) {
  // F600 = 10 mm/s along x on line 2, above v_max 4 (feed: error; clamp slows it instead)
  write("fast.gcode", "G1 X1 Y0 E1 F120\nG1 X11 Y0 E2 F600\n");
  const auto problems = problems_of(R"(
limits: {v_max: 4, a_max: 30}
toolpath: {gcode: {file: fast.gcode, feed: error}}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, (dir_ / "fast.gcode").string(), "toolpath.gcode", 2,
                 "print speed 10 mm/s needs 10 mm/s on x, above limits v_max 4");
}

TEST_F(ScenarioErrors, MissingGcodeFile) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  gcode: parts/missing.gcode
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.gcode", 3,
                 "G-code file 'parts/missing.gcode' not found");
}

TEST_F(ScenarioErrors, GcodeFileThatIsADirectory) {
  std::filesystem::create_directories(dir_ / "parts");
  const auto problems = problems_of("toolpath: {speed: 3, gcode: {file: parts}}\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(
      problems, scenario_path(), "toolpath.gcode.file", 1,
      "G-code file 'parts' is a directory (" + (dir_ / "parts").string() + "), not a file");
}

TEST_F(ScenarioErrors, GcodeWithoutPrintMoves) {
  write("travel.gcode", "G0 X10 Y10\nG1 X20 Y10 F600\n");
  const auto problems = problems_of("toolpath: {speed: 3, gcode: {file: travel.gcode, rule: e}}\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.gcode", 1, "has no print moves");
  // a file that is no G-code at all says so
  write("notes.gcode", "Print these at 30 mm/s.\n; (comment)\n");
  const auto not_code = problems_of("toolpath: {speed: 3, gcode: {file: notes.gcode}}\n");
  ASSERT_EQ(not_code.size(), 1u) << dump(not_code);
  expect_problem(not_code, scenario_path(), "toolpath.gcode", 1,
                 "G-code file 'notes.gcode' holds no G-code: none of its 2 lines has a G or M "
                 "code");
}

TEST_F(ScenarioErrors, BadOutputs) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
outputs:
  render: maybe
  image_width: 8
  image_height: 480.5
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "outputs.render", 3,
                 "expected true or false, got 'maybe'");
  expect_problem(problems, scenario_path(), "outputs.image_width", 4,
                 "must be a whole number in [16, 2048], got 8");
  expect_problem(problems, scenario_path(), "outputs.image_height", 5, "whole number");
}

TEST_F(ScenarioErrors, BadSim) {
  const auto problems = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
sim: {timestep_s: 0.02, cell_mm: -1, kp_scale: 0, settle_s: 0}
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "sim.timestep_s", 2,
                 "must be in [1e-05, 0.01], got 0.02");
  expect_problem(problems, scenario_path(), "sim.cell_mm", 2, "must be in [0, 100], got -1");
  expect_problem(problems, scenario_path(), "sim.kp_scale", 2, "must be in [0.1, 10], got 0");
}

TEST_F(ScenarioErrors, ProcessKeyOfTheOtherType) {
  const auto problems = problems_of(R"(
process:
  type: aerosol
  sigma_mm: 0
  tau_s: 0.05
  retract: true
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  expect_problem(problems, scenario_path(), "process.sigma_mm", 3,
                 "must be in [0.001, 100], got 0");
  expect_problem(problems, scenario_path(), "process.tau_s", 4,
                 "applies to extrusion, not to process type aerosol");
  expect_problem(problems, scenario_path(), "process.retract", 5,
                 "applies to extrusion, not to process type aerosol");
  // on extrusion, a word that is not true or false
  const auto word = problems_of(R"(
process: {type: extrusion, retract: sometimes}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(word.size(), 1u) << dump(word);
  expect_problem(word, scenario_path(), "process.retract", 1, "expected true or false, got");
}

// the cell of the deposition grid against the footprint it samples, and the servo loop's
// stability against the step: cross-checks between sections, at the key given
TEST_F(ScenarioErrors, SimAgainstProcessAndTheServoLoop) {
  const auto problems = problems_of(R"(
process: {type: aerosol, sigma_mm: 0.2}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
sim:
  cell_mm: 0.001
  timestep_s: 0.01
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  // sigma / 64 = 0.003125 mm
  expect_problem(problems, scenario_path(), "sim.cell_mm", 4,
                 "between sigma / 64 = 0.003125 and sigma = 0.2 mm");
  // kp_scale 1 at 10 ms: 1 * (10 ms / 1 ms)^2 = 100 > 25
  expect_problem(problems, scenario_path(), "sim.timestep_s", 5, "(timestep_s / 1 ms)^2 = 100");
}

// the servo loop's bound is the machine's, measured with its own gains: kp_scale 5 at 2 ms
// (20) runs on the XY stage and diverged on the linear delta (bound 10) and on the gantry
// (bound 16, which 4 ms at kp_scale 1 meets)
TEST_F(ScenarioErrors, TheServoLoopsBoundIsTheMachines) {
  const std::string toolpath = "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n";
  const std::string stiff = "sim: {kp_scale: 5, timestep_s: 0.002}\n";
  const auto stage = problems_of("machine: xy_stage\n" + toolpath + stiff);
  EXPECT_TRUE(stage.empty()) << dump(stage);
  const auto delta = problems_of("machine: linear_delta\n" + toolpath + stiff);
  ASSERT_EQ(delta.size(), 1u) << dump(delta);
  expect_problem(delta, scenario_path(), "sim.timestep_s", 3, "= 20, at most 10 on linear_delta");
  const std::string gantry =
      "machine: cartesian\ntoolpath: {speed: 3, segments: [[[50, 50], "
      "[51, 50]]]}\n";
  const auto refused = problems_of(gantry + stiff);
  ASSERT_EQ(refused.size(), 1u) << dump(refused);
  expect_problem(refused, scenario_path(), "sim.timestep_s", 3, "= 20, at most 16 on cartesian");
  const auto at_the_bound = problems_of(gantry + "sim: {timestep_s: 0.004}\n");
  EXPECT_TRUE(at_the_bound.empty()) << dump(at_the_bound);
}

// a path given twice is refused at the second, naming the first (either way round)
TEST_F(ScenarioErrors, RepeatedPathsNameTheFirst) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  segments:
    - [[0, 0], [1, 0]]
    - [[2, 0], [3, 0]]
    - [[1, 0], [0, 0]]
  )");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.segments[2]", 6,
                 "repeats toolpath.segments[0] (the same points, reversed)");
  const auto polylines = problems_of(R"(
toolpath:
  speed: 3
  polylines:
    - [[0, 0], [1, 0], [1, 1]]
    - [[0, 0], [1, 0], [1, 2]]
    - [[0, 0], [1, 0], [1, 1]]
)");
  ASSERT_EQ(polylines.size(), 1u) << dump(polylines);
  expect_problem(polylines, scenario_path(), "toolpath.polylines[2]", 6,
                 "repeats toolpath.polylines[0] (the same points)");
}

// a name (and a label) names a folder: printable, at most 100 bytes, refused otherwise
TEST_F(ScenarioErrors, HostileNamesAreRefused) {
  const auto problems = problems_of(
      "name: \"a\\nb\\tc\\a\"\n"
      "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n"
      "planners: [{name: lspb_mtt, label: \"x\\e[31m\"}]\n");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "name", 1, "'a\\x0Ab\\x09c\\x07' holds a control");
  expect_problem(problems, scenario_path(), "planners[0].label", 3, "'x\\x1B[31m' holds a control");
  const auto long_name = problems_of("name: " + std::string(101, 'n') +
                                     "\ntoolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n");
  ASSERT_EQ(long_name.size(), 1u) << dump(long_name);
  expect_problem(long_name, scenario_path(), "name", 1, "is 101 bytes long");
}

// a label names a run's folder beside the output folder's own files: the marker .depotwin (a
// run labelled so replaced it, and a sweep then wrote into the run's folder), compare's
// comparison.* (compare ran every simulation, then failed to move its table: exit 1) and a
// sweep task's task.json; a name starting with '.' (hidden) is refused with them
TEST_F(ScenarioErrors, ALabelCannotTakeTheNameOfAnOutputFile) {
  const auto scenario_with_label = [](const std::string& label) {
    return "toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n"
           "planners: [{name: lspb_mtt, label: \"" +
           label + "\"}, stop_and_go]\n";
  };
  for (const std::string label : {".depotwin", "comparison.json", "comparison.csv", "comparison.md",
                                  "comparison.png", "task.json", ".hidden"}) {
    const auto problems = problems_of(scenario_with_label(label));
    ASSERT_EQ(problems.size(), 1u) << dump(problems);
    expect_problem(problems, scenario_path(), "planners[0].label", 2,
                   "'" + label + "' cannot name a run: the run folders sit beside");
  }
  // names near them are labels like any other
  for (const std::string label : {"comparison", "comparison.txt", "a.depotwin", "task.json2"})
    EXPECT_TRUE(problems_of(scenario_with_label(label)).empty()) << label;
}

// process.flow_mm3_s on extrusion: a fixed nominal flow (a constant-rate extruder)
TEST_F(ScenarioErrors, ExtrusionTakesAFixedFlow) {
  const auto problems = problems_of(R"(
process: {type: extrusion, flow_mm3_s: 0.5}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  EXPECT_TRUE(problems.empty()) << dump(problems);
}

TEST_F(ScenarioErrors, UnknownProcessType) {
  const auto problems = problems_of(R"(
process: {type: inkjet}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "process.type", 1, "unknown process type 'inkjet'");
}

TEST_F(ScenarioErrors, UnknownMachineAndMissingModel) {
  const auto unknown = problems_of(R"(
machine: scara
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(unknown.size(), 1u) << dump(unknown);
  expect_problem(
      unknown, scenario_path(), "machine", 1,
      "unknown machine 'scara' (expected xy_stage, linear_delta, arm6, cartesian, or {model:");
  // a point the default machine (xy_stage) could not reach: no error about that machine
  const auto unknown_with_z = problems_of(R"(
machine: delta
toolpath: {speed: 3, segments: [[[0, 0, 5], [1, 0, 5]]]}
)");
  ASSERT_EQ(unknown_with_z.size(), 1u) << dump(unknown_with_z);
  expect_problem(unknown_with_z, scenario_path(), "machine", 1, "unknown machine 'delta'");
  // a missing model still names its family, whose reach is checked
  const auto missing = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
machine: {model: models/none.xml, kinematics: xy_stage}
)");
  ASSERT_EQ(missing.size(), 1u) << dump(missing);
  expect_problem(missing, scenario_path(), "machine.model", 2,
                 "MJCF file 'models/none.xml' not found");
  const auto missing_off_stage = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0, 5], [1, 0, 5]]]}
machine: {model: models/none.xml, kinematics: xy_stage}
)");
  ASSERT_EQ(missing_off_stage.size(), 4u) << dump(missing_off_stage);
  expect_problem(missing_off_stage, scenario_path(), "machine.model", 2,
                 "MJCF file 'models/none.xml' not found");
  // the stage has no z: 5 mm down (and 0.5 mm in -x, centred) brings the line onto it
  expect_problem(missing_off_stage, scenario_path(), "toolpath.offset", 1,
                 "moved by (-0.5, 0, -5) mm every point is within xy_stage's reach");
}

// an MJCF model names its kinematics family; it is never guessed from the file
TEST_F(ScenarioErrors, MjcfMachineNamesItsKinematics) {
  std::filesystem::create_directories(dir_ / "models");
  std::ofstream(dir_ / "models" / "mine.xml") << "<mujoco/>\n";
  const auto bare = problems_of(R"(
machine: models/mine.xml
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(bare.size(), 1u) << dump(bare);
  expect_problem(
      bare, scenario_path(), "machine", 1,
      "must name its kinematics family, which is never guessed: machine: {model: "
      "models/mine.xml, kinematics: NAME} with NAME one of xy_stage, linear_delta, arm6");
  const auto unknown_family = problems_of(R"(
machine: {model: models/mine.xml, kinematics: scara}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(unknown_family.size(), 1u) << dump(unknown_family);
  expect_problem(
      unknown_family, scenario_path(), "machine.kinematics", 1,
      "unknown kinematics family 'scara' (expected xy_stage, linear_delta, arm6, cartesian)");
  const auto missing_family = problems_of(R"(
machine: {model: models/mine.xml}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(missing_family.size(), 1u) << dump(missing_family);
  expect_problem(missing_family, scenario_path(), "machine", 1, "missing kinematics");
}

// a j_max is honoured by every planner (each has a jerk-limited mode): no planner line is an
// error, while a j_max that is not a number still is
TEST_F(ScenarioErrors, JerkLimitIsAcceptedByEveryPlanner) {
  const auto accepted = problems_of(R"(
limits: {v_max: 4, a_max: 30, j_max: 500}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners: [lspb_mtt, stop_and_go, bezier, conformal, firmware]
)");
  EXPECT_TRUE(accepted.empty()) << dump(accepted);
  const auto refused = problems_of(R"(
limits: {v_max: 4, a_max: 30, j_max: -5}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
planners: [bezier]
)");
  ASSERT_EQ(refused.size(), 1u) << dump(refused);
  expect_problem(refused, scenario_path(), "limits.j_max", 1, "must be in [0, 1e+12], got -5");
}

TEST_F(ScenarioErrors, DuplicateKey) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  segments: [[[0, 0], [1, 0]]]
  speed: 4
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.speed", 4, "given twice");
}

TEST_F(ScenarioErrors, EmptyValueIsReportedAtItsKey) {
  const auto problems = problems_of(R"(
limits:
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "limits", 1, "expected a map, got nothing");
}

// every problem of a surface toolpath in one run, each at its key
TEST_F(ScenarioErrors, SurfaceProblemsAreListedTogether) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  surface:
    mesh: part.stl
    units: furlong
    alpha: 2
    angles: []
    layers: 0
    layer_offset: sideways
    chord_tolerance_mm: 1e-12
)");
  ASSERT_EQ(problems.size(), 8u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.surface", 3, "missing file");
  expect_problem(problems, scenario_path(), "toolpath.surface.mesh", 4, "unknown key");
  expect_problem(problems, scenario_path(), "toolpath.surface.units", 5, "unknown units 'furlong'");
  expect_problem(problems, scenario_path(), "toolpath.surface.alpha", 6, "must be in [0, 1]");
  expect_problem(problems, scenario_path(), "toolpath.surface.angles", 7, "is empty");
  expect_problem(problems, scenario_path(), "toolpath.surface.layers", 8, "whole number");
  expect_problem(problems, scenario_path(), "toolpath.surface.layer_offset", 9,
                 "unknown layer offset 'sideways'");
  // (a tolerance of atoms ran shembekar_beam out of memory: bad_alloc after 5 GB)
  expect_problem(problems, scenario_path(), "toolpath.surface.chord_tolerance_mm", 10,
                 "is 1e-12 mm: give 0 (the grid's points only) or at least 0.0001 mm");
}

// a missing STL names the path looked for; an offset outside surface: is refused
TEST_F(ScenarioErrors, SurfaceFileMustExist) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  offset: [1, 2]
  surface: {file: nowhere.stl}
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.offset", 3, "surface.offset");
  expect_problem(problems, scenario_path(), "toolpath.surface.file", 4,
                 "STL file 'nowhere.stl' not found");
}

// a file that is no STL is named at its `file:` line; a hatch too coarse for the part says so
TEST_F(ScenarioErrors, SurfaceFileProblemsAtTheFileLine) {
  write("notes.stl", "hello, world\n");
  const auto problems = problems_of(R"(
machine: arm6
toolpath:
  speed: 3
  surface:
    units: mm
    file: notes.stl
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.surface.file", 6,
                 "'notes.stl': not an STL file");
  // a 1 mm square under a 2 mm hatch: no line crosses it in two points
  write("tiny.stl",
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 5\nvertex 1 0 5\nvertex 1 1 5\n"
        "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 5\nvertex 1 1 5\n"
        "vertex 0 1 5\nendloop\nendfacet\nendsolid t\n");
  const auto coarse = problems_of(R"(
machine: arm6
toolpath:
  speed: 3
  surface: {file: tiny.stl, hatch_mm: 2, offset: [400, 0, 0]}
)");
  ASSERT_EQ(coarse.size(), 1u) << dump(coarse);
  expect_problem(coarse, scenario_path(), "toolpath.surface", 4,
                 "no hatch line crosses it in two points: hatch_mm 2 mm over the part's 1 x 1 mm");
}

// `arm:` belongs to the arm
TEST_F(ScenarioErrors, ArmSettingsNeedTheArm) {
  const auto problems = problems_of(R"(
machine: xy_stage
arm: {roll: sideways}
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  expect_problem(problems, scenario_path(), "arm", 2, "applies to machine arm6");
  expect_problem(problems, scenario_path(), "arm.roll", 2, "unknown roll strategy 'sideways'");
}

TEST_F(ScenarioErrors, BadRandomSegments) {
  const auto problems = problems_of(R"(
toolpath:
  speed: 3
  random_segments:
    n: 0
    bed: [100]
    length: [40, 10]
    seed: 1.5
)");
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.random_segments.n", 4,
                 "must be a whole number in [1, 100000], got 0");
  expect_problem(problems, scenario_path(), "toolpath.random_segments.bed", 5,
                 "expected a list of 2 numbers, got a list of 1");
  expect_problem(problems, scenario_path(), "toolpath.random_segments.length", 6, "min <= max");
  expect_problem(problems, scenario_path(), "toolpath.random_segments.seed", 7,
                 "whole number >= 0");
  // the bed and the lengths are required (they were defaulted silently)
  const auto missing = problems_of("toolpath:\n  speed: 3\n  random_segments: {n: 5}\n");
  ASSERT_EQ(missing.size(), 2u) << dump(missing);
  expect_problem(missing, scenario_path(), "toolpath.random_segments.bed", 3,
                 "missing: the bed's size [w, h] in mm");
  expect_problem(missing, scenario_path(), "toolpath.random_segments.length", 3,
                 "missing: the segments' lengths [min, max] in mm");
}

TEST_F(ScenarioErrors, BadName) {
  const auto problems = problems_of(R"(
name: ../escape
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, scenario_path(), "name", 1, "cannot name a results folder");
}

TEST_F(ScenarioErrors, TextYamlCppLoopsOnIsAFileWithoutSettings) {
  // yaml-cpp 0.7's LoadAll never returned on these (null documents without end, memory
  // growing): found by fuzz_scenario
  for (const char* text : {",", ",-/"}) {
    const auto problems = problems_of(text);
    ASSERT_EQ(problems.size(), 1u) << text << "\n" << dump(problems);
    EXPECT_EQ(problems[0].line, 1) << problems[0].str();
  }
}

TEST_F(ScenarioErrors, EmptyFileAndSeveralDocuments) {
  const auto empty = problems_of("# only a comment\n");
  ASSERT_EQ(empty.size(), 1u) << dump(empty);
  EXPECT_NE(empty[0].message.find("holds no settings"), std::string::npos) << empty[0].str();
  const auto two = problems_of(R"(
toolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}
---
name: second
)");
  ASSERT_EQ(two.size(), 1u) << dump(two);
  EXPECT_EQ(two[0].line, 3) << two[0].str();
  EXPECT_NE(two[0].message.find("more than one YAML document"), std::string::npos);
  const auto list = problems_of("- just\n- a list\n");
  ASSERT_EQ(list.size(), 1u) << dump(list);
  EXPECT_EQ(list[0].line, 1);
  EXPECT_NE(list[0].message.find("expected a map, got a list"), std::string::npos);
}

// a YAML tag would make text of a number or null of a value the reader takes by its text:
// `speed: !!str 3` was read as the number 3 (and `"3"` refused); every tag is refused at its
// line, a quoted or plain value is read as before
TEST_F(ScenarioErrors, YamlTagsAreRefusedAtTheirLine) {
  for (const std::string tagged : {"!!str 3", "!!null 3", "!!int 3.5", "!!float \"3\"", "!foo 3"}) {
    const auto problems = problems_of("name: tags\ntoolpath:\n  speed: " + tagged +
                                      "\n  segments: [[[0, 0], [1, 0]]]\n");
    ASSERT_EQ(problems.size(), 1u) << tagged << "\n" << dump(problems);
    EXPECT_EQ(problems[0].line, 3) << problems[0].str();
    const std::string tag = tagged.substr(0, tagged.find(' '));
    EXPECT_EQ(
        problems[0].message.rfind("YAML tag '" + tag + "': a scenario file's values are plain", 0),
        0u)
        << problems[0].str();
  }
  const auto on_a_map = problems_of("toolpath: !!map {speed: 3, segments: [[[0, 0], [1, 0]]]}\n");
  ASSERT_EQ(on_a_map.size(), 1u) << dump(on_a_map);
  EXPECT_EQ(on_a_map[0].line, 1);
  EXPECT_TRUE(
      problems_of("name: plain\ntoolpath: {speed: 3, segments: [[[0, 0], [1, 0]]]}\n").empty());
}

// three independent mistakes: all three reported, in line order, by one InputError
TEST_F(ScenarioErrors, ReportsEveryProblemNotOnlyTheFirst) {
  const std::string path = write("three.yaml", R"(
name: three_problems
limits: {v_max: 0, a_max: 30}
toolpath:
  speed: 3
  segments:
    - [[0, 0], [0, 0]]
planners: [lspb_mtt, teleport]
)");
  try {
    load_scenario(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::vector<Problem>& problems = e.problems();
    ASSERT_EQ(problems.size(), 3u) << dump(problems);
    EXPECT_EQ(problems[0].str(), path + ":2: limits.v_max: must be in [1e-06, 1e+06], got 0");
    EXPECT_EQ(problems[1].key, "toolpath.segments[0]");
    EXPECT_EQ(problems[1].line, 6);
    EXPECT_EQ(problems[2].key, "planners[1]");
    EXPECT_EQ(problems[2].line, 7);
    // what() carries every problem, one per line
    const std::string text = e.what();
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);
  }
}

}  // namespace
}  // namespace depotwin
