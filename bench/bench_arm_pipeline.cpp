// What the 6-DOF arm's twin costs per step (issue: "the physics engine is the floor"; target:
// the full pipeline <= 1.3 x bare mj_step on the same model), and the realtime factor of the
// arm's conformal scenario scenarios/shembekar_beam.yaml.
//
//   BM_ArmFullOverRaw/d   Simulation::run of the beam's `conformal` plan over its first
//                         kBenchPaths hatch lines (layer 0) on the job's model (models/arm6.xml
//                         with the part): joint references (every step's pose through
//                         Arm6::inverse_near), the servo controller with inverse-dynamics
//                         feed-forward, mj_step1/mj_step2, recording, contact logging, and
//                         (d = 1) an on_step that deposits into the job's LayeredDeposit exactly
//                         as simulate_job does (extrusion, batched; the batches flushed), d = 0
//                         without deposition. Timed alternately, in the same iteration, against
//                         bare mj_step loops on the same model for the same number of steps:
//                           raw       the arm holding its start posture (qpos and a constant
//                                     ctrl at the run's first joints): the floor
//                           raw_moving  ctrl replaying the run's recorded joints every step
//                                     (the same motion: friction and damping work as in the run)
//                         Ratios on thread CPU time (robust on a shared machine): full_over_raw,
//                         full_over_raw_moving; full_over_raw_wall on wall time.
//   BM_ArmIkPerStep       what the references' IK costs per step: the plan sampled at every
//                         step (TrajectoryCursor) and Arm6::inverse_near seeded by the previous
//                         step, as sim/joint_reference.cpp does; ns per step and solutions/s
//   BM_ShembekarRealtime/L  the scenario with its first L layers (8: all of it): simulate_job
//                         (plan, simulate, deposit, score; no files, no images) as the CLI runs
//                         it: realtime_factor = simulated s / wall s of simulate_job. Then the
//                         same job again through a replica of simulate_job with a clock between
//                         its stages (staged_over_job checks it against the real one), for the
//                         stages' shares of a job's wall time (prepare_job + simulate_job):
//                         prepare (ordering, limits, posture), of which posture
//                         (choose_arm_posture re-run on the prepared toolpath), plan (plan_job),
//                         setup (the Simulation: the MJCF with the part compiled; the deposit),
//                         simulation (Simulation::run without the deposition's on_step),
//                         deposition (on_step's time, the remaining flow and finish()) and
//                         metrics (the scores), of which arm_stats (arm_run_stats: posture
//                         measures and clearance to the part over the recorded run).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_clock.hpp"
#include "deposition/deposition_metrics.hpp"
#include "deposition/job_deposition.hpp"
#include "deposition/layered_deposit.hpp"
#include "kinematics/arm6.hpp"
#include "metrics/run_report.hpp"
#include "pipeline/job.hpp"
#include "pipeline/run.hpp"
#include "posture/arm_posture.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

using bench::Clock;
using bench::seconds_since;
using bench::thread_cpu_s;

const char* const kScenario = DEPOTWIN_SCENARIOS_DIR "/shembekar_beam.yaml";
// hatch lines of the per-step benchmarks (layer 0's first ones, in the scenario's order)
constexpr size_t kBenchPaths = 4;
// src/pipeline/run.cpp's period of the arm's clearance checks over a run
constexpr double kArmClearancePeriod_s = 0.02;

// the beam scenario with its first `paths` print paths (0: all) or its first `layers` layers
Scenario beam_scenario(size_t paths, int layers = 0) {
  Scenario scenario = load_scenario(kScenario);
  std::vector<PrintPath>& all = scenario.toolpath.paths;
  if (layers > 0)
    all.erase(std::remove_if(all.begin(), all.end(),
                             [layers](const PrintPath& p) { return p.layer >= layers; }),
              all.end());
  if (paths > 0 && paths < all.size()) all.resize(paths);
  return scenario;
}

// the job prepared and planned by `conformal`
struct BeamJob {
  PreparedJob job;
  PlannerSpec spec;
  PlannedRun plan;
};

std::unique_ptr<BeamJob> beam_job(size_t paths) {
  auto beam = std::make_unique<BeamJob>();
  beam->job = prepare_job(beam_scenario(paths));
  beam->spec = select_planners(beam->job.scenario, "conformal").front();
  beam->plan = plan_job(beam->job, beam->spec);
  return beam;
}

