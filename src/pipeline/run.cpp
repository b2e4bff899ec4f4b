#include "pipeline/run.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>

#include "core/error.hpp"
#include "deposition/deposition_metrics.hpp"
#include "deposition/field_io.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "report/trajectory_csv.hpp"

namespace depotwin {

namespace fs = std::filesystem;

DepositionSettings deposition_settings(const Scenario& scenario) {
  const ProcessSpec& p = scenario.process;
  DepositionSettings s;
  s.type = process_type_from_name(p.type);
  s.flow_mm3_s = p.flow_mm3_s;
  s.sigma_mm = p.sigma_mm;
  s.line_width_mm = p.line_width_mm;
  s.bead_width_mm = p.bead_width_mm;
  s.layer_height_mm = p.layer_height_mm;
  s.tau_s = p.tau_s;
  return s;
}

namespace {

// "\r<label> 42 %" on a terminal once the run has taken a second; nothing otherwise
class ProgressLine {
 public:
  ProgressLine(std::string label, bool enabled)
      : label_(std::move(label)),
        enabled_(enabled && ::isatty(STDERR_FILENO)),
        start_(std::chrono::steady_clock::now()) {}
  void update(double fraction) {
    if (!enabled_) return;
    const double elapsed = seconds();
    if (elapsed < 1.0) return;
    std::fprintf(stderr, "\r%s %3.0f %% (%.1f s)", label_.c_str(), 100.0 * fraction, elapsed);
    std::fflush(stderr);
    shown_ = true;
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\r%s done in %.1f s        \n", label_.c_str(), seconds());
  }

 private:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  std::string label_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
};

// the recorded nozzle as motion samples (the same shape as the plan's)
MotionSamples simulated_samples(const RecordedRun& record) {
  MotionSamples samples;
  samples.reserve(record.size());
  for (size_t k = 0; k < record.size(); ++k)
    samples.push_back(record.t_s[k], record.nozzle_mm[k], record.nozzle_velocity_mm_s[k],
                      record.deposit_command[k], record.path_index[k],
                      record.desired_speed_mm_s[k]);
  return samples;
}

MotionSamples plan_at(const Trajectory& trajectory, const std::vector<double>& times) {
  MotionSamples samples;
  samples.reserve(times.size());
  for (double t : times) {
    const TrajectorySample s = trajectory.at(t);
    samples.push_back(t, s.position_mm, s.velocity_mm_s, s.depositing, s.path_index,
                      s.desired_speed_mm_s);
  }
  return samples;
}

// peaks of joint velocity, acceleration and force against the machine's limits
ActuatorStats actuator_stats(const RecordedRun& record, const Machine& machine,
                             const std::vector<double>& force_limits) {
  ActuatorStats stats;
  const auto& limits = machine.joint_limits();
  for (int j = 0; j < record.joint_count; ++j) {
    double v = 0.0, a = 0.0, f = 0.0;
    for (size_t k = 0; k < record.size(); ++k) {
      v = std::max(v, std::abs(record.joint(record.joint_velocity, k, j)));
      a = std::max(a, std::abs(record.joint(record.joint_acceleration, k, j)));
      f = std::max(f, std::abs(record.joint(record.actuator_force, k, j)));
    }
    stats.joint_names.push_back(record.joint_names[j]);
    stats.peak_vel.push_back(v);
    stats.peak_acc.push_back(a);
    stats.peak_force.push_back(f);
    const double v_lim = j < static_cast<int>(limits.size()) ? limits[j].v_max : 0.0;
    const double a_lim = j < static_cast<int>(limits.size()) ? limits[j].a_max : 0.0;
    const double f_lim = j < static_cast<int>(force_limits.size()) ? force_limits[j] : 0.0;
    stats.limit_vel.push_back(v_lim);
    stats.limit_acc.push_back(a_lim);
    stats.limit_force.push_back(f_lim);
    const double plan_a = j < static_cast<int>(record.reference_peak_acceleration.size())
                              ? record.reference_peak_acceleration[j]
                              : 0.0;
    stats.plan_peak_acc.push_back(plan_a);
    stats.peak_acc_over_plan.push_back(plan_a > 0.0 ? a / plan_a : 0.0);
    if (v_lim > 0 && v > v_lim) ++stats.limit_violations;
    if (a_lim > 0 && a > a_lim) ++stats.limit_violations;
    if (f_lim > 0 && f > f_lim) ++stats.limit_violations;
  }
  return stats;
}

}  // namespace

std::vector<plots::LineProfile> centreline_profiles(const ThicknessField& field,
                                                    const Toolpath& toolpath) {
  std::vector<plots::LineProfile> profiles;
  const double step_mm = field.cell_mm();
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    plots::LineProfile profile;
    profile.path_index = static_cast<int>(i);
    const auto& points = toolpath.paths[i].points;
    double arc = 0.0;
    for (size_t k = 0; k + 1 < points.size(); ++k) {
      const Vec3 edge = points[k + 1] - points[k];
      const double length = edge.norm();
      const int samples = std::max(1, static_cast<int>(std::ceil(length / step_mm)));
      for (int n = 0; n < samples; ++n) {
        const double u = static_cast<double>(n) / samples;
        const Vec3 p = points[k] + u * edge;
        profile.arc_length_mm.push_back(arc + u * length);
        profile.thickness_um.push_back(1000.0 * field.thickness_mm_at(p.x(), p.y()));
      }
      arc += length;
    }
    profile.arc_length_mm.push_back(arc);
    profile.thickness_um.push_back(1000.0 *
                                   field.thickness_mm_at(points.back().x(), points.back().y()));
    profiles.push_back(std::move(profile));
  }
  return profiles;
}

