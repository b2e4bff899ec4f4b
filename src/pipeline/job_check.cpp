#include "pipeline/job_check.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "core/input_ranges.hpp"
#include "core/number_text.hpp"
#include "deposition/process.hpp"
#include "pipeline/models_dir.hpp"
#include "pipeline/run.hpp"
#include "pipeline/step_heartbeat.hpp"
#include "sim/simulation.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

// the plan's samples, as plan_job takes them (trajectory.csv, planned metrics)
constexpr double kSamplePeriod_s = 0.001;
// a plan this many times the bound before planning, from a planner given parameters: the
// planner's parameters make it long (RunEstimate::planner_line)
constexpr double kPlannerDrivenRatio = 10.0;
// What a run keeps, per unit, measured on thompson_fig7 stretched to 340 s (430 B per 1 ms
// step on the XY stage, both kinds together) and rounded up: per physics step the recorded
// state (73 B + 32 B per joint), the simulated and re-sampled motion and the joint
// references; per 1 ms sample the planned motion and its trajectory.csv row (written as text).
constexpr double kBytesPerStep = 150.0;
constexpr double kBytesPerStepPerJoint = 40.0;
constexpr double kBytesPerSample = 350.0;
constexpr double kBytesPerPlannedSample = 220.0;  // `plan`: the csv row without sim columns
// a deposition field cell is a double; the deposit holds a field per layer, the stacked one
// and the one along the normal (one per layer too on a part)
constexpr double kBytesPerCell = 8.0;
// the process itself: libraries, MuJoCo's model and data, the renderer's buffers
constexpr double kProcessBytes = 250e6;
// per print path, the toolpath's copies (scenario, job, order) and their metrics
constexpr double kBytesPerPath = 600.0;
// per triangle of a conformal job's part: the mesh, the projector's BVH and corner normals,
// the clearance's tree and the scene's copy; a run on a 1.0e6-triangle STL peaked 1.13 GB
// above one on 1e4 triangles, validate 1.26 GB (with the STL reader's own copy)
constexpr double kBytesPerPartTriangle = 1300.0;
// the footprint's reach (deposition: truncation at 5 sigma, smoothed over 0.25 sigma) and a
// tile's side in cells (deposition/sparse_tiles.hpp), for the grid's covered area
constexpr double kFootprintSigmas = 5.25;
constexpr double kTileCells = 64.0;

std::string number(double value) {
  return message_number(value);
}

// a count as a whole number, every digit
std::string whole_count_text(double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.0f", value);
  return text;
}

