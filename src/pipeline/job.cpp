#include "pipeline/job.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "kinematics/arm6.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "report/trajectory_csv.hpp"
#include "sim/part_model.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

constexpr double kSamplePeriod_s = 0.001;  // trajectory.csv and planned metrics
// at most this many unreachable points are listed (the rest counted)
constexpr size_t kMaxNamedPoints = 20;
// the longest job planned, sampled and simulated (at 1 ms, about 14 M samples)
constexpr double kMaxJobDuration_s = 4.0 * 3600.0;

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
                   ? (fs::path(DEPOTWIN_MODELS_DIR) / machine->model_file()).string()
                   : scenario.model_path;
  return machine;
}

// "" when every toolpath pose is reachable; else one problem per unreachable pose
std::vector<Problem> unreachable_poses(const Scenario& scenario, const Machine& machine) {
  std::vector<Problem> problems;
  size_t unnamed = 0;  // beyond kMaxNamedPoints: counted, not listed
  JointVector joints;
  const int surface_line = scenario.surface ? scenario.surface->line : 0;
  auto check_reachable = [&](const Pose& pose, const std::string& key, int line,
                             const std::string& where) {
    std::string why;
    if (machine.inverse(pose, joints, &why)) return;
    if (problems.size() >= kMaxNamedPoints) {
      ++unnamed;
      return;
    }
    const Vec3& p = pose.position_mm;
    std::ostringstream msg;
    msg << where << "point (" << p.x() << ", " << p.y() << ", " << p.z()
        << ") mm is not reachable by " << machine.name() << ": " << why;
    problems.push_back(Problem{scenario.file, line, key, msg.str()});
  };
  const Toolpath& toolpath = scenario.toolpath;
  check_reachable(Pose(toolpath.start_mm), "toolpath.start", 0, "");
  check_reachable(Pose(toolpath.end_mm), "toolpath.end", 0, "");
  for (const PrintPath& path : toolpath.paths)
    for (size_t i = 0; i < path.points.size(); ++i) {
      // a surface's points by their layer, line and index (only the ones listed are named)
      const bool named = scenario.surface && problems.size() < kMaxNamedPoints;
      check_reachable(Pose(path.points[i], path.tool_axis(i)),
                      scenario.surface ? "toolpath.surface"
                                       : "toolpath path " + std::to_string(path.source_index),
                      surface_line,
                      named ? scenario.surface->describe_point(path.source_index, i,
                                                               path.points.size(), false) +
                                  ": "
                            : "");
    }
  if (unnamed > 0)
    problems.push_back(
        Problem{scenario.file, surface_line, scenario.surface ? "toolpath.surface" : "toolpath",
                "... and " + std::to_string(unnamed) + " more unreachable points (the first " +
                    std::to_string(kMaxNamedPoints) + " are listed)"});
  return problems;
}

// Problems of the arm's posture (no file, key "toolpath") placed at the scenario's toolpath
std::vector<Problem> at_toolpath(const Scenario& scenario, std::vector<Problem> problems) {
  for (Problem& p : problems) {
    if (!p.file.empty()) continue;
    p.file = scenario.file;
    p.line = scenario.surface ? scenario.surface->line : 0;
    p.key = scenario.surface ? "toolpath.surface" : "toolpath";
  }
  return problems;
}

// A 6-DOF arm: the roll about the nozzle axis at every point and the branch of the job (the
// ladder graph of posture/), checked against the part
void choose_posture(const Scenario& scenario, Arm6& arm, PreparedJob& job) {
  if (job.part) job.clearance = std::make_shared<const PartClearance>(*job.part);
  // a point named by its layer, line and index for a surface toolpath
  const auto name = [&](size_t path, size_t point) {
    const PrintPath& printed = job.toolpath.paths[path];
    const int source = printed.source_index;
    if (!scenario.surface || source < 0 ||
        static_cast<size_t>(source) >= scenario.toolpath.paths.size())
      return "toolpath path " + std::to_string(source) + ", point " + std::to_string(point);
    const PrintPath& given = scenario.toolpath.paths[static_cast<size_t>(source)];
    const bool reversed = (given.front() - printed.front()).norm() > kJoinTolerance_mm;
    return scenario.surface->describe_point(printed.source_index, point, printed.points.size(),
                                            reversed);
  };
  try {
    job.posture = choose_arm_posture(arm, job.clearance.get(), job.toolpath,
                                     scenario.arm.value_or(ArmPostureSettings{}), name);
  } catch (const InputError& e) {
    throw InputError(at_toolpath(scenario, e.problems()));
  }
  arm.set_branch(job.posture->branch);
  job.toolpath = job.posture->toolpath;
}

}  // namespace

PreparedJob prepare_job(const Scenario& scenario) {
  PreparedJob job;
  job.scenario = scenario;
  job.machine = machine_for(scenario, job.model_path);
  if (scenario.has_joint_limits) {
    const std::string problem = job.machine->set_joint_limits(scenario.joint_limits);
    if (!problem.empty())
      throw InputError(scenario.file, scenario.joint_limits_line, "limits.joint", problem);
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
    const std::vector<Problem> problems = unreachable_poses(scenario, *job.machine);
    if (!problems.empty()) throw InputError(problems);
  }

  // the TCP limits: the user's, refined per move by the machine (Klipper's check_move)
  job.limits = job.machine->tcp_limits(scenario.limits);

  // print order (Ganganath et al.), before every planner
  // (the lower bound, every pair of path ends, only where an order is searched for: the given
  // order's job never needs it, and a hatched part has hundreds of paths)
  SequencerOptions sequencing;
  sequencing.lower_bound = scenario.order.method != "as_given";
  job.order = sequence(scenario.toolpath, job.limits, scenario.order, sequencing);
  job.toolpath = apply_order(scenario.toolpath, job.order);

  // an arm: its roll at every point and its branch, away from limits, singularities and the part
  if (arm) choose_posture(scenario, *arm, job);
  return job;
}

