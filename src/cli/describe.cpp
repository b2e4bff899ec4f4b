#include "cli/describe.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "core/error.hpp"
#include "core/types.hpp"
#include "kinematics/arm6.hpp"
#include "kinematics/linear_delta.hpp"
#include "kinematics/machine.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/planner.hpp"
#include "scenario/schema.hpp"

namespace depotwin {

namespace {

using Rows = std::vector<std::vector<std::string>>;
using nlohmann::json;

// an aligned table: the first row is the header, underlined; columns two spaces apart, the
// last one unpadded
std::string table(const Rows& rows) {
  std::vector<std::size_t> width;
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (width.size() <= c) width.push_back(0);
      width[c] = std::max(width[c], row[c].size());
    }
  std::string out;
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string text;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      text += cells[c];
      if (c + 1 < cells.size()) text += std::string(width[c] - cells[c].size() + 2, ' ');
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    out += text + '\n';
  };
  for (std::size_t r = 0; r < rows.size(); ++r) {
    line(rows[r]);
    if (r == 0) {
      std::vector<std::string> dashes;
      for (std::size_t c = 0; c < rows[0].size(); ++c) dashes.push_back(std::string(width[c], '-'));
      line(dashes);
    }
  }
  return out;
}

// a number for the tables: up to 6 significant digits
std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string joined(const std::vector<std::string>& names, const std::string& separator) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : separator) + name;
  return text;
}

// ---- scenario sections (scenario/schema.hpp) ----

// "`limits:` ", or nothing for the top level, whose summary says what it is
std::string section_title(const SchemaSection& section) {
  return section.path.empty() ? "" : "`" + section.path + ":` ";
}

std::string section_text(const SchemaSection& section) {
  const bool typed = std::any_of(section.keys.begin(), section.keys.end(),
                                 [](const SchemaKey& k) { return !k.applies_to.empty(); });
  Rows rows;
  std::vector<std::string> header{"key", "unit", "accepted", "default", "meaning"};
  if (typed) header.insert(header.begin() + 1, "applies to");
  rows.push_back(header);
  for (const SchemaKey& k : section.keys) {
    std::vector<std::string> row{k.name, k.unit.empty() ? "-" : k.unit, k.accepted(),
                                 k.default_text, k.meaning};
    if (typed) row.insert(row.begin() + 1, k.applies_to.empty() ? "both" : k.applies_to);
    rows.push_back(row);
  }
  return section_title(section) + section.summary + "\n\n" + table(rows);
}

json key_json(const SchemaKey& k) {
  json out{{"name", k.name},
           {"type", k.type},
           {"unit", k.unit},
           {"accepted", k.accepted()},
           {"default", k.default_text},
           {"meaning", k.meaning}};
  if (std::isfinite(k.range.min)) {
    out["min"] = k.range.min;
    out["min_inclusive"] = k.range.min_inclusive;
  }
  if (std::isfinite(k.range.max)) {
    out["max"] = k.range.max;
    out["max_inclusive"] = k.range.max_inclusive;
  }
  if (!k.choices.empty()) out["choices"] = k.choices;
  if (k.default_value) out["default_value"] = *k.default_value;
  if (!k.applies_to.empty()) out["applies_to"] = k.applies_to;
  return out;
}

json section_json(const SchemaSection& section) {
  json keys = json::array();
  for (const SchemaKey& k : section.keys) keys.push_back(key_json(k));
  return {{"path", section.path}, {"summary", section.summary}, {"keys", keys}};
}

// ---- machines (kinematics/registry.cpp and each machine's own parameters) ----

struct MachineFact {
  std::string name, value, unit, meaning;
};

