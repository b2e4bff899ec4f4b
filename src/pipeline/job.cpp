#include "pipeline/job.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "kinematics/arm6.hpp"
#include "metrics/motion_metrics.hpp"
#include "pipeline/models_dir.hpp"
#include "pipeline/run.hpp"
#include "pipeline/step_heartbeat.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "report/summary_table.hpp"
#include "report/trajectory_csv.hpp"
#include "sim/joint_reference.hpp"
#include "sim/part_model.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

constexpr double kSamplePeriod_s = 0.001;  // trajectory.csv and planned metrics
// at most this many unreachable points are listed (the rest counted)
constexpr size_t kMaxNamedPoints = 20;
// the most 1 ms samples a plan may have at all (pipeline/job_check.hpp refuses far smaller
// jobs against sim.max_steps and --max-memory before they are planned for a verb; this guards
// the sample count's integer conversion for every caller)
constexpr double kMaxPlanSamples = 1e12;

// The machine named in the scenario, from the registry (the loader checked the name), and the
// MJCF it is simulated in: the scenario's own model file, else the machine's shipped one.
std::unique_ptr<Machine> machine_for(const Scenario& scenario, std::string& model_path) {
  std::unique_ptr<Machine> machine = make_machine(scenario.machine);
  if (!machine) {
    std::string known;
    for (const std::string& name : machine_names()) known += (known.empty() ? "" : ", ") + name;
    throw InputError(scenario.file, scenario.machine_line, "machine",
                     "unknown machine '" + scenario.machine + "' (known: " + known + ")");
  }
  model_path = scenario.model_path.empty()
                   ? (fs::path(models_directory()) / machine->model_file()).string()
                   : scenario.model_path;
  return machine;
}

// A point as the posture's messages name it, and where its problems belong
struct NamedPoint {
  std::string name;  // what the posture's message starts with
  Problem location;  // file, line and key of the point; message: its name for the user
};

// Problems of the arm's posture (no file, key "toolpath") placed at the point they name (its
// file, line and dotted key), else at the scenario's toolpath
std::vector<Problem> at_toolpath(const Scenario& scenario, const std::vector<NamedPoint>& named,
                                 std::vector<Problem> problems) {
  for (Problem& p : problems) {
    if (!p.file.empty()) continue;
    // the point a message is about: named at its start, or after the branch's number in the
    // summary of a job no branch prints ("no posture ... (branch 4: the start ... is ...)")
    const auto about = [&](const std::string& name) {
      if (p.message.rfind(name, 0) == 0) return true;
      const size_t branch = p.message.find("(branch ");
      const size_t colon = branch == std::string::npos ? branch : p.message.find(": ", branch);
      return colon != std::string::npos && p.message.compare(colon + 2, name.size(), name) == 0;
    };
    const auto point = std::find_if(named.begin(), named.end(),
                                    [&](const NamedPoint& n) { return about(n.name); });
    if (point != named.end()) {
      p.file = point->location.file;
      p.line = point->location.line;
      p.key = point->location.key;
      // named at the start, the user's name for it leads; in the summary the message stays
      if (p.message.rfind(point->name, 0) == 0)
        p.message = point->location.message + p.message.substr(point->name.size());
      continue;
    }
    p.file = scenario.file;
    p.line = scenario.surface ? scenario.surface->line : scenario.toolpath_line;
    p.key = scenario.surface ? "toolpath.surface" : "toolpath";
    // the start and the end at their own keys and lines (where given)
    for (const auto& [name, key, line] :
         {std::tuple<const char*, const char*, int>{"the start ", "toolpath.start",
                                                    scenario.start_line},
          std::tuple<const char*, const char*, int>{"the end ", "toolpath.end", scenario.end_line}})
      if (about(name)) {
        p.key = key;
        if (line > 0) p.line = line;
      }
  }
  return problems;
}

