// The path error's distances (metrics/polyline_distance.hpp): 1 ms samples measured against
// one long print path, the binned search against the plain loop over every segment
// (distance_to_polyline) in the same run. The path: a spiral of N chords of 0.5 mm printed at
// 30 mm/s (a slicer's vase mode, a conformal hatch), samples 0.02 mm off it; N = 10^3, 10^4.
// The ratio to read: plain / binned per sample, which grows with N (the plain loop is
// O(N) per sample, the binned one about constant).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "metrics/motion_metrics.hpp"
#include "metrics/polyline_distance.hpp"

using namespace depotwin;

namespace {

constexpr double kChord_mm = 0.5, kSpeed_mm_s = 30.0, kSample_s = 0.001;

// a flat spiral of `chords` chords of about kChord_mm, from radius 40 mm inwards
std::vector<Vec3> spiral(int chords) {
  std::vector<Vec3> points;
  double angle = 0.0;
  for (int k = 0; k <= chords; ++k) {
    const double r = 40.0 - 35.0 * k / chords;
    points.emplace_back(r * std::cos(angle), r * std::sin(angle), 0.2);
    angle += kChord_mm / r;
  }
  return points;
}

// the samples along it every kSample_s at kSpeed_mm_s, each 0.02 mm off to the side
std::vector<Vec3> samples_along(const std::vector<Vec3>& path) {
  std::vector<Vec3> samples;
  const double step = kSpeed_mm_s * kSample_s;
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    const Vec3 d = path[k + 1] - path[k];
    const Vec3 side = Vec3(-d.y(), d.x(), 0.0).normalized() * 0.02;
    for (double s = 0.0; s < d.norm(); s += step)
      samples.push_back(path[k] + d * (s / d.norm()) + side);
  }
  return samples;
}

void BM_PathErrorPlainLoop(benchmark::State& state) {
  const std::vector<Vec3> path = spiral(static_cast<int>(state.range(0)));
  const std::vector<Vec3> samples = samples_along(path);
  for (auto _ : state) {
    double worst = 0.0;
    for (const Vec3& p : samples) worst = std::max(worst, distance_to_polyline(p, path));
    benchmark::DoNotOptimize(worst);
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * samples.size()), benchmark::Counter::kIsRate);
}

// the binned search, its grid built in every iteration (as path_error builds it once per path)
void BM_PathErrorBinned(benchmark::State& state) {
  const std::vector<Vec3> path = spiral(static_cast<int>(state.range(0)));
  const std::vector<Vec3> samples = samples_along(path);
  for (auto _ : state) {
    const PolylineDistance distance(path);
    double worst = 0.0;
    for (const Vec3& p : samples) worst = std::max(worst, distance(p));
    benchmark::DoNotOptimize(worst);
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * samples.size()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_PathErrorPlainLoop)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PathErrorBinned)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