double target_thickness_um(const Process& process, const Toolpath& toolpath) {
  // a straight line at its desired speed peaks at Q / (v sigma sqrt(2 pi)); extrusion's
  // nominal flow is v w h, so its peak is w h / (sigma sqrt(2 pi)) at any speed
  if (toolpath.paths.empty()) return 0.0;
  const DepositionSettings& s = process.settings();
  const double sigma = s.footprint_sigma_mm();
  const double root = sigma * std::sqrt(2.0 * kPi);
  if (s.type == ProcessType::aerosol)
    return 1000.0 * s.aerosol_flow_mm3_s() / (toolpath.paths.front().speed_mm_s * root);
  if (s.flow_mm3_s > 0.0) return 1000.0 * s.flow_mm3_s / (toolpath.paths.front().speed_mm_s * root);
  return 1000.0 * s.bead_width_mm * s.layer_height_mm / root;
}

SimSettings sim_settings(const Scenario& scenario) {
  SimSettings s;
  s.timestep_s = scenario.sim.timestep_s;
  s.control_period_s = scenario.sim.control_period_s;
  s.kp_scale = scenario.sim.kp_scale;
  s.settle_s = scenario.sim.settle_s;
  s.shutter_time_s = scenario.process.shutter_time_s;
  return s;
}

bool deposition_step(const StepState& before, const StepState& after, double job_end_s,
                     DepositionStep& step) {
  if (before.t_s >= job_end_s - 1e-12) return false;
  step.t0_s = before.t_s;
  step.t1_s = after.t_s;
  step.p0_mm = before.nozzle_mm;
  step.p1_mm = after.nozzle_mm;
  step.open0 = before.open_fraction;
  step.open1 = after.open_fraction;
  // the step that straddles the job's end is cut there (chord and flap linear in time)
  if (after.t_s > job_end_s) {
    const double f = (job_end_s - before.t_s) / (after.t_s - before.t_s);
    step.t1_s = job_end_s;
    step.p1_mm = before.nozzle_mm + f * (after.nozzle_mm - before.nozzle_mm);
    step.open1 = before.open_fraction + f * (after.open_fraction - before.open_fraction);
  }
  step.flow_command = before.deposit_command ? 1.0 : 0.0;
  step.desired_speed_mm_s = before.desired_speed_mm_s;
  return true;
}

Simulation::FeedForwardHook closure_feedforward_hook(const Machine& machine,
                                                     const Trajectory& trajectory,
                                                     const SimSettings& sim) {
  // the TCP acceleration the servo's setpoints give over the coming control period: the
  // second difference of the TCP setpoints, as the joints' references (Simulation)
  const double period_s = static_cast<double>(sim.control_stride()) * sim.timestep_s;
  return [&machine, &trajectory, period_s](const JointReference& reference, double* force) {
    const TrajectorySample s = trajectory.at(reference.t_s);
    const Vec3 next_mm = trajectory.at(reference.t_s + period_s).position_mm;
    const Vec3 velocity_mm_s =
        reference.t_s >= period_s
            ? Vec3((s.position_mm - trajectory.at(reference.t_s - period_s).position_mm) / period_s)
            : s.velocity_mm_s;
    const Vec3 acceleration_mm_s2 =
        ((next_mm - s.position_mm) / period_s - velocity_mm_s) / period_s;
    machine.closure_feedforward(s.position_mm, velocity_mm_s, acceleration_mm_s2, force);
  };
}

