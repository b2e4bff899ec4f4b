// Planning time against the number of print segments (issue 16's target: a 10^4-segment
// toolpath planned in at most 1 s on one core, the time growing linearly with the segments):
// every planner that plans an arbitrary planar toolpath (lspb_mtt, stop_and_go, bezier,
// firmware) on 10^3, 10^4 and 10^5 segments of one slicer-like toolpath, and uniform on 10^3
// and 10^4.
//
// Two measures per size, each against the same planner on the first 10^3 segments measured in
// the same benchmark (as many times as make the same number of segments: 10x at 10^4, 100x at
// 10^5), so that `..._vs_1e3` is the cost per segment at this size over that at 10^3 (1.0:
// linear; 10 at 10^4 would be quadratic):
// - fresh (the benchmark's time, s_per_plan, us_per_segment, per_segment_vs_1e3): one plan in a
//   freshly forked process, as `depotwin plan` or `run` plans once. Its CPU time (this core)
//   includes the page faults of first touching the plan's memory (minor_faults_per_segment);
// - warm (warm_us_per_segment, warm_vs_1e3): the same plan repeated in one process, the best
//   of three. A 10^3-segment plan then reuses the heap a previous one left (no page faults),
//   while a larger one outgrows it and faults its memory in again, so warm per-segment costs
//   rise with the size even when the work per segment does not.
//
//   build/bench/bench_planning_scale --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <random>

#include "bench_clock.hpp"
#include "planners/planner.hpp"

using namespace depotwin;

namespace {

constexpr int kBaselineSegments = 1000;

// A slicer-like planar toolpath of `segments` print segments: chains (polylines) of 1 to 12
// connected segments 0.4 to 2 mm long turning by up to 90 degrees at each joint, the next
// chain starting within 3 mm of the last one's end (a short travel, as between a slicer's
// perimeters and infill), on a 200 x 200 mm bed, printed at 40 mm/s. The same seed gives the
// same toolpath, and a toolpath of n segments is the first n of a larger one.
Toolpath slicer_like_toolpath(int segments) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Toolpath toolpath;
  toolpath.start_mm = Vec3(0, 0, 0);
  Vec3 at(0, 0, 0);
  double heading_rad = 0.0;
  int made = 0;
  while (made < segments) {
    PrintPath path;
    path.speed_mm_s = 40.0;
    path.source_index = static_cast<int>(toolpath.paths.size());
    // a short travel to the chain's start, kept on the bed
    at += Vec3(6.0 * unit(rng) - 3.0, 6.0 * unit(rng) - 3.0, 0.0);
    at = at.cwiseMax(Vec3(-100, -100, 0)).cwiseMin(Vec3(100, 100, 0));
    path.points.push_back(at);
    const int chain = 1 + static_cast<int>(12 * unit(rng));
    for (int k = 0; k < chain && made < segments; ++k, ++made) {
      heading_rad += (unit(rng) - 0.5) * kPi;  // a turn of up to 90 degrees either way
      const double length_mm = 0.4 + 1.6 * unit(rng);
      Vec3 next = at + length_mm * Vec3(std::cos(heading_rad), std::sin(heading_rad), 0.0);
      // turn back at the bed's edge
      if (std::abs(next.x()) > 100.0 || std::abs(next.y()) > 100.0) {
        heading_rad += kPi;
        next = at + length_mm * Vec3(std::cos(heading_rad), std::sin(heading_rad), 0.0);
      }
      path.points.push_back(next);
      at = next;
    }
    toolpath.paths.push_back(std::move(path));
  }
  toolpath.end_mm = at + Vec3(5, 5, 0);
  return toolpath;
}

// a desktop printer's x and y (Klipper's cartesian defaults): 300 mm/s, 3000 mm/s^2
MachineLimits printer_limits() {
  return MachineLimits::uniform(300.0, 3000.0);
}

// one plan of the toolpath in this process: thread CPU seconds (one core)
double plan_cpu_s(const Planner& planner, const Toolpath& toolpath, const MachineLimits& limits) {
  const double start_s = bench::thread_cpu_s();
  Trajectory plan = planner.plan(toolpath, limits);
  benchmark::DoNotOptimize(plan);
  return bench::thread_cpu_s() - start_s;
}

// what one plan cost in a fresh process
struct FreshPlan {
  double cpu_s = 0.0;
  double minor_faults = 0.0;
};

