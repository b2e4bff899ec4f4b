// The run pipeline: scenario -> machine + limits -> print order -> plan -> (simulate ->
// deposit ->) score -> write. The CLI verbs are thin wrappers around these functions.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "collision/part_clearance.hpp"
#include "core/triangle_mesh.hpp"
#include "kinematics/machine.hpp"
#include "metrics/metrics_report.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/planner.hpp"
#include "posture/arm_posture.hpp"
#include "scenario/scenario.hpp"
#include "toolpath/surface_projection.hpp"

namespace depotwin {

// A scenario made ready for planning: its machine, the TCP limits the planners get (the
// machine's joint limits mapped over each move's box), and the print order.
struct PreparedJob {
  Scenario scenario;
  std::unique_ptr<Machine> machine;
  std::string model_path;  // the MJCF to simulate
  // the MJCF text compiled in its place when the job adds a part to it (sim/part_model.hpp);
  // empty: the file as it is
  std::string model_text;
  // the part printed on (conformal work), placed in the work frame; null for planar work
  std::shared_ptr<const TriangleMesh> part;
  // ray casting onto it (heights and normals under a point; thread-safe)
  std::shared_ptr<const SurfaceProjector> surface;
  // a 6-DOF arm: the exact distance to the part, and the roll and branch chosen along the
  // toolpath (the toolpath above carries the rolls)
  std::shared_ptr<const PartClearance> clearance;
  std::optional<ArmPosture> posture;
  TcpLimits limits;  // what every planner must respect (refers to *machine)
  OrderResult order;
  Toolpath toolpath;  // in print order; G-code arcs as chords within chord_tolerance_mm
  // a G-code file's arcs (none: both empty): the paths of `toolpath` with their arcs exact,
  // for the planners that consume them (PlannerInfo::consumes_arcs), and as chords within
  // 0.001 mm, the intended path that path errors and thickness are measured against
  Toolpath exact_toolpath;
  Toolpath reference_toolpath;

  // the plans made while the job was checked (check_runs), one per planner spec: plan_job
  // takes a spec's plan from here instead of planning again. Planning is deterministic, so
  // it is the same plan; for `uniform`, whose plan predicts every corner's deposit, it halves
  // a verb's planning time
  struct CheckedPlan {
    PlannerSpec spec;
    std::shared_ptr<const Trajectory> trajectory;
  };
  std::vector<CheckedPlan> checked_plans;

  // what the metrics measure against: the file's arcs (finely chorded) when it has any
  const Toolpath& intended_toolpath() const {
    return reference_toolpath.paths.empty() ? toolpath : reference_toolpath;
  }
  // the plan check_runs made for `spec` (same planner, parameters and choices), or null
  const Trajectory* checked_plan(const PlannerSpec& spec) const;
};

// the sagitta of the chords the metrics measure G-code arcs by (mm)
constexpr double kReferenceChordTolerance_mm = 1e-3;
// What a job is prepared for: the print order's lower bound (every pair of path ends matched,
// LEMON) is computed only when a report shows it and an order is searched for (as_given
// never needs it), and only up to SequencerOptions::lower_bound_max_paths paths.
struct PrepareOptions {
  bool lower_bound = true;
};

// Throws InputError for an unknown machine, joint limits it cannot honour, an unreachable
// toolpath, a planner that ignores a jerk limit, ...
PreparedJob prepare_job(const Scenario& scenario, const PrepareOptions& options = {});

// the planners to run: all of the scenario's, or those named (comma list); InputError
// for a name the scenario does not list
std::vector<PlannerSpec> select_planners(const Scenario& scenario, const std::string& names);

// results/<scenario name> unless --out is given
std::string output_directory(const Scenario& scenario, const std::string& requested);

// the plan and its metrics
struct PlannedRun {
  PlannerSpec spec;
  Trajectory trajectory;
  MotionSamples planned;  // the plan every 1 ms
  MetricsReport report;   // planned metrics only
};
// the plan: the one check_runs made for this spec when there is one, else planned now
PlannedRun plan_job(const PreparedJob& job, const PlannerSpec& spec);
// what the planner said of its plan, and, where the plan deposits farther off the toolpath
// than the line is wide, how far and where (as plan_job reports them; `validate` lists them)
std::vector<std::string> plan_warnings(const PreparedJob& job, const Trajectory& plan);
// the scenario line of a planner's entry (its own list item, else the `planners` key): where
// a problem of its plan is reported
int planner_entry_line(const Scenario& scenario, const PlannerSpec& spec);
// The plan's poses, as the simulation will solve them (check_trajectory_poses at the
// scenario's sim.timestep_s): a pose out of reach or a joint outside its travel is an
// InputError at the planner's entry, key `planners`: "the <run label> plan at t = ...: ..."
void check_plan_poses(const PreparedJob& job, const PlannerSpec& spec,
                      const Trajectory& trajectory);
// problems of a plan found as it is solved (key "trajectory", no file) moved to the planner's
// entry as check_plan_poses words them; the others as they are
void locate_plan_problems(const Scenario& scenario, const PlannerSpec& spec,
                          std::vector<Problem>& problems);
// the planner's trajectory alone (plan_job's first step): InputError for a jerk limit the
// planner ignores, a toolpath it cannot plan, or a plan too long to sample at all
Trajectory plan_trajectory(const PreparedJob& job, const PlannerSpec& spec);

// `depotwin plan`: DIR/<planner>/metrics.json and trajectory.csv per planner; returns the
// reports in planner order
std::vector<MetricsReport> write_plans(const PreparedJob& job,
                                       const std::vector<PlannerSpec>& planners,
                                       const std::string& directory);

// the console's summary of the reports: one line per column of report/summary_table.hpp
// (the columns of comparison.{csv,md,json}), one column per run
std::string summary_table(const std::vector<MetricsReport>& reports);

}  // namespace depotwin
