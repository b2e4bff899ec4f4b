// What the whole twin costs per step on the XY stage, against the physics engine alone
// (issue: "the physics engine is the floor"; target: full pipeline <= 1.3 x bare mj_step).
//
//   BM_PipelineOverRaw/0   Simulation::run of thompson_fig7 / lspb_mtt (plan sampling and IK,
//                          servo controller, recording), no deposition callback
//   BM_PipelineOverRaw/1   the same with the aerosol process fed every step exactly as
//                          src/pipeline/run.cpp does (batched deposition, the default)
//   BM_PipelineOverRaw/2   the same with every step deposited on its own (batching off):
//                          what the deposition cost before batching
//                          each against a bare mj_step loop on models/xy_stage.xml for the same
//                          number of steps, timed alternately in the same iteration; the
//                          ratio `full_over_raw` uses thread CPU time (robust on a shared
//                          machine), `full_over_raw_wall` wall time. The floor is the
//                          stage at rest; `full_over_raw_moving` is against bare mj_step with
//                          the servo targets replaying the run's joint positions (the same
//                          motion, so friction and damping work as in the run)
//   BM_DepositionKernel/b  the deposition alone (ns per step): the recorded thompson_fig7 steps
//                          replayed through Process::advance + flush (b = 1 batched, 0 not)
//   BM_SimulateJob         simulate_job + write_run without rendering (what
//                          `depotwin run thompson_fig7 --planners lspb_mtt --no-render` does
//                          per planner): realtime factor = simulated time / wall time
//   BM_RenderScene         scene.png of the finished job (render_scene_png): ms per image
//   BM_RenderRunPlots      the run plots (plots::render_run_plots, one gnuplot process):
//                          ms per call and per image
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bench_clock.hpp"
#include "deposition/process.hpp"
#include "pipeline/job.hpp"
#include "pipeline/run.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using bench::Clock;
using bench::seconds_since;
using bench::thread_cpu_s;

const char* const kModel = DEPOTWIN_MODELS_DIR "/xy_stage.xml";
const char* const kScenario = DEPOTWIN_SCENARIOS_DIR "/thompson_fig7.yaml";

// thompson_fig7 prepared and planned by lspb_mtt
struct PlannedJob {
  PreparedJob job;
  PlannerSpec spec;
  PlannedRun plan;
};

PlannedJob plan_thompson() {
  PlannedJob planned{prepare_job(load_scenario(kScenario)), {}, {}};
  planned.spec = select_planners(planned.job.scenario, "lspb_mtt").front();
  planned.plan = plan_job(planned.job, planned.spec);
  return planned;
}

DepositionSettings aerosol_settings(const Scenario& scenario, bool batched) {
  DepositionSettings settings = deposition_settings(scenario);
  if (!batched) settings.batch_length_sigmas = 0.0;
  return settings;
}

// bare physics: mj_step on the same model and timestep, servos holding their start
double raw_steps_cpu_s(const mjModel& model, mjData& data, long steps) {
  mj_resetData(&model, &data);
  const double start = thread_cpu_s();
  for (long k = 0; k < steps; ++k) mj_step(&model, &data);
  return thread_cpu_s() - start;
}

// bare physics of the same motion: mj_step with each servo's target set to the recorded
// joint position (slides mm -> m) every step, so the stage moves as in the run (friction and
// damping active) without any controller, planner or recording work
double raw_moving_steps_cpu_s(const mjModel& model, mjData& data, const RecordedRun& run) {
  std::vector<int> actuators;
  std::vector<double> to_si;  // slides record mm, hinges rad
  for (const std::string& name : run.joint_names) {
    actuators.push_back(mj_name2id(&model, mjOBJ_ACTUATOR, name.c_str()));
    const int joint = mj_name2id(&model, mjOBJ_JOINT, name.c_str());
    to_si.push_back(joint >= 0 && model.jnt_type[joint] == mjJNT_SLIDE ? 1e-3 : 1.0);
  }
  const size_t joints = actuators.size();
  std::vector<double> targets(run.joint_position.size());
  for (size_t i = 0; i < targets.size(); ++i)
    targets[i] = to_si[i % joints] * run.joint_position[i];
  mj_resetData(&model, &data);
  const double start = thread_cpu_s();
  for (long k = 0; k < run.steps; ++k) {
    for (size_t j = 0; j < joints; ++j)
      if (actuators[j] >= 0) data.ctrl[actuators[j]] = targets[k * joints + j];
    mj_step(&model, &data);
  }
  return thread_cpu_s() - start;
}