// "1.2e+07 steps" style counts: whole below a million, else %.3g
std::string count_text(double value) {
  if (value < 1e6) return whole_count_text(value);
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// the machine's MJCF, as prepare_job picks it
std::string model_path_of(const Scenario& scenario, const Machine& machine) {
  return scenario.model_path.empty()
             ? (fs::path(models_directory()) / machine.model_file()).string()
             : scenario.model_path;
}

// true when some problem's key is one of these sections or lies under one
bool has_problem_in(const std::vector<Problem>& problems,
                    const std::vector<std::string>& sections) {
  return std::any_of(problems.begin(), problems.end(), [&](const Problem& p) {
    return std::any_of(sections.begin(), sections.end(), [&](const std::string& section) {
      return p.key.compare(0, section.size(), section) == 0 &&
             (p.key.size() == section.size() || p.key[section.size()] == '.' ||
              p.key[section.size()] == '[');
    });
  });
}

// The MJCF model's problems, placed at the scenario's `machine` key: the model file and
// element (and the MJCF's own line) in the message
std::vector<Problem> model_problems(const Scenario& scenario) {
  std::unique_ptr<Machine> machine = make_machine(scenario.machine);
  if (!machine) return {};
  if (scenario.has_joint_limits && !machine->set_joint_limits(scenario.joint_limits).empty())
    return {};  // already reported by the loader
  const std::string model_path = model_path_of(scenario, *machine);
  std::vector<Problem> found = check_simulation_model(model_path, *machine, sim_settings(scenario));
  const std::string key = scenario.model_path.empty() ? "machine" : "machine.model";
  const std::string shown = fs::path(model_path).filename().string();
  std::vector<Problem> problems;
  for (const Problem& p : found) {
    // the settings' own problems are the sim section's, found by the loader too
    if (p.file.empty()) continue;
    std::string where = shown;
    if (p.line > 0) where += ":" + std::to_string(p.line);
    const std::string element = p.key == "model" ? "" : p.key + ": ";
    // a shipped model that is not there: where it was looked for, and why there
    const bool shipped_missing = scenario.model_path.empty() && p.key == "model" && p.line == 0 &&
                                 !fs::is_regular_file(model_path);
    const std::string folder = shipped_missing ? " (the shipped models are looked for in " +
                                                     models_directory_text() +
                                                     "; DEPOTWIN_MODELS_DIR names another folder)"
                                               : "";
    problems.push_back(
        scenario.problem_at(key, "MJCF " + where + ": " + element + p.message + folder));
  }
  return problems;
}

// The settings the deposition and the simulation check again when a run starts, checked the
// same way now (their problems name only a key: placed at its line)
std::vector<Problem> downstream_setting_problems(const Scenario& scenario) {
  std::vector<Problem> problems;
  try {
    make_process(deposition_settings(scenario), scenario.sim.cell_mm);
  } catch (const InputError& e) {
    problems = scenario.located(e.problems());
  }
  const std::string sim = sim_settings(scenario).validate(scenario.machine);
  if (!sim.empty()) problems.push_back(scenario.problem_at("sim", sim));
  return problems;
}

// the time to reach velocity `speed` along `direction` from rest, each axis at its a_max
double ramp_s(const MachineLimits& limits, double speed_mm_s, const Vec3& direction) {
  double time_s = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double a_max = limits.axes[axis].a_max_mm_s2;
    if (a_max > 0.0) time_s = std::max(time_s, speed_mm_s * std::abs(direction[axis]) / a_max);
  }
  return time_s;
}

// the deposition grid's cells over the toolpath: a band the footprint's reach wide (and a
// tile's rounding) along every path, at most the paths' bounding box, over every field
double grid_cells(const Scenario& scenario) {
  const ProcessSpec& process = scenario.process;
  const bool aerosol = process.type == "aerosol";
  const double sigma_mm = aerosol ? process.sigma_mm : 0.25 * process.bead_width_mm;
  const double cell_mm = scenario.sim.cell_mm > 0.0
                             ? scenario.sim.cell_mm
                             : (aerosol ? 0.25 * process.sigma_mm : 0.125 * process.bead_width_mm);
  if (!(sigma_mm > 0.0) || !(cell_mm > 0.0)) return 0.0;
  const double band_mm = 2.0 * kFootprintSigmas * sigma_mm + kTileCells * cell_mm;
  double along_mm2 = 0.0;
  for (const PrintPath& path : scenario.toolpath.paths)
    along_mm2 += (path.length_mm() + band_mm) * band_mm;
  Vec3 lo, hi;
  scenario.toolpath.bounds(lo, hi);
  const double box_mm2 = (hi.x() - lo.x() + band_mm) * (hi.y() - lo.y() + band_mm);
  const double area_mm2 = std::min(along_mm2, box_mm2);
  // fields: the layers' (together the area once), the stacked one, the one along the normal
  // (and the layers' along the normal on a part)
  const double fields = scenario.part ? 4.0 : 3.0;
  return fields * area_mm2 / (cell_mm * cell_mm);
}

