// Deposition kernel cost per simulation step (ns per advance), the number that decides
// whether recording a 1e5..1e6-step run is negligible next to the physics. Batched (the
// default: one 4-node quadrature per sigma of path) and unbatched (every step its own
// footprint box, batch_length_sigmas = 0) side by side; the batched runs flush once at
// the end so every step's material is in the field.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/toolpath.hpp"
#include "core/types.hpp"
#include "deposition/deposition_metrics.hpp"
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

// Scoring a slicer-like deposit (deposition_metrics.hpp: the band's cells by their share, the
// thickness figures, the material split) against laying it down: an extrusion spiral of 0.5 mm
// chords, 2 mm apart, 600 mm at 30 mm/s in 1 ms steps, scored whole each iteration.
// `score_over_deposit`: one scoring's time over the deposit's (the quickest of three), in the
// same run.
void BM_ScoreSpiralAgainstItsDeposit(benchmark::State& state) {
  depotwin::Toolpath toolpath;
  depotwin::PrintPath path;
  path.speed_mm_s = 30.0;
  for (double s = 0.0, angle = 0.0; s <= 600.0; s += 0.5) {
    const double radius = 2.0 + 2.0 * angle / (2.0 * M_PI);  // 2 mm further each turn
    path.points.emplace_back(radius * std::cos(angle), radius * std::sin(angle), 0.0);
    angle += 0.5 / radius;
  }
  toolpath.paths.push_back(path);
  // the deposit: the nozzle along the chords at the print speed, 1 ms steps; laid down three
  // times in fresh processes, the quickest kept as the baseline
  const auto lay_down = [&](depotwin::Process& process) {
    DepositionStep step;
    step.open0 = step.open1 = 1.0;
    step.flow_command = 1.0;
    step.desired_speed_mm_s = path.speed_mm_s;
    double t_s = 0.0;
    for (std::size_t k = 0; k + 1 < path.points.size(); ++k) {
      const Vec3 a = path.points[k], b = path.points[k + 1];
      const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.03)));
      for (int i = 0; i < steps; ++i) {
        step.t0_s = t_s;
        step.t1_s = t_s += (b - a).norm() / steps / path.speed_mm_s;
        step.p0_mm = a + (b - a) * (static_cast<double>(i) / steps);
        step.p1_mm = a + (b - a) * (static_cast<double>(i + 1) / steps);
        process.advance(step);
      }
    }
    process.flush();
  };
  double deposit_s = std::numeric_limits<double>::infinity();
  for (int round = 0; round < 2; ++round) {
    depotwin::ExtrusionProcess scratch(extrusion(1.0), 0.0);
    const auto start = std::chrono::steady_clock::now();
    lay_down(scratch);
    deposit_s = std::min(
        deposit_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  depotwin::ExtrusionProcess process(extrusion(1.0), 0.0);
  {
    const auto start = std::chrono::steady_clock::now();
    lay_down(process);
    deposit_s = std::min(
        deposit_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  double scored_s = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const depotwin::DepositionMetrics metrics = depotwin::evaluate_deposition(
        process.field(), toolpath, process.line_width_mm(), process.account());
    scored_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    benchmark::DoNotOptimize(metrics.thickness.cv);
  }
  state.counters["score_over_deposit"] =
      scored_s / static_cast<double>(state.iterations()) / deposit_s;
  state.counters["chords"] = static_cast<double>(path.points.size() - 1);
}
BENCHMARK(BM_ScoreSpiralAgainstItsDeposit)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