// one plan in a forked child (a fresh heap: the parent never plans), which sends back its
// thread CPU seconds and minor page faults through a pipe
FreshPlan plan_in_fresh_process(const Planner& planner, const Toolpath& toolpath,
                                const MachineLimits& limits) {
  int channel[2];
  if (::pipe(channel) != 0) std::abort();
  const pid_t child = ::fork();
  if (child < 0) std::abort();
  if (child == 0) {
    ::close(channel[0]);
    rusage before{}, after{};
    ::getrusage(RUSAGE_THREAD, &before);
    FreshPlan result;
    result.cpu_s = plan_cpu_s(planner, toolpath, limits);
    ::getrusage(RUSAGE_THREAD, &after);
    result.minor_faults = static_cast<double>(after.ru_minflt - before.ru_minflt);
    const bool sent = ::write(channel[1], &result, sizeof result) == sizeof result;
    ::_exit(sent ? 0 : 1);
  }
  ::close(channel[1]);
  FreshPlan result;
  const bool received = ::read(channel[0], &result, sizeof result) == sizeof result;
  ::close(channel[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (!received || !WIFEXITED(status) || WEXITSTATUS(status) != 0) std::abort();
  return result;
}

// the best of `repeats` plans in this process (warm heap)
double warm_plan_cpu_s(const Planner& planner, const Toolpath& toolpath,
                       const MachineLimits& limits, int repeats) {
  double best_s = 1e300;
  for (int r = 0; r < repeats; ++r)
    best_s = std::min(best_s, plan_cpu_s(planner, toolpath, limits));
  return best_s;
}

// BM_Plan/<planner>/<segments>: per iteration the toolpath planned once in a fresh process
// (the iteration's time) and the 10^3-segment baseline as many times as make the same number
// of segments, also each in a fresh process; then the warm figures for both
void plan_scale(benchmark::State& state, const char* planner_name) {
  const int segments = static_cast<int>(state.range(0));
  const Toolpath toolpath = slicer_like_toolpath(segments);
  const Toolpath baseline = slicer_like_toolpath(kBaselineSegments);
  const MachineLimits limits = printer_limits();
  const auto planner = make_planner(PlannerSpec{planner_name, {}, 0});
  const int baseline_repeats = std::max(1, segments / kBaselineSegments);
  double plan_s = 0.0, baseline_s = 0.0, faults = 0.0;
  for (auto _ : state) {
    const FreshPlan fresh = plan_in_fresh_process(*planner, toolpath, limits);
    state.SetIterationTime(fresh.cpu_s);
    plan_s += fresh.cpu_s;
    faults += fresh.minor_faults;
    state.PauseTiming();
    for (int r = 0; r < baseline_repeats; ++r)
      baseline_s += plan_in_fresh_process(*planner, baseline, limits).cpu_s;
    state.ResumeTiming();
  }
  const double iterations = static_cast<double>(state.iterations());
  const double per_segment_s = plan_s / iterations / segments;
  const double baseline_per_segment_s =
      baseline_s / (iterations * baseline_repeats) / kBaselineSegments;
  // warm: the baseline first (its heap then serves it), then this size
  const double warm_baseline_per_segment_s =
      warm_plan_cpu_s(*planner, baseline, limits, 3) / kBaselineSegments;
  const double warm_per_segment_s = warm_plan_cpu_s(*planner, toolpath, limits, 3) / segments;
  state.counters["segments"] = segments;
  state.counters["s_per_plan"] = plan_s / iterations;
  state.counters["us_per_segment"] = 1e6 * per_segment_s;
  state.counters["per_segment_vs_1e3"] = per_segment_s / baseline_per_segment_s;
  state.counters["minor_faults_per_segment"] = faults / iterations / segments;
  state.counters["warm_us_per_segment"] = 1e6 * warm_per_segment_s;
  state.counters["warm_vs_1e3"] = warm_per_segment_s / warm_baseline_per_segment_s;
  state.SetComplexityN(segments);
}

// sizes 10^3 up to largest_segments
void register_planner(const char* planner_name, int largest_segments) {
  auto* bench = benchmark::RegisterBenchmark(
      (std::string("BM_Plan/") + planner_name).c_str(),
      [planner_name](benchmark::State& state) { plan_scale(state, planner_name); });
  for (int segments = kBaselineSegments; segments <= largest_segments; segments *= 10)
    bench->Arg(segments);
  bench->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
}

}  // namespace

int main(int argc, char** argv) {
  for (const char* name : {"lspb_mtt", "stop_and_go", "bezier", "firmware"})
    register_planner(name, 100000);
  // uniform predicts the deposit at each corner (about 0.2 ms per segment here): 10^4 at most,
  // its 10^5 (three plans, 300 baseline plans, three warm ones) would add minutes
  register_planner("uniform", 10000);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