// the run's steps, samples, cells and memory from its duration
RunEstimate sized(const Scenario& scenario, int joints, RunEstimate run) {
  const SimSpec& sim = scenario.sim;
  run.samples = run.duration_s / kSamplePeriod_s + 2.0;
  run.steps = run.simulated ? std::ceil((run.duration_s + sim.settle_s) / sim.timestep_s) : 0.0;
  run.cells = run.simulated ? grid_cells(scenario) : 0.0;
  const double per_step = kBytesPerStep + kBytesPerStepPerJoint * joints;
  run.memory_bytes = run.simulated ? run.steps * per_step + run.samples * kBytesPerSample +
                                         run.cells * kBytesPerCell
                                   : run.samples * kBytesPerPlannedSample;
  return run;
}

int joint_count(const Scenario& scenario) {
  const std::unique_ptr<Machine> machine = make_machine(scenario.machine);
  return machine ? static_cast<int>(machine->joint_limits().size()) : 6;
}

// The key that drives a run's size, for the problem's line: the settling time, the step, the
// grid, or the plan (its print speeds, or its limits when ramps and transitions dominate)
std::string size_driver(const Scenario& scenario, const RunEstimate& run, bool memory) {
  if (memory && run.cells * kBytesPerCell > 0.5 * run.memory_bytes)
    return scenario.key_lines.count("sim.cell_mm") ? "sim.cell_mm"
           : scenario.process.type == "aerosol"    ? "process.sigma_mm"
                                                   : "process.bead_width_mm";
  if (scenario.sim.settle_s > run.duration_s) return "sim.settle_s";
  if (scenario.key_lines.count("sim.timestep_s") && scenario.sim.timestep_s < 1e-3 &&
      run.duration_s * 1e3 < input_ranges::kDefaultMaxSteps)
    return "sim.timestep_s";
  if (run.print_s >= 0.5 * run.duration_s)
    return scenario.key_lines.count("toolpath.speed") ? "toolpath.speed" : "toolpath";
  // a jerk limit in force lengthens every move most; else the accelerations
  if (scenario.limits.jerk_limited()) return "limits.j_max";
  return "limits.a_max";
}

// a size problem at the key that drives it: the planner's entry when its parameters make the
// plan long (RunEstimate::planner_line), else the scenario key size_driver names
Problem at_driver(const Scenario& scenario, const RunEstimate& run, bool memory,
                  const std::string& message) {
  if (run.planner_line > 0)
    return Problem{scenario.file, run.planner_line, "planners",
                   message + "; the " + run.label +
                       " plan is far longer than the paths at their speeds: check its parameters"};
  return scenario.problem_at(size_driver(scenario, run, memory), message);
}

// what a run's duration is made of, for messages
std::string duration_text(const Scenario& scenario, const RunEstimate& run) {
  std::string text = run.label.empty()
                         ? "at least " + number(run.duration_s) + " s of motion (" +
                               number(run.print_s) + " s of it printing at the speeds given)"
                         : "its plan lasts " + number(run.duration_s) + " s";
  if (scenario.sim.settle_s > 0.0)
    text += ", then " + number(scenario.sim.settle_s) + " s settling";
  return text;
}

// for a G-code file printing several layers (those `layers:` selected, numbered from 0 in
// the toolpath): the key that prints fewer
std::string fewer_layers_hint(const Scenario& scenario) {
  const int layers = scenario.toolpath.layer_count();
  if (!scenario.gcode || layers < 2) return "";
  return ", print fewer of its " + std::to_string(layers) +
         " layers (toolpath.gcode.layers: [from, to])";
}

// the largest --max-memory, 1048576T (1 EiB): a size beyond it is no budget anyone gives
constexpr double kMostMemoryBytes = 1024.0 * 1024.0 * 1024.0 * 1024.0 * 1024.0 * 1024.0;

}  // namespace

