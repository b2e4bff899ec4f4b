// Scenario overrides: changes to a scenario file's YAML tree made before it is loaded, so each
// overridden scenario is validated exactly like a file (a sweep's parameters, `depotwin
// sweep`). No yaml-cpp here: values travel as YAML text.
//
// A key is a dotted path into the scenario's tree: `toolpath.speed`, `limits.a_max`,
// `limits.x.v_max`, `order`, `order.refine`, `planners[0].delta`,
// `toolpath.random_segments.seed`. Missing map keys are created (the loader then says whether
// they are allowed); a list index must exist in the base scenario. Descending into a scalar
// turns it into its map form where the schema has one: a planner name into {name: X}, an order
// name into {method: X}, a G-code file into {file: X}.
//
// `planner` is not a scenario key: it keeps one planner of the scenario, chosen by its run
// label or name (its parameters kept), or names one the scenario does not list (a name, or
// {name: X, parameter: value}); it is applied after every other override, so `planners[i]`
// indices refer to the base scenario's list.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "scenario/scenario.hpp"

namespace depotwin {

struct ScenarioOverride {
  std::string key;  // dotted key, or `planner`
  std::string
      value_yaml;    // the value as YAML text, e.g. "3", "bezier", "{name: bezier, delta: 0.3}"
  std::string file;  // where it was given, for messages (e.g. the sweep file)
  int line = 0;      // 1-based; 0: unknown
};

// "" when `key` is a well-formed override key (names and [index]es joined by dots, or
// `planner`), else what is wrong with it
std::string override_key_problem(const std::string& key);

// The scenario text with the overrides applied, and the files it reads.
struct ResolvedScenario {
  // the overridden tree written back as YAML (comments and layout dropped): the same
  // scenario and overrides always give the same text
  std::string text;
  // files the scenario reads besides itself (G-code, STL, MJCF model), resolved against the
  // scenario file's directory, in the order the tree names them
  std::vector<std::string> input_files;
  // the shipped machine named by `machine: NAME`, or the default when none is named ("" for an
  // MJCF of one's own): it reads that machine's model from the models folder, which the
  // loader's caller knows
  std::string shipped_machine;
  // the run label (label:, else name) of each `planners` entry; nothing when the tree has no
  // `planners` (the loader's default planners run)
  std::optional<std::vector<std::string>> planners;
};

// Applies the overrides to the tree of `text` (the scenario file at `path`, which names it in
// messages and resolves relative paths). InputError for malformed YAML, and for an override
// the tree cannot take (an index past a list's end, a key under a number, a `planner` the
// scenario lists twice), at the override's file and line. Does not validate the scenario.
ResolvedScenario resolve_scenario(const std::string& path, const std::string& text,
                                  const std::vector<ScenarioOverride>& overrides);

// load_scenario on the overridden tree: every problem the loader finds, those under an
// overridden key (the key itself, or a key inside its value) placed at the override's file and
// line, the others at the scenario file's lines.
Scenario load_scenario(const std::string& path, const std::string& text,
                       const std::vector<ScenarioOverride>& overrides);

}  // namespace depotwin
