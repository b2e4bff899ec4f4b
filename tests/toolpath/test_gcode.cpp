// The G-code importer: print moves become polylines with the right points and speeds,
// modal state (G90/G91, M82/M83, G92, G20/G21, F) is followed, bad lines are reported.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "scenario/scenario_test_util.hpp"
#include "toolpath/gcode.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;

const std::string kFixture = std::string(DEPOTWIN_SOURCE_DIR) + "/tests/toolpath/data/square.gcode";

GcodeImport parse(const std::string& text, double default_speed_mm_s = 0.0) {
  std::istringstream in(text);
  return parse_gcode(in, "test.gcode", default_speed_mm_s);
}

// the problems of G-code text that must not parse
std::vector<Problem> problems_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.problems();
  }
  ADD_FAILURE() << "expected an InputError for:\n" << text;
  return {};
}

void expect_points(const PrintPath& path, const std::vector<Vec3>& expected) {
  ASSERT_EQ(path.points.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_TRUE(path.points[i].isApprox(expected[i], 1e-12) ||
                (path.points[i] - expected[i]).norm() < 1e-12)
        << "point " << i << ": " << path.points[i].transpose() << " != " << expected[i].transpose();
}

TEST(Gcode, FixtureGivesThreePaths) {
  const GcodeImport imported = read_gcode(kFixture, 0.0);
  const Toolpath& toolpath = imported.toolpath;
  ASSERT_EQ(toolpath.paths.size(), 3u);
  expect_points(toolpath.paths[0], {Vec3(10, 10, 0.2), Vec3(20, 10, 0.2), Vec3(20, 20, 0.2)});
  expect_points(toolpath.paths[1], {Vec3(20, 20, 0.2), Vec3(10, 20, 0.2)});
  expect_points(toolpath.paths[2], {Vec3(30, 10, 0.2), Vec3(40, 10, 0.2), Vec3(40, 15, 0.2)});
  // F600, F1200, F300 mm/min
  EXPECT_DOUBLE_EQ(toolpath.paths[0].speed_mm_s, 10.0);
  EXPECT_DOUBLE_EQ(toolpath.paths[1].speed_mm_s, 20.0);
  EXPECT_DOUBLE_EQ(toolpath.paths[2].speed_mm_s, 5.0);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(toolpath.paths[i].source_index, i);
  // the scenario sets start and end
  EXPECT_EQ(toolpath.start_mm, Vec3::Zero());
  EXPECT_EQ(toolpath.end_mm, Vec3::Zero());
  // lines of the moves that reached each point
  EXPECT_EQ(imported.point_lines[0], (std::vector<int>{15, 15, 16}));
  EXPECT_EQ(imported.point_lines[1], (std::vector<int>{17, 17}));
  EXPECT_EQ(imported.point_lines[2], (std::vector<int>{23, 23, 25}));
  // import_gcode is the same paths
  EXPECT_EQ(import_gcode(kFixture, 0.0).paths.size(), 3u);
}

TEST(Gcode, RelativePositioningMakesExtrusionRelativeToo) {
  // G91 makes E relative even under M82 (Marlin, Klipper), so E1 twice prints twice
  const GcodeImport imported = parse("M82\nG91\nG1 X5 E1 F600\nG1 Y5 E1\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5, 5, 0)});
  // absolute E under M82/G90: E1 then E1 again is no extrusion, so a travel
  const GcodeImport absolute = parse("M82\nG90\nG1 X5 E1 F600\nG1 Y5 E1\n");
  ASSERT_EQ(absolute.toolpath.paths.size(), 1u);
  expect_points(absolute.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(5, 0, 0)});
  // M83 then G90: relative E with absolute positions (Klipper's rule)
  const GcodeImport m83 = parse("M83\nG90\nG1 X5 E1 F600\nG1 X5 Y5 E1\n");
  ASSERT_EQ(m83.toolpath.paths.size(), 1u);
  expect_points(m83.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(5, 0, 0), Vec3(5, 5, 0)});
}

TEST(Gcode, RetractionIsNotAPrintMove) {
  // relative E: a negative E move (retract) with motion is a travel and ends the path
  const GcodeImport imported = parse("M83\nG1 X1 E1 F600\nG1 X2 E-0.5\nG1 X3 E1\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 2u);
  expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(1, 0, 0)});
  expect_points(imported.toolpath.paths[1], {Vec3(2, 0, 0), Vec3(3, 0, 0)});
}

// a move shorter than the toolpath's tolerance for one point (kJoinTolerance_mm) is no move: a
// CAM program's rounding does not become a zero-length segment the scenario check refuses
TEST(Gcode, SubMicronMoveIsNoSegment) {
  const GcodeImport imported = parse("G1 X1 E1 F600\nG1 X1.0000002 E1\nG1 X2 E2\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  const PrintPath& path = imported.toolpath.paths[0];
  ASSERT_EQ(path.points.size(), 3u);
  expect_points(path, {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)});
  for (std::size_t k = 0; k + 1 < path.points.size(); ++k)
    EXPECT_GT((path.points[k + 1] - path.points[k]).norm(), kJoinTolerance_mm);
}

// M codes take axis letters as parameters (a slicer's start code: M201 accelerations, M203
// feeds, M205 jerk, M92 steps per mm): never a move, before the first move (which used to be
// refused as axis words without a motion command) or after one (a modal G1 to X1000)
TEST(Gcode, McodeAxisWordsAreParametersNotMoves) {
  const GcodeImport imported = parse(
      "M201 X1000 Y1000 Z200 E5000\nM203 X200 Y200 Z12 E120\nM205 X8.00 Y8.00 Z0.40 E4.50\n"
      "G1 X1 E1 F600\nM92 X80 Y80\nG1 Y1 E2\nM906 X800 Y800\nX2 E3\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  // the modal G1 still holds for a bare axis line after the M codes
  expect_points(imported.toolpath.paths[0],
                {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(2, 1, 0)});
}

// an M code that takes no axis words (coolant, spindle, tool change, fan) beside a modal
// move: the move runs (Fanuc's `X20. M8`, Haas's `G43 H01 Z0.1 M08`), as LinuxCNC runs it; a
// line that starts with one is no exception
TEST(Gcode, ModalMovesBesideCoolantAndSpindleCodesRun) {
  const GcodeImport imported = parse(
      "G21 G90 G1 F600\nX0 Y0 E0 M8\nX10 E1 M9\nM7 Y10 E2\nG43 H01 Z1 M08\nX0 E3 M106\n"
      "M201 X1000\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 2u);
  expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(10, 10, 0)});
  expect_points(imported.toolpath.paths[1], {Vec3(10, 10, 1), Vec3(0, 10, 1)});
}

// M2 or M30 alone ends the program, and so does the `%` closing one a `%` opened (RS274/NGC,
// grbl): nothing after them is read, only counted (not the closing `%` after an M30, as CAM
// posts end their files); Marlin's `M30 file.gco` deletes a file
TEST(Gcode, TheProgramEndsAtM2M30OrTheClosingPercent) {
  GcodeOptions options;
  for (const auto& [text, end_line, after] : std::vector<std::tuple<std::string, int, int>>{
           {"G1 X10 E1 F600\nM30 (end)\n\nG1 X500 E2\nG1 Y500 E3\n", 2, 2},
           {"G1 X10 E1 F600\nG0 Z5 M2\nG1 X500 E2\n", 2, 1},
           {"%\nG1 X10 E1 F600\n%\nG1 X500 E2\n", 3, 1},
           {"%\nG1 X10 E1 F600\nM30\n%\n", 3, 0},
           {"%\nG1 X10 E1 F600\nM30\n %\n%\nG1 X500 E2\n", 3, 2},
           {"G1 X10 E1 F600\nM30 part.gco\n", 0, 0},
           {"G1 X10 E1 F600\n%\n", 0, 0}}) {
    const GcodeProgram program = parse_gcode_program(text, "end.gcode", options);
    EXPECT_EQ(program.program_end_line, end_line) << text;
    EXPECT_EQ(program.n_lines_after_end, after) << text;
    const GcodeImport imported = import_gcode_program(program, options);
    ASSERT_EQ(imported.toolpath.paths.size(), 1u) << text;
    expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  }
}

// a Klipper macro whose name starts with `_` is a named command like any other (no motion);
// more G and M codes on a line than the reader holds are named as that
TEST(Gcode, UnderscoreMacrosAndCrowdedLines) {
  const GcodeImport imported = parse("_CLIENT_RETRACT LENGTH=1\nG1 X1 E1 F600\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  std::string crowded = "G1 X1";
  for (int i = 0; i < 20; ++i) crowded += " M" + std::to_string(220 + i);
  const auto problems = problems_of(crowded + "\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].message.rfind("more than 16 G and M codes on one line (at 'M235')", 0), 0u)
      << problems[0].str();
}

// G4: S in seconds wins over P in milliseconds (Marlin), Fanuc's X is seconds
TEST(Gcode, DwellsReadSOverPAndFanucX) {
  GcodeOptions options;
  const GcodeProgram program = parse_gcode_program(
      "G1 X1 E1 F600\nG4 S1 P250\nG4 P500\nG04 X2.\nG4 S0.25\n", "dwell.gcode", options);
  ASSERT_EQ(program.pauses.size(), 4u);
  EXPECT_DOUBLE_EQ(program.pauses[0].duration_s, 1.0);
  EXPECT_DOUBLE_EQ(program.pauses[1].duration_s, 0.5);
  EXPECT_DOUBLE_EQ(program.pauses[2].duration_s, 2.0);
  EXPECT_DOUBLE_EQ(program.pauses[3].duration_s, 0.25);
  EXPECT_DOUBLE_EQ(program.dwell_s, 3.75);
  // a negative one is no wait a firmware makes (it was read as 0): refused at its line
  const auto problems = problems_of("G1 X1 E1 F600\nG4 P-5000\nG4 S-3\nG4 X-1\n");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2);
  EXPECT_EQ(problems[0].message, "G4 P-5000: a dwell must be 0 or more");
  EXPECT_EQ(problems[1].message, "G4 S-3: a dwell must be 0 or more");
  EXPECT_EQ(problems[2].line, 4);
}

// a PrusaSlicer start block: firmware checks whose parameters are text (M862.3 P "MK3S",
// M115 U3.13.2), homing with axes named by letter alone (G28 W, G28 X Y: to 0 on those axes),
// Prusa's G29 flags and G80 mesh levelling, grbl's $H and $X; none of it moves the print, and
// a bad G word on an M line is still found
TEST(Gcode, SlicerStartBlockWithTextParameters) {
  const GcodeImport imported = parse(
      "$H\n$X\nM862.3 P \"MK3S\" ; printer model check\nM862.1 P0.4\nM115 U3.13.2\n"
      "M204 P1250 R1250 T1250\nG28 W ; home all without mesh bed level\nG80\nG29 A\nG29 G\n"
      "G1 X5 Y5 F600\nG28 X Y\nG1 X1 E1\nM555 X50 Y50 W100 H100\n");
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  // homed x and y from (5, 5): the print move starts at the origin
  expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(1, 0, 0)});
  const auto problems = problems_of("M104 S200 G1 X1e308\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_NE(problems[0].message.find("out of range"), std::string::npos);
}