double parse_memory_size(const std::string& text, const std::string& option) {
  // a number, then an optional unit: K, M, G, T (x 1024^n), with an optional i and B
  std::size_t end = 0;
  double value = std::numeric_limits<double>::quiet_NaN();
  try {
    value = std::stod(text, &end);
  } catch (const std::exception&) {
    end = 0;
  }
  std::string unit = text.substr(std::min(end, text.size()));
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() > 1 && unit.back() == 'B') unit.pop_back();
  if (unit.size() > 1 && unit.back() == 'I') unit.pop_back();
  double scale = 1.0;
  const std::string units = "KMGT";
  if (unit == "B" || unit.empty()) {
    scale = 1.0;
  } else if (unit.size() == 1 && units.find(unit[0]) != std::string::npos) {
    scale = std::pow(1024.0, static_cast<double>(units.find(unit[0]) + 1));
  } else {
    end = 0;
  }
  // between 1M and 1048576T (1 MiB and 1 EiB), in the powers of 1024 the units are
  constexpr double kLeast_bytes = 1024.0 * 1024.0;
  if (end == 0 || !std::isfinite(value) || !(value > 0.0) || !(value * scale >= kLeast_bytes) ||
      !(value * scale <= kMostMemoryBytes))
    throw InputError(option, "'" + printable_text(text) +
                                 "' is not a memory size between 1M and 1048576T (1 MiB and 1 "
                                 "EiB; e.g. 8G, 512M, 1.5GiB, or bytes)");
  return value * scale;
}

std::string format_bytes(double bytes) {
  char text[48];
  const double mib = bytes / (1024.0 * 1024.0);
  if (mib < 1024.0)
    std::snprintf(text, sizeof text, "%.0f MB", mib);
  else if (mib < 1024.0 * 1024.0)
    std::snprintf(text, sizeof text, "%.3g GB", mib / 1024.0);
  // from 1 PiB up to the largest --max-memory, TB in full (the units the command line takes);
  // beyond it (a job at 1e-300 mm/s) three digits, as in full they would not fit
  else if (mib >= 1024.0 * 1024.0 * 1024.0 && bytes <= kMostMemoryBytes)
    std::snprintf(text, sizeof text, "%.0f TB", mib / (1024.0 * 1024.0));
  else
    std::snprintf(text, sizeof text, "%.3g TB", mib / (1024.0 * 1024.0));
  return text;
}

RunEstimate estimate_before_planning(const Scenario& scenario, bool simulate) {
  // every path at its print speed, the first printed reached from rest and the last left to
  // rest: whichever path ends they are, no ramp is shorter than the shortest of all
  RunEstimate run;
  run.simulated = simulate;
  double shortest_ramp_s = std::numeric_limits<double>::infinity();
  for (const PrintPath& path : scenario.toolpath.paths) {
    if (!(path.speed_mm_s > 0.0) || path.points.size() < 2) continue;
    run.print_s += path.length_mm() / path.speed_mm_s;
    const Vec3 first = path.points[1] - path.points[0];
    const Vec3 last = path.points.back() - path.points[path.points.size() - 2];
    for (const Vec3& edge : {first, last})
      if (edge.norm() > 0.0)
        shortest_ramp_s =
            std::min(shortest_ramp_s, ramp_s(scenario.limits, path.speed_mm_s, edge / edge.norm()));
  }
  run.duration_s = run.print_s + (std::isfinite(shortest_ramp_s) ? 2.0 * shortest_ramp_s : 0.0);
  return sized(scenario, joint_count(scenario), run);
}

RunEstimate estimate_planned(const PreparedJob& job, const std::string& label, double duration_s,
                             bool simulate) {
  RunEstimate run;
  run.label = label;
  run.simulated = simulate;
  run.duration_s = duration_s;
  for (const PrintPath& path : job.toolpath.paths)
    if (path.speed_mm_s > 0.0) run.print_s += path.length_mm() / path.speed_mm_s;
  return sized(job.scenario, static_cast<int>(job.machine->joint_limits().size()), run);
}

