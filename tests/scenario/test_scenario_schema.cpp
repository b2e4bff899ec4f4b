// The schema tables (scenario/schema.hpp) against the loader and SCHEMA.md: every key the
// loader accepts is in a table and every table key is accepted; the ranges in the tables are
// the ones enforced; a file without a key gets the table's default; SCHEMA.md names every key.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include "kinematics/machine.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/planner.hpp"
#include "scenario/scenario_test_util.hpp"
#include "scenario/schema.hpp"

namespace depotwin {
namespace {

using testing_scenario::dump;
using SchemaFiles = testing_scenario::ScenarioFiles;

constexpr const char* kSegments = "toolpath: {speed: 1, segments: [[[0, 0], [1, 0]]]}\n";

// a scenario whose map at `path` holds the unknown key `zzz` (and what the map needs)
std::string with_unknown_key(const std::string& path) {
  if (path.empty()) return std::string("zzz: 1\n") + kSegments;
  if (path == "limits.x") return std::string("limits: {x: {zzz: 1}}\n") + kSegments;
  if (path == "limits.joint")
    return std::string("limits: {joint: {v_max: 1, a_max: 1, zzz: 1}}\n") + kSegments;
  if (path == "toolpath") return "toolpath: {speed: 1, zzz: 1, segments: [[[0, 0], [1, 0]]]}\n";
  if (path == "toolpath.polylines[]")
    return "toolpath: {speed: 1, polylines: [{points: [[0, 0], [1, 0]], zzz: 1}]}\n";
  if (path == "toolpath.random_segments")
    return "toolpath: {speed: 1, random_segments: {n: 2, bed: [20, 20], length: [1, 2], zzz: "
           "1}}\n";
  if (path == "toolpath.gcode") return "toolpath: {speed: 1, gcode: {file: a.gcode, zzz: 1}}\n";
  if (path == "toolpath.surface") return "toolpath: {speed: 1, surface: {file: a.stl, zzz: 1}}\n";
  if (path == "arm") return std::string("machine: arm6\narm: {zzz: 1}\n") + kSegments;
  return path + ": {zzz: 1}\n" + kSegments;
}

// the key list of the loader's "unknown key (expected one of: a, b)" message
std::vector<std::string> listed_keys(const std::string& message) {
  const std::string marker = "expected one of: ";
  const std::size_t from = message.find(marker);
  if (from == std::string::npos) return {};
  const std::string list =
      message.substr(from + marker.size(), message.rfind(')') - from - marker.size());
  std::vector<std::string> keys;
  std::stringstream in(list);
  std::string key;
  while (std::getline(in, key, ',')) keys.push_back(key.substr(key.find_first_not_of(' ')));
  return keys;
}

// every map section of the file: what the loader accepts is what the table lists
TEST_F(SchemaFiles, EveryAcceptedKeyIsDescribedAndViceVersa) {
  int sections = 0;
  for (const SchemaSection& section : scenario_schema()) {
    if (section.path == "planners[]") continue;  // a planner's keys are its parameters
    ++sections;
    const std::vector<Problem> problems = problems_of(with_unknown_key(section.path));
    const std::string key = section.path.empty()                     ? "zzz"
                            : section.path == "toolpath.polylines[]" ? "toolpath.polylines[0].zzz"
                                                                     : section.path + ".zzz";
    const auto unknown = std::find_if(problems.begin(), problems.end(),
                                      [&](const Problem& p) { return p.key == key; });
    ASSERT_NE(unknown, problems.end()) << section.path << ":\n" << dump(problems);
    EXPECT_EQ(listed_keys(unknown->message), section.key_names()) << unknown->message;
  }
  EXPECT_EQ(sections, 14);
}

// a planner entry's keys: name, label, and the registry's parameters
TEST_F(SchemaFiles, PlannerEntryKeysAreNameLabelAndTheRegistrysParameters) {
  EXPECT_EQ(schema_section("planners[]").key_names(), (std::vector<std::string>{"name", "label"}));
  const std::vector<Problem> problems =
      problems_of(std::string(kSegments) + "planners: [{name: bezier, label: b, zzz: 1}]\n");
  ASSERT_EQ(problems.size(), 1u) << dump(problems);
  EXPECT_EQ(problems[0].key, "planners[0].zzz");
  EXPECT_NE(problems[0].message.find("(known: delta, weight, period_s, lead_in, merge)"),
            std::string::npos)
      << problems[0].message;
}

// the value just outside `range` at its lower end
double below(const ValueRange& range) {
  return range.min_inclusive ? range.min - 1.0 : range.min;
}

// every bounded number of a table is refused just below its range, with the range's text
TEST_F(SchemaFiles, TheTablesRangesAreTheOnesEnforced) {
  int checked = 0;
  for (const char* path : {"process", "sim", "outputs", "arm", "toolpath.surface", "limits",
                           "toolpath.random_segments"}) {
    const SchemaSection& section = schema_section(path);
    for (const SchemaKey& key : section.keys) {
      if (key.type != "number" && key.type != "whole number") continue;
      if (!std::isfinite(key.range.min) || key.name == "seed") continue;
      std::ostringstream yaml;
      yaml.precision(17);
      const std::string value = format_number(below(key.range));
      const std::string path_text = path;
      if (path_text == "toolpath.surface") {
        yaml << "toolpath: {speed: 1, surface: {file: a.stl, " << key.name << ": " << value
             << "}}\n";
      } else if (path_text == "toolpath.random_segments") {
        yaml << "toolpath: {speed: 1, random_segments: {bed: [20, 20], length: [1, 2], " << key.name
             << ": " << value << "}}\n";
      } else {
        if (path_text == "arm") yaml << "machine: arm6\n";
        const std::string type = key.applies_to.empty() ? "" : "type: " + key.applies_to + ", ";
        yaml << path << ": {" << type << key.name << ": " << value << "}\n" << kSegments;
      }
      const std::vector<Problem> problems = problems_of(yaml.str());
      const std::string dotted = std::string(path) + "." + key.name;
      const auto found = std::find_if(problems.begin(), problems.end(),
                                      [&](const Problem& p) { return p.key == dotted; });
      ASSERT_NE(found, problems.end()) << yaml.str() << dump(problems);
      EXPECT_NE(found->message.find(key.range.text()), std::string::npos)
          << dotted << ": " << found->message;
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
}

// a file without the sections gets the tables' defaults
TEST_F(SchemaFiles, AFileWithoutTheKeysGetsTheTablesDefaults) {
  const Scenario s = load_scenario(write("minimal.yaml", kSegments));
  const auto expect_default = [](const std::string& path, const std::string& key, double loaded) {
    const SchemaKey& declared = schema_section(path).key(key);
    ASSERT_TRUE(declared.default_value.has_value()) << path << "." << key;
    EXPECT_DOUBLE_EQ(*declared.default_value, loaded) << path << "." << key;
    EXPECT_EQ(declared.default_text, format_number(loaded)) << path << "." << key;
  };
  expect_default("process", "flow_mm3_s", s.process.flow_mm3_s);
  expect_default("process", "sigma_mm", s.process.sigma_mm);
  expect_default("process", "shutter_time_s", s.process.shutter_time_s);
  expect_default("process", "line_width_mm", s.process.line_width_mm);
  expect_default("process", "bead_width_mm", s.process.bead_width_mm);
  expect_default("process", "layer_height_mm", s.process.layer_height_mm);
  expect_default("process", "tau_s", s.process.tau_s);
  EXPECT_EQ(schema_section("process").key("type").default_text, s.process.type);
  EXPECT_EQ(schema_section("process").key("retract").default_text,
            s.process.retract ? "true" : "false");
  expect_default("sim", "timestep_s", s.sim.timestep_s);
  expect_default("sim", "control_period_s", s.sim.control_period_s);
  expect_default("sim", "cell_mm", s.sim.cell_mm);
  expect_default("sim", "kp_scale", s.sim.kp_scale);
  expect_default("sim", "settle_s", s.sim.settle_s);
  expect_default("outputs", "image_width", s.outputs.image_width);
  expect_default("outputs", "image_height", s.outputs.image_height);
  for (int axis = 0; axis < 3; ++axis) {
    expect_default("limits", "v_max", s.limits.axes[axis].v_max_mm_s);
    expect_default("limits", "a_max", s.limits.axes[axis].a_max_mm_s2);
    expect_default("limits", "j_max", s.limits.axes[axis].j_max_mm_s3);
  }
  EXPECT_EQ(schema_section("order").key("method").default_text, s.order.method);
  EXPECT_EQ(schema_section("order").key("cost_model").default_text, s.order.cost_model);
  expect_default("order", "seed", static_cast<double>(s.order.seed));
  // the numbers a user looks for, as documented (README, SCHEMA.md)
  EXPECT_EQ(s.process.sigma_mm, 0.1);
  EXPECT_EQ(s.process.shutter_time_s, 0.02);
  EXPECT_EQ(s.process.bead_width_mm, 0.4);
  EXPECT_EQ(s.process.tau_s, 0.05);
  EXPECT_EQ(s.sim.kp_scale, 1.0);
  EXPECT_EQ(s.limits.axes[0].v_max_mm_s, 4.0);
  EXPECT_EQ(s.limits.axes[0].a_max_mm_s2, 30.0);
}

// the arm's and the surface's defaults are their structs' (loaded when the section is given
// without the key)
TEST_F(SchemaFiles, ArmAndSurfaceDefaultsAreTheirStructs) {
  const ArmPostureSettings arm;
  const SchemaSection& arm_section = schema_section("arm");
  EXPECT_EQ(*arm_section.key("roll_step_deg").default_value, arm.roll_step_deg);
  EXPECT_EQ(*arm_section.key("sample_spacing_mm").default_value, arm.sample_spacing_mm);
  EXPECT_EQ(*arm_section.key("min_joint_margin_deg").default_value, arm.min_joint_margin_deg);
  EXPECT_EQ(*arm_section.key("min_clearance_mm").default_value, arm.min_clearance_mm);
  EXPECT_EQ(*arm_section.key("branch").default_value, arm.branch);
  const SurfaceToolpath surface;
  const SchemaSection& surface_section = schema_section("toolpath.surface");
  EXPECT_EQ(*surface_section.key("hatch_mm").default_value, surface.hatch_mm);
  EXPECT_EQ(*surface_section.key("alpha").default_value, surface.alpha);
  EXPECT_EQ(*surface_section.key("layers").default_value, surface.layers);
  EXPECT_EQ(*surface_section.key("layer_height_mm").default_value, surface.layer_height_mm);
  // the same numbers, as documented
  EXPECT_EQ(surface.hatch_mm, 0.5);
  EXPECT_EQ(arm.roll_step_deg, 15.0);
}

std::string schema_md() {
  std::ifstream in(std::string(DEPOTWIN_SOURCE_DIR) + "/src/scenario/SCHEMA.md");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// SCHEMA.md names every key of every table, every planner parameter, sequencer and machine,
// and points to `depotwin describe`: the documentation cannot lose a parameter
TEST(SchemaDocument, NamesEveryParameterAndPointsToDescribe) {
  const std::string text = schema_md();
  ASSERT_FALSE(text.empty());
  EXPECT_NE(text.find("depotwin describe"), std::string::npos);
  const auto named = [&](const std::string& name) {
    return text.find("`" + name + "`") != std::string::npos ||
           text.find(name + ":") != std::string::npos;
  };
  for (const SchemaSection& section : scenario_schema())
    for (const SchemaKey& key : section.keys)
      EXPECT_TRUE(named(key.name)) << section.path << "." << key.name;
  for (const PlannerInfo& planner : planner_registry()) {
    EXPECT_TRUE(named(planner.name)) << planner.name;
    for (const PlannerParameter& parameter : planner.parameters)
      EXPECT_TRUE(named(parameter.name)) << planner.name << "." << parameter.name;
  }
  for (const std::string& name : sequencer_methods()) EXPECT_TRUE(named(name)) << name;
  for (const std::string& name : machine_names()) EXPECT_TRUE(named(name)) << name;
  // the joint angle is defined where it is used
  EXPECT_NE(text.find("interior angle"), std::string::npos);
}

// SCHEMA.md's tables are the schema's own (schema_markdown_table): every section's table sits
// between `<!-- schema: PATH -->` and `<!-- end schema -->`, character for character, so every
// range, default and unit in them is the one the loader enforces
TEST(SchemaDocument, TablesAreTheSchemasOwn) {
  const std::string text = schema_md();
  ASSERT_FALSE(text.empty());
  for (const SchemaSection& section : scenario_schema()) {
    const std::string begin =
        "<!-- schema: " + (section.path.empty() ? "top" : section.path) + " -->\n";
    const std::string expected = schema_markdown_table(section);
    const std::size_t at = text.find(begin);
    EXPECT_NE(at, std::string::npos)
        << "SCHEMA.md has no table for '" << section.path << "'; add:\n"
        << begin << expected << "<!-- end schema -->";
    if (at == std::string::npos) continue;
    const std::size_t from = at + begin.size();
    const std::size_t to = text.find("<!-- end schema -->", from);
    ASSERT_NE(to, std::string::npos) << section.path;
    // a table inside a list item is indented: compared without the indent
    std::string table;
    std::istringstream lines(text.substr(from, to - from));
    for (std::string line; std::getline(lines, line);) {
      line.erase(0, line.find_first_not_of(' '));
      if (!line.empty()) table += line + "\n";
    }
    EXPECT_EQ(table, expected) << "SCHEMA.md's table for '" << section.path
                               << "' differs from the schema; replace it "
                               << "with:\n"
                               << begin << expected << "<!-- end schema -->";
  }
}

}  // namespace
}  // namespace depotwin