// code numbers beyond any firmware's (the fuzzer's M999999999 overflowed the code in tenths)
// are refused, naming the word; the largest accepted code is still read as an unknown M code
TEST(Gcode, HugeCodeNumbersAreRefused) {
  const auto problems =
      problems_of("M999999999\nG1 X1 E1\nM5 X1 G19999999\nM99999 X1\nM-999999999\n");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  EXPECT_EQ(problems[0].line, 1);
  EXPECT_EQ(problems[0].message, "code number out of range in 'M999999999' (at most 99999)");
  EXPECT_EQ(problems[1].line, 3);
  EXPECT_EQ(problems[1].message, "code number out of range in 'G19999999' (at most 99999)");
  EXPECT_EQ(problems[2].line, 5);
  EXPECT_EQ(problems[2].message, "malformed code 'M-999999999'");
  // a shutter code beyond that, or not a number, is refused before any line is read
  for (const std::string code : {"M1e12", "Mnan", "M-3", "M99999.1"}) {
    GcodeOptions options;
    options.open_code = code;
    try {
      parse_gcode_program("G1 X1\n", "test.gcode", options);
      ADD_FAILURE() << "expected an InputError for open code " << code;
    } catch (const InputError& e) {
      ASSERT_EQ(e.problems().size(), 1u);
      EXPECT_EQ(e.problems()[0].key, "toolpath.gcode.open");
      EXPECT_EQ(e.problems()[0].message,
                "'" + code + "' is not a G or M code (e.g. M3, M5, M106, M107)");
    }
  }
  // a code the reader follows as motion or a mode cannot be the shutter's too (`--open G1`
  // opened it on every G1 line); another G code can (a machine's own)
  const std::vector<ShutterCodeProblem> motion = shutter_code_problems("G1", "G0");
  ASSERT_EQ(motion.size(), 2u);
  EXPECT_FALSE(motion[0].at_close);
  EXPECT_EQ(motion[0].message.rfind("'G1' is a motion or mode code the reader follows", 0), 0u)
      << motion[0].message;
  EXPECT_TRUE(motion[1].at_close);
  EXPECT_EQ(shutter_code_problems("G91", "M5").size(), 1u);
  EXPECT_TRUE(shutter_code_problems("G800", "G801").empty());
}

TEST(Gcode, PowerZeroClosesTheShutter) {
  // a grbl laser file (LightBurn's M4 S0, then power per move): S0 on a move, or alone, prints
  // nothing though the open code is active; M104 S0 and G4 S0 are no power
  GcodeOptions laser;
  laser.open_code = "M4";
  laser.close_code = "M5";
  const GcodeProgram program = parse_gcode_program(
      "G21 G90\nM4 S0\nG0 X0 Y0\nG1 X10 F600 S1000\nG1 Y10 S0\nG1 X0 S500\nM104 S0\n"
      "G4 S0\nG1 Y5\nS0\nG1 Y0\nM4\nG1 X5\nM4 S300\nG1 X0\n",
      "laser.gcode", laser);
  const GcodeImport imported = import_gcode_program(program, laser);
  EXPECT_EQ(imported.rule, PrintRule::shutter);
  // printed: X10 (S1000), then X0 and Y5 (S500), then X0 (S300); not Y10, Y0 or X5 (S0)
  ASSERT_EQ(imported.toolpath.paths.size(), 3u);
  expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  expect_points(imported.toolpath.paths[1], {Vec3(10, 10, 0), Vec3(0, 10, 0), Vec3(0, 5, 0)});
  expect_points(imported.toolpath.paths[2], {Vec3(5, 0, 0), Vec3(0, 0, 0)});
}

