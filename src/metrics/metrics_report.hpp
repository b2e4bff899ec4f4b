// Everything metrics.json holds (docs/ARCHITECTURE.md, "metrics.json"): plain data, filled
// by the pipeline, written by report/. Sections a run did not compute stay empty and are
// left out of the file (a `plan` has no simulation, no deposition).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "metrics/motion_metrics.hpp"

namespace depotwin {

struct TimeStats {
  double total_s = 0.0, print_s = 0.0, transition_s = 0.0;
};

struct ThicknessSummary {
  double mean_um = 0.0, cv = 0.0, line_cv = 0.0, min_rel = 0.0, max_rel = 0.0;
};

// waste.* are fractions of the emitted material; material_mm3.* are volumes
struct WasteStats {
  double fraction = 0.0, shutter_captured = 0.0, overspray = 0.0, closed_time_s = 0.0;
};
struct MaterialStats {
  double emitted = 0.0, on_target = 0.0, overspray = 0.0, captured = 0.0;
};

// per joint, in the joint's user units (mm/s, mm/s^2, N), with the limits they are held to
struct ActuatorStats {
  std::vector<std::string> joint_names;
  std::vector<double> peak_vel, peak_acc, peak_force;
  std::vector<double> limit_vel, limit_acc, limit_force;
  // the plan's own peak joint acceleration (what the servo is asked for), and the simulated
  // peak against it: the servo's overshoot (0 where the plan asks none)
  std::vector<double> plan_peak_acc, peak_acc_over_plan;
  int limit_violations = 0;  // joints x quantities whose peak exceeds the limit
};

struct OrderStats {
  std::string method = "as_given", refine, cost_model = "machine";
  double cost_s = 0.0;
  std::optional<double> lower_bound_s;
};

struct SimStats {
  long steps = 0;
  double timestep_s = 0.0, wall_s = 0.0, realtime_factor = 0.0;
  double max_constraint_violation_mm = 0.0;
};

struct MetricsReport {
  std::string scenario, machine, planner, sequencer = "as_given";
  std::string label;  // the run's name (PlannerSpec::run_label): the planner's, or its label
  TimeStats time;
  std::optional<VelocityErrorStats> velocity_error;  // simulated
  VelocityErrorStats planned_velocity_error;
  PathErrorStats path_error;                         // simulated when simulated, else planned
  std::optional<PathErrorStats> planned_path_error;  // also given when simulated
  std::optional<ThicknessSummary> thickness;
  std::optional<WasteStats> waste;
  std::optional<MaterialStats> material;
  std::optional<ActuatorStats> actuators;
  std::optional<OrderStats> order;
  std::vector<std::string> warnings;
  std::optional<SimStats> sim;
};

}  // namespace depotwin
