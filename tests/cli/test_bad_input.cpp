// Bad input, one row each, through the built CLI: every row must end with exit status 2,
// a message naming the file, line and key (or the command-line option), nothing left in an
// earlier output folder changed, nothing written where the verb would write, and within a
// time budget. A scenario row is given to `validate` and to `run`, which must both refuse it
// with the same first message: one validator (pipeline/job_check.hpp). Issue 15's probe cases
// and its categories: malformed YAML, alias bombs, unknown keys at every level, wrong types,
// NaN and infinities, huge and tiny numbers, broken MJCF, unreachable points, bad G-code, bad
// --out, hostile names. (tests/scenario/test_scenario_ranges.cpp sweeps every numeric key of
// the schema at its extremes in-process.)
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "pipeline/pipeline_test_util.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::read_text;
using testing_support::write_text;

// the longest a row may take: most fail in milliseconds, the slowest (an arm's posture)
// in about a second on an idle machine
constexpr int kBudget_s = 60;

// the probe's scenario: two segments on the XY stage, one planner
std::string probe(const std::string& extra = "", const std::string& name = "probe") {
  return "name: " + name +
         "\n"
         "machine: xy_stage\n"
         "limits: {v_max: 4, a_max: 30}\n"
         "process: {type: aerosol}\n"
         "toolpath:\n"
         "  speed: 3\n"
         "  start: [0, 0]\n"
         "  segments:\n"
         "    - [[2, 2], [8, 2]]\n"
         "    - [[8, 2], [5, 7]]\n"
         "planners: [lspb_mtt]\n" +
         extra;
}

// `text` with the first line that starts with `starts` replaced by `line`
std::string replace_line(std::string text, const std::string& starts, const std::string& line) {
  for (std::size_t at = 0; at < text.size(); at = text.find('\n', at) + 1) {
    if (text.compare(at, starts.size(), starts) != 0) {
      if (text.find('\n', at) == std::string::npos) break;
      continue;
    }
    return text.replace(at, text.find('\n', at) - at, line);
  }
  ADD_FAILURE() << "no line starts with " << starts;
  return text;
}

// the probe with one line replaced
std::string probe_with(const std::string& starts, const std::string& line) {
  return replace_line(probe(), starts, line);
}

// a YAML alias bomb ("billion laughs"): nine levels of nine references, 9^9 leaves if expanded
std::string alias_bomb(const std::string& use) {
  std::string text = "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (char level = 'b'; level <= 'i'; ++level) {
    const std::string previous(1, static_cast<char>(level - 1));
    text += std::string(1, level) + ": &" + level + " [";
    for (int k = 0; k < 9; ++k) text += (k ? ", *" : "*") + previous;
    text += "]\n";
  }
  return text + use;
}

// a G-code file with a NUL, an escape sequence and a bell on its second line
const std::string kBinaryGcode = [] {
  const char bytes[] = "G1 X1 Y1\n\0\x1b[31mRED\x07\nG1 X2\n";
  return std::string(bytes, sizeof bytes - 1);
}();

const char* const kPendulum = R"(<mujoco model="pendulum">
  <worldbody>
    <body name="pole" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.02" mass="1"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
)";

struct Row {
  std::string name;
  // files written into the row's folder: name -> contents (scenario.yaml for scenario rows)
  std::map<std::string, std::string> files;
  // the command after `depotwin`; {dir} is the row's folder, {out} an earlier output folder
  // in it. Empty: a scenario row, given to both `validate {dir}/scenario.yaml` and `run
  // {dir}/scenario.yaml --out {out} --no-render --quiet`
  std::string command;
  // an ECMAScript pattern the output must hold; {s} is the scenario's path, regex-escaped
  std::string pattern;
  std::string validate_options = {};  // extra options of both commands of a scenario row
};

Row scenario(const std::string& name, const std::string& yaml, const std::string& pattern,
             std::map<std::string, std::string> files = {}) {
  files["scenario.yaml"] = yaml;
  return Row{name, files, "", pattern};
}

Row command(const std::string& name, const std::string& command, const std::string& pattern,
            std::map<std::string, std::string> files = {}) {
  return Row{name, files, command, pattern};
}