// how far the TCP reaches from the work origin along a direction at z = 0 with the nozzle
// vertical (roll 0; the arm on its default branch): 1 mm steps, then bisection to 0.01 mm
double reach_mm(const Machine& machine, const Vec3& direction) {
  JointVector joints;
  const auto reachable = [&](double r) { return machine.inverse(Pose(r * direction), joints); };
  if (!reachable(0.0)) return 0.0;
  double good = 0.0, bad = -1.0;
  for (double r = 1.0; r <= 2000.0; r += 1.0) {
    if (!reachable(r)) {
      bad = r;
      break;
    }
    good = r;
  }
  if (bad < 0.0) return good;
  while (bad - good > 0.01) {
    const double mid = 0.5 * (good + bad);
    (reachable(mid) ? good : bad) = mid;
  }
  return good;
}

std::vector<MachineFact> machine_geometry(const Machine& machine) {
  std::vector<MachineFact> facts;
  if (const auto* delta = dynamic_cast<const LinearDelta*>(&machine)) {
    const LinearDeltaGeometry& g = delta->geometry();
    facts = {
        {"column_angles",
         number_text(g.column_angle_deg[0]) + ", " + number_text(g.column_angle_deg[1]) + ", " +
             number_text(g.column_angle_deg[2]),
         "deg", "the three columns, from world +x, counter-clockwise seen from above"},
        {"carriage_radius", number_text(g.carriage_radius_mm), "mm",
         "axis to the carriage rod joints (pair centre)"},
        {"platform_radius", number_text(g.platform_radius_mm), "mm",
         "platform centre to its rod joints (pair centre)"},
        {"rod_length", number_text(g.rod_length_mm), "mm", "joint centre to joint centre, all six"},
        {"rod_spacing", number_text(g.rod_spacing_mm), "mm", "between the two rods of a pair"},
        {"max_rod_angle", number_text(g.max_rod_angle_deg), "deg", "rod angle from vertical"},
        {"carriage_travel",
         number_text(g.carriage_min_mm) + " .. " + number_text(g.carriage_max_mm), "mm",
         "each carriage, from its home height (TCP at the origin)"},
        {"substrate_above_joints", number_text(g.substrate_above_joints_mm), "mm",
         "substrate surface above the platform's rod joints"},
        {"min_tcp_z", number_text(g.min_tcp_z_mm), "mm",
         "the nozzle may not go deeper below the substrate surface"},
        {"limit_margin", number_text(g.limit_margin), "",
         "TCP limits keep the carriages within this fraction of their limits"},
    };
  } else if (const auto* arm = dynamic_cast<const Arm6*>(&machine)) {
    const Arm6Geometry& g = arm->geometry();
    const auto point = [](const Vec3& p) {
      return number_text(p.x()) + ", " + number_text(p.y()) + ", " + number_text(p.z());
    };
    facts = {
        {"c1", number_text(g.c1_mm), "mm", "base to shoulder (joint 2 axis)"},
        {"c2", number_text(g.c2_mm), "mm", "upper arm"},
        {"c3", number_text(g.c3_mm), "mm", "forearm: joint 3 to the wrist centre"},
        {"c4", number_text(g.c4_mm), "mm", "wrist centre to flange"},
        {"a2", number_text(g.a2_mm), "mm", "elbow offset"},
        {"nozzle_tilt", number_text(g.nozzle_tilt_deg), "deg", "nozzle from the flange normal"},
        {"tip_in_flange", point(g.tip_in_flange_mm), "mm", "nozzle tip in the flange frame"},
        {"work_origin", point(g.work_origin_mm), "mm",
         "the work frame (substrate) origin in the robot's base frame"},
        {"limit_margin", number_text(g.limit_margin), "",
         "TCP limits keep the joints within this fraction of their limits"},
    };
  }
  // the reach at z = 0 along the axes, for every machine
  static const std::pair<const char*, Vec3> kDirections[4] = {
      {"+x", Vec3(1, 0, 0)}, {"-x", Vec3(-1, 0, 0)}, {"+y", Vec3(0, 1, 0)}, {"-y", Vec3(0, -1, 0)}};
  std::string reach;
  for (const auto& [label, direction] : kDirections)
    reach += (reach.empty() ? "" : ", ") + std::string(label) + " " +
             number_text(std::round(reach_mm(machine, direction) * 10.0) / 10.0);
  facts.push_back({"tcp_reach_at_z0", reach, "mm",
                   "how far the TCP goes from the work origin on the substrate, nozzle vertical"});
  return facts;
}

