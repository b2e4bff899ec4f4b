// Private to scenario/: the YAML side of scenario overrides (scenario/overrides.hpp) and of
// sweep files (scenario/sweep_file.hpp): parsing a scenario's text into its tree, editing the
// tree, and placing the loader's problems at the override that caused them.
#pragma once

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "scenario/overrides.hpp"
#include "scenario/yaml_reader.hpp"

namespace depotwin::scenario_detail {

// A scenario file's text as one YAML document holding something (the loader's rules: bytes
// that are not UTF-8 text, malformed YAML, an empty file or several documents are problems);
// nothing when it is not. `kind` names the file in the messages ("scenario", "sweep").
// `aliased_positions` (optional, out): YamlDocuments' (the nodes aliases repeat).
std::optional<YAML::Node> parse_scenario_text(const std::string& text, ProblemList& problems,
                                              const std::string& kind = "scenario",
                                              std::vector<int>* aliased_positions = nullptr);

// One step of an override key: a map key, or a list index (name empty).
struct KeyStep {
  std::string name;
  long long index = -1;
};
// the steps of a dotted key (`planners[0].delta` -> planners, [0], delta); nothing and `why`
// set when it is malformed
std::optional<std::vector<KeyStep>> parse_override_key(const std::string& key, std::string& why);

// Applies the overrides to `root` in order, `planner` last; a problem (at the override's file
// and line) for each override the tree cannot take, and for each that would edit a node an
// alias repeats (`aliased_positions`, from parse_scenario_text): the edit would change every
// place the alias names, silently.
void apply_overrides(YAML::Node root, const std::vector<ScenarioOverride>& overrides,
                     std::vector<Problem>& problems,
                     const std::vector<int>& aliased_positions = {});

// The loader's problems under an overridden key (the key itself, or one inside its value;
// for `planner`, anything under `planners`) moved to that override's file and line.
void attribute_to_overrides(std::vector<Problem>& problems,
                            const std::vector<ScenarioOverride>& overrides);

// a value as one line of YAML (flow style): `3`, `bezier`, `{name: bezier, delta: 0.3}`
std::string flow_text(const YAML::Node& node);

}  // namespace depotwin::scenario_detail
