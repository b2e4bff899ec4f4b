// A sweep file (`depotwin sweep`): a base scenario and the overrides that make its tasks.
// Read here because only scenario/ sees yaml-cpp; what the tasks are and how they run is
// src/sweep/. Schema: src/scenario/SCHEMA.md, "Sweep files".
//
//   name: corner_study              # names results/<name>; default: the file's stem
//   base: ../thompson_fig11.yaml    # the scenario every task starts from (relative to this file)
//   keep: metrics                   # metrics (default): each task keeps metrics.json;
//                                   # all: everything `run --no-render` writes
//   set:                            # overrides every task gets (not parameters)
//     sim.settle_s: 0.1
//   grid:                           # the cartesian product, the last key varying fastest
//     planner: [lspb_mtt, stop_and_go, bezier]
//     toolpath.speed: [1, 2, 3]
//     limits.a_max: {from: 10, to: 100, count: 3}
//   zip:                            # lists of one length advanced together (after the grid)
//     toolpath.random_segments.seed: {from: 1, to: 200}
//     ...
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scenario/overrides.hpp"

namespace depotwin {

// One value a parameter takes.
struct SweepValue {
  std::string yaml;              // as YAML text: ScenarioOverride::value_yaml
  std::string text;              // as shown in tables: the scalar, or one line of YAML
  std::optional<double> number;  // a plain (unquoted) number
};

// A swept key and its values, in the file's order.
struct SweepParameter {
  std::string key;  // a scenario override key (scenario/overrides.hpp), or `planner`
  int line = 0;     // where it was given
  std::vector<SweepValue> values;
};

struct SweepSpec {
  std::string file;       // the sweep file as given
  std::string directory;  // its directory, absolute
  std::string name;
  std::string base;  // the base scenario: `base:` joined to the sweep file's directory
  int base_line = 0;
  std::string keep = "metrics";         // metrics | all
  std::vector<ScenarioOverride> fixed;  // `set:`, in the file's order
  std::vector<SweepParameter> grid;     // cartesian product, last fastest
  std::vector<SweepParameter> zip;      // advanced together, after the grid's keys
  std::uint64_t task_count = 0;         // product of the grid's sizes times the zip's length
};

// the most tasks a sweep may have
constexpr std::uint64_t kMaxSweepTasks = 10000000;

// Reads and checks a sweep file: its keys, the override keys' syntax, each parameter's values
// (a non-empty list, or {from, to[, step | count]}), the zip's lists of one length, no key
// given twice, the base scenario present. InputError listing every problem
// (file:line: key: message). The overrides themselves are checked when the tasks' scenarios
// load (src/sweep/).
SweepSpec read_sweep_file(const std::string& path);

}  // namespace depotwin