// A 6-DOF arm: the roll about the nozzle axis at every point and the branch of the job (the
// ladder graph of posture/), checked against the part
void choose_posture(const Scenario& scenario, Arm6& arm, PreparedJob& job) {
  if (job.part) job.clearance = std::make_shared<const PartClearance>(*job.part);
  // a point named by its layer, line and index for a surface toolpath, else by its path's key
  // and index as given in the file (a sequencer may have reversed the path)
  std::vector<NamedPoint> named;
  const auto name = [&](size_t path, size_t point) {
    const PrintPath& printed = job.toolpath.paths[path];
    const int source = printed.source_index;
    const PrintPath* given = nullptr;
    for (const PrintPath& candidate : scenario.toolpath.paths)
      if (candidate.source_index == source) given = &candidate;
    const bool reversed = given && (given->front() - printed.front()).norm() > kJoinTolerance_mm;
    const size_t given_point = reversed ? printed.points.size() - 1 - point : point;
    NamedPoint entry;
    entry.location = path_point_problem(scenario, source, given_point, "");
    // the message without the trailing separator is the name the user reads
    entry.name = entry.location.key + " " + entry.location.message;
    while (!entry.name.empty() && (entry.name.back() == ' ' || entry.name.back() == ':'))
      entry.name.pop_back();
    std::string& shown = entry.location.message;
    while (!shown.empty() && (shown.back() == ' ' || shown.back() == ':')) shown.pop_back();
    named.push_back(entry);
    return entry.name;
  };
  try {
    job.posture = choose_arm_posture(arm, job.clearance.get(), job.toolpath,
                                     scenario.arm.value_or(ArmPostureSettings{}), name);
  } catch (const InputError& e) {
    throw InputError(at_toolpath(scenario, named, e.problems()));
  }
  arm.set_branch(job.posture->branch);
  job.toolpath = job.posture->toolpath;
}

// A warning where the plan deposits farther from its toolpath than the line is wide (material
// beside the line, not on it: e.g. lspb_mtt's blends under a tiny j_max), naming where; ""
// where it does not
std::string off_path_warning(const PreparedJob& job, const MotionSamples& planned,
                             double path_error_max_mm) {
  const double line_width_mm = deposition_settings(job.scenario).resolved_line_width_mm();
  if (!(path_error_max_mm > line_width_mm)) return "";
  const Toolpath& toolpath = job.intended_toolpath();
  const std::vector<double> distances = path_distances(planned, toolpath);
  size_t farthest = 0;
  for (size_t k = 0; k < distances.size(); ++k)
    if (distances[k] > distances[farthest] || std::isnan(distances[farthest])) farthest = k;
  const int path = planned.path_index[farthest];
  const int shown_path = path >= 0 && static_cast<size_t>(path) < toolpath.paths.size()
                             ? toolpath.paths[static_cast<size_t>(path)].source_index
                             : path;
  char text[320];
  std::snprintf(text, sizeof text,
                "the plan deposits up to %.4g mm off the toolpath (path %d, at %.3f s), more than "
                "the line is wide (%.4g mm): that material lands beside the line",
                path_error_max_mm, shown_path, planned.t_s[farthest], line_width_mm);
  return text;
}

// plan_warnings on the plan sampled (`planned`, its largest distance off the toolpath given)
std::vector<std::string> plan_warnings(const PreparedJob& job, const Trajectory& plan,
                                       const MotionSamples& planned, double path_error_max_mm) {
  std::vector<std::string> warnings = plan.warnings();
  const std::string off_path = off_path_warning(job, planned, path_error_max_mm);
  if (!off_path.empty()) warnings.push_back(off_path);
  return warnings;
}

}  // namespace

