// Deposition kernel cost per simulation step (ns per advance), the number that decides
// whether recording a 1e5..1e6-step run is negligible next to the physics. Batched (the
// default: one 4-node quadrature per sigma of path) and unbatched (every step its own
// footprint box, batch_length_sigmas = 0) side by side; the batched runs flush once at
// the end so every step's material is in the field.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>

#include "core/types.hpp"
#include "deposition/process.hpp"

namespace {

using depotwin::DepositionSettings;
using depotwin::DepositionStep;
using depotwin::ProcessType;
using depotwin::Vec3;

// nozzle on a circle of radius_mm at speed_mm_s: the field stays bounded however long it runs
Vec3 on_circle(double t_s, double radius_mm, double speed_mm_s) {
  const double angle = speed_mm_s * t_s / radius_mm;
  return Vec3(radius_mm * std::cos(angle), radius_mm * std::sin(angle), 0.0);
}

void run_steps(benchmark::State& state, depotwin::Process& process, double radius_mm,
               double speed_mm_s, double dt_s) {
  DepositionStep step;
  step.open0 = step.open1 = 1.0;
  step.flow_command = 1.0;
  step.desired_speed_mm_s = speed_mm_s;
  long long k = 0;
  for (auto _ : state) {
    step.t0_s = static_cast<double>(k) * dt_s;
    step.t1_s = step.t0_s + dt_s;
    step.p0_mm = on_circle(step.t0_s, radius_mm, speed_mm_s);
    step.p1_mm = on_circle(step.t1_s, radius_mm, speed_mm_s);
    process.advance(step);
    ++k;
  }
  process.flush();
  benchmark::DoNotOptimize(process.account().landed_mm3);
  state.counters["allocated_cells"] = static_cast<double>(process.field().allocated_cells());
  const depotwin::StepBatch::Stats& stats = process.batch_stats();
  state.counters["steps_per_box"] =
      static_cast<double>(stats.steps) /
      static_cast<double>(std::max(1L, stats.quadratures + stats.single_steps));
}

DepositionSettings aerosol(double batch_length_sigmas) {
  DepositionSettings settings;
  settings.type = ProcessType::aerosol;
  settings.sigma_mm = 0.1;
  settings.batch_length_sigmas = batch_length_sigmas;
  return settings;
}

DepositionSettings extrusion(double batch_length_sigmas) {
  DepositionSettings settings;
  settings.type = ProcessType::extrusion;
  settings.batch_length_sigmas = batch_length_sigmas;
  return settings;
}

// aerosol: sigma 0.1 mm, cell sigma/4, 3 mm/s, 1 ms steps (3 um chords; a ~43 x 43-cell
// box per footprint)
void BM_AerosolStep1ms(benchmark::State& state) {
  depotwin::AerosolProcess process(aerosol(1.0), 0.025);
  run_steps(state, process, 5.0, 3.0, 1e-3);
}
BENCHMARK(BM_AerosolStep1ms);

void BM_AerosolStep1msUnbatched(benchmark::State& state) {
  depotwin::AerosolProcess process(aerosol(0.0), 0.025);
  run_steps(state, process, 5.0, 3.0, 1e-3);
}
BENCHMARK(BM_AerosolStep1msUnbatched);

// aerosol at 10 um cells (sigma/10): the sparsity test's resolution
void BM_AerosolStep1msFineCells(benchmark::State& state) {
  depotwin::AerosolProcess process(aerosol(1.0), 0.01);
  run_steps(state, process, 5.0, 3.0, 1e-3);
}
BENCHMARK(BM_AerosolStep1msFineCells);

void BM_AerosolStep1msFineCellsUnbatched(benchmark::State& state) {
  depotwin::AerosolProcess process(aerosol(0.0), 0.01);
  run_steps(state, process, 5.0, 3.0, 1e-3);
}
BENCHMARK(BM_AerosolStep1msFineCellsUnbatched);

// extrusion: bead 0.4 x 0.2 mm, cell w/8, 30 mm/s, 1 ms steps (0.3 sigma), lagging flow
void BM_ExtrusionStep1ms(benchmark::State& state) {
  depotwin::ExtrusionProcess process(extrusion(1.0), 0.0);
  run_steps(state, process, 20.0, 30.0, 1e-3);
}
BENCHMARK(BM_ExtrusionStep1ms);

void BM_ExtrusionStep1msUnbatched(benchmark::State& state) {
  depotwin::ExtrusionProcess process(extrusion(0.0), 0.0);
  run_steps(state, process, 20.0, 30.0, 1e-3);
}
BENCHMARK(BM_ExtrusionStep1msUnbatched);

}  // namespace

BENCHMARK_MAIN();