double job_memory_bytes(const Scenario& scenario, const std::vector<RunEstimate>& runs) {
  double memory_bytes =
      kProcessBytes + kBytesPerPath * 3.0 * static_cast<double>(scenario.toolpath.paths.size());
  if (scenario.part)
    memory_bytes += kBytesPerPartTriangle * static_cast<double>(scenario.part->triangle_count());
  for (const RunEstimate& run : runs) memory_bytes += run.memory_bytes;
  return memory_bytes;
}

std::vector<Problem> size_problems(const Scenario& scenario, const std::vector<RunEstimate>& runs,
                                   const JobBudget& budget) {
  std::vector<Problem> problems;
  if (runs.empty()) return problems;
  // each run's physics steps against sim.max_steps
  const double max_steps = static_cast<double>(scenario.sim.max_steps);
  for (const RunEstimate& run : runs) {
    if (!run.simulated || !(run.steps > max_steps)) continue;
    // whole numbers where three digits would show the two as equal ("1e+07, more than 1e+07")
    std::string steps_text = count_text(run.steps), max_text = count_text(max_steps);
    if (steps_text == max_text) {
      steps_text = whole_count_text(run.steps);
      max_text = whole_count_text(max_steps);
    }
    problems.push_back(at_driver(
        scenario, run, false,
        (run.label.empty() ? std::string("the job") : "run " + run.label) + " would take " +
            steps_text + " physics steps, more than sim.max_steps = " + max_text + ": " +
            duration_text(scenario, run) + ", at sim.timestep_s " +
            number(scenario.sim.timestep_s) + " s (check the print speeds, the limits and sim" +
            fewer_layers_hint(scenario) + ", or raise sim.max_steps)"));
    if (run.label.empty()) break;  // before planning every run is the same estimate
  }
  // every run a verb keeps together, against the memory budget
  const double memory_bytes = job_memory_bytes(scenario, runs);
  const RunEstimate* largest = &runs.front();
  for (const RunEstimate& run : runs)
    if (run.memory_bytes > largest->memory_bytes) largest = &run;
  if (memory_bytes > budget.max_memory_bytes) {
    const RunEstimate& run = *largest;
    std::string parts = (run.simulated ? count_text(run.steps) + " physics steps, " : "") +
                        count_text(run.samples) + " samples of the plan";
    if (run.cells > 0.0) parts += ", " + count_text(run.cells) + " deposition cells";
    // a conformal job's part: its share, and a coarser STL among the remedies
    std::string part_share, coarser_part;
    if (scenario.part) {
      const double triangles = static_cast<double>(scenario.part->triangle_count());
      part_share = "; the part's " + count_text(triangles) + " triangles take about " +
                   format_bytes(kBytesPerPartTriangle * triangles);
      coarser_part = ", a coarser STL";
    }
    problems.push_back(at_driver(
        scenario, run, true,
        std::string(runs.size() > 1 ? "the " + std::to_string(runs.size()) + " runs" : "the run") +
            " would need about " + format_bytes(memory_bytes) +
            " of memory, more than --max-memory " + format_bytes(budget.max_memory_bytes) + ": " +
            (run.label.empty() ? "each run " : "run " + run.label + " ") + "keeps " + parts + " (" +
            duration_text(scenario, run) + ")" + part_share +
            "; check the print speeds, the limits, sim.timestep_s and sim.cell_mm, run fewer "
            "planners" +
            fewer_layers_hint(scenario) + coarser_part + ", or raise --max-memory"));
  }
  return problems;
}