SimulatedRun simulate_job(const PreparedJob& job, const PlannerSpec& spec,
                          const RunSettings& settings) {
  SimulatedRun run;
  run.plan = plan_job(job, spec);
  const Trajectory& trajectory = run.plan.trajectory;
  const Scenario& scenario = job.scenario;

  // the twin: the machine's MJCF, driven through its actuators
  run.simulation =
      std::make_unique<Simulation>(job.model_path, *job.machine, sim_settings(scenario));
  const DepositionSettings deposition = deposition_settings(scenario);
  deposition.validate();
  run.process = make_process(deposition, scenario.sim.cell_mm);

  // loads carried through closed chains (a delta's platform) by the machine's own model
  if (job.machine->has_closures())
    run.simulation->set_feedforward_hook(
        closure_feedforward_hook(*job.machine, trajectory, sim_settings(scenario)));

  // every step of the job deposits along the simulated nozzle's chord; the aerosol stream
  // runs from job start to job end (the end of the trajectory), not through the settling
  Process& process = *run.process;
  const double job_end_s = trajectory.duration_s();
  auto on_step = [&](const StepState& before, const StepState& after) {
    DepositionStep step;
    if (deposition_step(before, after, job_end_s, step)) process.advance(step);
  };
  ProgressLine progress(scenario.name + "/" + spec.name + ": simulating", settings.progress);
  run.record =
      run.simulation->run(trajectory, on_step, [&](double fraction) { progress.update(fraction); });
  progress.finish();
  run.simulation->set_feedforward_hook({});  // it refers to this function's locals

  // extrusion: what still flows from the nozzle when the job ends (the lag's ooze, Q tau)
  // lands where the nozzle stopped, instead of vanishing with the last step
  if (deposition.type == ProcessType::extrusion && process.nozzle_flow_mm3_s() > 0.0 &&
      !run.record.nozzle_mm.empty()) {
    DepositionStep ooze;
    ooze.t0_s = job_end_s;
    ooze.t1_s = job_end_s + 40.0 * deposition.tau_s;  // exp(-40): the rest goes down at once
    ooze.p0_mm = ooze.p1_mm = run.record.nozzle_mm.back();
    process.advance(ooze);
  }
  process.flush();  // the last batched deposition steps, before anything reads the field

  // scores from the recorded run only
  run.simulated = simulated_samples(run.record);
  run.planned_at_steps = plan_at(trajectory, run.record.t_s);
  MetricsReport& r = run.report;
  r = run.plan.report;
  r.planned_path_error = r.path_error;
  r.velocity_error = velocity_error(run.simulated);
  r.path_error = path_error(run.simulated, job.toolpath);

  // thickness over what is printed in one go: joints inside a continuous print are not ends
  const DepositionMetrics deposited =
      evaluate_deposition(process.field(), merge_joined_paths(job.toolpath),
                          process.line_width_mm(), process.account());
  ThicknessSummary thickness;
  thickness.mean_um = deposited.thickness.mean_um;
  thickness.cv = deposited.thickness.cv;
  thickness.line_cv = deposited.thickness.line_cv;
  thickness.min_rel = deposited.thickness.min_rel;
  thickness.max_rel = deposited.thickness.max_rel;
  r.thickness = thickness;
  const MaterialSplit& m = deposited.material;
  MaterialStats material;
  material.emitted = m.emitted_mm3;
  material.on_target = m.on_target_mm3;
  material.overspray = m.overspray_mm3;
  material.captured = m.captured_mm3;
  r.material = material;
  WasteStats waste;
  waste.fraction = m.fraction;
  waste.shutter_captured = m.emitted_mm3 > 0 ? m.captured_mm3 / m.emitted_mm3 : 0.0;
  waste.overspray = m.emitted_mm3 > 0 ? m.overspray_mm3 / m.emitted_mm3 : 0.0;
  waste.closed_time_s = m.closed_time_s;
  r.waste = waste;
  r.actuators = actuator_stats(run.record, *job.machine, run.simulation->actuator_force_limits());

  SimStats sim;
  sim.steps = run.record.steps;
  sim.timestep_s = run.record.timestep_s;
  sim.wall_s = run.record.wall_s;
  const double simulated_s = run.record.t_s.empty() ? 0.0 : run.record.t_s.back();
  sim.realtime_factor = run.record.wall_s > 0 ? simulated_s / run.record.wall_s : 0.0;
  sim.max_constraint_violation_mm = run.record.max_constraint_violation_mm;
  r.sim = sim;
  return run;
}

