// `toolpath: {gcode: {file, rule, open, close, layers, feed, chord_tolerance_mm}}` (issue 14):
// feed rates clamped to the machine's limits and counted, the start at the file's first point,
// one error for several z levels on a machine without z, layer selection, arcs chorded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scenario/scenario_test_util.hpp"
#include "scenario/schema.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using testing_scenario::expect_problem;

class ScenarioGcode : public testing_scenario::ScenarioFiles {};

// three layers of a 10 mm line, z = 0, 0.2, 0.4 (lines 2, 4, 6 start them)
constexpr const char* kThreeLayers =
    "G90\nG1 X0 Y0 Z0 F600\nG1 X10 Y0 E1\nG0 X0 Y0 Z0.2\nG1 X10 Y0 E2\nG0 X0 Y0 Z0.4\n"
    "G1 X10 Y0 E3\n";

// F600 = 10 mm/s: along x and along y it needs 10 mm/s of one axis (v_max 4: slowed to 4), on
// the diagonal 7.07 mm/s of each (slowed to 4 sqrt 2); the first move, 2 mm/s, is within
TEST_F(ScenarioGcode, FeedAboveTheLimitsIsClampedPerMoveAndCounted) {
  write("fast.gcode", "G1 X1 Y0 E1 F120\nG1 X11 Y0 E2 F600\nG1 X11 Y10 E3\nG1 X21 Y20 E4\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
limits: {v_max: 4, a_max: 30}
toolpath: {gcode: fast.gcode}
)"));
  ASSERT_TRUE(s.gcode);
  EXPECT_EQ(s.gcode->feed, "clamp");
  EXPECT_EQ(s.gcode->print_moves, 4);
  EXPECT_EQ(s.gcode->clamped_moves, 3);
  // a speed change starts a new path at the same point
  ASSERT_EQ(s.toolpath.paths.size(), 3u);
  EXPECT_DOUBLE_EQ(s.toolpath.paths[0].speed_mm_s, 2.0);
  EXPECT_DOUBLE_EQ(s.toolpath.paths[1].speed_mm_s, 4.0);
  EXPECT_EQ(s.toolpath.paths[1].points.size(), 3u);
  EXPECT_NEAR(s.toolpath.paths[2].speed_mm_s, 4.0 * std::sqrt(2.0), 1e-12);
  for (std::size_t i = 0; i < s.toolpath.paths.size(); ++i)
    EXPECT_EQ(s.toolpath.paths[i].source_index, static_cast<int>(i));
  EXPECT_DOUBLE_EQ(s.toolpath.print_length_mm(), 1.0 + 10.0 + 10.0 + std::hypot(10.0, 10.0));
  // the count reaches metrics.json's warnings; auto says which rule it chose
  ASSERT_EQ(s.notes.size(), 2u);
  EXPECT_EQ(s.notes[0].rfind("toolpath.gcode: auto chose e", 0), 0u) << s.notes[0];
  EXPECT_EQ(s.notes[1],
            "toolpath.gcode: 3 of 4 print moves asked for more than the machine's speed limits "
            "and were slowed to them (feed: clamp, as firmware does; the largest cut 10 -> 4 "
            "mm/s)");
}

// an M220 speed factor: the print paths run at F times it, and metrics.json's warnings say so
TEST_F(ScenarioGcode, ASpeedFactorScalesThePrintSpeedsAndIsNoted) {
  write("slow.gcode", "G1 X0 Y0 F600\nM220 S50\nG1 X10 Y0 E1\nG1 X10 Y10 E2\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
limits: {v_max: 100, a_max: 1000}
toolpath: {gcode: {file: slow.gcode, rule: e}}
)"));
  ASSERT_EQ(s.toolpath.paths.size(), 1u);
  EXPECT_DOUBLE_EQ(s.toolpath.paths[0].speed_mm_s, 5.0);
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_EQ(s.notes[0],
            "toolpath.gcode: the M220 on line 2 sets a speed factor other than 100 %: 2 moves "
            "run at their F times it, as firmware runs them");
}