// one joint's unit and its values in that unit (deg for hinges)
struct JointText {
  std::string unit;
  double scale = 1.0;
};
JointText joint_unit(const JointLimit& joint) {
  return joint.revolute ? JointText{"deg", rad_to_deg(1.0)} : JointText{"mm", 1.0};
}

std::string machines_text() {
  std::string out =
      "machines (scenario `machine: NAME`, or `machine: {model: FILE.xml, kinematics: NAME}`); "
      "joint limits are the machine's own, `limits: {joint: ...}` replaces them on every joint; "
      "the TCP limits default to v_max " +
      number_text(kDefaultTcpVMax_mm_s) + " mm/s, a_max " + number_text(kDefaultTcpAMax_mm_s2) +
      " mm/s^2 (see `depotwin describe limits`)\n";
  for (const MachineInfo& info : machine_registry()) {
    const std::unique_ptr<Machine> machine = info.make();
    out +=
        "\n" + info.name + ": " + info.description + " (models/" + machine->model_file() + ")\n\n";
    Rows joints{{"joint", "kind", "range", "v_max", "a_max", "j_max"}};
    for (const JointLimit& j : machine->joint_limits()) {
      const JointText unit = joint_unit(j);
      joints.push_back(
          {j.name, j.revolute ? "hinge" : "slide",
           number_text(j.min * unit.scale) + " .. " + number_text(j.max * unit.scale) + " " +
               unit.unit,
           number_text(j.v_max * unit.scale) + " " + unit.unit + "/s",
           number_text(j.a_max * unit.scale) + " " + unit.unit + "/s^2",
           j.j_max > 0.0 ? number_text(j.j_max * unit.scale) + " " + unit.unit + "/s^3" : "none"});
    }
    out += table(joints) + "\n";
    Rows geometry{{"geometry", "value", "unit", "meaning"}};
    for (const MachineFact& fact : machine_geometry(*machine))
      geometry.push_back(
          {fact.name, fact.value, fact.unit.empty() ? "-" : fact.unit, fact.meaning});
    out += table(geometry);
  }
  return out;
}

json machines_json() {
  json machines = json::array();
  for (const MachineInfo& info : machine_registry()) {
    const std::unique_ptr<Machine> machine = info.make();
    json joints = json::array();
    for (const JointLimit& j : machine->joint_limits()) {
      const JointText unit = joint_unit(j);
      joints.push_back({{"name", j.name},
                        {"kind", j.revolute ? "hinge" : "slide"},
                        {"unit", unit.unit},
                        {"min", j.min * unit.scale},
                        {"max", j.max * unit.scale},
                        {"v_max", j.v_max * unit.scale},
                        {"a_max", j.a_max * unit.scale},
                        {"j_max", j.j_max * unit.scale}});
    }
    json geometry = json::array();
    for (const MachineFact& fact : machine_geometry(*machine))
      geometry.push_back({{"name", fact.name},
                          {"value", fact.value},
                          {"unit", fact.unit},
                          {"meaning", fact.meaning}});
    machines.push_back({{"name", info.name},
                        {"description", info.description},
                        {"model", "models/" + machine->model_file()},
                        {"joints", joints},
                        {"geometry", geometry}});
  }
  return {
      {"machines", machines},
      {"tcp_limit_defaults", {{"v_max", kDefaultTcpVMax_mm_s}, {"a_max", kDefaultTcpAMax_mm_s2}}}};
}

// ---- planners (planners/registry.cpp) ----

std::string parameter_range(const PlannerParameter& p) {
  if (!p.choices.empty()) return joined(p.choices, " | ");
  std::string text = "[" + number_text(p.min_value) + ", " + number_text(p.max_value) + "]";
  if (p.whole_number) text += " whole";
  if (p.list_allowed) text += ", or a list";
  return text;
}