SceneRenderOptions scene_render_options(const Scenario& scenario) {
  SceneRenderOptions options;
  options.width = scenario.outputs.image_width;
  options.height = scenario.outputs.image_height;
  return options;
}

HeightMap field_heightmap(const ThicknessField& field, size_t max_cells) {
  const FieldBounds b = field.bounds();
  if (b.empty) return HeightMap{};
  const int stride =
      field.stride_for_max_cells(b.x_lo_mm, b.y_lo_mm, b.x_hi_mm, b.y_hi_mm, max_cells);
  return field.to_heightmap(b.x_lo_mm, b.y_lo_mm, b.x_hi_mm, b.y_hi_mm, stride);
}

void write_run(const PreparedJob& job, const SimulatedRun& run, const std::string& run_directory,
               const RunSettings& settings) {
  StagedDirectory out(run_directory);
  const ThicknessField& field = run.process->field();
  const HeightMap map = field_heightmap(field, kMaxExportCells);  // at most ~4 M cells
  const std::string directory = out.path();

  // the paper-style plots and the heat map: one gnuplot process, started first from a
  // worker thread, so that it draws on the second core while this thread writes the data
  // files and renders the scene
  std::future<void> plots_done;
  if (settings.render) {
    plots_done = std::async(std::launch::async, [&job, &run, &field, &map, &directory] {
      plots::RunPlotInput input;
      input.title = job.scenario.name + " / " + run.report.planner;
      input.toolpath = &job.toolpath;
      input.planned = &run.planned_at_steps;
      input.simulated = &run.simulated;
      input.transitions = plots::transition_intervals(run.plan.trajectory);
      if (!map.thickness_um.empty()) input.thickness = &map;
      input.profiles = centreline_profiles(field, job.toolpath);
      input.target_thickness_um = target_thickness_um(*run.process, job.toolpath);
      if (run.report.thickness) input.mean_thickness_um = run.report.thickness->mean_um;
      plots::render_run_plots(input, directory);
    });
  }

  // the plots are waited for (and their errors rethrown) even when this part fails, so no
  // thread outlives its inputs
  try {
    write_file_atomically(out.file("metrics.json"), metrics_json_text(run.report));
    write_file_atomically(out.file("trajectory.csv"),
                          planned_and_simulated_csv(run.planned_at_steps, run.simulated));

    // the thickness field: 16-bit PNG and CSV with origin and cell size
    if (!map.thickness_um.empty()) {
      const double scale = write_heightmap_png16(map, out.file("thickness_field.png"));
      write_heightmap_csv(map, out.file("thickness.csv"), scale);
    }

    // the MuJoCo scene through OSMesa
    if (settings.render) {
      const SceneRenderOptions scene = scene_render_options(job.scenario);
      SceneRenderer own_renderer;  // used only without a shared one
      SceneRenderer& renderer = settings.scene_renderer ? *settings.scene_renderer : own_renderer;
      renderer.render_png(*run.simulation, map, out.file("scene.png"), scene);
    }
  } catch (...) {
    if (plots_done.valid()) plots_done.wait();
    throw;
  }
  if (plots_done.valid()) plots_done.get();
  out.commit();
}

BackgroundRunWriter::~BackgroundRunWriter() {
  for (std::future<void>& write : pending_)
    if (write.valid()) write.wait();
}

void BackgroundRunWriter::submit(const PreparedJob& job, const SimulatedRun& run,
                                 std::string run_directory, const RunSettings& settings) {
  while (pending_.size() >= kWritesInFlight) wait_oldest();
  pending_.push_back(
      std::async(std::launch::async, [&job, &run, directory = std::move(run_directory), &settings] {
        write_run(job, run, directory, settings);
      }));
}

void BackgroundRunWriter::wait_oldest() {
  std::future<void> oldest = std::move(pending_.front());
  pending_.pop_front();
  oldest.get();
}

void BackgroundRunWriter::wait() {
  while (!pending_.empty()) wait_oldest();
}

}  // namespace depotwin