// `feed: error` keeps the error, at the move's line
TEST_F(ScenarioGcode, FeedErrorRefusesMovesAboveTheLimits) {
  write("fast.gcode", "G1 X1 Y0 E1 F120\nG1 X11 Y0 E2 F600\n");
  const auto problems = problems_of(R"(
limits: {v_max: 4, a_max: 30}
toolpath: {gcode: {file: fast.gcode, feed: error}}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, (dir_ / "fast.gcode").string(), "toolpath.gcode", 2,
                 "print speed 10 mm/s needs 10 mm/s on x, above limits v_max 4");
}

// the start (and end) default to the file's first print point; offset moves them with it
TEST_F(ScenarioGcode, StartDefaultsToTheFirstPointAndMovesWithTheOffset) {
  write("far.gcode", "G0 X30 Y40\nG1 X50 Y60 F120\nG1 X60 Y60 E1\nG1 X60 Y70 E2\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
toolpath:
  gcode: {file: far.gcode, rule: e}
  offset: [-50, -60]
)"));
  ASSERT_EQ(s.toolpath.paths.size(), 1u);
  EXPECT_EQ(s.toolpath.paths[0].points.front(), Vec3(0, 0, 0));
  EXPECT_EQ(s.toolpath.start_mm, Vec3(0, 0, 0));
  EXPECT_EQ(s.toolpath.end_mm, Vec3(0, 0, 0));
  EXPECT_TRUE(s.notes.empty());  // no auto, nothing clamped
}