std::string parameter_default(const PlannerParameter& p) {
  return p.choices.empty() ? number_text(p.default_value) : p.choices.front();
}

std::string planners_text() {
  std::string out = section_text(schema_section("planners[]"));
  for (const PlannerInfo& info : planner_registry()) {
    out += "\n" + info.name + ": " + info.description + "; " +
           (info.honours_jerk_limit ? "honours limits j_max"
                                    : "acceleration-limited: refuses a j_max in force") +
           "\n";
    if (info.parameters.empty()) {
      out += "  (no parameters)\n";
      continue;
    }
    Rows rows{{"parameter", "unit", "accepted", "default", "meaning"}};
    for (const PlannerParameter& p : info.parameters)
      rows.push_back({p.name, p.unit.empty() ? "-" : p.unit, parameter_range(p),
                      parameter_default(p), p.description});
    out += "\n" + table(rows);
  }
  return out;
}

json planners_json() {
  json planners = json::array();
  for (const PlannerInfo& info : planner_registry()) {
    json parameters = json::array();
    for (const PlannerParameter& p : info.parameters) {
      json entry{{"name", p.name},
                 {"unit", p.unit},
                 {"accepted", parameter_range(p)},
                 {"default", parameter_default(p)},
                 {"meaning", p.description}};
      if (p.choices.empty()) {
        entry["min"] = p.min_value;
        entry["max"] = p.max_value;
        entry["default_value"] = p.default_value;
        entry["list_allowed"] = p.list_allowed;
        entry["whole_number"] = p.whole_number;
      } else {
        entry["choices"] = p.choices;
      }
      parameters.push_back(entry);
    }
    planners.push_back({{"name", info.name},
                        {"description", info.description},
                        {"honours_j_max", info.honours_jerk_limit},
                        {"parameters", parameters}});
  }
  return {{"entry", section_json(schema_section("planners[]"))}, {"planners", planners}};
}

// ---- sequencers (planners/ordering/registry.cpp) ----

std::string sequencers_text() {
  Rows rows{{"sequencer", "meaning"}};
  for (const SequencerInfo& info : sequencer_registry())
    rows.push_back({info.name, info.description});
  return "sequencers (scenario `order:`): the print order and direction of the paths, chosen by "
         "transition time\n\n" +
         table(rows) +
         "\nrefinements (local search, `method+refine`): " + joined(refine_methods(), ", ") +
         "\ncost models: " + joined(cost_models(), ", ") + "\n\n" +
         section_text(schema_section("order"));
}

json sequencers_json() {
  json sequencers = json::array();
  for (const SequencerInfo& info : sequencer_registry())
    sequencers.push_back({{"name", info.name}, {"description", info.description}});
  return {{"sequencers", sequencers},
          {"refinements", refine_methods()},
          {"cost_models", cost_models()},
          {"order", section_json(schema_section("order"))}};
}

// ---- outputs: the files a verb writes and the keys of metrics.json ----

// One thing a verb writes, and when: `written` names the verbs and conditions
struct OutputEntry {
  const char* name;
  const char* written;
  const char* meaning;
};

