// The common planner interface and the registry that maps scenario names to planners.
// A planner turns a Toolpath into a timed Trajectory (TCP position and tool axis) within the
// TCP limits; it knows nothing of MuJoCo or of the machine's geometry: the kinematics hand it
// limits per move (TcpLimits), as Klipper's check_move does.
//
// Adding a planner: one file pair in planners/motion/ implementing Planner, one entry in
// planners/registry.cpp (see docs/ARCHITECTURE.md, "Adding a planner").
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"

namespace depotwin {

struct DepositionSettings;  // deposition/process.hpp

// What a planner may know of the job besides the toolpath and the limits: the process that
// deposits (a planner that aims at the deposit predicts it with the project's own model) and
// the shutter's open/close time. Planners that only plan motion ignore it.
struct PlanningContext {
  std::shared_ptr<const DepositionSettings> process;  // null: not known
  double shutter_time_s = 0.02;                       // aerosol shutter open/close time
};

// A planner named in a scenario with its parameters: numbers (or lists of numbers), and
// choices (a word from the parameter's list, e.g. `control: both`).
struct PlannerSpec {
  std::string name;
  std::map<std::string, std::vector<double>> params;
  int line = 0;  // where it was declared, for messages
  std::map<std::string, std::string> choices = {};
  std::string label = {};  // names the run and its results folder when given (a planner run twice)

  // the parameter's first value, or `fallback` when absent
  double get(const std::string& key, double fallback) const;
  // a 0/1 switch: the parameter as a bool, or `fallback` when absent; InputError
  // ("planners.<name>.<key>") for any other number
  bool get_switch(const std::string& key, bool fallback) const;
  // the chosen word, or `fallback` when absent
  std::string get_choice(const std::string& key, const std::string& fallback) const;
  // the run's name: its label, else the planner's name
  const std::string& run_label() const { return label.empty() ? name : label; }
};

// A parameter a planner declares by name with its range (OMPL's declareParam), so a
// scenario can set any planner's settings generically and get range errors for free.
struct PlannerParameter {
  std::string name;
  double default_value = 0.0;
  double min_value = 0.0;
  double max_value = 0.0;
  std::string description;
  bool list_allowed = false;  // may be given as a list (e.g. one weight per corner)
  // a choice parameter: one of these words (the first is the default); numbers are refused
  std::vector<std::string> choices = {};
  std::string unit = {};      // mm, s, deg, ...; "" for a pure number or a word
  bool whole_number = false;  // only whole numbers in the range (e.g. a 0/1 switch)
};

class Planner {
 public:
  virtual ~Planner() = default;
  // Plan the whole job: from the toolpath's start at rest, through every print path in
  // order, to its end at rest, the tool axis following the paths' normals (vertical without).
  // Every move stays within the limits over its own box (TcpLimits::along, for_transition).
  // Throws InputError when the toolpath cannot be planned within the limits.
  virtual Trajectory plan(const Toolpath& toolpath, const TcpLimits& limits) const = 0;
  // the same, knowing the job's process (the pipeline calls this one); by default the process
  // does not matter
  virtual Trajectory plan_in_context(const Toolpath& toolpath, const TcpLimits& limits,
                                     const PlanningContext& /*context*/) const {
    return plan(toolpath, limits);
  }
};

struct PlannerInfo {
  std::string name;
  std::string description;
  std::vector<PlannerParameter> parameters;
  std::function<std::unique_ptr<Planner>(const PlannerSpec&)> make;
  // honours the limits' j_max (jerk-limited transitions and ramps); a planner that does not
  // refuses limits with one (check_planner_limits)
  bool honours_jerk_limit = false;
  // takes a toolpath's exact arcs (PrintPath::arcs: G-code G2/G3); the others get them as
  // chords within the scenario's chord_tolerance_mm
  bool consumes_arcs = false;
};

// every registered planner, in a stable order
const std::vector<PlannerInfo>& planner_registry();
const PlannerInfo* find_planner(const std::string& name);
// "" when the spec names a registered planner with known, in-range parameters; else the problem
std::string check_planner_spec(const PlannerSpec& spec);
// "" when the planner honours every limit that is set, else why not (a j_max sent to a
// planner that ignores it)
std::string check_planner_limits(const PlannerSpec& spec, const MachineLimits& limits);
// throws InputError when check_planner_spec fails
std::unique_ptr<Planner> make_planner(const PlannerSpec& spec);

}  // namespace depotwin
