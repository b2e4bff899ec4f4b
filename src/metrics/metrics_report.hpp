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

// per joint, with the limits they are held to: a prismatic joint in mm/s, mm/s^2 and N, a
// revolute one in deg/s, deg/s^2 and N m
struct ActuatorStats {
  std::vector<std::string> joint_names;
  std::vector<bool> revolute;  // per joint: a hinge (deg, N m) rather than a slide (mm, N)
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

// One layer of a multi-layer (conformal) job: the same metrics as the whole job, over that
// layer's paths, its own deposit (thickness along the surface normal) and its own material.
struct LayerReport {
  int layer = 0;
  int paths = 0;
  double print_length_mm = 0.0;
  double print_s = 0.0;                                     // planned depositing time on this layer
  std::optional<VelocityErrorStats> velocity_error;         // simulated
  std::optional<VelocityErrorStats> velocity_error_steady;  // simulated, outside the ramps
  VelocityErrorStats planned_velocity_error;
  VelocityErrorStats planned_velocity_error_steady;  // outside the plan's start and end ramps
  std::optional<PathErrorStats> path_error;          // simulated
  PathErrorStats planned_path_error;
  std::optional<ThicknessSummary> thickness;
  std::optional<WasteStats> waste;
  std::optional<MaterialStats> material;
};

// Where a 6-DOF arm stood over the job (metrics.json "arm"): the smallest distances to its
// joint limits, to singularity and to the part, and what went wrong.
struct ArmPostureStats {
  double min_joint_margin_deg = 0.0;        // smallest distance of a joint to its range's end
  double min_manipulability = 0.0;          // Yoshikawa's sqrt(det(J J^T)), linear rows in m
  double min_wrist_centre_offset_mm = 0.0;  // wrist centre from the joint-1 axis
  double min_wrist_alignment = 0.0;         // |sin q5|: 0 when joints 4 and 6 line up
  double min_clearance_mm = 0.0;            // links and tool body to the part (FCL)
  std::string nearest_shape;                // which shape came closest
};
// One roll for the whole job, as the arm's chosen rolls are compared with (planned, at the
// toolpath's stations, on the branch best for that roll)
struct FixedRollComparison {
  double roll_deg = 0.0;
  int branch = 0;
  bool feasible = true;  // every station reachable off limits, singularities and the part
  std::string problem;   // why not, when not
  ArmPostureStats stats;
  double mean_cost = 0.0;  // the posture's rung cost per station (infinite when not feasible)
  double joint_travel_deg = 0.0;  // how far the joints turn along the paths (summed)
};

struct ArmStats {
  // the simulated run (every recorded step; clearance every clearance_period_s)
  ArmPostureStats run;
  int collisions = 0;      // contact events: tool or links against the part (clearance <= 0),
                           // the table or each other (MuJoCo contacts)
  int part_contacts = 0;   // of which against the part
  int table_contacts = 0;  // of which against the table (or anything not an arm link)
  int self_contacts = 0;   // of which between the arm's own links
  int branch_changes = 0;  // changes of the IK branch along the run
  int branch = 0;          // the branch the job was printed on
  double clearance_period_s = 0.0;
  // the roll about the nozzle axis: as chosen, against roll 0 and the best fixed roll, at the
  // toolpath's stations (planned); the gain is what the chosen rolls add
  std::string roll_strategy;    // optimized | fixed
  double fixed_roll_deg = 0.0;  // the roll used under `fixed`
  ArmPostureStats chosen_roll;
  double chosen_mean_cost = 0.0;
  double chosen_joint_travel_deg = 0.0;
  FixedRollComparison roll_zero, best_fixed;
};

struct MetricsReport {
  std::string scenario, machine, planner, sequencer = "as_given";
  std::string label;  // the run's name (PlannerSpec::run_label): the planner's, or its label
  TimeStats time;
  // Every figure is either planned (from the trajectory alone: planned_*) or simulated (the
  // contract's keys, present once a simulation ran). The speed error is given over the whole
  // printed length and, as the papers give it, outside each printed stretch's start and end
  // ramps (_steady; speed_ramps() defines them).
  std::optional<VelocityErrorStats> velocity_error;         // simulated
  std::optional<VelocityErrorStats> velocity_error_steady;  // simulated, outside the ramps
  VelocityErrorStats planned_velocity_error;
  VelocityErrorStats planned_velocity_error_steady;
  std::optional<PathErrorStats> path_error;  // simulated
  PathErrorStats planned_path_error;
  // the plan's start and end ramps (not written as such: their count and total time are);
  // the simulated steady error excludes the same stretches of time
  std::vector<TimeSpan> speed_ramps;
  std::optional<ThicknessSummary> thickness;
  std::optional<WasteStats> waste;
  std::optional<MaterialStats> material;
  std::optional<ActuatorStats> actuators;
  std::optional<OrderStats> order;
  std::vector<std::string> warnings;
  // what the planner chose and why (metrics.json "planner"), e.g. uniform's corners
  std::vector<PlanDecision> planner_decisions;
  std::optional<SimStats> sim;
  std::vector<LayerReport> layers;  // multi-layer and conformal jobs
  std::optional<ArmStats> arm;      // the 6-DOF arm
};

}  // namespace depotwin
