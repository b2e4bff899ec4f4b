// `depotwin describe`: the tables the loader validates against, printed with units, ranges,
// defaults and meanings; aligned text or JSON; the machines' joints and geometry from the
// machines themselves.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/describe.hpp"
#include "core/error.hpp"
#include "kinematics/linear_delta.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/planner.hpp"
#include "scenario/scenario.hpp"
#include "scenario/schema.hpp"

namespace depotwin {
namespace {

using nlohmann::json;
using testing_support::depotwin;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

// the JSON entry named `name` of a list
const json& named(const json& list, const std::string& name) {
  for (const json& entry : list)
    if (entry.at("name") == name) return entry;
  throw std::out_of_range("no entry " + name);
}

TEST(Describe, WithoutATopicListsEveryTopic) {
  const std::string text = describe_text("");
  for (const auto& [topic, what] : describe_topics()) {
    EXPECT_NE(text.find(topic), std::string::npos) << topic;
    EXPECT_NE(text.find(what), std::string::npos) << what;
  }
  for (const char* required :
       {"machines", "planners", "sequencers", "processes", "sim", "limits", "outputs", "toolpath"})
    EXPECT_NE(text.find(required), std::string::npos) << required;
}

// every key of the section, with its unit, range and default, in columns that line up
TEST(Describe, ProcessesIsAnAlignedTableWithUnitsRangesAndDefaults) {
  const std::vector<std::string> lines = lines_of(describe_text("processes"));
  // the header, its underline, then one row per key
  const auto header = std::find_if(lines.begin(), lines.end(), [](const std::string& line) {
    return line.rfind("key", 0) == 0;
  });
  ASSERT_NE(header, lines.end());
  const std::size_t unit_column = header->find("unit");
  const std::size_t default_column = header->find("default");
  ASSERT_NE(unit_column, std::string::npos);
  const std::vector<std::string> keys = schema_section("process").key_names();
  ASSERT_GE(lines.end() - header, static_cast<long>(keys.size() + 2));
  EXPECT_EQ((header + 1)->find_first_not_of('-'), (header + 1)->find(' '));
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::string& row = *(header + 2 + static_cast<long>(i));
    EXPECT_EQ(row.rfind(keys[i] + " ", 0), 0u) << row;
    EXPECT_NE(row[unit_column], ' ') << row;
    EXPECT_EQ(row[unit_column - 1], ' ') << row;
    EXPECT_NE(row[default_column], ' ') << row;
  }
  // sigma_mm: mm, > 0, its default 0.1 in the default column
  const std::string sigma = *(header + 2 + 2);
  ASSERT_EQ(sigma.rfind("sigma_mm", 0), 0u);
  EXPECT_EQ(sigma.substr(unit_column, 3), "mm ");
  EXPECT_EQ(sigma.substr(default_column, 4), "0.1 ");
}

// the JSON carries the struct's defaults and the table's keys
TEST(Describe, JsonDefaultsAreTheStructs) {
  const json process = describe_json("processes");
  EXPECT_EQ(process.at("topic"), "processes");
  const json& keys = process.at("sections").at(0).at("keys");
  ASSERT_EQ(keys.size(), schema_section("process").keys.size());
  const ProcessSpec defaults;
  EXPECT_EQ(named(keys, "sigma_mm").at("default_value").get<double>(), defaults.sigma_mm);
  EXPECT_EQ(named(keys, "shutter_time_s").at("default_value").get<double>(),
            defaults.shutter_time_s);
  EXPECT_EQ(named(keys, "bead_width_mm").at("default_value").get<double>(), defaults.bead_width_mm);
  EXPECT_EQ(named(keys, "tau_s").at("default_value").get<double>(), defaults.tau_s);
  EXPECT_EQ(named(keys, "sigma_mm").at("unit"), "mm");
  EXPECT_EQ(named(keys, "sigma_mm").at("min").get<double>(), 0.001);
  EXPECT_TRUE(named(keys, "sigma_mm").at("min_inclusive").get<bool>());
  EXPECT_EQ(named(keys, "tau_s").at("applies_to"), "extrusion");
  const json sim = describe_json("sim").at("sections").at(0).at("keys");
  EXPECT_EQ(named(sim, "kp_scale").at("default_value").get<double>(), SimSpec{}.kp_scale);
  EXPECT_EQ(named(sim, "timestep_s").at("max").get<double>(), 0.01);
}

// every planner and every parameter of the registry, with ranges and defaults (bezier's
// period_s and lead_in included)
TEST(Describe, PlannersFromTheRegistry) {
  const json planners = describe_json("planners").at("planners");
  ASSERT_EQ(planners.size(), planner_registry().size());
  for (const PlannerInfo& info : planner_registry()) {
    const json& described = named(planners, info.name);
    EXPECT_EQ(described.at("honours_j_max").get<bool>(), info.honours_jerk_limit);
    ASSERT_EQ(described.at("parameters").size(), info.parameters.size()) << info.name;
    for (const PlannerParameter& p : info.parameters) {
      const json& parameter = named(described.at("parameters"), p.name);
      if (p.choices.empty()) {
        EXPECT_EQ(parameter.at("default_value").get<double>(), p.default_value);
        EXPECT_EQ(parameter.at("min").get<double>(), p.min_value);
        EXPECT_EQ(parameter.at("max").get<double>(), p.max_value);
      } else {
        EXPECT_EQ(parameter.at("default"), p.choices.front());
      }
    }
  }
  const json& bezier = named(planners, "bezier").at("parameters");
  EXPECT_EQ(named(bezier, "period_s").at("default_value").get<double>(), 0.001);
  EXPECT_EQ(named(bezier, "period_s").at("unit"), "s");
  EXPECT_TRUE(named(bezier, "lead_in").at("whole_number").get<bool>());
  const std::string text = describe_text("planners");
  EXPECT_NE(text.find("lead_in"), std::string::npos);
  EXPECT_NE(text.find("period_s"), std::string::npos);
}

TEST(Describe, SequencersRefinementsAndCostModels) {
  const json described = describe_json("order");  // an alias
  EXPECT_EQ(described.at("topic"), "sequencers");
  std::vector<std::string> names;
  for (const json& s : described.at("sequencers")) names.push_back(s.at("name"));
  EXPECT_EQ(names, sequencer_methods());
  EXPECT_EQ(described.at("refinements").get<std::vector<std::string>>(), refine_methods());
  EXPECT_EQ(described.at("cost_models").get<std::vector<std::string>>(), cost_models());
}

// the machines' joints, travel and geometry, from the machines themselves
TEST(Describe, MachinesJointsTravelAndGeometry) {
  const json machines = describe_json("machines").at("machines");
  std::vector<std::string> names;
  for (const json& m : machines) names.push_back(m.at("name"));
  EXPECT_EQ(names, machine_names());
  // the XY stage: +-50 mm on x and y, and the TCP reaches 50 mm each way
  const json& xy = named(machines, "xy_stage");
  const json& x = named(xy.at("joints"), "x");
  EXPECT_EQ(x.at("min").get<double>(), -50.0);
  EXPECT_EQ(x.at("max").get<double>(), 50.0);
  EXPECT_EQ(x.at("unit"), "mm");
  EXPECT_EQ(named(xy.at("geometry"), "tcp_reach_at_z0").at("value"), "+x 50, -x 50, +y 50, -y 50");
  // the delta's geometry
  const json& delta = named(machines, "linear_delta");
  EXPECT_EQ(named(delta.at("geometry"), "rod_length").at("value"),
            format_number(LinearDeltaGeometry{}.rod_length_mm));
  EXPECT_EQ(named(delta.at("joints"), "carriage1").at("v_max").get<double>(),
            LinearDeltaGeometry{}.carriage_v_max_mm_s);
  // the arm's hinges in degrees: j1 +-165 deg at 250 deg/s
  const json& j1 = named(named(machines, "arm6").at("joints"), "j1");
  EXPECT_EQ(j1.at("unit"), "deg");
  EXPECT_NEAR(j1.at("max").get<double>(), 165.0, 1e-9);
  EXPECT_NEAR(j1.at("v_max").get<double>(), 250.0, 1e-9);
  const std::string text = describe_text("machines");
  EXPECT_NE(text.find("-50 .. 50 mm"), std::string::npos) << text;
}

// the joint angle is defined where toolpaths are described
TEST(Describe, ToolpathDefinesTheJointAngle) {
  const std::string text = describe_text("toolpath");
  EXPECT_NE(text.find("interior angle between two consecutive segments"), std::string::npos);
  EXPECT_NE(text.find("180 deg = straight on"), std::string::npos);
  EXPECT_EQ(describe_json("toolpath").at("joint_angle"), kJointAngleDefinition);
}

// the top level opens with its own summary (it had a title run into it), and an axis' own
// limits default to the common ones, whatever those are set to (they read 4 and 30)
TEST(Describe, ScenarioSummaryAndTheAxisLimitsDefaults) {
  EXPECT_EQ(describe_text("scenario").rfind("a scenario file: one YAML map", 0), 0u);
  const json limits = describe_json("limits").at("sections");
  ASSERT_EQ(limits.at(1).at("path"), "limits.x");
  for (const json& key : limits.at(1).at("keys")) {
    EXPECT_EQ(key.at("default"), "limits." + key.at("name").get<std::string>());
    EXPECT_FALSE(key.contains("default_value")) << key.at("name");
  }
}

TEST(Describe, AnUnknownTopicIsBadInputNamingTheTopics) {
  try {
    describe_text("nozzles");
    FAIL() << "no error";
  } catch (const InputError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].key, "describe");
    EXPECT_NE(e.problems()[0].message.find("unknown topic 'nozzles' (topics: scenario, machines"),
              std::string::npos)
        << e.problems()[0].message;
  }
}

// the verb: exit 0 with the tables or JSON, 2 for an unknown topic
TEST(DescribeVerb, PrintsTablesOrJsonAndRefusesUnknownTopics) {
  const auto listed = depotwin("describe");
  EXPECT_EQ(listed.status, 0);
  EXPECT_EQ(listed.output, describe_text(""));
  const auto process = depotwin("describe processes");
  EXPECT_EQ(process.status, 0);
  EXPECT_EQ(process.output, describe_text("processes"));
  const auto as_json = depotwin("describe planners --json");
  ASSERT_EQ(as_json.status, 0);
  EXPECT_EQ(json::parse(as_json.output), describe_json("planners"));
  const auto unknown = depotwin("describe nozzles");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.output.find("error: describe: unknown topic 'nozzles'"), std::string::npos)
      << unknown.output;
}

}  // namespace
}  // namespace depotwin