// One run as simulate_job does it, without planning and scoring: with `deposit`, every step
// into the layer of its path, and the batched steps flushed at the end.
RecordedRun full_run(Simulation& simulation, const BeamJob& beam, LayeredDeposit* deposit) {
  const PreparedJob& job = beam.job;
  const Trajectory& trajectory = beam.plan.trajectory;
  const double job_end_s = trajectory.duration_s();
  Simulation::StepCallback on_step;
  int layer = 0;
  if (deposit)
    on_step = [&](const StepState& before, const StepState& after) {
      if (before.path_index >= 0) layer = job.toolpath.paths[before.path_index].layer;
      DepositionStep step;
      if (deposition_step(before, after, job_end_s, step)) deposit->advance(step, layer);
    };
  RecordedRun record = simulation.run(trajectory, on_step);
  if (deposit)
    for (int k = 0; k < deposit->layer_count(); ++k) deposit->layer(k).flush();
  return record;
}

// the job's model for the bare loops: the same MJCF text and timestep as the Simulation
struct RawModel {
  ModelPtr model;
  DataPtr data;
  std::vector<int> qpos, actuator;  // per joint
};

RawModel raw_model(const PreparedJob& job) {
  RawModel raw;
  raw.model = job.model_text.empty() ? load_model(job.model_path)
                                     : load_model_from_string(job.model_text, job.model_path);
  raw.model->opt.timestep = job.scenario.sim.timestep_s;
  raw.data = make_data(*raw.model);
  for (const JointLimit& limit : job.machine->joint_limits()) {
    const int joint = mj_name2id(raw.model.get(), mjOBJ_JOINT, limit.name.c_str());
    raw.qpos.push_back(raw.model->jnt_qposadr[joint]);
    raw.actuator.push_back(mj_name2id(raw.model.get(), mjOBJ_ACTUATOR, limit.name.c_str()));
  }
  return raw;
}

// bare mj_step: the arm at the run's first joints (rad), ctrl holding them
double raw_rest_cpu_s(RawModel& raw, const RecordedRun& run) {
  mjData* d = raw.data.get();
  mj_resetData(raw.model.get(), d);
  for (size_t j = 0; j < raw.qpos.size(); ++j) {
    d->qpos[raw.qpos[j]] = run.joint_position[j];
    d->ctrl[raw.actuator[j]] = run.joint_position[j];
  }
  const double start = thread_cpu_s();
  for (long k = 0; k < run.steps; ++k) mj_step(raw.model.get(), d);
  return thread_cpu_s() - start;
}

// bare mj_step of the same motion: ctrl replaying the recorded joints every step
double raw_moving_cpu_s(RawModel& raw, const RecordedRun& run) {
  mjData* d = raw.data.get();
  mj_resetData(raw.model.get(), d);
  const size_t joints = raw.qpos.size();
  for (size_t j = 0; j < joints; ++j) d->qpos[raw.qpos[j]] = run.joint_position[j];
  const double start = thread_cpu_s();
  for (long k = 0; k < run.steps; ++k) {
    const double* q = run.joint_position.data() + k * joints;
    for (size_t j = 0; j < joints; ++j) d->ctrl[raw.actuator[j]] = q[j];
    mj_step(raw.model.get(), d);
  }
  return thread_cpu_s() - start;
}

