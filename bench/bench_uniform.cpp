// Speed of `uniform` (issue 16): planning time per segment against lspb_mtt on the same
// toolpaths in the same run, 10^3, 10^4 and 10^5 segments (chains of 1..4
// connected segments on a 90 mm bed, random turns at every joint). Each of uniform's corners plans
// and deposits its candidates (deposition model), which is what its time goes to;
// `BM_UniformIsolated` runs the same toolpath as isolated segments (no corners: the time law and
// the transitions alone). `BM_UniformLayers` prints 10^3 segments' chains on 10 layers, the same
// (x, y) on each (a slicer's repeated layers), with each corner's decision reused from the
// first layer (CornerDecisionCache) and with every corner predicted: the ratio of the two is
// what the reuse saves.
#include <benchmark/benchmark.h>

#include <random>

#include "planners/motion/lspb_mtt.hpp"
#include "planners/motion/uniform/uniform_planner.hpp"

using namespace depotwin;

namespace {

// n segments in chains of 1..4 (corners: about 3/5 of the segments), or all isolated
Toolpath segments_toolpath(int n, bool chains) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> coordinate(-45, 45), step(-3, 3);
  Toolpath toolpath;
  int made = 0;
  while (made < n) {
    PrintPath path;
    path.speed_mm_s = 3.0;
    path.source_index = static_cast<int>(toolpath.paths.size());
    Vec3 p(coordinate(rng), coordinate(rng), 0);
    path.points.push_back(p);
    const int edges = chains ? 1 + made % 4 : 1;
    for (int k = 0; k < edges && made < n; ++k, ++made) {
      Vec3 q = p + Vec3(step(rng), step(rng), 0);
      if ((q - p).norm() < 0.5) q += Vec3(0.6, 0, 0);
      path.points.push_back(q);
      p = q;
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

void plan(benchmark::State& state, const Planner& planner, bool chains) {
  const Toolpath toolpath = segments_toolpath(static_cast<int>(state.range(0)), chains);
  const MachineLimits limits = MachineLimits::uniform(4, 30);
  for (auto _ : state) {
    Trajectory t = planner.plan(toolpath, limits);
    benchmark::DoNotOptimize(t);
  }
  state.SetComplexityN(state.range(0));
  state.counters["segments_per_s"] =
      benchmark::Counter(state.iterations() * state.range(0), benchmark::Counter::kIsRate);
}

// the chains of segments_toolpath(n) repeated on `layers` layers 0.2 mm apart
Toolpath layered_toolpath(int n, int layers) {
  const Toolpath one = segments_toolpath(n, true);
  Toolpath toolpath;
  for (int layer = 0; layer < layers; ++layer)
    for (PrintPath path : one.paths) {
      for (Vec3& p : path.points) p.z() += 0.2 * layer;
      path.layer = layer;
      path.source_index = static_cast<int>(toolpath.paths.size());
      toolpath.paths.push_back(path);
    }
  return toolpath;
}

void BM_UniformLayers(benchmark::State& state) {
  const int layers = static_cast<int>(state.range(1));
  const Toolpath toolpath = layered_toolpath(static_cast<int>(state.range(0)), layers);
  UniformSettings settings;
  settings.reuse_corner_decisions = state.range(2) != 0;
  const UniformPlanner planner(settings);
  const MachineLimits limits = MachineLimits::uniform(4, 30);
  for (auto _ : state) {
    Trajectory t = planner.plan(toolpath, limits);
    benchmark::DoNotOptimize(t);
  }
  state.counters["segments_per_s"] =
      benchmark::Counter(state.iterations() * state.range(0) * layers, benchmark::Counter::kIsRate);
}

void BM_LspbMtt(benchmark::State& state) {
  plan(state, LspbMttPlanner(), true);
}
void BM_Uniform(benchmark::State& state) {
  plan(state, UniformPlanner(UniformSettings{}), true);
}
void BM_UniformIsolated(benchmark::State& state) {
  plan(state, UniformPlanner(UniformSettings{}), false);
}

BENCHMARK(BM_LspbMtt)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity();
BENCHMARK(BM_Uniform)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity();
BENCHMARK(BM_UniformIsolated)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond)->Complexity();
BENCHMARK(BM_UniformLayers)
    ->ArgNames({"segments", "layers", "reuse"})
    ->Args({1000, 10, 1})
    ->Args({1000, 10, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