std::vector<PlannerSpec> select_planners(const Scenario& scenario, const std::string& names) {
  if (names.empty()) return scenario.planners;
  std::vector<PlannerSpec> selected;
  std::stringstream list(names);
  std::string name;
  while (std::getline(list, name, ',')) {
    if (name.empty()) continue;
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

PlannedRun plan_job(const PreparedJob& job, const PlannerSpec& spec) {
  // a jerk limit in force (the user's, or the joints' mapped) must be honoured
  Vec3 lo, hi;
  job.toolpath.bounds(lo, hi);
  const std::string ignored = check_planner_limits(spec, job.limits.over(lo, hi));
  if (!ignored.empty()) throw InputError(job.scenario.file, spec.line, "planners", ignored);

  PlannedRun run;
  run.spec = spec;
  run.trajectory = make_planner(spec)->plan(job.toolpath, job.limits);
  // a job far beyond any real print (e.g. a j_max of 1e-9 mm/s^3) would be sampled every
  // millisecond: refuse it before sampling anything
  if (!(run.trajectory.duration_s() <= kMaxJobDuration_s)) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the %s plan lasts %.4g s, beyond the %.0f h a job may last here; check the "
                  "print speeds and the limits (v_max, a_max, j_max)",
                  spec.name.c_str(), run.trajectory.duration_s(), kMaxJobDuration_s / 3600.0);
    throw InputError(job.scenario.file, spec.line, "planners", text);
  }
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
  r.planned_velocity_error = velocity_error(run.planned);
  r.path_error = path_error(run.planned, job.toolpath);
  OrderStats order;
  order.method = job.scenario.order.method;
  order.refine = job.scenario.order.refine;
  order.cost_model = job.scenario.order.cost_model;
  order.cost_s = job.order.cost_s;
  if (job.order.lower_bound_s > 0.0) order.lower_bound_s = job.order.lower_bound_s;
  r.order = order;
  r.warnings = run.trajectory.warnings();
  return run;
}

std::vector<MetricsReport> write_plans(const PreparedJob& job,
                                       const std::vector<PlannerSpec>& planners,
                                       const std::string& directory) {
  std::vector<MetricsReport> reports;
  for (const PlannerSpec& spec : planners) {
    const PlannedRun run = plan_job(job, spec);
    StagedDirectory out((fs::path(directory) / spec.run_label()).string());
    write_file_atomically(out.file("metrics.json"), metrics_json_text(run.report));
    write_file_atomically(out.file("trajectory.csv"), planned_trajectory_csv(run.planned));
    out.commit();
    reports.push_back(run.report);
  }
  return reports;
}

namespace {

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%", 100.0 * fraction);
  return text;
}

std::string fixed(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace

std::string summary_table(const std::vector<MetricsReport>& reports) {
  // one row per planner; simulated columns only when a simulation ran
  const bool simulated = !reports.empty() && reports.front().velocity_error.has_value();
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header{"planner",          "order",      "time s",
                                  "print s",          "transit s",  "plan vel err max",
                                  "plan vel err rms", "path err mm"};
  if (simulated) {
    header.insert(header.end(), {"sim vel err max", "thickness cv", "line cv", "waste"});
  }
  header.push_back("warnings");
  rows.push_back(header);
  for (const MetricsReport& r : reports) {
    std::vector<std::string> row{r.label.empty() ? r.planner : r.label,
                                 r.sequencer,
                                 fixed(r.time.total_s, 3),
                                 fixed(r.time.print_s, 3),
                                 fixed(r.time.transition_s, 3),
                                 percent(r.planned_velocity_error.max_rel),
                                 percent(r.planned_velocity_error.rms_rel),
                                 fixed(r.path_error.max_mm, 4)};
    if (simulated) {
      row.push_back(r.velocity_error ? percent(r.velocity_error->max_rel) : "-");
      row.push_back(r.thickness ? fixed(r.thickness->cv, 4) : "-");
      row.push_back(r.thickness ? fixed(r.thickness->line_cv, 4) : "-");
      row.push_back(r.waste ? percent(r.waste->fraction) : "-");
    }
    row.push_back(std::to_string(r.warnings.size()));
    rows.push_back(row);
  }
  // column widths, then the rows
  std::vector<size_t> width(header.size(), 0);
  for (const auto& row : rows)
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  std::string out;
  for (size_t i = 0; i < rows.size(); ++i) {
    for (size_t c = 0; c < rows[i].size(); ++c) {
      const std::string& cell = rows[i][c];
      const std::string pad(width[c] - cell.size(), ' ');
      out += c == 0 ? cell + pad : "  " + pad + cell;
    }
    out += '\n';
    if (i == 0) {
      for (size_t c = 0; c < width.size(); ++c) out += std::string(width[c] + (c ? 2 : 0), '-');
      out += '\n';
    }
  }
  return out;
}

}  // namespace depotwin