void BM_ArmFullOverRaw(benchmark::State& state) {
  const bool with_deposition = state.range(0) != 0;
  const std::unique_ptr<BeamJob> beam = beam_job(kBenchPaths);
  const PreparedJob& job = beam->job;
  Simulation simulation(job.model_path, *job.machine, sim_settings(job.scenario), job.model_text);
  RawModel raw = raw_model(job);
  double full_cpu_s = 0.0, full_wall_s = 0.0, raw_cpu_s = 0.0, raw_wall_s = 0.0;
  double raw_moving_s = 0.0;
  long steps = 0, contact_steps = 0;
  for (auto _ : state) {
    std::unique_ptr<LayeredDeposit> deposit;
    if (with_deposition) deposit = job_deposit(job);  // (outside the timing: per-job set-up)
    const Clock::time_point wall_start = Clock::now();
    const double cpu_start = thread_cpu_s();
    const RecordedRun run = full_run(simulation, *beam, deposit.get());
    full_cpu_s += thread_cpu_s() - cpu_start;
    full_wall_s += seconds_since(wall_start);
    if (deposit) benchmark::DoNotOptimize(deposit->account().emitted_mm3);

    const Clock::time_point raw_wall_start = Clock::now();
    raw_cpu_s += raw_rest_cpu_s(raw, run);
    raw_wall_s += seconds_since(raw_wall_start);
    raw_moving_s += raw_moving_cpu_s(raw, run);
    steps += run.steps;
    contact_steps += run.contacts.self_steps + run.contacts.other_steps;
  }
  state.counters["steps_per_run"] = static_cast<double>(steps) / state.iterations();
  state.counters["contact_steps"] = static_cast<double>(contact_steps) / state.iterations();
  state.counters["raw_us_per_step"] = 1e6 * raw_cpu_s / steps;
  state.counters["raw_moving_us_per_step"] = 1e6 * raw_moving_s / steps;
  state.counters["full_us_per_step"] = 1e6 * full_cpu_s / steps;
  state.counters["full_steps_per_s"] = steps / full_cpu_s;
  state.counters["raw_steps_per_s"] = steps / raw_cpu_s;
  state.counters["full_over_raw"] = full_cpu_s / raw_cpu_s;
  state.counters["full_over_raw_wall"] = full_wall_s / raw_wall_s;
  state.counters["full_over_raw_moving"] = full_cpu_s / raw_moving_s;
}
BENCHMARK(BM_ArmFullOverRaw)
    ->ArgName("deposition")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

void BM_ArmIkPerStep(benchmark::State& state) {
  const std::unique_ptr<BeamJob> beam = beam_job(kBenchPaths);
  const Machine& machine = *beam->job.machine;
  const Trajectory& trajectory = beam->plan.trajectory;
  const double dt = beam->job.scenario.sim.timestep_s;
  const long steps = static_cast<long>(std::ceil(trajectory.duration_s() / dt - 1e-9));
  JointVector joints, next;
  long solved = 0;
  double cpu_s = 0.0;
  for (auto _ : state) {
    const double start = thread_cpu_s();
    TrajectoryCursor cursor(trajectory);
    machine.inverse(cursor.at(0.0).pose(), joints);
    for (long k = 1; k <= steps; ++k) {
      const TrajectorySample sample = cursor.at(static_cast<double>(k) * dt);
      solved += machine.inverse_near(sample.pose(), joints, next) ? 1 : 0;
      joints.swap(next);
    }
    cpu_s += thread_cpu_s() - start;
    benchmark::DoNotOptimize(joints.data());
  }
  const double total = static_cast<double>(steps) * state.iterations();
  state.counters["ns_per_step"] = 1e9 * cpu_s / total;
  state.counters["solutions_per_s"] = static_cast<double>(solved) / cpu_s;
}
BENCHMARK(BM_ArmIkPerStep)->Unit(benchmark::kMillisecond)->Iterations(5);

// Stage times of one job (s)
struct StageTimes {
  double prepare = 0.0, posture = 0.0, plan = 0.0, setup = 0.0, simulation = 0.0;
  double deposition = 0.0, metrics = 0.0, arm_stats = 0.0;
  double total() const { return prepare + plan + setup + simulation + deposition + metrics; }
};