void BM_PipelineOverRaw(benchmark::State& state) {
  const int mode = static_cast<int>(state.range(0));  // 0 none, 1 batched, 2 unbatched
  const PlannedJob planned = plan_thompson();
  const Scenario& scenario = planned.job.scenario;
  const Trajectory& trajectory = planned.plan.trajectory;
  Simulation simulation(planned.job.model_path, *planned.job.machine, sim_settings(scenario));
  ModelPtr raw_model = load_model(kModel);
  raw_model->opt.timestep = scenario.sim.timestep_s;
  DataPtr raw_data = make_data(*raw_model);
  const double job_end_s = trajectory.duration_s();

  double full_cpu_s = 0.0, raw_cpu_s = 0.0, full_wall_s = 0.0, raw_wall_s = 0.0;
  double raw_moving_cpu_s = 0.0;
  long steps = 0;
  for (auto _ : state) {
    std::unique_ptr<Process> process;
    if (mode > 0)
      process = make_process(aerosol_settings(scenario, mode == 1), scenario.sim.cell_mm);
    Simulation::StepCallback on_step;
    if (process) {
      Process& p = *process;
      on_step = [&p, job_end_s](const StepState& before, const StepState& after) {
        DepositionStep step;
        if (deposition_step(before, after, job_end_s, step)) p.advance(step);
      };
    }
    // the full per-step pipeline (and the flush the pipeline does before reading the field)
    const Clock::time_point wall_start = Clock::now();
    const double cpu_start = thread_cpu_s();
    const RecordedRun run = simulation.run(trajectory, on_step);
    if (process) process->flush();
    full_cpu_s += thread_cpu_s() - cpu_start;
    full_wall_s += seconds_since(wall_start);
    if (process) benchmark::DoNotOptimize(process->field().cell_mm());

    // the floor: the same number of bare steps
    const Clock::time_point raw_wall_start = Clock::now();
    raw_cpu_s += raw_steps_cpu_s(*raw_model, *raw_data, run.steps);
    raw_wall_s += seconds_since(raw_wall_start);
    raw_moving_cpu_s += raw_moving_steps_cpu_s(*raw_model, *raw_data, run);
    steps += run.steps;
  }
  state.counters["steps_per_run"] = static_cast<double>(steps) / state.iterations();
  state.counters["raw_us_per_step"] = 1e6 * raw_cpu_s / steps;
  state.counters["full_us_per_step"] = 1e6 * full_cpu_s / steps;
  state.counters["full_over_raw"] = full_cpu_s / raw_cpu_s;
  state.counters["full_over_raw_wall"] = full_wall_s / raw_wall_s;
  state.counters["raw_moving_us_per_step"] = 1e6 * raw_moving_cpu_s / steps;
  state.counters["full_over_raw_moving"] = full_cpu_s / raw_moving_cpu_s;
}
BENCHMARK(BM_PipelineOverRaw)
    ->ArgName("deposition")
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(8);

