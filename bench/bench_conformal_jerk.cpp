// What a jerk limit costs the conformal planner's planning (jerk_time_law.hpp against
// TOPP-RA's law alone), on a conformal hatch: 12 lines of 40 mm over the wavy surface
// z = 3 sin(x / 5) mm, a point every 0.5 mm, tool axes the surface normals, 30 mm/s, TCP
// limits v_max 200, a_max 2000 (the Shembekar scenarios'), and j_max 50000 for the limited run.
//
//   BM_ConformalJerkOverFree  both plans in every iteration, alternately, on thread CPU time:
//                             jerk_over_free = CPU(j_max) / CPU(no j_max) (the issue's
//                             "must not blow up"), plan_ratio = the plans' durations likewise,
//                             free_ms and jerk_ms per plan.
#include <benchmark/benchmark.h>

#include <cmath>

#include "bench_clock.hpp"
#include "planners/planner.hpp"

using namespace depotwin;

namespace {

Toolpath wavy_hatch() {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(0, 0, 20);
  toolpath.end_mm = Vec3(40, 12, 20);
  for (int line = 0; line < 12; ++line) {
    PrintPath path;
    path.speed_mm_s = 30.0;
    path.source_index = line;
    const bool forward = line % 2 == 0;
    for (int i = 0; i <= 80; ++i) {
      const double x = 0.5 * (forward ? i : 80 - i);
      // z = 3 sin(x / 5): its normal (-dz/dx, 0, 1) normalised
      path.points.emplace_back(x, 1.0 * line, 3.0 * std::sin(x / 5.0));
      path.normals.push_back(Vec3(-0.6 * std::cos(x / 5.0), 0.0, 1.0).normalized());
    }
    toolpath.paths.push_back(path);
  }
  return toolpath;
}

void BM_ConformalJerkOverFree(benchmark::State& state) {
  const Toolpath toolpath = wavy_hatch();
  const auto planner = make_planner(PlannerSpec{"conformal", {}, 0});
  const MachineLimits free_limits = MachineLimits::uniform(200.0, 2000.0);
  const MachineLimits jerk_limits = MachineLimits::uniform(200.0, 2000.0, 50000.0);
  double free_cpu_s = 0.0, jerk_cpu_s = 0.0, free_plan_s = 0.0, jerk_plan_s = 0.0;
  for (auto _ : state) {
    double t0 = bench::thread_cpu_s();
    const Trajectory free_plan = planner->plan(toolpath, free_limits);
    free_cpu_s += bench::thread_cpu_s() - t0;
    t0 = bench::thread_cpu_s();
    const Trajectory jerk_plan = planner->plan(toolpath, jerk_limits);
    jerk_cpu_s += bench::thread_cpu_s() - t0;
    free_plan_s = free_plan.duration_s();
    jerk_plan_s = jerk_plan.duration_s();
    benchmark::DoNotOptimize(free_plan);
    benchmark::DoNotOptimize(jerk_plan);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["free_ms"] = 1e3 * free_cpu_s / n;
  state.counters["jerk_ms"] = 1e3 * jerk_cpu_s / n;
  state.counters["jerk_over_free"] = jerk_cpu_s / free_cpu_s;
  state.counters["plan_ratio"] = jerk_plan_s / free_plan_s;
}
BENCHMARK(BM_ConformalJerkOverFree)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