// the files of DIR/<run>/ (`run`, `plan`) and of DIR (`compare`), as README.md's Outputs
// section lists them
const std::vector<OutputEntry>& output_files() {
  static const std::vector<OutputEntry> files{
      {"metrics.json", "run, plan", "the figures (keys below; README.md, Metrics)"},
      {"trajectory.csv", "run, plan", "the plan every 1 ms; after a run the simulated nozzle too"},
      {"thickness.csv", "run", "the deposit map, µm per cell"},
      {"thickness_field.png", "run", "the same map as 16-bit grey (µm per level in its text)"},
      {"replay.json", "run", "for `view`: each frame's time and machine state"},
      {"replay_model.xml", "run", "for `view`: the MJCF as simulated"},
      {"replay_deposit.bin", "run", "for `view`: the deposit's growth, frame by frame"},
      {"scene.png", "run, rendered", "the machine and the deposit, offscreen"},
      {"path.png", "run, rendered", "planned and simulated path, print order"},
      {"axes.png", "run, rendered", "axis position, speed and acceleration against time"},
      {"errors.png", "run, rendered", "speed and position error against time"},
      {"thickness_profile.png", "run, rendered", "thickness along each print line"},
      {"thickness.png", "run, rendered", "the deposit map under the print paths"},
      {"joints.png", "run, rendered", "each joint against time, its range marked"},
      {"layers.png", "run, rendered, several layers or a part",
       "each layer's map on one colour scale"},
      {"paths3d.png", "run, rendered, several layers or a part", "the print paths in 3-D"},
      {"run.mp4", "run --video", "the run as a film (ffmpeg)"},
      {"comparison.json", "compare (in DIR)", "the summary table and each run's metrics"},
      {"comparison.csv", "compare (in DIR)", "the summary table"},
      {"comparison.md", "compare (in DIR)", "the summary table with links to the images"},
      {"comparison.png", "compare (in DIR), rendered", "the deposit maps side by side"},
  };
  return files;
}

// metrics.json's top-level keys, in the order written
const std::vector<OutputEntry>& metrics_keys() {
  static const std::vector<OutputEntry> keys{
      {"scenario", "run, plan", "the scenario's name"},
      {"machine", "run, plan", "the machine's name"},
      {"planner", "run, plan", "the planner's name"},
      {"run", "run, plan", "the run's label (the planner's name when it has none)"},
      {"sequencer", "run, plan", "the print order's method"},
      {"time_s", "run, plan", "total, print and transition time"},
      {"velocity_error", "run", "simulated speed error over the printed length"},
      {"velocity_error_steady", "run", "the same outside the start and end ramps (null: none)"},
      {"planned_velocity_error", "run, plan", "the plan's speed error over the printed length"},
      {"planned_velocity_error_steady", "run, plan", "the same outside the ramps (null: none)"},
      {"path_error_mm", "run", "simulated distance from the print path"},
      {"planned_path_error_mm", "run, plan", "the plan's distance from the print path"},
      {"speed_ramps", "run, plan", "the ramps the steady errors leave out: count, time"},
      {"thickness", "run", "mean, cv, line_cv, min and max of the deposit on the target"},
      {"waste", "run", "material off the target and caught by the shutter"},
      {"material_mm3", "run", "emitted, on target, overspray, captured"},
      {"actuators", "run", "each joint's peak speed, acceleration and force against limits"},
      {"order", "run, plan", "the print order: cost, lower bound, refinement"},
      {"warnings", "run, plan", "what the run warned of"},
      {"sim", "run", "the simulation's steps, timestep and wall time"},
      {"arm", "run, arm6", "postures: joint margins, branch, roll"},
      {"layers", "run, several layers or a part", "the figures per layer"},
      {"units", "run, plan", "every number's unit, in the same shape"},
  };
  return keys;
}

Rows output_rows(const std::vector<OutputEntry>& entries, const char* first) {
  Rows rows{{first, "written", "meaning"}};
  for (const OutputEntry& e : entries) rows.push_back({e.name, e.written, e.meaning});
  return rows;
}

json output_json(const std::vector<OutputEntry>& entries) {
  json list = json::array();
  for (const OutputEntry& e : entries)
    list.push_back({{"name", e.name}, {"written", e.written}, {"meaning", e.meaning}});
  return list;
}

std::string outputs_text() {
  return section_text(schema_section("outputs")) +
         "\nfiles: DIR/<run>/ for each run (`compare`'s own in DIR); \"rendered\": unless "
         "`render: false` or --no-render\n\n" +
         table(output_rows(output_files(), "file")) +
         "\nmetrics.json's keys (README.md, Metrics, defines each figure)\n\n" +
         table(output_rows(metrics_keys(), "key"));
}

// ---- topics ----