Scenario check_scenario(const std::string& path, const JobBudget& budget, std::size_t runs,
                        bool simulate) {
  const WorkingStep step("reading the scenario");
  ScenarioReading reading = read_scenario(path);
  std::vector<Problem>& problems = reading.problems;
  if (!reading.document_read) throw InputError(std::move(problems));
  const Scenario& scenario = reading.scenario;

  // the machine's MJCF model, compiled and bound (no simulation)
  if (!has_problem_in(problems, {"machine", "limits"})) {
    const std::vector<Problem> model = model_problems(scenario);
    problems.insert(problems.end(), model.begin(), model.end());
  }
  // what the deposition and the simulation check again when a run starts
  if (!has_problem_in(problems, {"process", "sim"})) {
    const std::vector<Problem> settings = downstream_setting_problems(scenario);
    problems.insert(problems.end(), settings.begin(), settings.end());
  }
  // the job's size before anything is planned, from a lower bound on its duration
  if (!has_problem_in(problems, {"toolpath", "limits", "process", "sim", "machine"}) &&
      !scenario.toolpath.paths.empty()) {
    const RunEstimate run = estimate_before_planning(scenario, simulate);
    const std::size_t count = runs > 0 ? runs : std::max<std::size_t>(scenario.planners.size(), 1);
    const std::vector<Problem> size =
        size_problems(scenario, std::vector<RunEstimate>(count, run), budget);
    problems.insert(problems.end(), size.begin(), size.end());
  }
  if (!problems.empty()) {
    sort_problems(problems, scenario.file);
    throw InputError(std::move(problems));
  }
  return std::move(reading.scenario);
}

std::vector<RunEstimate> check_runs(PreparedJob& job, const std::vector<PlannerSpec>& planners,
                                    bool simulate, std::vector<Problem>& problems,
                                    const JobBudget* pose_budget) {
  std::vector<RunEstimate> runs;
  for (const PlannerSpec& spec : planners) {
    // planned and measured; the plan itself is small (pieces, not samples), so the job keeps
    // it for the verb (PreparedJob::checked_plans) rather than plan it again
    try {
      if (!job.checked_plan(spec)) {
        const WorkingStep step("planning " + spec.run_label());
        job.checked_plans.push_back(
            {spec, std::make_shared<const Trajectory>(plan_trajectory(job, spec))});
      }
      const Trajectory& plan = *job.checked_plan(spec);
      RunEstimate run = estimate_planned(job, spec.run_label(), plan.duration_s(), simulate);
      if (!spec.params.empty()) {
        const double bound_s = estimate_before_planning(job.scenario, simulate).duration_s;
        if (bound_s > 0.0 && run.duration_s > kPlannerDrivenRatio * bound_s)
          run.planner_line = planner_entry_line(job.scenario, spec);
      }
      // validate, plan and export: its every pose solved now, as the simulation will (a
      // planner's move may leave the travel or the reach between the toolpath's points); a run
      // too large (sim.max_steps, the memory) is refused for that instead (size_problems),
      // before any such work
      if (pose_budget && size_problems(job.scenario, {run}, *pose_budget).empty()) {
        const WorkingStep step("solving every pose of the " + spec.run_label() + " plan");
        check_plan_poses(job, spec, plan);
      }
      runs.push_back(run);
    } catch (const InputError& e) {
      const std::vector<Problem> found = job.scenario.located(e.problems());
      problems.insert(problems.end(), found.begin(), found.end());
    }
  }
  return runs;
}

PreparedJob prepare_checked_job(const Scenario& scenario, const std::vector<PlannerSpec>& planners,
                                const JobBudget& budget, bool simulate, bool with_lower_bound,
                                std::vector<RunEstimate>* estimates, bool solve_poses) {
  PrepareOptions options;
  options.lower_bound = with_lower_bound;
  PreparedJob job = [&] {
    try {
      return prepare_job(scenario, options);
    } catch (const InputError& e) {
      throw InputError(scenario.located(e.problems()));
    }
  }();
  std::vector<Problem> problems;
  const std::vector<RunEstimate> runs =
      check_runs(job, planners, simulate, problems, solve_poses ? &budget : nullptr);
  if (problems.empty()) {
    const std::vector<Problem> size = size_problems(scenario, runs, budget);
    problems.insert(problems.end(), size.begin(), size.end());
  }
  if (!problems.empty()) {
    sort_problems(problems, scenario.file);
    throw InputError(std::move(problems));
  }
  if (estimates) *estimates = runs;
  return job;
}

}  // namespace depotwin