std::vector<Row> rows() {
  std::vector<Row> r;
  // ---- malformed YAML ----
  r.push_back(scenario("YamlUnclosedFlowMap", "limits: {v_max: 4\ntoolpath: {speed: 3}\n",
                       "{s}:\\d+: malformed YAML"));
  r.push_back(
      scenario("YamlTabIndentation", "toolpath:\n\tspeed: 3\n", "{s}:\\d+: malformed YAML"));
  r.push_back(
      scenario("YamlTwoDocuments", probe("---\nname: b\n"), "{s}:13: more than one YAML document"));
  r.push_back(scenario("YamlEmptyFile", "", "{s}:1: the file holds no settings"));
  r.push_back(scenario("YamlDuplicateKey", probe_with("limits:", "limits: {v_max: 4, v_max: 5}"),
                       "{s}:3: limits\\.v_max: given twice"));
  r.push_back(scenario("AliasBombAsKeys", alias_bomb(probe()), "{s}:1: a: unknown key"));
  r.push_back(scenario("AliasBombAsSegments", alias_bomb("toolpath: {speed: 3, segments: *i}\n"),
                       "{s}:\\d+: toolpath\\.segments\\[0\\]: expected a segment"));
  // ---- unknown keys at every level ----
  r.push_back(scenario("UnknownTopLevelKey", probe("colour: red\n"),
                       "{s}:12: colour: unknown key \\(expected one of: name, machine"));
  r.push_back(scenario("UnknownLimitsKey", probe_with("limits:", "limits: {vmax: 4}"),
                       "{s}:3: limits\\.vmax: unknown key"));
  r.push_back(scenario("UnknownAxisLimitsKey", probe_with("limits:", "limits: {x: {speed: 4}}"),
                       "{s}:3: limits\\.x\\.speed: unknown key"));
  r.push_back(scenario("UnknownJointLimitsKey",
                       probe_with("limits:", "limits: {joint: {v_max: 9, a_max: 9, jerk: 1}}"),
                       "{s}:3: limits\\.joint\\.jerk: unknown key"));
  r.push_back(scenario("UnknownProcessKey",
                       probe_with("process:", "process: {type: aerosol, viscosity: 2}"),
                       "{s}:4: process\\.viscosity: unknown key"));
  r.push_back(scenario("UnknownToolpathKey", probe_with("  speed:", "  spead: 3"),
                       "{s}:6: toolpath\\.spead: unknown key"));
  r.push_back(scenario("UnknownPolylineKey",
                       "toolpath:\n  polylines:\n    - {points: [[0, 0], [1, 0]], sped: 3}\n",
                       "{s}:3: toolpath\\.polylines\\[0\\]\\.sped: unknown key"));
  r.push_back(scenario("UnknownGcodeKey",
                       "toolpath:\n  speed: 3\n  gcode: {file: part.gcode, rules: e}\n",
                       "{s}:3: toolpath\\.gcode\\.rules: unknown key",
                       {{"part.gcode", "G1 X1 Y1 F180\nG1 X2 Y1 E1\n"}}));
  r.push_back(scenario(
      "UnknownRandomSegmentsKey",
      "toolpath:\n  speed: 3\n  random_segments: {count: 5, bed: [9, 9], length: [1, 2]}\n",
      "{s}:3: toolpath\\.random_segments\\.count: unknown key"));
  r.push_back(scenario("UnknownSurfaceKey",
                       "machine: arm6\ntoolpath:\n  speed: 3\n  surface: {file: p.stl, hatch: 1}\n",
                       "{s}:4: toolpath\\.surface\\.hatch: unknown key"));
  r.push_back(scenario("UnknownArmKey",
                       probe_with("machine:", "machine: arm6") + "arm: {rolls: fixed}\n",
                       "{s}:12: arm\\.rolls: unknown key"));
  r.push_back(scenario("UnknownOrderKey", probe("order: {methd: random}\n"),
                       "{s}:12: order\\.methd: unknown key"));
  r.push_back(scenario("UnknownSimKey", probe("sim: {timestep: 0.001}\n"),
                       "{s}:12: sim\\.timestep: unknown key"));
  r.push_back(scenario("UnknownOutputsKey", probe("outputs: {png: true}\n"),
                       "{s}:12: outputs\\.png: unknown key"));
  r.push_back(scenario("UnknownMachineKey",
                       probe_with("machine:", "machine: {modle: m.xml, kinematics: xy_stage}"),
                       "{s}:2: machine\\.modle: unknown key"));
  r.push_back(scenario("UnknownPlannerParameter",
                       probe_with("planners:", "planners: [{name: bezier, deltaa: 0.3}]"),
                       "{s}:11: planners\\[0\\]\\.deltaa: .*deltaa"));
  // ---- wrong types ----
  r.push_back(scenario("QuotedNumber", probe_with("limits:", "limits: {v_max: \"4\", a_max: 30}"),
                       "{s}:3: limits\\.v_max: expected a number, got the text \"4\" \\(write it "
                       "without quotes\\)"));
  r.push_back(scenario("ListForANumber", probe_with("  speed:", "  speed: [3]"),
                       "{s}:6: toolpath\\.speed: expected a number, got a list"));
  r.push_back(scenario("MapForAList", "toolpath:\n  speed: 3\n  segments: {a: 1}\n",
                       "{s}:3: toolpath\\.segments: expected a list of segments"));
  r.push_back(
      scenario("ListForAMap", probe("sim: [0.001]\n"), "{s}:12: sim: expected a map, got a list"));
  r.push_back(scenario("WordForABool", probe("outputs: {render: maybe}\n"),
                       "{s}:12: outputs\\.render: expected true or false, got 'maybe'"));
  // ---- NaN and infinities ----
  r.push_back(scenario("NanLimit", probe_with("limits:", "limits: {v_max: 4, a_max: .nan}"),
                       "{s}:3: limits\\.a_max: must be a finite number, got \\.nan"));
  r.push_back(scenario("MinusInfinityPoint", probe_with("  start:", "  start: [-.inf, 0]"),
                       "{s}:7: toolpath\\.start\\[0\\]: must be a finite number, got -\\.inf"));
  r.push_back(scenario("InfiniteSettle", probe("sim: {settle_s: .inf}\n"),
                       "{s}:12: sim\\.settle_s: must be a finite number, got \\.inf"));
  // ---- huge and tiny numbers (every key: tests/scenario/test_scenario_ranges.cpp) ----
  r.push_back(scenario("HugeSpeedPrintedShort", probe_with("  speed:", "  speed: 1e300"),
                       "{s}:6: toolpath\\.speed: must be in \\(0, 1e\\+06\\], got 1e\\+300"));
  r.push_back(
      scenario("FourHundredDigits",
               probe_with("limits:", "limits: {v_max: 4, a_max: 1" + std::string(400, '0') + "}"),
               "{s}:3: limits\\.a_max: must be a finite number, got a number beyond"));
  r.push_back(scenario("TinyLimit", probe_with("limits:", "limits: {v_max: 1e-300, a_max: 30}"),
                       "{s}:3: limits\\.v_max: must be in \\[1e-06, 1e\\+06\\], got 1e-300"));
  r.push_back(scenario("TinyTimestep", probe("sim: {timestep_s: 1e-9}\n"),
                       "{s}:12: sim\\.timestep_s: must be in \\[1e-05, 0\\.01\\], got 1e-09"));
  r.push_back(scenario("TinyCell", probe("sim: {cell_mm: 1e-9}\n"),
                       "{s}:12: sim\\.cell_mm: must be 0 \\(the default\\) or between sigma / 64"));
  r.push_back(scenario("HugeSettle", probe("sim: {settle_s: 1e308}\n"),
                       "{s}:12: sim\\.settle_s: must be in \\[0, 3600\\], got 1e\\+308"));
  r.push_back(scenario("HugeServoGains", probe("sim: {kp_scale: 1e300}\n"),
                       "{s}:12: sim\\.kp_scale: must be in \\[0\\.1, 10\\], got 1e\\+300"));
  r.push_back(scenario("TinyServoGains", probe("sim: {kp_scale: 1e-300}\n"),
                       "{s}:12: sim\\.kp_scale: must be in \\[0\\.1, 10\\], got 1e-300"));
  r.push_back(scenario("UnstableServoLoop", probe("sim: {timestep_s: 0.01}\n"),
                       "{s}:12: sim\\.timestep_s: .*makes the servos unstable"));
  r.push_back(scenario("TinyAccelerationAndSpeed",
                       replace_line(probe_with("limits:", "limits: {v_max: 4, a_max: 1e-9}"),
                                    "  speed:", "  speed: 1e-9"),
                       "{s}:3: limits\\.a_max: must be in \\[1e-06, 1e\\+09\\], got 1e-09"));
  // ---- the job's size (bounded resources) ----
  r.push_back(scenario("SlowAccelerationTooManySteps",
                       probe_with("limits:", "limits: {v_max: 4, a_max: 1e-3}"),
                       "{s}:3: limits\\.a_max: run lspb_mtt would take 2\\.95e\\+07 physics "
                       "steps, more than sim\\.max_steps = 1e\\+07"));
  // a plan leaving the travel between the toolpath's points (lspb_mtt's transitions fly past
  // the stage's edge at this acceleration): validate solves the plan's poses as run does
  r.push_back(scenario("PlanLeavesTheTravel",
                       probe_with("limits:", "limits: {v_max: 4, a_max: 0.05}"),
                       "{s}:11: planners: the lspb_mtt plan at t = [0-9.]+ s \\(in a transition "
                       "the planner added\\): joint x at 50\\.00[0-9]+ mm is outside its travel"));
  // plan and export, which simulate nothing, refuse it too rather than write it
  for (const auto& [name, verb] : std::vector<std::pair<std::string, std::string>>{
           {"PlanVerbRefusesAPlanLeavingTheTravel", "plan {dir}/scenario.yaml --out {out}"},
           {"ExportRefusesAPlanLeavingTheTravel",
            "export {dir}/scenario.yaml --planner lspb_mtt --out {dir}/plan.gcode"}})
    r.push_back(
        command(name, verb,
                "{s}:11: planners: the lspb_mtt plan at t = [0-9.]+ s \\(in a transition "
                "the planner added\\): joint x at 50\\.00[0-9]+ mm is outside its travel",
                {{"scenario.yaml", probe_with("limits:", "limits: {v_max: 4, a_max: 0.05}")}}));
  // a planner's own caps (firmware's max_velocity) make its plan long, not the limits: the
  // size problem is named at that planner's entry
  r.push_back(scenario("PlannerCapsMakeThePlanLong",
                       probe_with("planners:",
                                  "planners:\n  - {name: firmware, max_velocity: "
                                  "1e-3}"),
                       "{s}:12: planners: run firmware would take .* physics steps, more than "
                       "sim\\.max_steps .*the firmware plan is far longer than the paths at "
                       "their speeds: check its parameters"));
  r.push_back(scenario("SlowPrintTooManySteps", probe_with("  speed:", "  speed: 1e-5"),
                       "{s}:6: toolpath\\.speed: the job would take .* physics steps, more than "
                       "sim\\.max_steps"));
  r.push_back(scenario("MaxStepsBelowTheJob", probe("sim: {max_steps: 1000}\n"),
                       "{s}:6: toolpath\\.speed: .*more than sim\\.max_steps = 1000"));
  {
    Row row = scenario("MemoryBudgetBelowTheJob", probe(),
                       "{s}:6: toolpath\\.speed: the run would need about \\d+ MB of memory, "
                       "more than --max-memory 1 MB");
    row.validate_options = "--max-memory 1M";
    r.push_back(row);
  }
  r.push_back(command("MaxMemoryNotASize", "validate {dir}/scenario.yaml --max-memory lots",
                      "error: --max-memory: 'lots' is not a memory size",
                      {{"scenario.yaml", probe()}}));
  // ---- broken, empty and foreign MJCF ----
  r.push_back(scenario("MjcfBroken",
                       probe_with("machine:", "machine: {model: m.xml, kinematics: xy_stage}"),
                       "{s}:2: machine\\.model: MJCF m\\.xml:1: XML parse error",
                       {{"m.xml", "<mujoco><worldbody><body name=\"x\""}}));
  r.push_back(scenario("MjcfEmpty",
                       probe_with("machine:", "machine: {model: m.xml, kinematics: xy_stage}"),
                       "{s}:2: machine\\.model: MJCF m\\.xml: .*EMPTY_DOCUMENT", {{"m.xml", ""}}));
  {
    // every element the kinematics needs is named, not only the first
    Row row = scenario("MjcfForeignPendulum",
                       probe_with("machine:", "machine: {model: m.xml, kinematics: xy_stage}"),
                       "{s}:2: machine\\.model: MJCF m\\.xml: site nozzle: not found[\\s\\S]*"
                       "{s}:2: machine\\.model: MJCF m\\.xml: body substrate: not found[\\s\\S]*"
                       "{s}:2: machine\\.model: MJCF m\\.xml: joint x: not found[\\s\\S]*"
                       "{s}:2: machine\\.model: MJCF m\\.xml: joint y: not found",
                       {{"m.xml", kPendulum}});
    r.push_back(row);
  }
  r.push_back(scenario(
      "MjcfMissing", probe_with("machine:", "machine: {model: nowhere.xml, kinematics: xy_stage}"),
      "{s}:2: machine\\.model: MJCF file 'nowhere\\.xml' not found"));
  // ---- unreachable points ----
  r.push_back(scenario("OutsideTheStagesTravel",
                       probe_with("    - [[8, 2], [5, 7]]", "    - [[8, 2], [80, 7]]"),
                       "{s}:10: toolpath\\.segments\\[1\\]: point 1 \\(80, 7, 0\\) mm is not "
                       "reachable by xy_stage"));
  r.push_back(scenario("OutsideTheDeltasWorkspace",
                       "machine: linear_delta\nlimits: {v_max: 40, a_max: 300}\ntoolpath:\n"
                       "  speed: 3\n  polylines:\n    - [[0, 0], [500, 0]]\nplanners: [lspb_mtt]\n",
                       "{s}:6: toolpath\\.polylines\\[0\\]: point 1 \\(500, 0, 0\\) mm is not "
                       "reachable by linear_delta"));
  // the arm's reach depends on the roll and branch its posture chooses: found once the file
  // is clean, at the point's key and line
  r.push_back(scenario("OutOfTheArmsReach",
                       replace_line(probe_with("machine:", "machine: arm6"),
                                    "    - [[8, 2], [5, 7]]", "    - [[8, 2], [900, 7]]"),
                       "{s}:10: toolpath\\.segments\\[1\\]: point 1 \\(900\\.000, 7\\.000, "
                       "0\\.000\\) mm is out of the arm's reach"));
  r.push_back(scenario(
      "ArmStartAboveItsReach",
      replace_line(probe_with("machine:", "machine: arm6"), "  start:", "  start: [0, 0, 2000]"),
      "{s}:7: toolpath\\.start: the start \\(0\\.000, 0\\.000, 2000\\.000\\) mm "
      "is out of the arm's reach"));
  // near the arm's base its joints allow the TCP less than limits.v_max: the path is named at
  // its own line and key (not the ordering's "toolpath.paths[0]", nor a `speed:` it does not
  // hold), a G-code path at its first move
  r.push_back(scenario(
      "ArmPathTooFastNearItsBase",
      replace_line(replace_line(replace_line(probe_with("machine:", "machine: arm6"),
                                             "limits:", "limits: {v_max: 200, a_max: 2000}"),
                                "  speed:", "  speed: 30"),
                   "    - [[2, 2], [8, 2]]", "    - [[-300, 2], [-290, 2]]"),
      "{s}:9: toolpath\\.segments\\[0\\]: print speed 30 mm/s exceeds "
      "v_max = [0-9.]+ mm/s of axis x at its ends \\(the machine's joint limits "
      "mapped over this path; limits v_max is 200\\)"));
  r.push_back(scenario("ArmGcodeTooFastNearItsBase",
                       "machine: arm6\nlimits: {v_max: 200, a_max: 2000}\ntoolpath:\n"
                       "  gcode: part.gcode\nplanners: [lspb_mtt]\n",
                       "part\\.gcode:3: toolpath\\.gcode: the print path from this line: print "
                       "speed 50 mm/s exceeds v_max = [0-9.]+ mm/s of axis x at its ends",
                       {{"part.gcode", "G21\nG1 X-300 Y0 Z5 F3000\nG1 X-290 E1\nG1 Y10 E2\n"}}));
  r.push_back(scenario("ArmPointAKilometreAway",
                       probe_with("    - [[8, 2], [5, 7]]", "    - [[8, 2], [1e300, 7]]"),
                       "{s}:10: toolpath\\.segments\\[1\\]\\[1\\]\\[0\\]: must be in "
                       "\\[-1e\\+06, 1e\\+06\\], got 1e\\+300"));
  r.push_back(scenario("RandomBedBeyondTheTravel",
                       "toolpath:\n  speed: 3\n  random_segments: {n: 5, bed: [300, 300], "
                       "length: [5, 10]}\nplanners: [lspb_mtt]\n",
                       "{s}:1: toolpath\\.start: \\(the default\\) .* is not reachable by "
                       "xy_stage"));
  // ---- bad G-code (problems name the G-code file and its line) ----
  const std::string gcode_scenario =
      "limits: {v_max: 20, a_max: 100}\ntoolpath:\n  speed: 3\n  gcode: part.gcode\n"
      "planners: [lspb_mtt]\n";
  r.push_back(scenario("GcodeHugeNumber", gcode_scenario,
                       "part\\.gcode:2: toolpath\\.gcode: number out of range in 'X1e308'",
                       {{"part.gcode", "G21\nG1 X1e308 Y0 E1 F600\n"}}));
  r.push_back(scenario("GcodeBinaryBytes", gcode_scenario,
                       "part\\.gcode:2: toolpath\\.gcode: binary or control byte \\\\x00",
                       {{"part.gcode", kBinaryGcode}}));
  r.push_back(scenario("GcodeSpline", gcode_scenario, "part\\.gcode:2: toolpath\\.gcode: .*G5",
                       {{"part.gcode", "G1 X1 Y1 F600\nG5 I1 J1 P1 Q1 X2 Y2\n"}}));
  r.push_back(scenario("GcodeWordTwice", gcode_scenario,
                       "part\\.gcode:2: toolpath\\.gcode: E given twice on one line",
                       {{"part.gcode", "G1 X1 Y1 F600\nG1 X2 E1 E2\n"}}));
  r.push_back(scenario("GcodeFileMissing", gcode_scenario,
                       "{s}:4: toolpath\\.gcode: G-code file 'part\\.gcode' not found"));
  // ---- a path given twice ----
  r.push_back(scenario("DuplicateSegment",
                       probe_with("    - [[8, 2], [5, 7]]", "    - [[8, 2], [2, 2]]"),
                       "{s}:10: toolpath\\.segments\\[1\\]: repeats toolpath\\.segments\\[0\\] "
                       "\\(the same points, reversed\\)"));
  r.push_back(scenario("ZeroLengthSegment",
                       probe_with("    - [[8, 2], [5, 7]]", "    - [[8, 2], [8, 2]]"),
                       "{s}:10: toolpath\\.segments\\[1\\]: segment has zero length"));
  r.push_back(scenario("SpeedAboveTheLimits", probe_with("  speed:", "  speed: 5"),
                       "{s}:9: toolpath\\.segments\\[0\\]: print speed 5 mm/s needs 5 mm/s on "
                       "x, above limits v_max 4"));
  // a planner's own refusal of a setting names the scenario's key and the planner's line
  r.push_back(scenario("BezierWeightsOnSingleLines",
                       probe_with("planners:",
                                  "planners:\n  - lspb_mtt\n"
                                  "  - {name: bezier, weight: [1, 2]}"),
                       "{s}:13: planners\\[1\\]\\.weight: has 2 values; the toolpath has no "
                       "corners \\(every path is a single line\\): give one value"));
  // ---- hostile names ----
  r.push_back(scenario("NameOf300Characters", probe("", std::string(300, 'n')),
                       "{s}:1: name: 'n{40}\\.\\.\\.' is 300 bytes long"));
  r.push_back(scenario("NameWithNewlineTabBell", probe("", "\"a\\nb\\tc\\a\""),
                       "{s}:1: name: 'a\\\\x0Ab\\\\x09c\\\\x07' holds a control character"));
  r.push_back(scenario("NameBlank", probe("", "\"   \""), "{s}:1: name: '   ' is blank"));
  r.push_back(scenario("TabIndentation", replace_line(probe(), "  speed:", "\tspeed: 3"),
                       "{s}:6: malformed YAML: .*line 6 is indented with a tab"));
  r.push_back(scenario("NameClimbingOut", probe("", "../x"),
                       "{s}:1: name: '\\.\\./x' cannot name a results folder"));
  r.push_back(scenario("LabelWithEscape",
                       probe_with("planners:", "planners: [{name: lspb_mtt, label: \"x\\e[31m\"}]"),
                       "{s}:11: planners\\[0\\]\\.label: 'x\\\\x1B\\[31m' holds a control"));
  // raw bytes that are not text: a Latin-1 name, a NUL inside a key (before any YAML parsing)
  r.push_back(scenario("NameNotUtf8", replace_line(probe(), "name:", "name: \xff\xfe bad"),
                       "{s}:1: byte 0xFF at column 7 is not UTF-8: a scenario is UTF-8 text"));
  r.push_back(scenario("NulInsideAKey",
                       replace_line(probe(), "  segments:", std::string("  segme\0nts:", 12)),
                       "{s}:8: control byte 0x00 \\(NUL\\) at column 8: a scenario is text"));
  // ---- bad --out (checked before any work) ----
  r.push_back(command("OutIsAFile", "run {dir}/scenario.yaml --out {dir}/afile --no-render --quiet",
                      "error: --out: .*afile: is a file, not a folder",
                      {{"scenario.yaml", probe()}, {"afile", "keep me\n"}}));
  // a folder replaced whole must not hold a file the scenario reads, nor be a sweep's; a sweep
  // is not written into a run's folder; export never writes over its input
  const std::string gcode_job =
      "machine: cartesian\nlimits: {v_max: 100, a_max: 1000}\n"
      "process: {type: extrusion, bead_width_mm: 0.4, layer_height_mm: 0.2}\n"
      "toolpath: {gcode: out/part.gcode}\nplanners: [lspb_mtt]\n";
  const std::string part = "G1 X0 Y0 Z0.2 F600\nG1 X10 E1\n";
  r.push_back(command("OutHoldsTheGcodeItReads",
                      "run {dir}/scenario.yaml --out {out} --no-render --quiet",
                      "error: --out: .*out: holds .*part\\.gcode, which the scenario reads",
                      {{"scenario.yaml", gcode_job}, {"out/part.gcode", part}}));
  r.push_back(command("ExportOverTheGcodeItReads",
                      "export {dir}/scenario.yaml --planner lspb_mtt --out {out}/part.gcode",
                      "error: --out: '.*part\\.gcode' is a file the scenario reads",
                      {{"scenario.yaml", gcode_job}, {"out/part.gcode", part}}));
  // export renames its file into place: never over standard output's name, nor with codes
  // that are no shutter switch, nor with E beyond the doubles
  r.push_back(command(
      "ExportToStandardOutput", "export {dir}/scenario.yaml --planner lspb_mtt --out -",
      "error: --out: '-' \\(standard output\\) is not supported", {{"scenario.yaml", probe()}}));
  r.push_back(command("ExportOpenCodeIsAMove",
                      "export {dir}/scenario.yaml --planner lspb_mtt --out {dir}/a.gcode "
                      "--open 'G1 X100'",
                      "error: --open: 'G1 X100' is not a G or M code",
                      {{"scenario.yaml", probe()}}));
  r.push_back(command("ExportOpenAndCloseTheSame",
                      "export {dir}/scenario.yaml --planner lspb_mtt --out {dir}/a.gcode "
                      "--open M5 --close M5",
                      "error: --close: 'M5' would close what 'M5' opens",
                      {{"scenario.yaml", probe()}}));
  r.push_back(command("ExportFilamentTooThin",
                      "export {dir}/scenario.yaml --planner lspb_mtt --out {dir}/a.gcode "
                      "--filament-diameter 1e-300",
                      "--filament-diameter: expected a number in \\[0\\.01, 100\\], got '1e-300'",
                      {{"scenario.yaml", probe()}}));
  // a start under a part's patch: the summary of the branches names the start, so it stands
  // at toolpath.start's line, not at the surface's
  const std::string plate_stl =
      "solid plate\nfacet normal 0 0 1\nouter loop\nvertex -10 -10 5\nvertex 10 -10 5\n"
      "vertex 10 10 5\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex -10 -10 5\n"
      "vertex 10 10 5\nvertex -10 10 5\nendloop\nendfacet\nendsolid plate\n";
  // an arm hatching plate.stl with `conformal`; `toolpath` its toolpath section's lines
  const auto arm_on_plate = [](const std::string& toolpath) {
    return "name: plate\nmachine: arm6\nlimits: {v_max: 200, a_max: 2000}\n"
           "process: {type: extrusion, bead_width_mm: 0.5, layer_height_mm: 0.5}\n"
           "toolpath:\n  speed: 30\n" +
           toolpath + "planners: [conformal]\n";
  };
  r.push_back(scenario("ArmStartUnderThePart",
                       arm_on_plate("  start: [0, 0, 1]\n"
                                    "  surface: {file: plate.stl, hatch_mm: 4, angles: [0]}\n"),
                       "{s}:7: toolpath\\.start: no posture of arm6 .*\\(branch \\d: the start "
                       "\\(0\\.000, 0\\.000, 1\\.000\\) mm is too close to the part",
                       {{"plate.stl", plate_stl}}));
  // a hatch too fast: each segment by its layer, line and segment, at the surface's speed key
  r.push_back(scenario("ArmSurfaceSpeedAboveTheLimits",
                       arm_on_plate("  surface:\n    file: plate.stl\n"
                                    "    hatch_mm: 4\n    angles: [0]\n    speed: 250\n"),
                       "{s}:11: toolpath\\.surface\\.speed: layer 0, line 0, segment 0 \\(points 0 "
                       "and 1\\): print speed 250 mm/s needs 250 mm/s on x, above limits v_max 200",
                       {{"plate.stl", plate_stl}}));
  r.push_back(command("RunIntoASweepFolder",
                      "run {dir}/scenario.yaml --out {dir}/study --no-render --quiet",
                      "error: --out: .*study: is a depotwin sweep folder \\(s\\), not a run's",
                      {{"scenario.yaml", probe()},
                       {"study/.depotwin", "depotwin sweep folder (s): tasks/<i> per task\n"},
                       {"study/results.csv", "task\n0\n"}}));
  const std::string sweep_of_probe = "base: scenario.yaml\ngrid: {limits.a_max: [20, 30]}\n";
  r.push_back(command("SweepIntoARunFolder", "sweep {dir}/sweep.yaml --out {out}",
                      "error: --out: .*out: is a depotwin output folder, not a sweep's",
                      {{"scenario.yaml", probe()}, {"sweep.yaml", sweep_of_probe}}));
  r.push_back(command("SweepKeyInsideAnother", "sweep {dir}/sweep.yaml --list --out {dir}/study",
                      "sweep\\.yaml:[23]: (set\\.limits: overlaps "
                      "limits\\.a_max|grid\\.limits\\.a_max: overlaps limits)",
                      {{"scenario.yaml", probe()},
                       {"sweep.yaml", sweep_of_probe + "set: {limits: {v_max: 4, a_max: 50}}\n"}}));
  r.push_back(command("SweepTaskEmpty", "sweep {dir}/sweep.yaml --task '' --out {dir}/study",
                      "error: --task: an empty value",
                      {{"scenario.yaml", probe()}, {"sweep.yaml", sweep_of_probe}}));
  r.push_back(command("SweepJobsZero", "sweep {dir}/sweep.yaml -j 0 --out {dir}/study",
                      "--jobs: expected a number above 0, got '0'",
                      {{"scenario.yaml", probe()}, {"sweep.yaml", sweep_of_probe}}));
  r.push_back(command("ComparePlannersUnknown",
                      "compare {dir}/scenario.yaml --planners lspb_mtt,nope --out {dir}/cmp",
                      "error: --planners: unknown planner 'nope'", {{"scenario.yaml", probe()}}));
  r.push_back(command("OutUnderAFile",
                      "run {dir}/scenario.yaml --out {dir}/afile/results --no-render --quiet",
                      "error: --out: .*afile/results: lies under .*afile, which is a file",
                      {{"scenario.yaml", probe()}, {"afile", "keep me\n"}}));
  r.push_back(command(
      "OutInAReadOnlyPlace", "run {dir}/scenario.yaml --out {readonly}/results --no-render --quiet",
      "error: --out: .*results: cannot (create|write)", {{"scenario.yaml", probe()}}));
  r.push_back(command("OutIsSomeoneElsesFolder",
                      "run {dir}/scenario.yaml --out {dir}/theirs --no-render --quiet",
                      "error: --out: .*theirs: exists and is not a depotwin output folder",
                      {{"scenario.yaml", probe()}, {"theirs/notes.txt", "keep me\n"}}));
  // ---- the command line ----
  r.push_back(command("MoveTinyJerk", "move --q0 0 --q1 10 --vmax 5 --amax 10 --jmax 1e-300",
                      "error: --jmax: must be 0 \\(no jerk limit\\) or in \\[1e-06, 1e\\+12\\] "
                      "mm/s\\^3, got 1e-300"));
  r.push_back(command("MoveZeroSpeedLimit", "move --q0 0 --q1 10 --vmax 0 --amax 10",
                      "error: --vmax: must be in \\[1e-06, 1e\\+06\\] mm/s, got 0"));
  r.push_back(command("MoveHugeTarget", "move --q0 0 --q1 1e300 --vmax 5 --amax 10",
                      "error: --q1: must be in \\[-1e\\+06, 1e\\+06\\] mm, got 1e\\+300"));
  // just past a bound: the value's own digits, not the bound's (it read "got 1e+06")
  r.push_back(command("MoveTargetJustPastTheTravel", "move --q0 0 --q1 1000001 --vmax 5 --amax 10",
                      "error: --q1: must be in \\[-1e\\+06, 1e\\+06\\] mm, got 1000001"));
  r.push_back(command("MoveSpeedLimitJustPastItsRange",
                      "move --q0 0 --q1 1 --vmax 1000001 --amax 10",
                      "error: --vmax: must be in \\[1e-06, 1e\\+06\\] mm/s, got 1000001"));
  r.push_back(command("MoveNotANumber", "move --q0 0 --q1 nan --vmax 5 --amax 10",
                      "error: --q1: 'nan' is not a finite number"));
  r.push_back(command("MoveListEndingInAComma", "move --q0 0,0 --q1 10, --vmax 5 --amax 10",
                      "error: --q1: '10,' ends with a comma: a value is missing"));
  r.push_back(command("PlannerNamedTwice",
                      "run {dir}/scenario.yaml --planner lspb_mtt,lspb_mtt --out {out} "
                      "--no-render --quiet",
                      "error: --planner: 'lspb_mtt' is named twice", {{"scenario.yaml", probe()}}));
  r.push_back(command("UnknownPlanner",
                      "run {dir}/scenario.yaml --planner teleport --out {out} --no-render --quiet",
                      "error: --planner: .*teleport", {{"scenario.yaml", probe()}}));
  return r;
}

