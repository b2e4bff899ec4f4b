// Print-ordering speed at scale (issue 6): the sequencers alone are timed (no lower
// bound); the gap to the exact matching lower bound is reported as counters, the bound
// computed once per instance outside the timing.
//
// Instances: N random non-crossing segments, lengths U[10, 40] mm, on a square bed of
// side 10 sqrt(N) mm (the density of the paper's N = 100 case), machine limits 4 mm/s
// and 30 mm/s^2 per axis, print at 3 mm/s.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "planners/ordering/lower_bound.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"
#include "toolpath/random_segments.hpp"

namespace {

using namespace depotwin;

const MachineLimits kLimits = MachineLimits::uniform(4.0, 30.0);

const Toolpath& instance(int count) {
  static std::map<int, Toolpath> cache;
  auto it = cache.find(count);
  if (it == cache.end()) {
    RandomSegmentsSpec spec;
    spec.count = count;
    spec.bed_x_mm = spec.bed_y_mm = 10.0 * std::sqrt(static_cast<double>(count));
    spec.seed = 1;
    it = cache.emplace(count, make_random_segments(spec)).first;
  }
  return it->second;
}

double lower_bound_s(int count, const std::string& cost_model) {
  static std::map<std::pair<int, std::string>, double> cache;
  auto it = cache.find({count, cost_model});
  if (it == cache.end()) {
    const TransitionCost cost(instance(count), kLimits, parse_cost_model(cost_model));
    it = cache.emplace(std::make_pair(count, cost_model), matching_lower_bound(cost)).first;
  }
  return it->second;
}

void sequence_benchmark(benchmark::State& state, std::string method, std::string refine,
                        std::string cost_model) {
  const int count = static_cast<int>(state.range(0));
  const Toolpath& toolpath = instance(count);
  OrderSpec spec;
  spec.method = method, spec.refine = refine, spec.cost_model = cost_model;
  SequencerOptions options;
  options.lower_bound = false;
  OrderResult result;
  for (auto _ : state) {
    result = sequence(toolpath, kLimits, spec, options);
    benchmark::DoNotOptimize(result.cost_s);
  }
  const double bound_s = lower_bound_s(count, cost_model);
  state.counters["cost_s"] = result.cost_s;
  state.counters["lower_bound_s"] = bound_s;
  state.counters["gap_pct"] = 100.0 * (result.cost_s - bound_s) / bound_s;
}

// name, sizes, iterations (1 for the long ones)
void register_all() {
  struct Case {
    const char* method;
    const char* refine;
    std::vector<int> sizes;
  };
  const Case cases[] = {
      {"nearest_neighbor", "", {1000, 10000, 100000}},
      {"nearest_neighbor", "two_opt", {1000, 10000, 100000}},
      {"nearest_neighbor", "or_opt", {1000, 10000}},
      {"nearest_neighbor", "three_opt", {1000, 10000}},
      {"christofides", "", {1000, 10000}},
      {"christofides", "two_opt", {1000, 10000}},
      {"christofides", "three_opt", {1000, 10000}},
  };
  for (const char* cost_model : {"machine", "along_line"}) {
    for (const Case& c : cases) {
      const std::string name = std::string("sequence/") + cost_model + "/" + c.method +
                               (c.refine[0] ? std::string("+") + c.refine : "");
      auto* bench = benchmark::RegisterBenchmark(name.c_str(), sequence_benchmark, c.method,
                                                 c.refine, cost_model);
      for (int size : c.sizes) bench->Arg(size);
      bench->Unit(benchmark::kMillisecond)->Iterations(1);
    }
  }
  // the exact lower bound itself (pricing on the neighbour-list graph)
  benchmark::RegisterBenchmark(
      "lower_bound/machine",
      [](benchmark::State& state) {
        const TransitionCost cost(instance(static_cast<int>(state.range(0))), kLimits,
                                  CostModel::machine);
        MatchingBoundStats stats;
        for (auto _ : state) benchmark::DoNotOptimize(matching_lower_bound(cost, &stats));
        state.counters["rounds"] = stats.rounds;
        state.counters["added_pairs"] = static_cast<double>(stats.added_pairs);
      })
      ->Arg(1000)
      ->Arg(10000)
      ->Arg(100000)
      ->Unit(benchmark::kMillisecond)
      ->Iterations(1);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