PreparedJob prepare_job(const Scenario& scenario, const PrepareOptions& options) {
  PreparedJob job;
  job.scenario = scenario;
  job.machine = machine_for(scenario, job.model_path);
  // every problem of the machine with the scenario in one list (load_scenario has found
  // these already for a scenario it loaded; a scenario changed in code is checked again)
  std::vector<Problem> problems;
  if (scenario.has_joint_limits) {
    const std::string problem = job.machine->set_joint_limits(scenario.joint_limits);
    if (!problem.empty())
      problems.push_back(
          Problem{scenario.file, scenario.joint_limits_line, "limits.joint", problem});
  }

  // the part, in the machine's model too (shown in the scene, carried by the substrate)
  Arm6* arm = dynamic_cast<Arm6*>(job.machine.get());
  if (scenario.part) {
    job.part = scenario.part;
    job.surface = scenario.part_projector;
    if (!job.surface) throw InternalError("prepare_job: the scenario's part has no projector");
    job.model_text = mjcf_with_part(read_text_file(job.model_path), job.model_path, *job.part);
  }

  // every pose of the toolpath must be reachable by the machine (an arm: for some roll, on
  // its posture's branch, below)
  if (!arm) {
    std::vector<Problem> unreachable = unreachable_points(scenario, *job.machine, kMaxNamedPoints);
    problems.insert(problems.end(), unreachable.begin(), unreachable.end());
  }
  if (!problems.empty()) throw InputError(problems);

  // the TCP limits: the user's, refined per move by the machine (Klipper's check_move)
  job.limits = job.machine->tcp_limits(scenario.limits);

  // print order (Ganganath et al.), before every planner
  // (the lower bound, every pair of path ends, only where an order is searched for: the given
  // order's job never needs it, and a hatched part has hundreds of paths)
  SequencerOptions sequencing;
  sequencing.lower_bound = options.lower_bound && scenario.order.method != "as_given";
  {
    const WorkingStep step("ordering " + std::to_string(scenario.toolpath.paths.size()) +
                           " print paths (" + scenario.order.label() + ")");
    job.order = sequence(scenario.toolpath, job.limits, scenario.order, sequencing);
  }
  job.toolpath = apply_order(scenario.toolpath, job.order);
  // G-code arcs: exact for the planners that consume them, and finely chorded as the path the
  // metrics measure against (the file's own geometry, not the planners' chords)
  if (!scenario.exact_toolpath.paths.empty() && !arm) {
    job.exact_toolpath = apply_order(scenario.exact_toolpath, job.order);
    const double chord_tolerance_mm =
        scenario.gcode ? scenario.gcode->chord_tolerance_mm : kReferenceChordTolerance_mm;
    job.reference_toolpath =
        job.exact_toolpath.chorded(std::min(kReferenceChordTolerance_mm, chord_tolerance_mm));
  }

  // an arm: its roll at every point and its branch, away from limits, singularities and the part
  if (arm) {
    const WorkingStep step("choosing the arm's posture along " +
                           std::to_string(job.toolpath.paths.size()) + " print paths");
    choose_posture(scenario, *arm, job);
  }
  return job;
}

std::vector<PlannerSpec> select_planners(const Scenario& scenario, const std::string& names) {
  if (names.empty()) return scenario.planners;
  std::vector<PlannerSpec> selected;
  std::stringstream list(names);
  std::string name;
  // an empty name (`a,`, `a,,b`: a comma with no name beside it) is refused, as `move`
  // refuses its lists' (it was skipped); spaces around a name are not part of it
  const auto empty_name = [&] {
    return InputError("--planner",
                      "'" + names + "' has an empty name (a comma with no name beside it)");
  };
  if (names.find_last_not_of(" \t") != std::string::npos &&
      names[names.find_last_not_of(" \t")] == ',')
    throw empty_name();
  while (std::getline(list, name, ',')) {
    const size_t first = name.find_first_not_of(" \t");
    if (first == std::string::npos) throw empty_name();
    name = name.substr(first, name.find_last_not_of(" \t") - first + 1);
    bool found = false;
    // a run's label, else every run of the planner of that name
    for (const PlannerSpec& spec : scenario.planners) {
      if (spec.label != name) continue;
      selected.push_back(spec);
      found = true;
    }
    if (found) continue;
    for (const PlannerSpec& spec : scenario.planners) {
      if (spec.name != name) continue;
      selected.push_back(spec);
      found = true;
    }
    if (found) continue;
    // a registered planner the scenario does not list runs with its defaults
    PlannerSpec spec{name, {}, 0};
    const std::string problem = check_planner_spec(spec);
    if (!problem.empty()) throw InputError("--planner", problem);
    selected.push_back(spec);
  }
  if (selected.empty()) throw InputError("--planner", "no planner named");
  return selected;
}