// the scenario sections a topic shows
std::vector<std::string> topic_sections(const std::string& topic) {
  if (topic == "scenario") return {""};
  if (topic == "limits") return {"limits", "limits.x", "limits.joint"};
  if (topic == "processes") return {"process"};
  if (topic == "toolpath")
    return {"toolpath", "toolpath.polylines[]", "toolpath.gcode", "toolpath.random_segments",
            "toolpath.surface"};
  if (topic == "arm" || topic == "sim") return {topic};
  return {};
}

// aliases a user may type
std::string canonical(const std::string& topic) {
  if (topic == "machine") return "machines";
  if (topic == "planner") return "planners";
  if (topic == "process") return "processes";
  if (topic == "sequencer" || topic == "order") return "sequencers";
  return topic;
}

void check_topic(const std::string& topic) {
  for (const auto& [name, what] : describe_topics())
    if (name == topic) return;
  std::vector<std::string> names;
  for (const auto& [name, what] : describe_topics()) names.push_back(name);
  throw InputError("describe",
                   "unknown topic '" + topic + "' (topics: " + joined(names, ", ") + ")");
}

}  // namespace

const std::vector<std::pair<std::string, std::string>>& describe_topics() {
  static const std::vector<std::pair<std::string, std::string>> topics{
      {"scenario", "the scenario file's top-level keys"},
      {"machines", "each machine's joints, travel, geometry and default limits"},
      {"limits", "the TCP's and the joints' speed, acceleration and jerk limits"},
      {"processes", "aerosol and extrusion parameters"},
      {"toolpath", "print paths: segments, polylines, G-code, random segments, STL surfaces"},
      {"arm", "the 6-DOF arm's roll and branch search"},
      {"sequencers", "print orders, refinements and cost models (`order:`)"},
      {"planners", "each planner and its parameters"},
      {"sim", "simulation settings"},
      {"outputs", "what a run writes"},
  };
  return topics;
}

std::string describe_text(const std::string& requested) {
  if (requested.empty()) {
    Rows rows{{"topic", "what"}};
    for (const auto& [name, what] : describe_topics()) rows.push_back({name, what});
    return "depotwin describe TOPIC [--json]: every parameter with its unit, accepted values, "
           "default and meaning\n\n" +
           table(rows);
  }
  const std::string topic = canonical(requested);
  check_topic(topic);
  if (topic == "machines") return machines_text();
  if (topic == "planners") return planners_text();
  if (topic == "sequencers") return sequencers_text();
  if (topic == "outputs") return outputs_text();
  std::string out;
  for (const std::string& path : topic_sections(topic))
    out += (out.empty() ? "" : "\n") + section_text(schema_section(path));
  if (topic == "toolpath") out += std::string("\n") + kJointAngleDefinition + "\n";
  return out;
}

json describe_json(const std::string& requested) {
  if (requested.empty()) {
    json topics = json::array();
    for (const auto& [name, what] : describe_topics())
      topics.push_back({{"topic", name}, {"what", what}});
    return {{"topics", topics}};
  }
  const std::string topic = canonical(requested);
  check_topic(topic);
  json out;
  if (topic == "machines") {
    out = machines_json();
  } else if (topic == "planners") {
    out = planners_json();
  } else if (topic == "sequencers") {
    out = sequencers_json();
  } else if (topic == "outputs") {
    out = {{"sections", json::array({section_json(schema_section("outputs"))})},
           {"files", output_json(output_files())},
           {"metrics_keys", output_json(metrics_keys())}};
  } else {
    json sections = json::array();
    for (const std::string& path : topic_sections(topic))
      sections.push_back(section_json(schema_section(path)));
    out = {{"sections", sections}};
    if (topic == "toolpath") out["joint_angle"] = kJointAngleDefinition;
  }
  out["topic"] = topic;
  return out;
}

int describe_verb(const std::string& topic, bool as_json) {
  if (as_json)
    std::cout << describe_json(topic).dump(2) << '\n';
  else
    std::cout << describe_text(topic);
  return kExitOk;
}

}  // namespace depotwin