// simulate_job (src/pipeline/run.cpp) step by step with a clock between its stages; the
// deposition's on_step timed call by call (two clock reads a step, ~0.3 % of a step)
void staged_simulate_job(const PreparedJob& job, const PlannerSpec& spec, StageTimes& times) {
  Clock::time_point start = Clock::now();
  const PlannedRun plan = plan_job(job, spec);
  times.plan += seconds_since(start);
  const Trajectory& trajectory = plan.trajectory;
  const Scenario& scenario = job.scenario;

  start = Clock::now();
  Simulation simulation(job.model_path, *job.machine, sim_settings(scenario), job.model_text);
  const std::unique_ptr<LayeredDeposit> deposit_owner = job_deposit(job);
  LayeredDeposit& deposit = *deposit_owner;
  times.setup += seconds_since(start);

  const double job_end_s = trajectory.duration_s();
  int layer = 0;
  double advance_s = 0.0;
  auto on_step = [&](const StepState& before, const StepState& after) {
    const Clock::time_point step_start = Clock::now();
    if (before.path_index >= 0) layer = job.toolpath.paths[before.path_index].layer;
    DepositionStep step;
    if (deposition_step(before, after, job_end_s, step)) deposit.advance(step, layer);
    advance_s += seconds_since(step_start);
  };
  const RecordedRun record = simulation.run(trajectory, on_step);
  times.simulation += record.wall_s - advance_s;
  start = Clock::now();
  if (!record.nozzle_mm.empty())
    deposit_remaining_flow(deposit.layer(layer), record.nozzle_mm.back(), job_end_s);
  deposit.finish();
  times.deposition += advance_s + seconds_since(start);

  start = Clock::now();
  const MotionSamples simulated = recorded_motion(record);
  const MotionSamples planned_at_steps = trajectory_motion_at(trajectory, record.t_s);
  benchmark::DoNotOptimize(planned_at_steps.t_s.data());
  MetricsReport report = plan.report;
  const Toolpath merged = merge_joined_paths(job.toolpath);
  const TargetRegion region(merged, deposit.line_width_mm(), deposit.field().cell_mm());
  DepositionMetrics deposited;
  deposited.thickness = thickness_stats(deposit.normal_field(), region, merged);
  deposited.material = split_material(deposit.field(), region, deposit.account());
  add_simulated_metrics(report, record, simulated, job.toolpath, deposited);
  if (job.toolpath.layer_count() > 1 || job.part)
    report.layers = layer_reports(job.toolpath, plan.planned, simulated, deposit);
  report.actuators =
      actuator_stats(record, job.machine->joint_limits(), simulation.actuator_force_limits());
  const Clock::time_point arm_start = Clock::now();
  if (const auto* arm = dynamic_cast<const Arm6*>(job.machine.get()); arm && job.posture)
    report.arm =
        arm_run_stats(*arm, job.clearance.get(), record, *job.posture, kArmClearancePeriod_s);
  times.arm_stats += seconds_since(arm_start);
  times.metrics += seconds_since(start);
  benchmark::DoNotOptimize(&report);
}

void BM_ShembekarRealtime(benchmark::State& state) {
  const int layers = static_cast<int>(state.range(0));
  const Scenario scenario = beam_scenario(0, layers);
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  StageTimes times;
  double job_s = 0.0, run_s = 0.0, simulated_s = 0.0;
  long steps = 0;
  for (auto _ : state) {
    Clock::time_point start = Clock::now();
    const PreparedJob job = prepare_job(scenario);
    times.prepare += seconds_since(start);
    const PlannerSpec spec = select_planners(job.scenario, "conformal").front();
    // the posture on its own (prepare_job's last stage), re-run on the prepared toolpath
    start = Clock::now();
    const ArmPosture posture = choose_arm_posture(
        dynamic_cast<const Arm6&>(*job.machine), job.clearance.get(), job.toolpath,
        job.scenario.arm.value_or(ArmPostureSettings{}), [](size_t, size_t) { return ""; });
    times.posture += seconds_since(start);
    benchmark::DoNotOptimize(posture.branch);

    // the real thing
    start = Clock::now();
    const SimulatedRun run = simulate_job(job, spec, settings);
    job_s += seconds_since(start);
    simulated_s += run.record.t_s.back();
    run_s += run.record.wall_s;
    steps += run.record.steps;

    // the same, stage by stage
    staged_simulate_job(job, spec, times);
  }
  const double n = static_cast<double>(state.iterations());
  const double total_s = times.total();
  state.counters["simulated_s"] = simulated_s / n;
  state.counters["steps"] = static_cast<double>(steps) / n;
  state.counters["job_wall_s"] = job_s / n;
  state.counters["realtime_factor"] = simulated_s / job_s;      // simulate_job
  state.counters["sim_realtime_factor"] = simulated_s / run_s;  // Simulation::run (+ on_step)
  state.counters["staged_over_job"] = (total_s - times.prepare) / job_s;  // the replica's check
  state.counters["share_prepare"] = times.prepare / total_s;
  state.counters["share_posture"] = times.posture / total_s;  // within prepare
  state.counters["share_plan"] = times.plan / total_s;
  state.counters["share_setup"] = times.setup / total_s;
  state.counters["share_simulation"] = times.simulation / total_s;
  state.counters["share_deposition"] = times.deposition / total_s;
  state.counters["share_metrics"] = times.metrics / total_s;
  state.counters["share_arm_stats"] = times.arm_stats / total_s;  // within metrics
}
BENCHMARK(BM_ShembekarRealtime)
    ->ArgName("layers")
    ->Arg(1)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