// a string as a regular expression that matches it literally
std::string regex_escaped(const std::string& text) {
  static const std::regex kSpecial(R"([.^$|()\[\]{}*+?\\])");
  return std::regex_replace(text, kSpecial, R"(\$&)");
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

// every file under a folder with its contents (what "untouched" compares)
std::map<std::string, std::string> snapshot(const fs::path& folder) {
  std::map<std::string, std::string> files;
  if (!fs::exists(folder)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    files[fs::relative(entry.path(), folder).string()] =
        entry.is_regular_file() ? read_text(entry.path().string()) : "<folder>";
  return files;
}

struct Outcome {
  int status = -1;
  std::string output;
  double seconds = 0.0;
};

// the CLI run in `dir` (its default results/ folder would land there), within the budget
Outcome run_cli(const fs::path& dir, const std::string& arguments) {
  const std::string command = "cd '" + dir.string() + "' && timeout -k 5 " +
                              std::to_string(kBudget_s) + " " + DEPOTWIN_BINARY_DIR + "/depotwin " +
                              arguments;
  const auto start = std::chrono::steady_clock::now();
  Outcome outcome;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe != nullptr) {
    char buffer[4096];
    std::size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) outcome.output.append(buffer, n);
    const int status = ::pclose(pipe);
    outcome.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return outcome;
}

std::string first_line(const std::string& text) {
  return text.substr(0, text.find('\n'));
}

class BadInput : public ::testing::TestWithParam<Row> {};

TEST_P(BadInput, ExitsTwoNamingFileLineAndKeyAndTouchesNothing) {
  const Row& row = GetParam();
  const fs::path dir = testing_support::fresh_directory("bad_input/" + row.name);
  for (const auto& [name, contents] : row.files) {
    fs::create_directories((dir / name).parent_path());
    write_text(dir.string(), name, contents);
  }
  // an earlier result in the output folder: a bad run must leave it as it was
  const fs::path out = dir / "out";
  fs::create_directories(out / "lspb_mtt");
  write_text(out.string(), ".depotwin", "depotwin output folder (an earlier result)\n");
  write_text((out / "lspb_mtt").string(), "metrics.json", "{\"earlier\": true}\n");
  // a place even root cannot write: /proc (chmod does not stop root)
  const std::string readonly = ::geteuid() == 0 ? "/proc/depotwin_bad_input" : [&] {
    fs::create_directories(dir / "readonly");
    ::chmod((dir / "readonly").c_str(), 0555);
    return (dir / "readonly").string();
  }();
  const auto before = snapshot(dir);

  const std::string scenario = (dir / "scenario.yaml").string();
  const std::string pattern = replaced(row.pattern, "{s}", regex_escaped(scenario));
  const auto expand = [&](std::string arguments) {
    arguments = replaced(arguments, "{dir}", dir.string());
    arguments = replaced(arguments, "{out}", out.string());
    return replaced(arguments, "{readonly}", readonly);
  };
  std::vector<std::string> commands;
  if (row.command.empty()) {
    // (--quiet: a step slower than the progress period, as under the sanitizers, would put
    // its progress line before the problem)
    commands.push_back("validate " + scenario + " --quiet " + row.validate_options);
    commands.push_back("run " + scenario + " --out " + out.string() + " --no-render --quiet " +
                       row.validate_options);
  } else {
    commands.push_back(expand(row.command));
  }

  std::vector<std::string> first_lines;
  for (const std::string& arguments : commands) {
    const Outcome outcome = run_cli(dir, arguments);
    SCOPED_TRACE("depotwin " + arguments);
    EXPECT_NE(outcome.status, 124) << "over the " << kBudget_s << " s budget";
    EXPECT_EQ(outcome.status, 2) << outcome.output;
    EXPECT_TRUE(std::regex_search(outcome.output, std::regex(pattern)))
        << "pattern: " << pattern << "\noutput:\n"
        << outcome.output;
    // never a crash, never an internal error, never a raw control byte echoed
    EXPECT_EQ(outcome.output.find("internal error"), std::string::npos) << outcome.output;
    EXPECT_EQ(outcome.output.find('\x1b'), std::string::npos) << outcome.output;
    first_lines.push_back(first_line(outcome.output));
  }
  // validate and run agree: the same first problem
  if (first_lines.size() == 2) {
    EXPECT_EQ(first_lines[0], first_lines[1]);
  }

  // nothing written, nothing changed: the earlier result, the inputs, no staging folder, no
  // results/ where the verb runs
  EXPECT_EQ(snapshot(dir), before);
}

std::string row_name(const ::testing::TestParamInfo<Row>& info) {
  return info.param.name;
}

INSTANTIATE_TEST_SUITE_P(Rows, BadInput, ::testing::ValuesIn(rows()), row_name);

// the table covers the probe's cases and categories: at least 45 rows
TEST(BadInputTable, HasAtLeastFortyFiveRows) {
  EXPECT_GE(rows().size(), 45u);
}

}  // namespace
}  // namespace depotwin