TEST(Gcode, MarlinsLaserFlagAndFanSpeed) {
  // Marlin's `M3 I` (the laser's inline mode) is a flag, not a malformed word; an M106 open
  // code without S runs the fan at full speed (255) after an M106 S0, as Marlin does
  GcodeOptions laser;
  const GcodeImport inline_mode = import_gcode_program(
      parse_gcode_program("G21 G90\nM3 I\nG1 X10 F600 S200\nM3 I S0\nG1 Y10\nM5\nG0 X0\n",
                          "laser.gcode", laser),
      laser);
  ASSERT_EQ(inline_mode.toolpath.paths.size(), 1u);
  expect_points(inline_mode.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  GcodeOptions fan;
  fan.open_code = "M106";
  fan.close_code = "M107";
  const GcodeImport full_speed = import_gcode_program(
      parse_gcode_program("G21 G90\nM106 S0\nG0 X0 Y0 F3000\nM106\nG1 X10 F600\nM107\nG0 X20\n"
                          "M106 S255\nG1 X30\nM107\n",
                          "fan.gcode", fan),
      fan);
  ASSERT_EQ(full_speed.toolpath.paths.size(), 2u);
  expect_points(full_speed.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  // an R too short for its chord, in inches: the message gives R in the file's unit and in mm
  const auto problems = problems_of("G20 G90\nG1 X0 Y0 F60\nG2 X2 Y0 R0.5\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_NE(problems[0].message.find("radius R0.5 (12.7 mm) is shorter than half the chord "
                                     "(25.4 mm)"),
            std::string::npos)
      << problems[0].str();
}

// Prusa's MMU tool choices, `T?` (its firmware asks which filament to load), `Tx` and `Tc`, are
// read as T0 is: no geometry (before, `T?` refused the whole file as a malformed word)
TEST(Gcode, PrusasMmuToolChoicesAreNoGeometry) {
  GcodeOptions options;
  for (const char* choice : {"T?", "t? ; menu", "Tx\nTc", "T0"}) {
    const GcodeImport imported = import_gcode_program(
        parse_gcode_program(std::string("M83\nG1 X0 Y0 F600\n") + choice + "\nG1 X10 E1\n",
                            "mmu.gcode", options),
        options);
    ASSERT_EQ(imported.toolpath.paths.size(), 1u) << choice;
    expect_points(imported.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  }
  // a T with anything else after it is still malformed
  const auto problems = problems_of("G1 X0 Y0 F600\nT?1\nG1 X10 E1\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_NE(problems[0].message.find("malformed word 'T?1'"), std::string::npos)
      << problems[0].str();
}

TEST(Gcode, M3AndM4BothOpenTheShutter) {
  // a grbl laser file switches the laser on with M4 (dynamic power), a mill's spindle may turn
  // either way: under the default open code M3 (and under M4), both open, M5 closes
  for (const std::string open : {"M3", "M4"}) {
    GcodeOptions options;
    options.open_code = open;
    const GcodeProgram program = parse_gcode_program(
        "G21 G90\nM4 S0\nG0 X10 Y10\nG1 X30 Y10 S800 F600\nM5\nG1 X40\nM3 S100\nG1 Y20\nM5\n",
        "laser.gcode", options);
    const GcodeImport imported = import_gcode_program(program, options);
    EXPECT_EQ(imported.rule, PrintRule::shutter) << open;
    ASSERT_EQ(imported.toolpath.paths.size(), 2u) << open;
    expect_points(imported.toolpath.paths[0], {Vec3(10, 10, 0), Vec3(30, 10, 0)});
    expect_points(imported.toolpath.paths[1], {Vec3(40, 10, 0), Vec3(40, 20, 0)});
  }
  // open and close must be two switches: the same code, or M3 and M4, are refused
  for (const auto& [open, close] : std::vector<std::pair<std::string, std::string>>{
           {"M3", "M3"}, {"M3", "M4"}, {"M106", "M106"}}) {
    GcodeOptions options;
    options.open_code = open, options.close_code = close;
    try {
      parse_gcode_program("G1 X1\n", "test.gcode", options);
      ADD_FAILURE() << "expected an InputError for open " << open << ", close " << close;
    } catch (const InputError& e) {
      ASSERT_EQ(e.problems().size(), 1u);
      EXPECT_EQ(e.problems()[0].key, "toolpath.gcode.close");
      EXPECT_EQ(
          e.problems()[0].message.rfind("'" + close + "' would close what '" + open + "' opens", 0),
          0u)
          << e.problems()[0].message;
    }
  }
}

TEST(Gcode, FirmwareRetractionsCountAndTemperaturesAreNoAxisWords) {
  // OrcaSlicer for Klipper: G10 retracts and G11 recovers (two runs, the repeated G10 one run);
  // RepRapFirmware's G10 P0 R150 S210 sets temperatures: no axis word to list as ignored; its
  // G10 P1 X3 tool offset is one
  const GcodeProgram program = parse_gcode_program(
      "G21 G90 M83\nG1 X0 Y0 F600\nG1 X10 E1\nG10\nG10\nG0 X20\nG11\nG1 X30 E1\nG10\n"
      "G11\nG10 P0 R150 S210\nG10 P1 X3\n",
      "orca.gcode", GcodeOptions{});
  EXPECT_EQ(program.n_retractions, 2);
  ASSERT_EQ(program.ignored_axis_codes.size(), 1u);
  EXPECT_EQ(g_code_name(program.ignored_axis_codes[0].tenths), "G10");
  EXPECT_EQ(program.ignored_axis_codes[0].n_lines, 1);
  EXPECT_EQ(program.ignored_axis_codes[0].first_line, 12);
}

TEST(Gcode, AnArcOffsetAlongItsPlanesNormalIsRefused) {
  // K in G17 or J in G18 belongs to another plane (LinuxCNC refuses it); 0 passes
  const auto problems = problems_of(
      "G1 X0 Y0 Z0 F600\nG2 X10 Y0 I5 J0 K7 E1\nG18\nG2 X20 Z0 I5 J-3 E2\nG17\n"
      "G2 X10 Y0 I5 K0 E3\n");
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2);
  EXPECT_EQ(problems[0].message,
            "an arc in the G17 plane takes I and J, not K7 (is the plane G17, G18 or G19 as the "
            "file means it?)");
  EXPECT_EQ(problems[1].line, 4);
  EXPECT_EQ(problems[1].message.rfind("an arc in the G18 plane takes K and I, not J-3", 0), 0u);
}

TEST(Gcode, ProgrammingAndSubprogramsAreNamed) {
  // LinuxCNC's O-word subroutines, # parameters and [ ] expressions, and Fanuc's M98 call: a
  // program, not a list of moves (RepRapFirmware's M98 P"macro.g" passes; a slicer's
  // placeholder is named as one)
  const auto problems = problems_of(
      "G21\n#1 = 5\nG1 X#1 F60\nO100 sub\no<probe> call\nG1 X[2*3]\nM98 P1000 L2\n"
      "M98 P\"0:/macros/start.g\"\nG1 Z{+0.0}\nO1000\nG1 X1\n");
  ASSERT_EQ(problems.size(), 7u) << dump(problems);
  const std::vector<int> lines = {2, 3, 4, 5, 6, 7, 9};
  const std::vector<std::string> starts = {"RS274/NGC parameters",    "RS274/NGC parameters",
                                           "O-word subroutines",      "O-word subroutines",
                                           "RS274/NGC expressions",   "M98 P1000: subprogram calls",
                                           "malformed word 'Z{+0.0}'"};
  for (std::size_t i = 0; i < problems.size(); ++i) {
    EXPECT_EQ(problems[i].line, lines[i]) << problems[i].str();
    EXPECT_EQ(problems[i].message.rfind(starts[i], 0), 0u) << problems[i].str();
  }
}

TEST(Gcode, ClassicMacLineEndsAreLines) {
  // CR alone ends a line in a file without LF (and CR LF is one line end, as before)
  for (const std::string end : {"\r", "\r\n", "\n"}) {
    const GcodeProgram program =
        parse_gcode_program("G90" + end + "M83" + end + "G1 X10 E1 F600" + end + "G1 Y10 E1" + end,
                            "mac.gcode", GcodeOptions{});
    EXPECT_EQ(program.n_lines, 4) << end.size();
    ASSERT_EQ(program.moves.size(), 2u);
    EXPECT_EQ(program.moves[1].to_mm, Vec3(10, 10, 0));
  }
}

TEST(Gcode, LineEndsMayBeMixedInOneFile) {
  // a file of CR line ends that another tool gave one LF (at its end): every CR still ends a
  // line, a CR LF is one line end; before, the CRs became spaces and the first comment hid
  // the whole file (0 moves, exit 0)
  const std::string text =
      "G21\r; a header comment\rG90\rM83\rG0 X0 Y0 F3000\rG1 X10 E1 F1200\rG1 Y10 E1\r"
      "G1 X0 E1\rG1 Y0 E1\r; end\r\n";
  const GcodeProgram program = parse_gcode_program(text, "mixed.gcode", GcodeOptions{});
  EXPECT_EQ(program.n_lines, 10);
  ASSERT_EQ(program.moves.size(), 4u);  // (G0 X0 Y0 goes nowhere: no move)
  EXPECT_EQ(program.moves[2].to_mm, Vec3(0, 10, 0));
  EXPECT_EQ(program.moves[2].line, 8);
  // a bad word is named at its own line whichever line ends come before it
  const auto problems = problems_of("G21\r\nG90\rG1 X1 F600\nG1 Xq\r\nG1 X2\r");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 4) << problems[0].str();
}

TEST(Gcode, ALineOfManyCommentsIsReadOnce) {
  // 10^5 parenthesised comments before the words of one line: read in a loop (before: a call
  // per comment, each scanning the rest of the line again; 200 000 took 31 s)
  std::string text = "G21\n";
  for (int i = 0; i < 100000; ++i) text += "(a)";
  text += " G1 X1 E1 F100\n(b)(c)G1 X2 E2\n";
  const GcodeProgram program = parse_gcode_program(text, "comments.gcode", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 2u);
  EXPECT_EQ(program.moves[0].to_mm, Vec3(1, 0, 0));
  EXPECT_EQ(program.moves[1].to_mm, Vec3(2, 0, 0));
  // a comment left open after closed ones is refused at its line, as one alone is
  const auto problems = problems_of("G21\n(b)(c)(unclosed G1 X3\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2) << problems[0].str();
}

TEST(Gcode, InchesAndSetPosition) {
  // G20: 1 inch = 25.4 mm; F60 in/min = 25.4 mm/s
  const GcodeImport inches = parse("G20\nG1 X1 Y0 E0.1 F60\n");
  ASSERT_EQ(inches.toolpath.paths.size(), 1u);
  expect_points(inches.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(25.4, 0, 0)});
  EXPECT_DOUBLE_EQ(inches.toolpath.paths[0].speed_mm_s, 25.4);
  // G92 X0 at X10 shifts the frame: X5 is then 15 on the machine
  const GcodeImport shifted = parse("G0 X10 F600\nG92 X0 E0\nG1 X5 E1\n");
  ASSERT_EQ(shifted.toolpath.paths.size(), 1u);
  expect_points(shifted.toolpath.paths[0], {Vec3(10, 0, 0), Vec3(15, 0, 0)});
}

TEST(Gcode, RunsThatPlungeWhileOpenAreLayeredWhereTheyPrintFlat) {
  // a CAM-style shutter program: two passes, each plunging from the 5 mm safe height with the
  // shutter already open (the first straight down, the second on a ramp), then a flat square
  // side; and a climbing run whose every move changes z (a spiral vase's)
  const std::string text =
      "G21 G90\nM3\nG0 X0 Y0 Z5\nG1 Z-0.2 F300\nG1 X10 F600\nG0 Z5\n"
      "G0 X0 Y5\nG1 X2 Z-0.4 F300\nG1 X10 F600\nG0 Z5\n"
      "G0 X0 Y10 Z1\nG1 X5 Z1.1\nG1 X10 Z1.2\nM5\n";
  const GcodeProgram program = parse_gcode_program(text, "cam.nc", GcodeOptions{});
  const GcodeImport all = import_gcode_program(program, GcodeOptions{});
  EXPECT_EQ(all.rule, PrintRule::shutter);
  // the levels: the passes' flat heights (not their 5 mm start) and the climb's start
  EXPECT_EQ(all.layer_z_mm, (std::vector<double>{-0.4, -0.2, 1.0}));
  EXPECT_EQ(print_layer_levels(program, PrintRule::shutter), all.layer_z_mm);
  // five paths (a new one at each feed change): each takes its run's layer
  ASSERT_EQ(all.toolpath.paths.size(), 5u);
  const std::vector<int> layers = {1, 1, 0, 0, 2};
  for (std::size_t i = 0; i < layers.size(); ++i)
    EXPECT_EQ(all.toolpath.paths[i].layer, layers[i]) << "path " << i;
  // the plunge is printed, from the safe height
  expect_points(all.toolpath.paths[0], {Vec3(0, 0, 5), Vec3(0, 0, -0.2)});
  // layers [1, 1] is the first pass alone
  GcodeOptions first_pass;
  first_pass.first_layer = first_pass.last_layer = 1;
  const GcodeImport selected = import_gcode_program(program, first_pass);
  ASSERT_EQ(selected.toolpath.paths.size(), 2u);
  expect_points(selected.toolpath.paths[1], {Vec3(0, 0, -0.2), Vec3(10, 0, -0.2)});
  EXPECT_EQ(selected.toolpath.paths[0].layer, 0);
}

TEST(Gcode, SlicersLayerMarksAreCountedOthersAreNot) {
  // Cura's (a raft's negative one too), PrusaSlicer's, Bambu Studio's and Simplify3D's marks
  const std::string marks =
      ";LAYER:-1\n;LAYER:0\n;LAYER_CHANGE\n; CHANGE_LAYER\n; layer 3, Z = 0.600\n;LAYER:12 \n";
  // comments that only look like them
  const std::string others =
      ";LAYER_COUNT:3\n;LAYER:\n;LAYER:x\n;LAYERS\n; layer height 0.2\n;LAYER_CHANGED\n"
      "; layer 3 of 40\nG1 X1 F600 ;LAYER:4\n(LAYER:5)\n";
  EXPECT_EQ(parse_gcode_program(marks + others, "marks.gcode", GcodeOptions{}).n_layer_marks, 6);
  const GcodeProgram program =
      parse_gcode_program("G1 X1 E1 F600\n;LAYER:0\nG1 X2 E2\n", "m.gcode", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 2u);
  EXPECT_EQ(program.moves[0].layer_mark, 0);
  EXPECT_EQ(program.moves[1].layer_mark, 1);
}

// the slicer's declarations in a file's comments (a move after them, so the text is G-code)
SlicerNotes notes_of(const std::string& comments) {
  return parse_gcode_program(comments + "G1 X1 E1 F600\n", "notes.gcode", GcodeOptions{})
      .slicer_notes;
}

// Each slicer's own way of declaring who made the file, its time, layers and filament, as the
// headers and footers of PrusaSlicer, Cura, Bambu Studio, Simplify3D, ideaMaker and Slic3r
// write them (durations and units converted by hand: 1d 2h 3m 4s = 93784 s, 1.5 m = 1500 mm)
TEST(SlicerNotes, EachSlicersDeclarationsAreRead) {
  struct Case {
    std::string comments;
    SlicerNotes expected;
  };
  const std::vector<Case> cases = {
      {"; generated by PrusaSlicer 2.6.0+win64 on 2023-07-14 at 10:14:06 UTC\n"
       "; filament used [mm] = 123.5, 6.5\n; filament used [g] = 0.37\n"
       "; total layers count = 40\n; estimated printing time (silent mode) = 9h\n"
       "; estimated printing time (normal mode) = 1d 2h 3m 4s\n",
       {"PrusaSlicer 2.6.0+win64", 93784.0, 40, 130.0}},
      {";FLAVOR:Marlin\n;TIME:6666\n;Filament used: 1.5m, 0.25m\n;Layer height: 0.2\n"
       ";LAYER_COUNT:50\n;Generated with Cura_SteamEngine 5.4.0\n;TIME_ELAPSED:12.5\n",
       {"Cura_SteamEngine 5.4.0", 6666.0, 50, 1750.0}},
      {"; HEADER_BLOCK_START\n; BambuStudio 01.07.04.52\n"
       "; model printing time: 2h 1m 54s; total estimated time: 2h 8m 2s\n"
       "; total layer number: 54\n; total filament length [mm] : 7520.05\n",
       {"BambuStudio 01.07.04.52", 7682.0, 54, 7520.05}},
      {"; G-Code generated by Simplify3D(R) Version 4.1.2\n;   Build time: 1 hour 2 minutes\n"
       ";   Filament length: 1234.5 mm (1.23 m)\n",
       {"Simplify3D(R) Version 4.1.2", 3720.0, std::nullopt, 1234.5}},
      // ideaMaker: every material's length summed
      {";Sliced by ideaMaker 4.2.1\n;Print Time: 1234\n;Material#1 Used: 1000.5\n"
       ";Material#2 Used: 20\n",
       {"ideaMaker 4.2.1", 1234.0, std::nullopt, 1020.5}},
      // Slic3r: the length before its volume
      {"; generated by Slic3r 1.3.0 on 2018-01-01 at 10:00:00\n"
       "; filament used = 1234.5mm (3.0cm3)\n",
       {"Slic3r 1.3.0", std::nullopt, std::nullopt, 1234.5}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.comments);
    const SlicerNotes notes = notes_of(c.comments);
    EXPECT_EQ(notes.slicer, c.expected.slicer);
    EXPECT_EQ(notes.estimated_time_s, c.expected.estimated_time_s);
    EXPECT_EQ(notes.layer_count, c.expected.layer_count);
    EXPECT_EQ(notes.filament_used_mm, c.expected.filament_used_mm);
  }
}

// A file without declarations has none; only a declaration's first statement counts, and one
// whose value does not read is left out (no error: the comments are the slicer's); a slicer
// name's broken UTF-8 is escaped (JSON holds only UTF-8).
TEST(SlicerNotes, OnlyFirstAndWellFormedDeclarationsAreTaken) {
  const SlicerNotes none = notes_of(";LAYER:0\n; layer height 0.2\n(TIME:5)\n");
  EXPECT_FALSE(none.slicer || none.estimated_time_s || none.layer_count || none.filament_used_mm);
  const SlicerNotes first = notes_of(";TIME:100\n;TIME:200\n;LAYER_COUNT:3\n;LAYER_COUNT:4\n");
  EXPECT_EQ(first.estimated_time_s, 100.0);
  EXPECT_EQ(first.layer_count, 3);
  const SlicerNotes malformed = notes_of(
      "; estimated printing time (normal mode) = soon\n; total layers count = 2.5\n"
      ";LAYER_COUNT:-3\n;Filament used: 1.5 furlongs\n;TIME:nan\n");
  EXPECT_FALSE(malformed.estimated_time_s);
  EXPECT_FALSE(malformed.layer_count);
  EXPECT_FALSE(malformed.filament_used_mm);
  EXPECT_EQ(notes_of("; generated by Odd\xff 1.0\n").slicer, "Odd\\xFF 1.0");
}

// the firmware settings a file makes, as "command parameter value line last_value n_changes"
std::vector<std::string> settings_of(const std::string& text) {
  std::vector<std::string> listed;
  for (const GcodeSetting& s :
       parse_gcode_program(text, "settings.gcode", GcodeOptions{}).firmware_settings.settings) {
    std::ostringstream row;
    row << s.command << ' ' << s.parameter << ' ' << s.value << ' ' << s.line << ' ' << s.last_value
        << ' ' << s.n_changes;
    listed.push_back(row.str());
  }
  return listed;
}

// PrusaSlicer's MK3 start block sets the limits its estimate uses (M201-M205), and with accel
// control a print acceleration per feature (M204 P): each setting's first value and line, its
// last and how often it changed; M204's T is a setting there, never a tool change; moves are
// read as before
TEST(GcodeSettings, AMarlinStartBlocksLimitsAreListedAsSet) {
  const std::string text =
      "M201 X1000 Y1000 Z200 E5000 ; sets maximum accelerations, mm/sec^2\n"
      "M203 X200 Y200 Z12 E120 ; sets maximum feedrates, mm / sec\n"
      "M204 P1250 R1250 T1250\nM205 X8.00 Y8.00 Z0.40 E4.50\nM205 S0 T0\nM900 K0.04\n"
      "G1 X10 Y10 F3000\nM204 P800\nG1 X20 E1\nM204 P1250\nG1 X30 E2\nM204 P1250\n"
      "M221 S95\nM220 S100\nM117 M204 P5\n";
  const std::vector<std::string> expected = {
      "M201 X 1000 1 1000 0", "M201 Y 1000 1 1000 0", "M201 Z 200 1 200 0",
      "M201 E 5000 1 5000 0", "M203 X 200 2 200 0",   "M203 Y 200 2 200 0",
      "M203 Z 12 2 12 0",     "M203 E 120 2 120 0",   "M204 P 1250 3 1250 2",
      "M204 R 1250 3 1250 0", "M204 T 1250 3 1250 0", "M205 X 8 4 8 0",
      "M205 Y 8 4 8 0",       "M205 Z 0.4 4 0.4 0",   "M205 E 4.5 4 4.5 0",
      "M205 S 0 5 0 0",       "M205 T 0 5 0 0",       "M900 K 0.04 6 0.04 0",
      "M221 S 95 13 95 0",    "M220 S 100 14 100 0"};
  EXPECT_EQ(settings_of(text), expected);
  const GcodeProgram program = parse_gcode_program(text, "mk3.gcode", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 3u);
  EXPECT_EQ(program.moves[2].to_mm, Vec3(30, 10, 0));
}

// Klipper's SET_VELOCITY_LIMIT and SET_PRESSURE_ADVANCE: their NAME=VALUE parameters, any case,
// up to a comment; a value that is no finite number, another command's parameters and other
// named commands set nothing; a file without settings lists none
TEST(GcodeSettings, KlippersSettingCommandsAreListed) {
  const std::string text =
      "SET_VELOCITY_LIMIT ACCEL=5000 square_corner_velocity=5 ; per the printer.cfg\n"
      "set_velocity_limit Accel=3000 VELOCITY=nan MINIMUM_CRUISE_RATIO=0.5x\n"
      "SET_PRESSURE_ADVANCE EXTRUDER=extruder ADVANCE=0.04 SMOOTH_TIME=0.04 # tuned\n"
      "SET_VELOCITY_LIMIT VELOCITY=300 ACCEL=3000 ; ACCEL_TO_DECEL=1\n"
      "SET_FAN_SPEED FAN=part SPEED=0.5\nM204 S2500\nG1 X1 E1 F600\n";
  const std::vector<std::string> expected = {"SET_VELOCITY_LIMIT ACCEL 5000 1 3000 1",
                                             "SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY 5 1 5 0",
                                             "SET_PRESSURE_ADVANCE ADVANCE 0.04 3 0.04 0",
                                             "SET_PRESSURE_ADVANCE SMOOTH_TIME 0.04 3 0.04 0",
                                             "SET_VELOCITY_LIMIT VELOCITY 300 4 300 0",
                                             "M204 S 2500 6 2500 0"};
  EXPECT_EQ(settings_of(text), expected);
  EXPECT_TRUE(settings_of("G1 X1 E1 F600\nM104 S200\nM106 S255\n").empty());
  // words that are no parameters are stepped over, each at least a character on
  EXPECT_TRUE(settings_of("SET_VELOCITY_LIMIT ( * = =5 ACCEL ACCEL:5\nM204 (P5) P*5 Q1\n"
                          "M201 E5000:5000\nG1 X1 E1 F600\n")
                  .empty());
}

// the motion limits in force per move (inspect --limits file): a change makes a new entry only
// once a move came under the last, so settings without moves between them take no room
TEST(GcodeSettings, EachMoveIsUnderTheMotionLimitsInForce) {
  std::string text = "G1 X1 F600\n";
  for (int i = 0; i < 1000; ++i) text += i % 2 == 0 ? "M204 T500\n" : "M204 T700\n";
  text += "G1 X2\nM201 X200\nSET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=0\nG1 X3\nG1 X4\n";
  const GcodeProgram program = parse_gcode_program(text, "limits.gcode", GcodeOptions{});
  const std::vector<FileMotionLimits>& limits = program.firmware_settings.motion_limits;
  ASSERT_EQ(limits.size(), 3u);
  std::vector<int> states;
  for (const GcodeMove& move : program.moves) states.push_back(move.motion_limits);
  EXPECT_EQ(states, (std::vector<int>{0, 1, 2, 2}));
  EXPECT_EQ(limits[0].travel_accel_mm_s2, 0.0);  // nothing set before the first move
  EXPECT_EQ(limits[1].travel_accel_mm_s2, 700.0);
  EXPECT_EQ(limits[2].axis_accel_mm_s2[0], 200.0);
  EXPECT_EQ(limits[2].travel_accel_mm_s2, 700.0);    // kept
  EXPECT_EQ(limits[2].square_corner_velocity, 0.0);  // 0 is a setting
  EXPECT_TRUE(std::isnan(limits[1].square_corner_velocity));
  // Marlin's classic jerks, per axis and E
  const GcodeProgram jerks =
      parse_gcode_program("M205 X8 Y9 Z0.4 E4.5 S0\nG1 X1 F600\n", "jerk.gcode", GcodeOptions{});
  const FileMotionLimits& jerk = jerks.firmware_settings.motion_limits.at(0);
  EXPECT_EQ(std::vector<double>(jerk.jerk_mm_s, jerk.jerk_mm_s + 4),
            (std::vector<double>{8.0, 9.0, 0.4, 4.5}));
  EXPECT_EQ(jerk.junction_deviation_mm, 0.0);
  // values no firmware takes set no limit: negative, above 1e9, a feed rate too small to move
  // at (the machine's holds), a cruise ratio of 1 or more
  const GcodeProgram odd = parse_gcode_program(
      "M203 X1e-300 Y-5 Z2e9\nM204 T1e-7\nSET_VELOCITY_LIMIT MINIMUM_CRUISE_RATIO=1\n"
      "G1 X1 F600\n",
      "odd.gcode", GcodeOptions{});
  const FileMotionLimits& none = odd.firmware_settings.motion_limits.at(0);
  EXPECT_EQ(none.axis_feed_mm_s[0], 0.0);
  EXPECT_EQ(none.axis_feed_mm_s[1], 0.0);
  EXPECT_EQ(none.axis_feed_mm_s[2], 0.0);
  EXPECT_EQ(none.travel_accel_mm_s2, 0.0);
  EXPECT_TRUE(std::isnan(none.minimum_cruise_ratio));
  EXPECT_EQ(odd.firmware_settings.settings.size(), 5u);  // each listed as written
}

// M220 S scales the feed rate of every move after it, as firmware runs them (Marlin, Klipper,
// RepRapFirmware): B saves the factor, R restores it; an E-only move's time too
TEST(GcodeSettings, TheSpeedFactorScalesTheFeedRatesAfterIt) {
  const GcodeProgram program = parse_gcode_program(
      "G1 X10 F600\nM220 S50\nG1 X20\nM220 B\nM220 S200\nG1 X30\nM220 R\nG1 X40\n"
      "G1 E-1\nM220 S100\nG1 X50\n",
      "m220.gcode", GcodeOptions{});
  std::vector<double> feeds;
  for (const GcodeMove& move : program.moves) feeds.push_back(move.feed_mm_s);
  EXPECT_EQ(feeds, (std::vector<double>{10.0, 5.0, 20.0, 5.0, 10.0}));
  ASSERT_EQ(program.pauses.size(), 1u);
  EXPECT_DOUBLE_EQ(program.pauses[0].duration_s, 1.0 / 5.0);  // 1 mm of E at 5 mm/s
  EXPECT_EQ(program.n_speed_factor_moves, 3);
  EXPECT_EQ(program.first_speed_factor_line, 2);
  // a factor of 100 % changes nothing and is not counted
  const GcodeProgram as_written =
      parse_gcode_program("M220 S100\nG1 X10 F600\n", "s100.gcode", GcodeOptions{});
  EXPECT_EQ(as_written.moves.at(0).feed_mm_s, 10.0);
  EXPECT_EQ(as_written.first_speed_factor_line, 0);
  // a factor from 1 to 10000 %: none, one that would take the feed rates under the least
  // read (1e-6 per minute; F1 at S1e-300 % gave a 1e-301 mm/s move an estimate of 0 s), or
  // none that reads, is refused at its line
  const auto problems = problems_of(
      "G1 X1 E1 F600\nM220 S0\nM220 S-5\nM220 Sfast\nM220 S1e-300\nM220 S10001\nM220 S1\n"
      "M220 S10000\n");
  ASSERT_EQ(problems.size(), 5u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2);
  EXPECT_EQ(problems[0].message,
            "M220 S0: a speed factor must be a percentage from 1 to 10000 (S100: the feed rates "
            "as written)");
  EXPECT_EQ(problems[2].line, 4);
  EXPECT_EQ(problems[4].line, 6);
}

TEST(Gcode, APurgeLineAtItsOwnHeightStaysALayerOfItsOwn) {
  // Cura's start block purges at z = 0.3 over a first layer at 0.2: layered by z, marks or
  // not, so that layers [1, 1]... leave it out and layers [0, 0] is the part's first layer
  // alone (one height, as a machine without z needs)
  const std::string text =
      "G1 X0 Y20 Z0.3 F5000\nG1 Y100 E5 F1500\nG92 E0\n;LAYER_COUNT:2\n;LAYER:0\n"
      "G0 X10 Y10 Z0.2\nG1 X20 E1\n;LAYER:1\nG0 Z0.4\nG1 X10 E2\n";
  const GcodeProgram program = parse_gcode_program(text, "cura.gcode", GcodeOptions{});
  EXPECT_EQ(program.n_layer_marks, 2);
  EXPECT_EQ(print_layer_levels(program, PrintRule::e), (std::vector<double>{0.2, 0.3, 0.4}));
  GcodeOptions first;
  first.first_layer = first.last_layer = 0;
  const GcodeImport selected = import_gcode_program(program, first);
  ASSERT_EQ(selected.toolpath.paths.size(), 1u);
  expect_points(selected.toolpath.paths[0], {Vec3(10, 10, 0.2), Vec3(20, 10, 0.2)});
}

TEST(Gcode, ASpiralVaseIsCutIntoItsLayersAtTheSlicersMarks) {
  // PrusaSlicer's spiral vase: one climbing run, a ;LAYER_CHANGE at the start of each turn
  std::string text = "G1 X0 Y0 Z0.2 F3000\n";
  for (int turn = 0; turn < 3; ++turn) {
    const double z = 0.2 * (turn + 1);
    text += ";LAYER_CHANGE\n;Z:" + std::to_string(z) + "\n";
    // the square's four sides, each climbing a quarter of the layer
    const char* corners[] = {"X10", "Y10", "X0", "Y0"};
    for (int side = 1; side <= 4; ++side)
      text += std::string("G1 ") + corners[side - 1] + " Z" + std::to_string(z + 0.05 * side) +
              " E" + std::to_string(4 * turn + side) + "\n";
  }
  const GcodeImport vase = parse(text);
  // a layer per turn, each starting where the one before ends (printed on through)
  EXPECT_EQ(vase.layer_z_mm.size(), 3u);
  ASSERT_EQ(vase.toolpath.paths.size(), 3u);
  for (int turn = 0; turn < 3; ++turn) {
    EXPECT_EQ(vase.toolpath.paths[turn].layer, turn);
    EXPECT_NEAR(vase.layer_z_mm[turn], 0.2 * (turn + 1), 1e-12);
    if (turn > 0) {
      EXPECT_EQ(vase.toolpath.paths[turn].points.front(),
                vase.toolpath.paths[turn - 1].points.back());
    }
  }
  // without the marks: one run, one layer where it starts
  std::string unmarked;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(";LAYER_CHANGE", 0) != 0) unmarked += line + "\n";
  EXPECT_EQ(parse(unmarked).layer_z_mm, (std::vector<double>{0.2}));
}

