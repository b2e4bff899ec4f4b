// One validator: every check a verb can make before it simulates, made the same way by
// `depotwin validate` and by run, compare and plan before any work, so validate and run
// cannot disagree. Two stages, each listing every problem it finds in one InputError:
//
// 1. check_scenario: the scenario file (scenario/: types, ranges, names, travel, speeds), its
//    MJCF model loaded and compiled by MuJoCo (no simulation) with every site, body, joint and
//    actuator the machine needs, the settings the deposition and the simulation check again,
//    and the job's size from a lower bound on its duration (print time and the first and last
//    ramps), against sim.max_steps and the memory budget, before anything is planned.
// 2. check_runs: on the prepared job (print order, the arm's posture), every run planned (the
//    plans, which are small, kept in the job for the verb; their samples are not made here),
//    its exact duration giving the physics steps, the 1 ms samples and the memory of all the
//    runs a verb keeps together.
//
// Nothing here allocates in proportion to a job's duration or its deposition grid.
#pragma once

#include <string>
#include <vector>

#include "core/error.hpp"
#include "pipeline/job.hpp"
#include "scenario/scenario.hpp"

namespace depotwin {

// what a verb may use (--max-memory), in bytes; 8 GiB unless raised
constexpr double kDefaultMaxMemoryBytes = 8.0 * 1024 * 1024 * 1024;

struct JobBudget {
  double max_memory_bytes = kDefaultMaxMemoryBytes;
};

// --max-memory's text: a number of bytes with an optional unit K, M, G or T (powers of 1024;
// "KB", "KiB", "k" alike), e.g. 8G, 512M, 1.5GiB, 1073741824. InputError naming the option.
double parse_memory_size(const std::string& text, const std::string& option = "--max-memory");
// bytes for messages: "6.6 GB", "512 MB" (powers of 1024, as --max-memory reads them)
std::string format_bytes(double bytes);

// What one run of a job needs, estimated before anything is allocated.
struct RunEstimate {
  std::string label;          // the run (a planner's label), "" before planning
  double duration_s = 0.0;    // the motion: the plan's, or a lower bound before planning
  double print_s = 0.0;       // of which the print paths at their speeds (lower bound)
  double steps = 0.0;         // physics steps: (duration + settle_s) / timestep_s
  double samples = 0.0;       // the plan sampled every 1 ms (trajectory.csv, planned metrics)
  double cells = 0.0;         // deposition grid cells (every field of the deposit)
  double memory_bytes = 0.0;  // what the run keeps at its peak
  bool simulated = true;      // false: a plan only (`depotwin plan`)
  // the planner's entry line when its own parameters, not the scenario's limits, make the plan
  // long (a plan 10 times the bound before planning, from a planner given parameters, such
  // as firmware's max_velocity): a size problem is named there; 0 otherwise
  int planner_line = 0;
};

// The run of `scenario` before planning: a lower bound on its duration (every path at its
// print speed, the first and last path reached from rest and left to rest under limits.a_max)
RunEstimate estimate_before_planning(const Scenario& scenario, bool simulate);
// The run of a planned job: the plan's exact duration
RunEstimate estimate_planned(const PreparedJob& job, const std::string& label, double duration_s,
                             bool simulate);

// The memory a verb that keeps these runs together would need, as --max-memory counts it: the
// process itself (libraries, MuJoCo, the renderer), the toolpath's copies and every run's data
double job_memory_bytes(const Scenario& scenario, const std::vector<RunEstimate>& runs);

// The runs' problems against sim.max_steps (each run) and the budget (all runs together, as a
// verb keeps them: job_memory_bytes), each at the scenario key that drives it, naming the
// limit to raise
std::vector<Problem> size_problems(const Scenario& scenario, const std::vector<RunEstimate>& runs,
                                   const JobBudget& budget);

// Stage 1 (above): the scenario, or InputError listing every problem. `runs`: how many runs
// the verb keeps together; 0: the scenario's planners (what `run` does without --planner).
Scenario check_scenario(const std::string& path, const JobBudget& budget, std::size_t runs = 0,
                        bool simulate = true);

// Stage 2 (above): each planner's plan on the prepared job, measured; problems (a plan the
// planner refuses, a run too large) appended to `problems`, the estimates returned. With a
// pose_budget (validate, plan, export: the verbs that simulate nothing), each run's plan that
// fits it (sim.max_steps and the memory: size_problems finds nothing, so a plan of 1e8
// samples is refused for its size at once, not solved first) is also solved pose by pose as
// the simulation will solve it (check_plan_poses: a plan leaving the travel or the reach);
// run and compare leave
// that to the simulation itself, which says the same word for word (on an arm the inverse
// kinematics of every step is most of a run's cost, and would be paid twice). Each plan is
// kept in job.checked_plans, where plan_job takes it.
std::vector<RunEstimate> check_runs(PreparedJob& job, const std::vector<PlannerSpec>& planners,
                                    bool simulate, std::vector<Problem>& problems,
                                    const JobBudget* pose_budget = nullptr);

// What a verb does before its work: stage 2 on the job prepared for it (the lower bound of
// the print order computed only when `with_lower_bound`: a report shows it, validate does
// not), every problem thrown together. The estimates of the runs go to `estimates`.
PreparedJob prepare_checked_job(const Scenario& scenario, const std::vector<PlannerSpec>& planners,
                                const JobBudget& budget, bool simulate, bool with_lower_bound,
                                std::vector<RunEstimate>* estimates = nullptr,
                                bool solve_poses = false);

}  // namespace depotwin
