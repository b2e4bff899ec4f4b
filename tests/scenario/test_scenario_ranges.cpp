// Every number a scenario file can hold, at the extremes: for every numeric key of every
// section of the schema (scenario/schema.hpp, the tables `depotwin describe` prints), a huge
// value (1e300), a huge negative one and, where the key's range excludes it, a tiny one
// (1e-300) are refused at that key's line, by the loader, before anything else runs. The
// keys come from the schema itself, so a key added later is swept without a change here.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "scenario/scenario_test_util.hpp"
#include "scenario/schema.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using testing_scenario::ScenarioFiles;

class EveryNumber : public ScenarioFiles {
 protected:
  // a scenario with `key: value` in `section` and whatever that section needs besides
  // (its machine, its process type, a G-code file, a part); the dotted key the loader names
  std::pair<std::string, std::string> scenario_with(const SchemaSection& section,
                                                    const SchemaKey& key,
                                                    const std::string& value) {
    const std::string& path = section.path;
    const std::string segments = "  segments: [[[0, 0], [1, 0]]]\n";
    const std::string kv = key.name + ": " + value;
    if (path == "limits")
      return {"limits: {" + kv + "}\ntoolpath:\n  speed: 3\n" + segments, "limits." + key.name};
    if (path == "limits.x")
      return {"limits: {x: {" + kv + "}}\ntoolpath:\n  speed: 3\n" + segments,
              "limits.x." + key.name};
    if (path == "limits.joint") {
      std::map<std::string, std::string> joint{{"v_max", "200"}, {"a_max", "3000"}};
      joint[key.name] = value;
      std::string text;
      for (const auto& [name, given] : joint)
        text += (text.empty() ? "" : ", ") + name + ": " + given;
      return {"limits: {joint: {" + text + "}}\ntoolpath:\n  speed: 3\n" + segments,
              "limits.joint." + key.name};
    }
    if (path == "process") {
      const std::string type = key.applies_to.empty() ? "aerosol" : key.applies_to;
      return {"process: {type: " + type + ", " + kv + "}\ntoolpath:\n  speed: 3\n" + segments,
              "process." + key.name};
    }
    if (path == "toolpath") return {"toolpath:\n  " + kv + "\n" + segments, "toolpath." + key.name};
    if (path == "toolpath.polylines[]")
      return {"toolpath:\n  polylines: [{points: [[0, 0], [1, 0]], " + kv + "}]\n",
              "toolpath.polylines[0]." + key.name};
    if (path == "toolpath.gcode") {
      write("part.gcode", "G21\nG90\nG1 X1 Y0 F180\nG1 X2 Y1\n");
      return {"toolpath:\n  speed: 3\n  gcode: {file: part.gcode, " + kv + "}\n",
              "toolpath.gcode." + key.name};
    }
    if (path == "toolpath.random_segments")
      return {
          "toolpath:\n  speed: 3\n  random_segments: {bed: [20, 20], length: [1, 2], " + kv + "}\n",
          "toolpath.random_segments." + key.name};
    if (path == "toolpath.surface")
      return {"machine: arm6\ntoolpath:\n  speed: 3\n  surface: {file: part.stl, " + kv + "}\n",
              "toolpath.surface." + key.name};
    if (path == "arm")
      return {"machine: arm6\narm: {" + kv + "}\ntoolpath:\n  speed: 3\n" + segments,
              "arm." + key.name};
    if (path == "order")
      return {"order: {method: random, " + kv + "}\ntoolpath:\n  speed: 3\n" + segments,
              "order." + key.name};
    if (path == "sim")
      return {"sim: {" + kv + "}\ntoolpath:\n  speed: 3\n" + segments, "sim." + key.name};
    if (path == "outputs")
      return {"outputs: {" + kv + "}\ntoolpath:\n  speed: 3\n" + segments, "outputs." + key.name};
    ADD_FAILURE() << "no scenario for section '" << path << "': add one to this test";
    return {};
  }

  // the value is refused at the key, on the line the scenario gives it
  void expect_refused(const SchemaSection& section, const SchemaKey& key,
                      const std::string& value) {
    const auto [yaml, dotted] = scenario_with(section, key, value);
    if (yaml.empty()) return;
    const std::vector<Problem> problems = problems_of(yaml);
    int at_key = 0;
    for (const Problem& p : problems) {
      if (p.key != dotted) continue;
      ++at_key;
      EXPECT_GT(p.line, 0) << p.str();
      // the message prints the number at most with 6 significant digits
      EXPECT_EQ(p.message.find("000000000"), std::string::npos) << p.str();
    }
    EXPECT_EQ(at_key, 1) << dotted << " = " << value << " was not refused at its key:\n"
                         << yaml << "\n"
                         << dump(problems);
  }
};

TEST_F(EveryNumber, HugeAndTinyValuesAreRefusedAtTheirKey) {
  int keys = 0;
  for (const SchemaSection& section : scenario_schema())
    for (const SchemaKey& key : section.keys) {
      if (key.type != "number" && key.type != "whole number") continue;
      ++keys;
      expect_refused(section, key, "1e300");
      expect_refused(section, key, "-1e300");
      // 1e-300 where the key's range excludes it (a positive quantity with a floor); where
      // the range holds it (0 is "none" or "default"), it is a legal value
      if (!key.range.contains(1e-300)) expect_refused(section, key, "1e-300");
      // a number written with 400 digits is echoed as the number, not the digits
      expect_refused(section, key, "1" + std::string(400, '0'));
    }
  // every section's numbers: limits (9), process (7), toolpath (1), polylines (1), gcode (1),
  // random_segments (3), surface (6), arm (10), order (1), sim (6), outputs (2)
  EXPECT_EQ(keys, 47);
}

// the coordinates of every point: finite and within +-1e6 mm
TEST_F(EveryNumber, PointsOutsideAKilometreAreRefused) {
  const std::vector<Problem> problems = problems_of(R"(
toolpath:
  speed: 3
  start: [1e300, 0]
  offset: [0, -2e6]
  segments: [[[0, 0], [1, 1e7]]]
)");
  ASSERT_EQ(problems.size(), 3u) << dump(problems);
  testing_scenario::expect_problem(problems, scenario_path(), "toolpath.start[0]", 3,
                                   "must be in [-1e+06, 1e+06], got 1e+300");
  testing_scenario::expect_problem(problems, scenario_path(), "toolpath.offset[1]", 4,
                                   "got -2e+06");
  testing_scenario::expect_problem(problems, scenario_path(), "toolpath.segments[0][1][1]", 5,
                                   "got 1e+07");
}

}  // namespace
}  // namespace depotwin