std::string output_directory(const Scenario& scenario, const std::string& requested) {
  return requested.empty() ? (fs::path("results") / scenario.name).string() : requested;
}

int planner_entry_line(const Scenario& scenario, const PlannerSpec& spec) {
  return spec.line > 0 ? spec.line : scenario.line_of("planners");
}

void locate_plan_problems(const Scenario& scenario, const PlannerSpec& spec,
                          std::vector<Problem>& problems) {
  for (Problem& problem : problems) {
    if (!problem.file.empty() || problem.key != "trajectory") continue;
    problem.file = scenario.file;
    problem.line = planner_entry_line(scenario, spec);
    problem.key = "planners";
    problem.message = "the " + spec.run_label() + " plan " + problem.message;
  }
}

// A planner refusing one of its settings names it "planners.<name>.<key>" (PlannerSpec): the
// scenario's own key for it is "planners[<index>].<key>", on the planner's entry line
void locate_planner_setting_problems(const Scenario& scenario, const PlannerSpec& spec,
                                     std::vector<Problem>& problems) {
  const std::string prefix = "planners." + spec.name + ".";
  for (Problem& problem : problems) {
    if (!problem.file.empty() || problem.key.compare(0, prefix.size(), prefix) != 0) continue;
    for (std::size_t i = 0; i < scenario.planners.size(); ++i)
      if (spec.line > 0 && scenario.planners[i].line == spec.line)
        problem.key = "planners[" + std::to_string(i) + "]." + problem.key.substr(prefix.size());
    problem.file = scenario.file;
    problem.line = planner_entry_line(scenario, spec);
  }
}

void check_plan_poses(const PreparedJob& job, const PlannerSpec& spec,
                      const Trajectory& trajectory) {
  try {
    check_trajectory_poses(*job.machine, trajectory, job.scenario.sim.timestep_s);
  } catch (const InputError& e) {
    std::vector<Problem> problems = e.problems();
    locate_plan_problems(job.scenario, spec, problems);
    throw InputError(job.scenario.located(std::move(problems)));
  }
}

Trajectory plan_trajectory(const PreparedJob& job, const PlannerSpec& spec) {
  // a jerk limit in force (the user's, or the joints' mapped) must be honoured
  Vec3 lo, hi;
  job.toolpath.bounds(lo, hi);
  const std::string ignored = check_planner_limits(spec, job.limits.over(lo, hi));
  const int line = planner_entry_line(job.scenario, spec);
  if (!ignored.empty()) throw InputError(job.scenario.file, line, "planners", ignored);
  // exact arcs to a planner that consumes them; chords within the tolerance to the others
  const PlannerInfo* info = find_planner(spec.name);
  const bool exact = info && info->consumes_arcs && !job.exact_toolpath.paths.empty();
  // the process the job deposits with, for a planner that predicts the deposit (uniform)
  PlanningContext context;
  context.process = std::make_shared<const DepositionSettings>(deposition_settings(job.scenario));
  if (job.scenario.process.shutter_time_s > 0.0)
    context.shutter_time_s = job.scenario.process.shutter_time_s;
  Trajectory trajectory;
  try {
    trajectory = make_planner(spec)->plan_in_context(exact ? job.exact_toolpath : job.toolpath,
                                                     job.limits, context);
  } catch (const InputError& e) {
    std::vector<Problem> problems = e.problems();
    locate_planner_setting_problems(job.scenario, spec, problems);
    throw InputError(std::move(problems));
  }
  // a plan far beyond any real print (e.g. a j_max of 1e-300 mm/s^3) cannot be sampled
  if (!(trajectory.duration_s() / kSamplePeriod_s <= kMaxPlanSamples)) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "the %s plan lasts %.4g s: far too long to sample every ms; check the print "
                  "speeds and the limits (v_max, a_max, j_max)",
                  spec.name.c_str(), trajectory.duration_s());
    throw InputError(job.scenario.file, line, "planners", text);
  }
  return trajectory;
}