void BM_DepositionKernel(benchmark::State& state) {
  const bool batched = state.range(0) != 0;
  const PlannedJob planned = plan_thompson();
  const Scenario& scenario = planned.job.scenario;
  const double job_end_s = planned.plan.trajectory.duration_s();
  // the job's steps, recorded once from the simulation
  std::vector<DepositionStep> steps;
  {
    Simulation simulation(planned.job.model_path, *planned.job.machine, sim_settings(scenario));
    simulation.run(planned.plan.trajectory, [&](const StepState& before, const StepState& after) {
      DepositionStep step;
      if (deposition_step(before, after, job_end_s, step)) steps.push_back(step);
    });
  }
  const DepositionSettings settings = aerosol_settings(scenario, batched);
  StepBatch::Stats stats;
  double kernel_s = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    auto process = make_process(settings, scenario.sim.cell_mm);
    state.ResumeTiming();
    const double start = thread_cpu_s();
    for (const DepositionStep& step : steps) process->advance(step);
    process->flush();
    kernel_s += thread_cpu_s() - start;
    benchmark::DoNotOptimize(process->account().landed_mm3);
    stats = process->batch_stats();
  }
  const double total_steps = static_cast<double>(steps.size()) * state.iterations();
  state.counters["ns_per_step"] = 1e9 * kernel_s / total_steps;
  state.counters["steps"] = static_cast<double>(steps.size());
  state.counters["steps_with_material"] = static_cast<double>(stats.steps);
  state.counters["boxes"] = static_cast<double>(stats.quadratures + stats.single_steps);
  state.counters["splits"] = static_cast<double>(stats.splits);
}
BENCHMARK(BM_DepositionKernel)->ArgName("batched")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// a scratch directory for written outputs, removed at the end
struct ScratchDirectory {
  fs::path path = fs::temp_directory_path() /
                  ("depotwin_bench_pipeline_" + std::to_string(static_cast<long>(::getpid())));
  ScratchDirectory() { fs::create_directories(path); }
  ~ScratchDirectory() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

void BM_SimulateJob(benchmark::State& state) {
  const PreparedJob job = prepare_job(load_scenario(kScenario));
  const PlannerSpec spec = select_planners(job.scenario, "lspb_mtt").front();
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  ScratchDirectory scratch;
  double simulated_s = 0.0, wall_s = 0.0, run_wall_s = 0.0;
  for (auto _ : state) {
    const Clock::time_point start = Clock::now();
    const SimulatedRun run = simulate_job(job, spec, settings);
    write_run(job, run, (scratch.path / spec.name).string(), settings);
    wall_s += seconds_since(start);
    simulated_s += run.record.t_s.back();
    run_wall_s += run.record.wall_s;
  }
  state.counters["simulated_s"] = simulated_s / state.iterations();
  state.counters["realtime_factor"] = simulated_s / wall_s;          // plan + sim + score + write
  state.counters["sim_realtime_factor"] = simulated_s / run_wall_s;  // Simulation::run alone
}
BENCHMARK(BM_SimulateJob)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// the finished thompson_fig7 / lspb_mtt run, for the renderers
struct FinishedRun {
  PreparedJob job;
  SimulatedRun run;
  HeightMap map;
};

FinishedRun finished_run() {
  FinishedRun finished{prepare_job(load_scenario(kScenario)), {}, {}};
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  finished.run = simulate_job(finished.job,
                              select_planners(finished.job.scenario, "lspb_mtt").front(), settings);
  finished.map = field_heightmap(finished.run.deposit->normal_field());
  return finished;
}

void BM_RenderScene(benchmark::State& state) {
  const FinishedRun finished = finished_run();
  SceneRenderOptions options;
  options.width = finished.job.scenario.outputs.image_width;
  options.height = finished.job.scenario.outputs.image_height;
  ScratchDirectory scratch;
  const std::string png = (scratch.path / "scene.png").string();
  double wall_s = 0.0, cpu_s = 0.0;
  for (auto _ : state) {
    const Clock::time_point start = Clock::now();
    const double cpu_start = thread_cpu_s();
    render_scene_png(*finished.run.simulation, finished.map, png, options);
    cpu_s += thread_cpu_s() - cpu_start;
    wall_s += seconds_since(start);
  }
  state.counters["ms_per_image"] = 1e3 * wall_s / static_cast<double>(state.iterations());
  state.counters["cpu_ms_per_image"] = 1e3 * cpu_s / static_cast<double>(state.iterations());
}
BENCHMARK(BM_RenderScene)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

void BM_RenderRunPlots(benchmark::State& state) {
  const FinishedRun finished = finished_run();
  const SimulatedRun& run = finished.run;
  // the plot input write_run builds
  plots::RunPlotInput input;
  input.title = finished.job.scenario.name + " / " + run.report.planner;
  input.toolpath = &finished.job.toolpath;
  input.planned = &run.planned_at_steps;
  input.simulated = &run.simulated;
  input.transitions = plots::transition_intervals(run.plan.trajectory);
  if (!finished.map.thickness_um.empty()) input.thickness = &finished.map;
  input.profiles = centreline_profiles(*run.deposit, finished.job.toolpath);
  input.target_thickness_um = target_thickness_um(run.deposit->front(), finished.job.toolpath);
  if (run.report.thickness) input.mean_thickness_um = run.report.thickness->mean_um;
  input.layer_count = run.deposit->layer_count();
  ScratchDirectory scratch;
  size_t images = 0;
  double wall_s = 0.0;
  for (auto _ : state) {
    const Clock::time_point start = Clock::now();
    const plots::PlotResult result = plots::render_run_plots(input, scratch.path.string());
    wall_s += seconds_since(start);
    images += result.files.size();
  }
  state.counters["images_per_call"] = static_cast<double>(images) / state.iterations();
  state.counters["ms_per_image"] = 1e3 * wall_s / static_cast<double>(images);
}
BENCHMARK(BM_RenderRunPlots)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
