// What the linear delta's twin costs (issue 5): the full per-step pipeline against bare
// MuJoCo steps on models/linear_delta.xml, and the realtime factor of a whole scenario.
//   BM_DeltaRawStep      bare mj_step (servos holding the home pose, the six rod closures
//                        solved every step)
//   BM_DeltaFullRun      Simulation::run on giberti_circle's bezier plan: IK and joint
//                        references, the servo controller with the closure feed-forward hook,
//                        recording, and an on_step that advances the extrusion Process as
//                        src/pipeline/run.cpp does
//   BM_DeltaFullOverRaw  both on the same model and number of steps, as a ratio (target <= 1.3)
//   BM_GibertiCircleRealtime  simulate_job on scenarios/giberti_circle.yaml (plan, simulate,
//                        deposit, score): simulated seconds per wall second
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>

#include "deposition/process.hpp"
#include "pipeline/run.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

const std::string kCircleScenario = std::string(DEPOTWIN_SCENARIOS_DIR) + "/giberti_circle.yaml";

// the circle's job and its bezier plan, made once per benchmark
struct CircleJob {
  PreparedJob job;
  PlannedRun plan;
};

std::unique_ptr<CircleJob> circle_job() {
  auto circle = std::make_unique<CircleJob>();
  circle->job = prepare_job(load_scenario(kCircleScenario));
  circle->plan = plan_job(circle->job, circle->job.scenario.planners.front());
  return circle;
}

// bare steps from the model's home pose (the closed chain of qpos0)
double raw_steps_seconds(const std::string& model_path, long steps) {
  ModelPtr model = load_model(model_path);
  DataPtr data = make_data(*model);
  const auto start = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k) mj_step(model.get(), data.get());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One full run as simulate_job does it, without planning and scoring: the closure
// feed-forward hook and an extrusion Process advanced every step. Returns the steps taken.
long full_run(Simulation& simulation, const CircleJob& circle, double& emitted_mm3) {
  const Machine& machine = *circle.job.machine;
  const Trajectory& trajectory = circle.plan.trajectory;
  simulation.set_feedforward_hook(
      closure_feedforward_hook(machine, trajectory, sim_settings(circle.job.scenario)));
  const std::unique_ptr<Process> process =
      make_process(deposition_settings(circle.job.scenario), circle.job.scenario.sim.cell_mm);
  const double job_end_s = trajectory.duration_s();
  auto on_step = [&](const StepState& before, const StepState& after) {
    DepositionStep step;
    if (deposition_step(before, after, job_end_s, step)) process->advance(step);
  };
  const RecordedRun run = simulation.run(trajectory, on_step);
  simulation.set_feedforward_hook({});
  benchmark::DoNotOptimize(&process->field());  // puts down any batched steps
  emitted_mm3 = process->account().emitted_mm3;
  return run.steps;
}

void BM_DeltaRawStep(benchmark::State& state) {
  const std::unique_ptr<CircleJob> circle = circle_job();
  ModelPtr model = load_model(circle->job.model_path);
  DataPtr data = make_data(*model);
  for (auto _ : state) mj_step(model.get(), data.get());
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DeltaRawStep)->UseRealTime();

void BM_DeltaFullRun(benchmark::State& state) {
  const std::unique_ptr<CircleJob> circle = circle_job();
  Simulation simulation(circle->job.model_path, *circle->job.machine, SimSettings{});
  long steps = 0;
  for (auto _ : state) {
    double emitted_mm3 = 0.0;
    steps += full_run(simulation, *circle, emitted_mm3);
    benchmark::DoNotOptimize(emitted_mm3);
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["time_per_step"] = benchmark::Counter(
      static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
      benchmark::Counter::kIs1000);
}
BENCHMARK(BM_DeltaFullRun)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

void BM_DeltaFullOverRaw(benchmark::State& state) {
  const std::unique_ptr<CircleJob> circle = circle_job();
  Simulation simulation(circle->job.model_path, *circle->job.machine, SimSettings{});
  double raw_s = 0.0, full_s = 0.0;
  long steps = 0;
  for (auto _ : state) {
    double emitted_mm3 = 0.0;
    const auto start = std::chrono::steady_clock::now();
    const long run_steps = full_run(simulation, *circle, emitted_mm3);
    full_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    benchmark::DoNotOptimize(emitted_mm3);
    raw_s += raw_steps_seconds(circle->job.model_path, run_steps);
    steps += run_steps;
  }
  state.counters["raw_steps_per_s"] = steps / raw_s;
  state.counters["full_steps_per_s"] = steps / full_s;
  state.counters["full_over_raw"] = full_s / raw_s;
}
BENCHMARK(BM_DeltaFullOverRaw)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_GibertiCircleRealtime(benchmark::State& state) {
  const PreparedJob job = prepare_job(load_scenario(kCircleScenario));
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  double simulated_s = 0.0, wall_s = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const SimulatedRun run = simulate_job(job, job.scenario.planners.front(), settings);
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    simulated_s += run.record.t_s.back();
  }
  state.counters["simulated_s"] = simulated_s / state.iterations();
  state.counters["realtime_factor"] = simulated_s / wall_s;
}
BENCHMARK(BM_GibertiCircleRealtime)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
