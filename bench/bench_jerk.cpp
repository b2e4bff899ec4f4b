// Speed of jerk-limited minimum-time moves (double-S family, src/motion/jerk.hpp): one axis,
// and three axes synchronised to one duration; the acceleration-limited move for scale.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "motion/jerk.hpp"
#include "motion/mtt.hpp"
#include "motion/sync.hpp"

using namespace depotwin;

namespace {

constexpr double kVmax = 4.0, kAmax = 30.0, kJmax = 500.0;

// random boundary conditions, precomputed so the loop measures only the move; one in ten is
// a short move, where overshoot and blocked durations live
std::vector<AxisBoundary> random_boundaries(size_t count) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-50, 50), vel(-kVmax, kVmax);
  std::vector<AxisBoundary> out(count);
  for (size_t i = 0; i < count; ++i) {
    out[i] = {pos(rng), pos(rng), vel(rng), vel(rng)};
    if (i % 10 == 0) out[i].q1 = out[i].q0 + 0.01 * pos(rng);
  }
  return out;
}

void BM_JerkMinimumTimeMove1D(benchmark::State& state) {
  const auto boundaries = random_boundaries(4096);
  size_t i = 0;
  for (auto _ : state) {
    AxisProfile p = jerk_min_time_move(boundaries[i++ & 4095], kVmax, kAmax, kJmax);
    benchmark::DoNotOptimize(p);
  }
  state.counters["moves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_JerkMinimumTimeMove1D);

void BM_SynchronizedMove3D(benchmark::State& state) {
  const auto boundaries = random_boundaries(4096);
  std::vector<AxisMove> axes(3);
  size_t i = 0;
  for (auto _ : state) {
    for (size_t k = 0; k < 3; ++k) axes[k] = {boundaries[(i + k) & 4095], kVmax, kAmax, kJmax};
    ++i;
    SynchronizedMove m = synchronized_move(axes);
    benchmark::DoNotOptimize(m);
  }
  state.counters["moves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SynchronizedMove3D);

// the acceleration-limited move on the same boundaries, for scale
void BM_AccelerationMinimumTimeMove1D(benchmark::State& state) {
  const auto boundaries = random_boundaries(4096);
  size_t i = 0;
  for (auto _ : state) {
    AxisProfile p = min_time_move(boundaries[i++ & 4095], kVmax, kAmax);
    benchmark::DoNotOptimize(p);
  }
  state.counters["moves_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AccelerationMinimumTimeMove1D);

}  // namespace

BENCHMARK_MAIN();
