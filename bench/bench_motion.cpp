// Speed of the planning half: one minimum-time move, and lspb_mtt over many segments
// (planning time must grow linearly with the segment count).
#include <benchmark/benchmark.h>

#include <random>

#include "motion/mtt.hpp"
#include "motion/sync.hpp"
#include "planners/motion/lspb_mtt.hpp"

using namespace depotwin;

namespace {

// random boundary conditions, precomputed so the loop measures only the move
std::vector<AxisBoundary> random_boundaries(size_t count) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-50, 50), vel(-4, 4);
  std::vector<AxisBoundary> out(count);
  for (AxisBoundary& b : out) b = {pos(rng), pos(rng), vel(rng), vel(rng)};
  return out;
}

void BM_MinimumTimeMove1D(benchmark::State& state) {
  const auto boundaries = random_boundaries(4096);
  size_t i = 0;
  for (auto _ : state) {
    AxisProfile p = min_time_move(boundaries[i++ & 4095], 4.0, 30.0);
    benchmark::DoNotOptimize(p);
  }
  state.counters["moves_per_s"] =
      benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MinimumTimeMove1D);

void BM_SynchronizedMove2D(benchmark::State& state) {
  const auto boundaries = random_boundaries(4096);
  size_t i = 0;
  for (auto _ : state) {
    const std::vector<AxisMove> axes{{boundaries[i & 4095], 4, 30},
                                     {boundaries[(i + 1) & 4095], 4, 30}};
    ++i;
    SynchronizedMove m = synchronized_move(axes);
    benchmark::DoNotOptimize(m);
  }
  state.counters["moves_per_s"] =
      benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynchronizedMove2D);

// a toolpath of n segments: chains of 1..4 connected segments on a 100 mm bed
Toolpath segments_toolpath(int n) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> coordinate(-45, 45), step(-3, 3);
  Toolpath toolpath;
  int made = 0;
  while (made < n) {
    PrintPath path;
    path.speed_mm_s = 3.0;
    Vec3 p(coordinate(rng), coordinate(rng), 0);
    path.points.push_back(p);
    for (int k = 0; k < 1 + made % 4 && made < n; ++k, ++made) {
      Vec3 q = p + Vec3(step(rng), step(rng), 0);
      if ((q - p).norm() < 0.1) q += Vec3(0.2, 0, 0);
      path.points.push_back(q);
      p = q;
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

void BM_PlanLspbMtt(benchmark::State& state) {
  const Toolpath toolpath = segments_toolpath(static_cast<int>(state.range(0)));
  const MachineLimits limits = MachineLimits::uniform(4, 30);
  for (auto _ : state) {
    Trajectory t = LspbMttPlanner().plan(toolpath, limits);
    benchmark::DoNotOptimize(t);
  }
  state.SetComplexityN(state.range(0));
  state.counters["segments_per_s"] =
      benchmark::Counter(state.iterations() * state.range(0), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PlanLspbMtt)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity();

}  // namespace

BENCHMARK_MAIN();