// a file of several layers ends above its start at its highest print point, not by moving
// down through its layers to its first point; where that point is out of the machine's reach
// (the delta's carriages bottom out under (130, 0, 190)), at the file's last print point
TEST_F(ScenarioGcode, TheEndDefaultsToTheStartRaisedToTheTopLayer) {
  write("layers.gcode", kThreeLayers);
  // the three layers on the cartesian printer, with one more toolpath key
  const auto layers_with = [&](const std::string& name, const std::string& key) {
    return load_scenario(write(name,
                               "machine: cartesian\nlimits: {v_max: 20, a_max: 300}\n"
                               "toolpath:\n  gcode: layers.gcode\n  " +
                                   key + "\n"));
  };
  const Scenario layered = layers_with("s.yaml", "offset: [5, 0, 1]");
  EXPECT_EQ(layered.toolpath.start_mm, Vec3(5, 0, 1));
  EXPECT_EQ(layered.toolpath.end_mm, Vec3(5, 0, 1.4));
  // the start given: the end is it raised
  const Scenario given = layers_with("given.yaml", "start: [2, 3, 0]");
  EXPECT_EQ(given.toolpath.end_mm, Vec3(2, 3, 0.4));
  write("tall.gcode", "G1 X130 Y0 Z0 F600\nG1 X131 Y0 E1\nG0 X0 Y0 Z190\nG1 X1 Y0 E2\n");
  const Scenario tall = load_scenario(write("tall.yaml", R"(
machine: linear_delta
limits: {v_max: 20, a_max: 300, joint: {v_max: 200, a_max: 3000}}
process: {type: extrusion, bead_width_mm: 0.45, layer_height_mm: 0.2}
toolpath: {gcode: tall.gcode}
)"));
  EXPECT_EQ(tall.toolpath.start_mm, Vec3(130, 0, 0));
  EXPECT_EQ(tall.toolpath.end_mm, Vec3(1, 0, 190));
}

// a file below the cartesian's bed (zeroed on a stock's top): refused at its points, and the
// offset that lifts it onto the bed suggested (before: one that centred it at z = 70)
TEST_F(ScenarioGcode, AFileBelowTheBedIsLiftedOntoIt) {
  write("below.gcode", "G1 X10 Y0 Z-1.5 F600\nG1 X13 Y0 E1\n");
  const auto problems = problems_of(R"(
machine: cartesian
limits: {v_max: 20, a_max: 300}
toolpath: {gcode: below.gcode}
)");
  const auto offset = std::find_if(problems.begin(), problems.end(),
                                   [](const Problem& p) { return p.key == "toolpath.offset"; });
  ASSERT_NE(offset, problems.end()) << dump(problems);
  EXPECT_NE(offset->message.find("moved by (-11.5, 0, 1.5) mm every point is within cartesian's "
                                 "reach"),
            std::string::npos)
      << offset->message;
}

// several z levels on the XY stage: one problem, at the first move off the first level
TEST_F(ScenarioGcode, SeveralZLevelsWithoutZIsOneError) {
  write("layers.gcode", kThreeLayers);
  const auto problems = problems_of(R"(
limits: {v_max: 20, a_max: 300}
toolpath: {gcode: layers.gcode}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, (dir_ / "layers.gcode").string(), "toolpath.gcode", 5,
                 "the file prints at 3 z levels (0 to 0.4 mm) but xy_stage has no z axis");
}

// a CAM pass that plunges with the shutter already open changes z within its print run: no
// layer choice helps (before, the message counted its points' heights as "2 z levels" and
// suggested `layers: [k, k]`, though the file has one layer and [0, 0] was refused alike)
TEST_F(ScenarioGcode, APlungeWhilePrintingWithoutZIsNotCalledLayers) {
  write("plunge.gcode", "G21 G90\nG0 X0 Y0 Z5\nM3\nG1 Z0 F300\nG1 X10 F600\nG1 Y10\nM5\nG0 Z5\n");
  for (const char* toolpath : {"{gcode: {file: plunge.gcode, rule: shutter}}",
                               "{gcode: {file: plunge.gcode, rule: shutter, layers: [0, 0]}}"}) {
    const auto problems =
        problems_of(std::string("limits: {v_max: 20, a_max: 300}\ntoolpath: ") + toolpath + "\n");
    ASSERT_EQ(problems.size(), 1u) << dump(problems);
    expect_problem(problems, (dir_ / "plunge.gcode").string(), "toolpath.gcode", 4,
                   "this print move changes z from 5 to 0 mm while printing");
    EXPECT_EQ(problems[0].message.find("layers: [k, k]"), std::string::npos) << problems[0].str();
  }
}

// on the cartesian machine every layer loads; `layers: [from, to]` selects some
TEST_F(ScenarioGcode, CartesianLoadsLayersAndSelectsThem) {
  write("layers.gcode", kThreeLayers);
  const Scenario all = load_scenario(write("all.yaml", R"(
machine: cartesian
limits: {v_max: 20, a_max: 300}
toolpath: {gcode: layers.gcode}
)"));
  ASSERT_EQ(all.toolpath.paths.size(), 3u);
  EXPECT_EQ(all.toolpath.layer_count(), 3);
  const Scenario some = load_scenario(write("some.yaml", R"(
machine: cartesian
limits: {v_max: 20, a_max: 300}
toolpath: {gcode: {file: layers.gcode, layers: [1, 2]}}
)"));
  ASSERT_EQ(some.toolpath.paths.size(), 2u);
  EXPECT_EQ(some.toolpath.paths[0].layer, 0);
  EXPECT_EQ(some.toolpath.paths[1].layer, 1);
  EXPECT_NEAR(some.toolpath.paths[0].points.front().z(), 0.2, 1e-12);
  EXPECT_EQ(some.gcode->layer_z_mm.size(), 3u);
  EXPECT_EQ(some.toolpath.start_mm, some.toolpath.paths[0].points.front());
}

// bad settings: each at its key and line
TEST_F(ScenarioGcode, BadSettingsNameTheirKeys) {
  write("layers.gcode", kThreeLayers);
  const auto problems = problems_of(R"(
machine: cartesian
toolpath:
  gcode:
    file: layers.gcode
    rule: sideways
    layers: [2, 1]
    feed: slow
    chord_tolerance_mm: 0
)");
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  expect_problem(problems, scenario_path(), "toolpath.gcode.rule", 5,
                 "unknown value 'sideways' (expected auto | e | shutter | feed)");
  expect_problem(problems, scenario_path(), "toolpath.gcode.layers", 6, "from (2) is after to (1)");
  expect_problem(problems, scenario_path(), "toolpath.gcode.feed", 7,
                 "unknown value 'slow' (expected clamp | error)");
  expect_problem(problems, scenario_path(), "toolpath.gcode.chord_tolerance_mm", 8,
                 "must be in [0.0001, 1], got 0");
}

// the shutter codes and a layer range the file lacks are named at their scenario keys, and a
// file that did not load adds no problem of the default start and end (its first print point,
// unknown): one problem each
TEST_F(ScenarioGcode, CodesAndLayersAreNamedAtTheirKeys) {
  write("layers.gcode", kThreeLayers);
  const auto bad_code = problems_of(R"(
machine: cartesian
toolpath:
  offset: [500, 0, 0]
  gcode: {file: layers.gcode, open: M4 S1000}
)");
  ASSERT_EQ(bad_code.size(), 1u) << dump(bad_code);
  expect_problem(bad_code, scenario_path(), "toolpath.gcode.open", 4,
                 "'M4 S1000' is not a G or M code (e.g. M3, M5, M106, M107)");
  const auto clash = problems_of(R"(
machine: cartesian
toolpath:
  gcode: {file: layers.gcode, open: M4, close: M3}
)");
  ASSERT_EQ(clash.size(), 1u) << dump(clash);
  expect_problem(clash, scenario_path(), "toolpath.gcode.close", 3,
                 "'M3' would close what 'M4' opens: M3 and M4 both switch a spindle or laser on");
  const auto layers = problems_of(R"(
machine: cartesian
limits: {v_max: 20, a_max: 300}
toolpath:
  offset: [500, 0, 0]
  gcode:
    file: layers.gcode
    layers: [0, 7]
)");
  ASSERT_EQ(layers.size(), 1u) << dump(layers);
  expect_problem(layers, scenario_path(), "toolpath.gcode.layers", 7,
                 "layers [0, 7] not in the file's 3 layers (0 to 2) of 'layers.gcode'");
}

// a G3 quarter circle of radius 10 becomes chords within the tolerance, on the circle
TEST_F(ScenarioGcode, ArcsAreChordedWithinTheTolerance) {
  write("arc.gcode", "G1 X10 Y0 F600\nG3 X0 Y10 I-10 J0 E1\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
machine: cartesian
limits: {v_max: 50, a_max: 500}
toolpath: {gcode: {file: arc.gcode, chord_tolerance_mm: 0.01}}
)"));
  ASSERT_EQ(s.toolpath.paths.size(), 1u);
  const PrintPath& path = s.toolpath.paths[0];
  EXPECT_FALSE(path.has_arcs());
  // 10 (1 - cos(theta / 2)) <= 0.01 needs at least 18 chords over 90 degrees
  EXPECT_GE(path.points.size(), 19u);
  for (std::size_t k = 0; k < path.points.size(); ++k)
    EXPECT_NEAR(path.points[k].head<2>().norm(), 10.0, 1e-9) << k;
  for (std::size_t k = 0; k + 1 < path.points.size(); ++k) {
    const double chord_mm = (path.points[k + 1] - path.points[k]).norm();
    EXPECT_LE(10.0 - std::sqrt(100.0 - chord_mm * chord_mm / 4.0), 0.01 + 1e-12) << k;
  }
  EXPECT_EQ(s.gcode->print_moves, 1);
  EXPECT_EQ(s.gcode->rule_applied, "e");
}

// Arcs stay exact beside their chords (issue 14: "arcs stay exact geometry until planning"):
// the same paths one for one, the exact ones with the file's arc lengths; `offset` moves the
// arcs' centres with their points; a feed clamp that splits a path splits its arcs with it.
TEST_F(ScenarioGcode, ArcsStayExactBesideTheirChords) {
  write("arc.gcode", "G1 X10 Y0 F600\nG1 X20 Y0 E1\nG3 X30 Y10 I0 J10 E2\nG1 X30 Y30 E3\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
machine: cartesian
limits: {v_max: 50, a_max: 500}
toolpath: {gcode: {file: arc.gcode, chord_tolerance_mm: 0.01}, offset: [-5, -5, 0]}
)"));
  ASSERT_EQ(s.toolpath.paths.size(), 1u);
  ASSERT_EQ(s.exact_toolpath.paths.size(), 1u);
  const PrintPath& exact = s.exact_toolpath.paths[0];
  const PrintPath& chorded = s.toolpath.paths[0];
  ASSERT_EQ(exact.points.size(), 4u);
  ASSERT_EQ(exact.arcs.size(), 3u);
  EXPECT_TRUE(exact.arcs[1].is_arc());
  EXPECT_NEAR(exact.length_mm(), 10.0 + 5.0 * kPi + 20.0, 1e-9);
  EXPECT_LT(chorded.length_mm(), exact.length_mm());
  EXPECT_GT(chorded.points.size(), 4u);
  // moved by the offset, centre included: (20, 10) - (5, 5)
  EXPECT_LT((exact.arcs[1].center_mm - Vec3(15, 5, 0)).norm(), 1e-12);
  EXPECT_LT((exact.points.front() - chorded.points.front()).norm(), 1e-12);
  EXPECT_LT((exact.points.back() - chorded.points.back()).norm(), 1e-12);
  EXPECT_LT((s.exact_toolpath.start_mm - s.toolpath.start_mm).norm(), 1e-12);
  EXPECT_EQ(s.exact_toolpath.chord_tolerance_mm, 0.01);

  // x's v_max 5 mm/s: the lines along x and the arc (it starts along x) are slowed, the last
  // line along y is not: two paths, the arc kept whole in the first
  const Scenario clamped = load_scenario(write("c.yaml", R"(
machine: cartesian
limits: {v_max: 50, a_max: 500, x: {v_max: 5}}
toolpath: {gcode: {file: arc.gcode, chord_tolerance_mm: 0.01}}
)"));
  ASSERT_EQ(clamped.exact_toolpath.paths.size(), clamped.toolpath.paths.size());
  double exact_mm = 0.0;
  for (const PrintPath& path : clamped.exact_toolpath.paths) {
    EXPECT_EQ(path.arcs.empty() ? path.points.size() - 1 : path.arcs.size(),
              path.points.size() - 1);
    exact_mm += path.length_mm();
  }
  EXPECT_NEAR(exact_mm, 10.0 + 5.0 * kPi + 20.0, 1e-9);
  EXPECT_GE(clamped.toolpath.paths.size(), 2u);
}

// A full circle far above the speed limits is slowed to them along the chords the checks see
// too: a coarse chord across the circle's top runs along x where no fine chord does, and the
// clamp from fine chords alone refused this file ("needs 300 mm/s on x, above v_max 300").
// Every chord of the loaded path then needs at most v_max on each axis.
TEST_F(ScenarioGcode, AFastCircleIsClampedAlongTheChordsTheChecksSee) {
  write("circle.gcode",
        "G21\nG90\nM83\nG1 X0 Y0 Z0.2 F6000\n"
        "G2 X0 Y0 I1.14554 J4.23418 E0.02 F60960\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
machine: cartesian
limits: {v_max: 300, a_max: 3000}
toolpath: {gcode: {file: circle.gcode, feed: clamp}}
)"));
  ASSERT_EQ(s.gcode->clamped_moves, 1);
  for (const PrintPath& path : s.toolpath.paths)
    for (std::size_t k = 0; k + 1 < path.points.size(); ++k) {
      const Vec3 step = path.points[k + 1] - path.points[k];
      for (int axis = 0; axis < 2; ++axis)
        EXPECT_LE(path.speed_mm_s * std::abs(step[axis]) / step.norm(), 300.0 * (1.0 + 1e-9))
            << "chord " << k << ", axis " << axis;
    }
  EXPECT_NEAR(s.toolpath.paths.front().speed_mm_s, 300.0, 0.5);
}

// A circle passes through tangents along x and y, so the clamp slows it to v_max exactly: the
// fine chords alone miss those tangents by half a chord's turn and allowed 300.15 mm/s at
// radius 2 mm, which chords cut otherwise (the uniform planner's) then needed on an axis
TEST_F(ScenarioGcode, AnArcIsClampedAlongItsExactTangents) {
  write("small.gcode", "G21\nG90\nM83\nG1 X0 Y0 Z0.2 F6000\nG2 X0 Y0 I2 J0 E0.02 F60000\n");
  const Scenario s = load_scenario(write("s.yaml", R"(
machine: cartesian
limits: {v_max: 300, a_max: 3000}
toolpath: {gcode: {file: small.gcode, feed: clamp}}
)"));
  ASSERT_EQ(s.exact_toolpath.paths.size(), 1u);
  const PrintPath& circle = s.exact_toolpath.paths.front();
  EXPECT_NEAR(circle.speed_mm_s, 300.0, 300.0 * 1e-12);
  // the exact arc's chords at any tolerance need at most v_max on each axis
  for (const double tolerance_mm : {0.05, 0.01, 1e-3, 1e-4, 1e-6}) {
    const PrintPath chords = circle.chorded(tolerance_mm);
    for (std::size_t k = 0; k + 1 < chords.points.size(); ++k) {
      const Vec3 step = chords.points[k + 1] - chords.points[k];
      for (int axis = 0; axis < 2; ++axis)
        EXPECT_LE(circle.speed_mm_s * std::abs(step[axis]) / step.norm(), 300.0 * (1.0 + 1e-12))
            << "tolerance " << tolerance_mm << ", chord " << k << ", axis " << axis;
    }
  }
}

// describe shows the keys (the same tables the loader checks)
// arcs whose chords a job cannot hold are counted, not cut: 100 circles of radius 1e9 mm (a
// number a file may hold) would take 7 * 10^7 chords within 0.01 mm, minutes to cut before
// each point is found out of reach; refused at once at the largest arc's line
TEST_F(ScenarioGcode, ArcsTooLargeToChordAreRefusedBeforeAnyIsCut) {
  std::string text = "G21 G90\nG1 X0 Y0 F6000\n";
  for (int i = 0; i < 100; ++i) text += i == 40 ? "G2 I999999999 E1\n" : "G2 I990000000 E1\n";
  write("huge.gcode", text);
  const auto problems = problems_of(R"(
toolpath: {gcode: {file: huge.gcode, rule: feed}}
)");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  expect_problem(problems, (dir_ / "huge.gcode").string(), "toolpath.gcode", 43,
                 "points with their arcs cut into chords within chord_tolerance_mm 0.01 mm, more "
                 "than a job holds (67108864); the arc on this line alone takes 702482 (radius "
                 "1e+09 mm)");
  // a circle of radius 40 mm is cut as before, its chords within 0.01 mm
  write("circle.gcode", "G21 G90\nG1 X0 Y0 F600\nG2 I40 E1\n");
  const Scenario circle = load_scenario(write("c.yaml", R"(
limits: {v_max: 100, a_max: 1000}
machine: cartesian
toolpath: {gcode: {file: circle.gcode, rule: feed}}
)"));
  ASSERT_EQ(circle.toolpath.paths.size(), 1u);
  EXPECT_EQ(circle.toolpath.paths[0].points.size(),
            static_cast<std::size_t>(arc_chord_count(40.0, 2.0 * kPi, 0.01)) + 1);
}

TEST(ScenarioGcodeSchema, TheTablesHoldTheGcodeKeys) {
  const SchemaSection& section = schema_section("toolpath.gcode");
  EXPECT_EQ(section.key_names(),
            (std::vector<std::string>{"file", "rule", "open", "close", "layers", "feed",
                                      "chord_tolerance_mm"}));
  EXPECT_EQ(section.key("chord_tolerance_mm").default_text, "0.01");
  EXPECT_EQ(section.key("feed").default_text, "clamp");
  EXPECT_EQ(section.key("rule").default_text, "auto");
}

}  // namespace
}  // namespace depotwin
