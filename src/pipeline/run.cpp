#include "pipeline/run.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <iostream>
#include <optional>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "deposition/deposition_metrics.hpp"
#include "deposition/field_io.hpp"
#include "kinematics/arm6.hpp"
#include "metrics/run_report.hpp"
#include "pipeline/deposition_worker.hpp"
#include "pipeline/progress_line.hpp"
#include "pipeline/replay.hpp"  // moving pictures
#include "pipeline/step_heartbeat.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "render/video.hpp"  // moving pictures
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "report/trajectory_csv.hpp"
#include "toolpath/surface_projection.hpp"

namespace depotwin {

namespace fs = std::filesystem;

// each layer's map for layers.png: the plot shows at most 400 cells a side
constexpr size_t kLayerMapCells = 800 * 800;
// the arm's clearance to the part is measured this often over a run (and at every step near it)
constexpr double kArmClearancePeriod_s = 0.02;

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
  s.retract = p.retract;
  return s;
}

std::vector<plots::LineProfile> centreline_profiles(const LayeredDeposit& deposit,
                                                    const Toolpath& toolpath) {
  std::vector<plots::LineProfile> profiles;
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    // (its layer as the run deposited it: clamped to the deposit's layers)
    const int layer = std::clamp(toolpath.paths[i].layer, 0, deposit.layer_count() - 1);
    const ThicknessField& field = deposit.layer_normal_field(layer);
    const double step_mm = field.cell_mm();
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

SimSettings sim_settings(const Scenario& scenario) {
  SimSettings s;
  s.timestep_s = scenario.sim.timestep_s;
  s.control_period_s = scenario.sim.control_period_s;
  s.kp_scale = scenario.sim.kp_scale;
  s.settle_s = scenario.sim.settle_s;
  s.shutter_time_s = scenario.process.shutter_time_s;
  return s;
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

std::unique_ptr<LayeredDeposit> job_deposit(const PreparedJob& job) {
  const DepositionSettings deposition = deposition_settings(job.scenario);
  deposition.validate();
  // one process per layer; on a part, the surface's slope under each cell (n_z) turns the
  // vertical thickness into thickness along the normal
  LayeredDeposit::NormalZ normal_z;
  if (job.surface) {
    std::shared_ptr<const SurfaceProjector> projector = job.surface;
    normal_z = [projector](double x_mm, double y_mm) {
      const std::optional<SurfaceHit> hit = projector->project_down(x_mm, y_mm);
      return hit && hit->faces_up() ? hit->normal.z() : 1.0;
    };
  }
  return std::make_unique<LayeredDeposit>(deposition, job.scenario.sim.cell_mm,
                                          job.toolpath.layer_count(), normal_z);
}

SimulatedRun simulate_job(const PreparedJob& job, const PlannerSpec& spec,
                          const RunSettings& settings) {
  SimulatedRun run;
  {
    const WorkingStep step("sampling the " + spec.run_label() + " plan");
    run.plan = plan_job(job, spec);
  }
  const Trajectory& trajectory = run.plan.trajectory;
  const Scenario& scenario = job.scenario;

  // the twin: the machine's MJCF, driven through its actuators
  run.simulation = std::make_unique<Simulation>(job.model_path, *job.machine,
                                                sim_settings(scenario), job.model_text);
  run.deposit = job_deposit(job);

  // loads carried through closed chains (a delta's platform) by the machine's own model
  if (job.machine->has_closures())
    run.simulation->set_feedforward_hook(
        closure_feedforward_hook(*job.machine, trajectory, sim_settings(scenario)));

  // every step of the job deposits along the simulated nozzle's chord, into the layer of the
  // path being printed (a transition's into the last one's); the aerosol stream runs from job
  // start to job end (the end of the trajectory), not through the settling
  LayeredDeposit& deposit = *run.deposit;
  const double job_end_s = trajectory.duration_s();
  int layer = 0;
  // moving pictures: MuJoCo's whole state sampled for the replay data
  run.states = std::make_shared<StateSamples>(*run.simulation);
  StateSamples& states = *run.states;
  // (laid down on a worker thread while the simulation goes on, in the same order)
  DepositionWorker depositing(deposit);
  auto on_step = [&](const StepState& before, const StepState& after) {
    if (before.path_index >= 0) layer = job.toolpath.paths[before.path_index].layer;
    DepositionStep step;
    if (deposition_step(before, after, job_end_s, step)) depositing.push(step, layer);
    states.on_step(after);
  };
  // the progress line names the run (a compare's order and planner: its label); no step shown
  // meanwhile, then the scores'
  std::optional<WorkingStep> step(std::in_place, "");
  ProgressLine progress(scenario.name + "/" + spec.run_label() + ": simulating",
                        ProgressLine::style_for_stderr(settings.progress));
  // a plan that leaves the machine's reach or travel is the planner's doing: said at its entry
  // in the scenario, by name (a compare runs several)
  try {
    run.record = run.simulation->run(trajectory, on_step,
                                     [&](double fraction) { progress.update(fraction); });
  } catch (const InputError& e) {
    std::vector<Problem> problems = e.problems();
    locate_plan_problems(scenario, spec, problems);
    throw InputError(scenario.located(std::move(problems)));
  }
  depositing.finish();
  progress.finish();
  step.reset();
  step.emplace("scoring the " + spec.run_label() + " run");
  run.simulation->set_feedforward_hook({});  // it refers to this function's locals

  // extrusion: what still flows when the job ends lands where the nozzle stopped
  if (!run.record.nozzle_mm.empty())
    deposit_remaining_flow(deposit.layer(layer), run.record.nozzle_mm.back(), job_end_s);
  deposit.finish();  // the last batched steps put down, the layers stacked

  // scores from the recorded run only: joints inside a continuous print are not path ends;
  // thickness along the surface normal, volumes from the vertical deposit
  run.simulated = recorded_motion(run.record);
  run.planned_at_steps = trajectory_motion_at(trajectory, run.record.t_s);
  run.report = run.plan.report;
  const Toolpath& intended = job.intended_toolpath();  // a G-code file's arcs as they are
  const Toolpath merged = merge_joined_paths(intended);
  const TargetRegion region(merged, deposit.line_width_mm(), deposit.field().cell_mm());
  DepositionMetrics deposited;
  deposited.thickness = thickness_stats(deposit.normal_field(), region, merged);
  deposited.material = split_material(deposit.field(), region, deposit.account());
  add_simulated_metrics(run.report, run.record, run.simulated, intended, deposited);
  // multi-layer and conformal jobs: every metric per layer too
  if (intended.layer_count() > 1 || job.part)
    run.report.layers = layer_reports(intended, run.plan.planned, run.simulated, deposit);
  run.report.actuators = actuator_stats(run.record, job.machine->joint_limits(),
                                        run.simulation->actuator_force_limits());
  // a joint beyond its limits is said in the warnings, not only counted
  for (std::string& warning : actuator_limit_warnings(*run.report.actuators))
    run.report.warnings.push_back(std::move(warning));
  // an arm: its posture over the run (limits, singularities, the part, contacts, branch)
  if (const auto* arm = dynamic_cast<const Arm6*>(job.machine.get()); arm && job.posture)
    run.report.arm =
        arm_run_stats(*arm, job.clearance.get(), run.record, *job.posture, kArmClearancePeriod_s);
  // a collision is said in the warnings too, not only counted in metrics.json's arm
  if (run.report.arm) {
    std::string warning = arm_collision_warning(*run.report.arm, run.record.contacts);
    if (!warning.empty()) run.report.warnings.push_back(std::move(warning));
  }
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
  throw_if_interrupted();  // a signal asked to stop (core/interrupt.hpp): nothing more to write
  StagedDirectory out(run_directory);
  const ThicknessField& field = run.deposit->normal_field();
  const HeightMap map = field_heightmap(field, kMaxExportCells);  // at most ~4 M cells
  const std::string directory = out.path();

  // the paper-style plots and the heat map: one gnuplot process, started first from a
  // worker thread, so that it draws on the second core while this thread writes the data
  // files and renders the scene
  std::future<void> plots_done;
  if (settings.render) {
    plots_done = std::async(std::launch::async, [&job, &run, &map, &directory] {
      plots::RunPlotInput input;
      // the planner, and the run's label where it has its own (an order, a setting)
      const MetricsReport& r = run.report;
      input.title = job.scenario.name + " / " + r.planner +
                    (r.label.empty() || r.label == r.planner ? "" : " (" + r.label + ")");
      input.toolpath = &job.toolpath;
      input.planned = &run.planned_at_steps;
      input.simulated = &run.simulated;
      input.transitions = plots::transition_intervals(run.plan.trajectory);
      if (!map.thickness_um.empty()) input.thickness = &map;
      input.profiles = centreline_profiles(*run.deposit, job.toolpath);
      input.target_thickness_um = target_thickness_um(run.deposit->front(), job.toolpath);
      // where that target comes from, said under thickness_profile.png
      const DepositionSettings& process = run.deposit->front().settings();
      input.target_note = plots::target_thickness_note(
          process.type == ProcessType::extrusion, input.target_thickness_um,
          job.toolpath.paths.empty() ? 0.0 : job.toolpath.paths.front().speed_mm_s,
          process.footprint_sigma_mm(),
          process.type == ProcessType::aerosol ? process.aerosol_flow_mm3_s() : process.flow_mm3_s,
          process.bead_width_mm, process.layer_height_mm);
      if (run.report.thickness) input.mean_thickness_um = run.report.thickness->mean_um;
      input.layer_count = run.deposit->layer_count();
      // every machine's joints against their limits
      std::vector<bool> revolute;
      for (const JointLimit& limit : job.machine->joint_limits())
        revolute.push_back(limit.revolute);
      const plots::JointSeries joints =
          plots::joint_series(run.record, job.machine->joint_limits(), revolute);
      input.joints = &joints;
      // several layers or a part: each layer's deposit, and the paths in 3-D over the part
      std::vector<HeightMap> layer_maps;
      if (run.deposit->layer_count() > 1 || job.part) {
        for (int k = 0; k < run.deposit->layer_count(); ++k)
          layer_maps.push_back(field_heightmap(run.deposit->layer_normal_field(k), kLayerMapCells));
        for (const HeightMap& layer_map : layer_maps) input.layer_maps.push_back(&layer_map);
        if (job.scenario.surface)
          for (int k = 0; k < run.deposit->layer_count(); ++k) {
            const std::vector<double>& angles = job.scenario.surface->angles_deg;
            input.layer_angles_deg.push_back(angles[static_cast<size_t>(k) % angles.size()]);
          }
      }
      input.part = job.part.get();
      plots::render_run_plots(input, directory);
    });
  }

  // the plots are waited for (and their errors rethrown) even when this part fails, so no
  // thread outlives its inputs; between the stages, a signal that asked to stop ends the write
  try {
    // --- moving pictures: the replay data `depotwin view` reads (always)
    const ReplayData replay =
        build_replay(job, run, run_replay_timing(run, settings.video_length_s));
    write_replay(replay, directory);
    // ... and, asked for, run.mp4 (stated on the console: its length and speed-up)
    if (settings.video) {
      const VideoStats video = write_replay_video(replay, out.file("run.mp4"));
      char line[256];
      std::snprintf(line, sizeof line,
                    "%s/%s: run.mp4, %.3g s of video at %s (%d frames at %g fps), rendered in "
                    "%.1f s\n",
                    job.scenario.name.c_str(), run.plan.spec.run_label().c_str(), video.length_s,
                    speedup_text(replay.timing.speedup).c_str(), video.frames, replay.timing.fps,
                    video.render_s);
      std::cout << line << std::flush;
    }
    // --- end moving pictures
    throw_if_interrupted();
    write_file_atomically(out.file("metrics.json"), metrics_json_text(run.report));
    write_file_atomically(out.file("trajectory.csv"),
                          planned_and_simulated_csv(run.planned_at_steps, run.simulated));

    // the thickness field: 16-bit PNG and CSV with origin and cell size
    if (!map.thickness_um.empty()) {
      const double scale = write_heightmap_png16(map, out.file("thickness_field.png"));
      write_heightmap_csv(map, out.file("thickness.csv"), scale);
    }

    // the MuJoCo scene through OSMesa
    throw_if_interrupted();
    if (settings.render) {
      SceneRenderOptions scene = scene_render_options(job.scenario);
      // on a part, the deposit lies on its surface
      if (job.surface) {
        std::shared_ptr<const SurfaceProjector> surface = job.surface;
        scene.surface_height_mm = [surface](double x_mm, double y_mm) {
          return surface->height_at(x_mm, y_mm);
        };
      }
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