const Trajectory* PreparedJob::checked_plan(const PlannerSpec& spec) const {
  // the spec's line and label name the run; its name, parameters and choices make the plan
  for (const CheckedPlan& checked : checked_plans)
    if (checked.spec.name == spec.name && checked.spec.params == spec.params &&
        checked.spec.choices == spec.choices)
      return checked.trajectory.get();
  return nullptr;
}

PlannedRun plan_job(const PreparedJob& job, const PlannerSpec& spec) {
  PlannedRun run;
  run.spec = spec;
  const Trajectory* checked = job.checked_plan(spec);
  run.trajectory = checked ? *checked : plan_trajectory(job, spec);
  run.planned = sample_trajectory(run.trajectory, kSamplePeriod_s);

  MetricsReport& r = run.report;
  r.scenario = job.scenario.name;
  r.machine = job.machine->name();
  r.planner = spec.name;
  r.label = spec.run_label();
  r.sequencer = job.scenario.order.label();
  r.time.total_s = run.trajectory.duration_s();
  r.time.print_s = run.trajectory.depositing_time_s();
  r.time.transition_s = run.trajectory.transition_time_s();
  // planned figures only (simulate_job adds the simulated ones); the steady speed error
  // leaves out each printed stretch's start and end ramps
  r.speed_ramps = speed_ramps(run.planned);
  r.planned_velocity_error = velocity_error(run.planned);
  r.planned_velocity_error_steady = velocity_error(run.planned, r.speed_ramps);
  r.planned_path_error = path_error(run.planned, job.intended_toolpath());
  OrderStats order;
  order.method = job.scenario.order.method;
  order.refine = job.scenario.order.refine;
  order.cost_model = job.scenario.order.cost_model;
  order.cost_s = job.order.cost_s;
  if (job.order.lower_bound_s > 0.0) order.lower_bound_s = job.order.lower_bound_s;
  r.order = order;
  // the scenario's own (e.g. the rule a G-code file was read by, moves slowed to the
  // machine's limits), then the planner's
  r.warnings = job.scenario.notes;
  for (const std::string& warning :
       plan_warnings(job, run.trajectory, run.planned, r.planned_path_error.max_mm))
    r.warnings.push_back(warning);
  r.planner_decisions = run.trajectory.decisions();
  return run;
}

std::vector<std::string> plan_warnings(const PreparedJob& job, const Trajectory& plan) {
  const MotionSamples planned = sample_trajectory(plan, kSamplePeriod_s);
  return plan_warnings(job, plan, planned, path_error(planned, job.intended_toolpath()).max_mm);
}

std::vector<MetricsReport> write_plans(const PreparedJob& job,
                                       const std::vector<PlannerSpec>& planners,
                                       const std::string& directory) {
  std::vector<MetricsReport> reports;
  for (const PlannerSpec& spec : planners) {
    const WorkingStep step("writing the " + spec.run_label() + " plan");
    const PlannedRun run = plan_job(job, spec);
    StagedDirectory out((fs::path(directory) / spec.run_label()).string());
    write_file_atomically(out.file("metrics.json"), metrics_json_text(run.report));
    write_file_atomically(out.file("trajectory.csv"), planned_trajectory_csv(run.planned));
    out.commit();
    reports.push_back(run.report);
  }
  return reports;
}

std::string summary_table(const std::vector<MetricsReport>& reports) {
  // the same columns and names as comparison.{csv,md,json} (report/summary_table.hpp)
  return summary_console(reports);
}

}  // namespace depotwin