TEST(Gcode, DefaultSpeedUntilTheFirstFeedRate) {
  const GcodeImport imported = parse("G1 X1 E1\nG1 X2 E2 F120\n", 7.0);
  ASSERT_EQ(imported.toolpath.paths.size(), 2u);
  EXPECT_DOUBLE_EQ(imported.toolpath.paths[0].speed_mm_s, 7.0);
  EXPECT_DOUBLE_EQ(imported.toolpath.paths[1].speed_mm_s, 2.0);
  // without a default: the first print move without F is reported, once
  const auto problems = problems_of("G1 X1 E1\nG1 X2 E2\nG1 X3 E3 F60\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 1);
  EXPECT_NE(problems[0].message.find("before any feed rate"), std::string::npos);
}

TEST(Gcode, EveryMalformedLineIsReported) {
  const auto problems = problems_of(
      "G1 X1 E1 F600\n"     // 1 fine
      "G1 Xabc\n"           // 2 letter without number
      "G1 X1.2.3 E2\n"      // 3 not a number
      "G2 X1 Y1 I1 R1\n"    // 4 arc with both centre and radius
      "G1 X2 F0\n"          // 5 zero feed
      "G1 X3 X4 E3\n"       // 6 duplicate word
      "G0 G1 X1\n"          // 7 two motions
      "G1 X1e308\n"         // 8 out of range (never echoed as a huge number)
      "G1 X5 E5 #\n"        // 9 stray character
      "G1 X\x01\x02\n"      // 10 control bytes
      "G81 X1 Y1 Z-1 R1\n"  // 11 canned cycle
      "G1 X7 Y0 A30 B0\n"   // 12 a rotary axis that turns
      "M117 anything: goes here\n"
      "PRINT_START BED=60\n"
      "G1 X6 E6\n");
  ASSERT_EQ(problems.size(), 11u) << dump(problems);
  for (std::size_t i = 0; i < problems.size(); ++i) {
    EXPECT_EQ(problems[i].file, "test.gcode");
    EXPECT_EQ(problems[i].line, static_cast<int>(i) + 2) << problems[i].str();
    EXPECT_EQ(problems[i].key, "toolpath.gcode");
  }
  EXPECT_EQ(
      problems[0].str(),
      "test.gcode:2: toolpath.gcode: malformed word 'Xabc' (expected X followed by a number)");
  EXPECT_NE(problems[1].message.find("'X1.2.3'"), std::string::npos);
  EXPECT_NE(problems[2].message.find("not both"), std::string::npos);
  EXPECT_NE(problems[3].message.find("F must be > 0"), std::string::npos);
  EXPECT_NE(problems[4].message.find("X given twice"), std::string::npos);
  EXPECT_NE(problems[5].message.find("two motion commands"), std::string::npos);
  EXPECT_EQ(problems[6].message, "number out of range in 'X1e308' (at most 1e9 in magnitude)");
  // a feed rate too slow to print at (F1e-200 was estimated at 0 s by inspect: its squared
  // speed underflowed)
  const auto crawl = problems_of("G1 X0 Y0 F600\nG1 X10 E1 F1e-200\n");
  ASSERT_EQ(crawl.size(), 1u) << dump(crawl);
  EXPECT_EQ(crawl[0].line, 2);
  EXPECT_EQ(crawl[0].message,
            "feed rate F must be at least 1e-6 (per minute): F1e-200 is no speed to print at");
  // a number too close to 0 for a double is said as such
  const auto tiny = problems_of("G1 X1e-400 F600\n");
  ASSERT_EQ(tiny.size(), 1u) << dump(tiny);
  EXPECT_EQ(tiny[0].message,
            "number out of range in 'X1e-400' (too close to 0 to be read; write 0)");
  EXPECT_NE(problems[7].message.find("unexpected '#'"), std::string::npos);
  EXPECT_EQ(problems[8].message,
            "binary or control byte \\x01 at column 5 (is this a G-code text file?)");
  EXPECT_NE(problems[9].message.find("G81 is not supported"), std::string::npos);
  EXPECT_EQ(problems[10].message,
            "axis word A (30) on a move: only X, Y, Z and E are read, so a multi-axis file's "
            "rotary or extra axes would be dropped silently; convert it to 3-axis G-code first "
            "(or, if A is a MakerBot-flavour extruder, export with RepRap/Marlin flavour: E)");
  // DOS's end-of-file byte at the end (old CAM posts) ends the file; anywhere else it is a
  // control byte
  const GcodeImport dos = parse("G1 X0 Y0 F600\r\nG1 X10 E1\r\n\x1A\r\n");
  ASSERT_EQ(dos.toolpath.paths.size(), 1u);
  expect_points(dos.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  const auto inside = problems_of("G1 X0 Y0 F600\n\x1A\nG1 X10 E1\n");
  ASSERT_EQ(inside.size(), 1u) << dump(inside);
  EXPECT_EQ(inside[0].line, 2);
}

// A refused canned cycle's or spline's following lines repeat it (`X30` drills again): the
// code is reported once, where the lines had been read as the arc before it (an arc without
// I, J or R) or as straight moves
TEST(Gcode, LinesRepeatingARefusedCycleAreReportedOnce) {
  const auto drill = problems_of(
      "G0 X0 Y0 F600\nG2 X10 Y0 I5 J0\nG81 X20 Y20 Z-5 R2 F200\nX30\nX40 Y30\nG80\n"
      "G0 X0 Y0\nG1 X5 F600\n");
  ASSERT_EQ(drill.size(), 1u) << dump(drill);
  EXPECT_EQ(drill[0].line, 3);
  EXPECT_NE(drill[0].message.find("G81 is not supported"), std::string::npos);
  // a spline's, until G80 cancels the mode (then axis words alone have no motion command)
  const auto spline = problems_of("G1 X0 Y0 F600\nG5 I1 J1 P1 Q1 X1 Y1\nX2 Y2\nG80\nX4\n");
  ASSERT_EQ(spline.size(), 2u) << dump(spline);
  EXPECT_EQ(spline[0].line, 2);
  EXPECT_EQ(spline[1].line, 5);
  EXPECT_NE(spline[1].message.find("without a motion command"), std::string::npos);
}

TEST(Gcode, PackedFilesAreNamedWithTheWayOut) {
  // PrusaSlicer's binary G-code, a Bambu .gcode.3mf (zip), a gzip file, UTF-16: one problem at
  // line 1 naming the container, instead of a control byte at a column
  const std::vector<std::pair<std::string, std::string>> packed = {
      {std::string("GCDE\x01\x00\x00\x00", 8), "binary G-code file (PrusaSlicer's .bgcode"},
      {std::string("PK\x03\x04\x14\x00", 6), "Metadata/plate_1.gcode"},
      {std::string("\x1f\x8b\x08\x00", 4), "gzip-compressed"},
      // UTF-16, with its byte order mark or without (a NUL beside each ASCII character)
      {std::string("\xFF\xFE"
                   "G\0"
                   "1\0",
                   6),
       "UTF-16 text"},
      {std::string("G\0"
                   "1\0"
                   " \0"
                   "X\0"
                   "1\0",
                   10),
       "UTF-16 text"}};
  for (const auto& [bytes, named] : packed) {
    const auto problems = problems_of(bytes);
    ASSERT_EQ(problems.size(), 1u) << dump(problems);
    EXPECT_EQ(problems[0].line, 1);
    EXPECT_NE(problems[0].message.find(named), std::string::npos) << problems[0].str();
  }
  // a text file whose first line merely begins with the letters is read as text (a named
  // command, as Klipper's)
  const GcodeProgram text = parse_gcode_program("GCDE\nG1 X1 F60\n", "t.gcode", GcodeOptions{});
  ASSERT_EQ(text.moves.size(), 1u);
  EXPECT_EQ(text.moves[0].to_mm, Vec3(1, 0, 0));
}

// codes that move every later point by what the file does not give, or by a transform the
// reader does not apply, are refused at their line; their cancels (G40, G15, G50.1, G69) pass
TEST(Gcode, CompensationAndCoordinateTransformsAreRefused) {
  const auto problems = problems_of(
      "G21 G90\nG1 X0 Y0 F600\n"
      "G41 D1\nG42.1 D2\nG16\nG51 X0 Y0 P2\nG51.1 X0\nG68 X0 Y0 R45\nG52 X20 Y10\n"
      "G65 P9810 X20 Y10\nG66 P9000 X1\nG1 X10 E1\n");
  ASSERT_EQ(problems.size(), 9u) << dump(problems);
  const char* codes[9] = {"G41", "G42.1", "G16", "G51", "G51.1", "G68", "G52", "G65", "G66"};
  for (std::size_t i = 0; i < problems.size(); ++i) {
    EXPECT_EQ(problems[i].line, static_cast<int>(i) + 3);
    EXPECT_EQ(problems[i].message.rfind(std::string(codes[i]) + " is not supported: ", 0), 0u)
        << problems[i].str();
  }
  EXPECT_NE(problems[0].message.find("cutter radius compensation"), std::string::npos);
  EXPECT_NE(problems[5].message.find("rotation"), std::string::npos);
  // a local offset (LinuxCNC, Fanuc, Mach3), read as no offset, put the path 20 x 10 mm off;
  // a macro call's moves (Renishaw's G65 P9810 positioning) are not in the file
  EXPECT_NE(problems[6].message.find("local offsets"), std::string::npos);
  EXPECT_NE(problems[7].message.find("macro call"), std::string::npos);
  // the cancels change nothing: one 10 mm print move
  const GcodeImport cancels = parse("G21 G90\nG40\nG15\nG50.1\nG69\nG1 X0 Y0 F600\nG1 X10 E1\n");
  ASSERT_EQ(cancels.toolpath.paths.size(), 1u);
  expect_points(cancels.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
}

// G28.1 and G30.1 store the position G28 and G30 go to (RS274/NGC, grbl): before, G28 went
// to 0 whatever was stored and the print ran from (0, 0, 0) instead of (20, 20, 1); G30 goes
// to its stored position once one is (without, it is Marlin's probe, its words parameters)
TEST(Gcode, G28AndG30GoToThePositionsG28p1AndG30p1Stored) {
  const GcodeImport g28 =
      parse("G21 G90\nG0 X20 Y20 Z1\nG28.1\nG0 X0 Y0 Z0\nG28\nG91 G1 X5 E1 F600\n");
  ASSERT_EQ(g28.toolpath.paths.size(), 1u);
  expect_points(g28.toolpath.paths[0], {Vec3(20, 20, 1), Vec3(25, 20, 1)});
  // only the named axes go (through the intermediate point, a travel)
  const GcodeImport named =
      parse("G21 G90\nG0 X20 Y20 Z1\nG28.1\nG0 X3 Y4 Z5\nG28 Z7\nG91 G1 X5 E1 F600\n");
  ASSERT_EQ(named.toolpath.paths.size(), 1u);
  expect_points(named.toolpath.paths[0], {Vec3(3, 4, 1), Vec3(8, 4, 1)});
  const GcodeImport g30 =
      parse("G21 G90\nG0 X7 Y8 Z2\nG30.1\nG0 X0 Y0 Z0\nG28\nG30\nG91 G1 X5 E1 F600\n");
  ASSERT_EQ(g30.toolpath.paths.size(), 1u);
  expect_points(g30.toolpath.paths[0], {Vec3(7, 8, 2), Vec3(12, 8, 2)});
  // no G28.1 before: machine 0; no G30.1: G30 moves nothing
  const GcodeImport plain = parse("G21 G90\nG0 X20 Y20 Z1\nG28\nG30 Z9\nG1 X5 E1 F600\n");
  ASSERT_EQ(plain.toolpath.paths.size(), 1u);
  expect_points(plain.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(5, 0, 0)});
  // homing clears G92's offset on the homed axes, as Marlin does (X5 is then machine 5); the
  // others keep theirs (Y15 is machine 8 after G92 Y10 at machine 3)
  const GcodeImport homed = parse("G21 G90\nG0 X2 Y3\nG92 X10 Y10\nG28 X\nG1 X5 Y15 E1 F600\n");
  ASSERT_EQ(homed.toolpath.paths.size(), 1u);
  expect_points(homed.toolpath.paths[0], {Vec3(0, 3, 0), Vec3(5, 8, 0)});
}

// the open and close codes on one line (`S1000 M3 M5`): LinuxCNC refuses two spindle codes on
// a line; before, the last won and the file printed nothing
TEST(Gcode, OpenAndCloseCodesOnOneLineAreRefused) {
  const auto problems = problems_of("G21 G90\nG0 X0 Y0\nS1000 M3 M5\nG1 X10 F600\nM5\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 3);
  EXPECT_EQ(problems[0].message.rfind("the open code and the close code on one line", 0), 0u)
      << problems[0].str();
}

// a space inside a number (`X1 0.5`, which LinuxCNC reads as X10.5), a nested comment and an
// unclosed one are refused with what they are, not only as an unexpected character or a malformed
// word
TEST(Gcode, ASpaceInsideANumberAndANestedCommentAreNamed) {
  const auto split = problems_of("G21 G90\nG1 X1 0.5 F600\n");
  ASSERT_EQ(split.size(), 1u) << dump(split);
  EXPECT_NE(split[0].message.find("a space inside a number is not read"), std::string::npos)
      << split[0].str();
  const auto nested = problems_of("G21 G90\n(a (b) c)\nG1 X1 F600\n");
  ASSERT_EQ(nested.size(), 1u) << dump(nested);
  EXPECT_EQ(nested[0].line, 2);
  EXPECT_NE(nested[0].message.find("comments do not nest"), std::string::npos) << nested[0].str();
  // a '(' left open is refused the same on a line of its own and after words (it could hide
  // the words after it either way)
  for (const char* line : {"(G1 X5 Y5 is a move", "G1 X1 F600 (then Y5"}) {
    const auto unclosed = problems_of("G21 G90\n" + std::string(line) + "\nG1 X2 F600\n");
    ASSERT_EQ(unclosed.size(), 1u) << line << dump(unclosed);
    EXPECT_EQ(unclosed[0].line, 2) << line;
    EXPECT_EQ(unclosed[0].message.rfind("comment '(' not closed on its line", 0), 0u)
        << unclosed[0].str();
  }
  // a stray character elsewhere keeps the plain message
  const auto stray = problems_of("G21 G90\nG1 X1 F600 ?\n");
  ASSERT_EQ(stray.size(), 1u) << dump(stray);
  EXPECT_EQ(stray[0].message.find("space inside"), std::string::npos) << stray[0].str();
}

TEST(Gcode, UnknownCodesKeepTheirAxisWords) {
  // a Bambu Lab print's start: G380 probes (relative), G29.1 sets a z trim, G38.2 probes; none
  // is a move, so the first print move starts where the last real move ended
  const std::string text =
      "G90\nM83\nG1 X5 Y5 Z5 F600\nG91\nG380 S2 Z30 F300\nG380 S2 Z-25 F300\nG90\n"
      "G29.1 Z0\nG38.2 Z-10 F50\nG1 X10 E1\nG90 X15 E1\n";
  const GcodeProgram program = parse_gcode_program(text, "bambu.gcode", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 3u);
  EXPECT_EQ(program.moves[1].from_mm, Vec3(5, 5, 5));
  EXPECT_EQ(program.moves[1].to_mm, Vec3(10, 5, 5));
  // G90 is a mode: its line's axis words are a move in the modal G1
  EXPECT_EQ(program.moves[2].to_mm, Vec3(15, 5, 5));
  ASSERT_EQ(program.ignored_axis_codes.size(), 3u);
  EXPECT_EQ(g_code_name(program.ignored_axis_codes[0].tenths), "G380");
  EXPECT_EQ(program.ignored_axis_codes[0].n_lines, 2);
  EXPECT_EQ(program.ignored_axis_codes[0].first_line, 5);
  EXPECT_EQ(g_code_name(program.ignored_axis_codes[1].tenths), "G29.1");
  EXPECT_EQ(program.ignored_axis_codes[1].first_line, 8);
  EXPECT_EQ(g_code_name(program.ignored_axis_codes[2].tenths), "G38.2");
  // PrusaSlicer's MK3S start: G80 levels the mesh over the first layer's area, never a move
  const GcodeProgram prusa = parse_gcode_program(
      "M83\nG28 W\nG80 X32.5 Y40.2 W150 H120 ; mesh bed levelling\nG1 Y-3.0 F1000.0\n"
      "G92 E0.0\nG1 X60.0 E9.0 F1000.0\n",
      "mk3s.gcode", GcodeOptions{});
  ASSERT_EQ(prusa.moves.size(), 2u);
  EXPECT_EQ(prusa.moves[0].from_mm, Vec3(0, 0, 0));
  EXPECT_EQ(prusa.moves[1].to_mm, Vec3(60, -3, 0));
  ASSERT_EQ(prusa.ignored_axis_codes.size(), 1u);
  EXPECT_EQ(g_code_name(prusa.ignored_axis_codes[0].tenths), "G80");
  EXPECT_EQ(prusa.ignored_axis_codes[0].first_line, 3);
  // Bambu's flag names hold "g29" and "g39": text, not G words
  const GcodeImport flags = parse(
      "M83\nM1002 judge_flag g29_before_print_flag\nM622 J1\nM1002 judge_flag "
      "g39_3rd_layer_detect_flag\nG39 S1\nM623\nG1 X0 Y0 F600\nG1 X10 E1\n");
  ASSERT_EQ(flags.toolpath.paths.size(), 1u);
  expect_points(flags.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
  // MakerBot's and Repetier's G161/G162 home to the axes' ends, named by letter alone
  const GcodeProgram homing = parse_gcode_program(
      "G162 X Y F2000\nG161 Z F900\nG92 X0 Y0 Z0\nG1 X10 F600\n", "mb.gcode", GcodeOptions{});
  ASSERT_EQ(homing.ignored_axis_codes.size(), 2u);
  EXPECT_EQ(g_code_name(homing.ignored_axis_codes[0].tenths), "G162");
  EXPECT_EQ(g_code_name(homing.ignored_axis_codes[1].tenths), "G161");
  ASSERT_EQ(homing.moves.size(), 1u);
  EXPECT_EQ(homing.moves[0].to_mm, Vec3(10, 0, 0));
}

TEST(Gcode, OffsetsAreClearedSuspendedAndRestored) {
  // G92 X0 at x 10 puts the program's 0 at 10; G92.2 suspends it, G92.3 restores, G92.1 clears
  const GcodeProgram program =
      parse_gcode_program("G1 X10 F600\nG92 X0\nG1 X5\nG92.2\nG1 X5\nG92.3\nG1 X1\nG92.1\nG1 X2\n",
                          "o.nc", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 5u);
  EXPECT_EQ(program.moves[1].to_mm.x(), 15.0);
  EXPECT_EQ(program.moves[2].to_mm.x(), 5.0);
  EXPECT_EQ(program.moves[3].to_mm.x(), 11.0);
  EXPECT_EQ(program.moves[4].to_mm.x(), 2.0);
  EXPECT_TRUE(program.ignored_axis_codes.empty());
}

TEST(Gcode, WorkSystemsAreSetSelectedAndBypassed) {
  // G10 L2 sets G54's offset to (100, 50); L20 at machine (120, 50) makes it read (0, 0);
  // G55 (system 2, offset -7 in x), G53 the machine frame for one line, G59.3 is system 9
  const GcodeProgram program = parse_gcode_program(
      "G10 L2 P1 X100 Y50\nG54 G1 X0 Y0 F600\nG1 X20\nG10 L20 P0 X0 Y0\nG1 X5 Y5\n"
      "G10 L2 P2 X-7\nG55 G0 X0 Y0\nG53 X3 Y4\nG1 X1\nG91 G10 L2 P9 Z2\nG59.3 G90 Z1\n"
      "G92 Z0\nG1 Z1\n",
      "w.ngc", GcodeOptions{});
  // the moves' ends in the machine frame; the last: G92 Z0 at machine z 3 in system 9
  // (offset 2) puts G92's offset at 1, so Z1 is 1 + 2 + 1
  const std::vector<Vec3> expected = {{100, 50, 0}, {120, 50, 0}, {125, 55, 0}, {-7, 0, 0},
                                      {3, 4, 0},    {-6, 4, 0},   {-6, 4, 3},   {-6, 4, 4}};
  ASSERT_EQ(program.moves.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_EQ(program.moves[i].to_mm, expected[i])
        << i << ": " << program.moves[i].to_mm.transpose();
  EXPECT_TRUE(program.ignored_axis_codes.empty());
}

TEST(Gcode, ToolOffsetsAndBadWorkSystemsAreNamed) {
  // RepRapFirmware's G10 P1 X3 (a tool's offsets): listed, never a move
  const GcodeProgram tool =
      parse_gcode_program("G1 X1 F600\nG10 P1 X3 Y4\nG1 X2\n", "t.gcode", GcodeOptions{});
  ASSERT_EQ(tool.ignored_axis_codes.size(), 1u);
  EXPECT_EQ(g_code_name(tool.ignored_axis_codes[0].tenths), "G10");
  EXPECT_EQ(tool.moves.back().to_mm, Vec3(2, 0, 0));
  const auto problems =
      problems_of("G10 L2 X1\nG10 L20 P12 X1\nG10 L2 P1 R30 X1\nG1 X1 F60\nG53 G2 X2 R1\n");
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  EXPECT_EQ(problems[0].message.rfind("G10 L2 needs P0-P9", 0), 0u) << problems[0].str();
  EXPECT_NE(problems[1].message.find("not P12"), std::string::npos) << problems[1].str();
  EXPECT_EQ(problems[2].message.rfind("G10 L2 R30 is not supported", 0), 0u) << problems[2].str();
  EXPECT_EQ(problems[3].line, 5);
}

TEST(Gcode, SavedPositionsAreReturnedTo) {
  // Marlin's park-and-return: G60 saves (20, 10, 0); G61 S0 X Y goes back over it at the
  // lifted z with F1200 for that move alone, G61 S0 Z comes down; a G61 beside a motion is
  // RS274/NGC's path mode
  const GcodeProgram marlin = parse_gcode_program(
      "M83\nG1 X10 Y10 F600\nG1 X20 E1\nG60 S0\nG91\nG1 Z5\nG90\nG0 X0 Y0 F3000\n"
      "G61 S0 X Y F1200\nG61 S0 Z\nG1 X30 E1\nG61 G1 X31 E0.1\n",
      "m.gcode", GcodeOptions{});
  const std::vector<Vec3> ends = {{10, 10, 0}, {20, 10, 0}, {20, 10, 5}, {0, 0, 5},
                                  {20, 10, 5}, {20, 10, 0}, {30, 10, 0}, {31, 10, 0}};
  ASSERT_EQ(marlin.moves.size(), ends.size());
  for (std::size_t i = 0; i < ends.size(); ++i)
    EXPECT_EQ(marlin.moves[i].to_mm, ends[i]) << i << ": " << marlin.moves[i].to_mm.transpose();
  // the returns travel (G0) at their own F; the print after them keeps the modal 3000/min
  EXPECT_EQ(marlin.moves[4].motion, 0);
  EXPECT_DOUBLE_EQ(marlin.moves[4].feed_mm_s, 20.0);
  EXPECT_DOUBLE_EQ(marlin.moves[5].feed_mm_s, 50.0);
  EXPECT_DOUBLE_EQ(marlin.moves[6].feed_mm_s, 50.0);
  EXPECT_EQ(marlin.moves[6].e_delta, 1.0);
  // G61 E restores the saved E (absolute, M82) without moving: the next E counts from it
  const GcodeProgram e_restore = parse_gcode_program(
      "M82\nG1 X10 E5 F600\nG60 S2\nG1 X20 E8\nG61 S2 E\nG1 X30 E6\n", "e.gcode", GcodeOptions{});
  ASSERT_EQ(e_restore.moves.size(), 3u);
  EXPECT_EQ(e_restore.moves[2].e_delta, 1.0);
  // RepRapFirmware's restore point: G1 R1 offsets the named axes from it, keeps the others
  const GcodeProgram reprap =
      parse_gcode_program("G1 X10 Y10 Z1 F600\nG60 S1\nG1 X20 Y30 Z3\nG1 R1 X0 Z2\nG0 R1 Y-1\n",
                          "r.gcode", GcodeOptions{});
  ASSERT_EQ(reprap.moves.size(), 4u);
  EXPECT_EQ(reprap.moves[2].to_mm, Vec3(10, 30, 3));
  EXPECT_EQ(reprap.moves[3].to_mm, Vec3(10, 9, 3));
  // without a G60 before: G61 alone is a path mode, G61 with axes and G1 R are refused
  const GcodeProgram path_mode = parse_gcode_program("G61\nG1 X5 F60\n", "p.ngc", GcodeOptions{});
  ASSERT_EQ(path_mode.moves.size(), 1u);
  EXPECT_EQ(path_mode.moves[0].to_mm, Vec3(5, 0, 0));
  const auto problems =
      problems_of("G1 X1 F60\nG61 X Y\nG1 R1 X0\nG60 S12\nG60 X5\nG60 S3\nG61 S4\n");
  ASSERT_EQ(problems.size(), 5u) << dump(problems);
  EXPECT_EQ(problems[0].message.rfind("G61 with axis words or a slot is Marlin's return", 0), 0u)
      << problems[0].str();
  EXPECT_EQ(problems[1].message.rfind("G1 R1 returns to restore point 1", 0), 0u)
      << problems[1].str();
  EXPECT_EQ(problems[2].message.rfind("G60 S12: the save slot must be", 0), 0u)
      << problems[2].str();
  EXPECT_EQ(problems[3].line, 5);
  EXPECT_NE(problems[4].message.find("G60 S4 saved"), std::string::npos) << problems[4].str();
}

TEST(Gcode, LowercaseFilesReadEAsAWord) {
  // `y0e1`: Y 0 then E 1 in a file written in lowercase; `X1e-05` keeps its exponent
  const GcodeProgram lower =
      parse_gcode_program("g90\nm83\ng1x10y0e1f1200\n", "l.gcode", GcodeOptions{});
  ASSERT_EQ(lower.moves.size(), 1u);
  EXPECT_EQ(lower.moves[0].e_delta, 1.0);
  EXPECT_EQ(lower.moves[0].to_mm, Vec3(10, 0, 0));
  const GcodeProgram script = parse_gcode_program("G1 X1e-05 Y2 F60\n", "s.gcode", GcodeOptions{});
  ASSERT_EQ(script.moves.size(), 1u);
  EXPECT_EQ(script.moves[0].to_mm.x(), 1e-05);
}

// an arc's end may miss its start's radius by 0.005 mm or 0.1 % of the radius, the larger; the
// message gives the figure applied to that arc (it once said 0.005 mm for every radius)
TEST(Gcode, AnArcsRadiusToleranceGrowsWithItsRadiusAndIsNamed) {
  const auto problems = problems_of(
      "G1 X0 Y0 F600\nG2 X20.008 Y0 I10 J0 E1\n"  // 2 r 10: 0.008 off, within 0.01 mm
      "G1 X0 Y0\nG2 X20.02 Y0 I10 J0 E2\n"        // 4 0.02 off
      "G1 X0 Y0\nG2 X1000.5 Y0 I500 J0 E3\n"      // 6 r 500: 0.5 off, within 0.5 mm
      "G1 X0 Y0\nG2 X1001 Y0 I500 J0 E4\n");      // 8 1 off
  ASSERT_EQ(problems.size(), 2u) << dump(problems);
  EXPECT_EQ(problems[0].line, 4);
  EXPECT_NE(problems[0].message.find("within 0.01 mm: 0.005 mm or 0.1 % of the radius"),
            std::string::npos)
      << problems[0].message;
  EXPECT_EQ(problems[1].line, 8);
  EXPECT_NE(problems[1].message.find("within 0.5 mm"), std::string::npos) << problems[1].message;
}

TEST(Gcode, ArcTurnsBeyondOneAreRefused) {
  // Bambu's spiral lift: a full helical turn, P1 (one turn), the same as without P
  const GcodeProgram lift = parse_gcode_program(
      "G1 X0 Y0 Z0 F600\nG17\nG2 Z1 I0.86 J0.86 P1 F20000\n", "b.gcode", GcodeOptions{});
  const GcodeProgram plain = parse_gcode_program(
      "G1 X0 Y0 Z0 F600\nG17\nG2 Z1 I0.86 J0.86 F20000\n", "b.gcode", GcodeOptions{});
  // (the G1 from the origin to it is no move)
  ASSERT_EQ(lift.moves.size(), 1u);
  EXPECT_DOUBLE_EQ(lift.moves[0].arc.sweep_rad, 2.0 * kPi);
  EXPECT_DOUBLE_EQ(lift.moves[0].length_mm, plain.moves[0].length_mm);
  EXPECT_NEAR(lift.moves[0].length_mm, std::hypot(2.0 * kPi * 0.86 * std::sqrt(2.0), 1.0), 1e-12);
  // more turns mean different things in LinuxCNC and Marlin: refused at the line
  const auto problems = problems_of("G1 X0 Y0 F600\nG3 X0 Y0 I5 P2 E1\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2);
  EXPECT_EQ(problems[0].message.rfind("G3 P2: arcs of more than one turn", 0), 0u)
      << problems[0].str();
}

// a full circle whose end is a hair off its start along the radius (G2 X10.001 from X10
// about X0): the chord's bisector lies far from the given centre, which once moved there and
// left a micrometre semicircle (10 mm printed where the 62.8 mm circle is); the centre stays
TEST(Gcode, AnEndAHairOffAFullCirclesStartKeepsItsCentre) {
  const GcodeProgram program =
      parse_gcode_program("G21 G90 G17\nG0 X10 Y0 Z0\nG1 F600\nG2 X10.001 Y0 I-10 J0\nG1 X20\n",
                          "c.ngc", GcodeOptions{});
  ASSERT_EQ(program.moves.size(), 3u);
  const GcodeMove& circle = program.moves[1];
  EXPECT_EQ(circle.line, 4);
  EXPECT_DOUBLE_EQ(circle.arc.sweep_rad, 2.0 * kPi);
  EXPECT_NEAR(circle.arc.center_mm.x(), 0.0, 1e-12);
  EXPECT_NEAR(circle.arc.center_mm.y(), 0.0, 1e-12);
  EXPECT_NEAR(circle.length_mm, 2.0 * kPi * 10.0, 1e-9);
  // an end off along the tangent is a circle through both ends, short of one turn by the gap
  const GcodeProgram tangent = parse_gcode_program(
      "G21 G90 G17\nG0 X10 Y0 Z0\nG1 F600\nG2 X10 Y0.001 I-10 J0\n", "t.ngc", GcodeOptions{});
  ASSERT_EQ(tangent.moves.size(), 2u);
  EXPECT_NEAR(tangent.moves[1].arc.sweep_rad, 2.0 * kPi - 1e-4, 1e-9);
}

// LinuxCNC's M66, M67 and M68 take their channel as E (`G1 X10 M67 E0 Q50`, an analog output
// set with the move): no extrusion, the print read by the spindle codes (before: rule e, no
// print at all)
TEST(Gcode, AnAnalogChannelIsNoExtrusion) {
  const GcodeImport imported = parse(
      "G21 G90\nG0 X0 Y0 Z0 F600\nM3 S1000\nG1 X10 M67 E0 Q50\nG1 X20 M67 E0 Q80\n"
      "G1 X30 M68 E1 Q20\nM5\nM2\n");
  EXPECT_EQ(imported.rule, PrintRule::shutter) << imported.rule_reason;
  ASSERT_EQ(imported.toolpath.paths.size(), 1u);
  expect_points(imported.toolpath.paths[0],
                {Vec3(0, 0, 0), Vec3(10, 0, 0), Vec3(20, 0, 0), Vec3(30, 0, 0)});
}

// other controllers' codes that cut what the file does not write out, or whose meaning
// depends on the controller, are refused at their line (before, each was skipped and its
// geometry lost, or G70's inch read as mm; G7's X as diameters read as radii, twice the
// part); Marlin's G12 nozzle clean passes, and G8, the lathe's radius mode
TEST(Gcode, PocketsCyclesAndAmbiguousUnitCodesAreRefused) {
  const auto problems = problems_of(
      "G21 G90\nG1 X0 Y0 F600\nG12 I10\nG13 I5\nG74 X1 Y1 Z-0.5 R0.1 F25\nG70\nG71\n"
      "G12.1\nG75 X1\nG18 G7\nG1 X10 E1\n");
  ASSERT_EQ(problems.size(), 8u) << dump(problems);
  const char* codes[8] = {"G12 I: circular pockets",
                          "G13 I: circular pockets",
                          "G74 is not supported: a canned cycle",
                          "G70 is not supported: it means inch or mm",
                          "G71 is not supported: it means inch or mm",
                          "G12.1 is not supported: polar",
                          "G75 is not supported: a canned",
                          "G7 is not supported: a lathe's diameter mode"};
  for (std::size_t i = 0; i < problems.size(); ++i) {
    EXPECT_EQ(problems[i].line, static_cast<int>(i) + 3);
    EXPECT_EQ(problems[i].message.rfind(codes[i], 0), 0u) << problems[i].str();
  }
  const GcodeImport clean = parse("G21 G90\nG12 P1 S3 T2\nG8\nG1 X0 Y0 F600\nG1 X10 E1\n");
  ASSERT_EQ(clean.toolpath.paths.size(), 1u);
  expect_points(clean.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
}

// a line that starts with a name is Klipper's command or macro (NAME=VALUE parameters, no
// geometry), but Sinumerik's frames and contours (`TRANS X10 Y10`, `ROT RPL=45`, `CIP ...`)
// and any name with bare axis words move the path: refused at their line, not skipped
TEST(Gcode, NamedCommandsWithGeometryAreRefusedKlippersPass) {
  const auto problems = problems_of(
      "G21 G90\nG1 X0 Y0 F600\nTRANS X10 Y10\nROT RPL=45\nCIP X20 Y10 I1=20 J1=0\n"
      "MY_MACRO X10\nG1 X10 E1\n");
  ASSERT_EQ(problems.size(), 4u) << dump(problems);
  for (std::size_t i = 0; i < problems.size(); ++i)
    EXPECT_EQ(problems[i].line, static_cast<int>(i) + 3) << problems[i].str();
  EXPECT_EQ(problems[0].message.rfind("`TRANS`: Sinumerik's frames", 0), 0u) << problems[0].str();
  EXPECT_EQ(problems[1].message.rfind("`ROT`: Sinumerik's frames", 0), 0u) << problems[1].str();
  EXPECT_EQ(problems[2].message.rfind("`CIP`: Sinumerik's frames", 0), 0u) << problems[2].str();
  EXPECT_EQ(problems[3].message.rfind("`MY_MACRO X10`: a named command with axis words", 0), 0u)
      << problems[3].str();
  const GcodeImport klipper = parse(
      "G21 G90\nSET_VELOCITY_LIMIT VELOCITY=100 ACCEL=3000\nRESPOND MSG=\"at X10 Y5\"\n"
      "_CLIENT_RETRACT LENGTH=1\nSET_KINEMATIC_POSITION X=0 Y=0 Z=0\nPRINT_START ; X10\n"
      "G1 X0 Y0 F600\nG1 X10 E1\n");
  ASSERT_EQ(klipper.toolpath.paths.size(), 1u);
  expect_points(klipper.toolpath.paths[0], {Vec3(0, 0, 0), Vec3(10, 0, 0)});
}

TEST(Gcode, PlaceholdersAreNamedAsATemplate) {
  const auto problems =
      problems_of("G90\nG1 Z{first_layer_height}\nM190 S[bed_temperature]\nG1 X1\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].line, 2);
  EXPECT_NE(problems[0].message.find("placeholder not filled in"), std::string::npos)
      << problems[0].str();
  // Bambu's start block keeps its z trim's expression in exported files: never a move, read
  const GcodeProgram bambu = parse_gcode_program(
      "G90\nG1 X5 Y5 F600\nG29.1 Z{+0.0} ; clear z-trim value first\nG1 X10 E1\n", "bambu.gcode",
      GcodeOptions{});
  ASSERT_EQ(bambu.moves.size(), 2u);
  EXPECT_EQ(bambu.moves[1].to_mm, Vec3(10, 5, 0));
  ASSERT_EQ(bambu.ignored_axis_codes.size(), 1u);
  EXPECT_EQ(g_code_name(bambu.ignored_axis_codes[0].tenths), "G29.1");
  EXPECT_EQ(bambu.ignored_axis_codes[0].first_line, 3);
  // other placeholders on that line, or a second axis word, are still a template
  EXPECT_EQ(problems_of("G29.1 Z{+0.0} Z{a}\n").size(), 1u);
}

TEST(Gcode, RotaryAxesAtZeroAreNoMove) {
  // a 5-axis post's output with its rotary axes at 0 (absolute) or not moved (relative): the
  // same path as without them
  const GcodeImport plain = parse("G1 X1 E1 F600\nG1 X2 Y1 E2\n");
  const GcodeImport zero = parse("G1 X1 A0 B0 C0 E1 F600\nG91\nG1 X1 Y1 A0 U0 E1\n");
  ASSERT_EQ(zero.toolpath.paths.size(), 1u);
  ASSERT_EQ(plain.toolpath.paths.size(), 1u);
  EXPECT_EQ(zero.toolpath.paths[0].points, plain.toolpath.paths[0].points);
}

TEST(Gcode, ManyBadLinesAreSummarised) {
  std::string text;
  for (int i = 0; i < 25; ++i) text += "G1 Xbad\n";
  const auto problems = problems_of(text);
  ASSERT_EQ(problems.size(), 21u);
  EXPECT_EQ(problems[19].line, 20);
  EXPECT_EQ(problems[20].message, "5 more problems not listed");
}

TEST(Gcode, MissingFileNamesIt) {
  try {
    import_gcode("/nonexistent/dir/part.gcode", 3.0);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].str(),
              "/nonexistent/dir/part.gcode: toolpath.gcode: G-code file not found");
  }
  // a directory (`inspect` given a folder) is told as one
  const std::string folder = std::string(DEPOTWIN_SOURCE_DIR) + "/tests/toolpath/data";
  try {
    import_gcode(folder, 3.0);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].str(),
              folder + ": toolpath.gcode: G-code file is a directory, not a file");
  }
}

}  // namespace
}  // namespace depotwin
