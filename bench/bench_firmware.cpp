// Speed of the firmware baseline: plan a whole 20 mm cube, every layer (issue 14's target: at
// most 2 s), against lspb_mtt on the same toolpath as the baseline measured in the same run.
#include <benchmark/benchmark.h>

#include "planners/planner.hpp"

using namespace depotwin;

namespace {

// A 20 mm cube sliced at 0.2 mm: per layer a closed square perimeter and a zig-zag infill at
// 0.4 mm pitch (alternately along x and y), as one slicer would print it.
Toolpath cube_toolpath(int layers) {
  Toolpath toolpath;
  const double size = 20.0, pitch = 0.4, layer_height = 0.2, speed = 60.0;
  for (int layer = 0; layer < layers; ++layer) {
    const double z = layer_height * (layer + 1);
    PrintPath perimeter;
    perimeter.points = {{0, 0, z}, {size, 0, z}, {size, size, z}, {0, size, z}, {0, 0.0, z}};
    perimeter.speed_mm_s = speed;
    perimeter.layer = layer;
    // the last edge stops short of the start, as slicers leave a seam gap
    perimeter.points.back().y() = pitch;
    PrintPath infill;
    infill.speed_mm_s = speed;
    infill.layer = layer;
    const bool along_x = layer % 2 == 0;
    for (int line = 0; pitch * (line + 1) < size; ++line) {
      const double across = pitch * (line + 1);
      const double from = line % 2 == 0 ? pitch : size - pitch, to = size - from;
      const auto point = [&](double along) {
        return along_x ? Vec3(along, across, z) : Vec3(across, along, z);
      };
      infill.points.push_back(point(from));
      infill.points.push_back(point(to));
    }
    perimeter.source_index = static_cast<int>(toolpath.paths.size());
    toolpath.paths.push_back(perimeter);
    infill.source_index = static_cast<int>(toolpath.paths.size());
    toolpath.paths.push_back(infill);
  }
  toolpath.start_mm = Vec3(0, 0, 0.2);
  toolpath.end_mm = Vec3(0, 0, 30);
  return toolpath;
}

// a desktop cartesian printer: fast x and y, slow z
MachineLimits printer_limits() {
  MachineLimits limits = MachineLimits::uniform(300.0, 3000.0);
  limits.axes[2] = AxisLimits{15.0, 200.0, 0.0};
  return limits;
}

void plan_cube(benchmark::State& state, const PlannerSpec& spec) {
  const Toolpath toolpath = cube_toolpath(100);
  const MachineLimits limits = printer_limits();
  const auto planner = make_planner(spec);
  size_t moves = 0;
  for (const PrintPath& path : toolpath.paths) moves += path.points.size() - 1;
  double duration = 0.0;
  for (auto _ : state) {
    Trajectory plan = planner->plan(toolpath, limits);
    duration = plan.duration_s();
    benchmark::DoNotOptimize(plan);
  }
  state.counters["print_moves"] = static_cast<double>(moves);
  state.counters["job_time_s"] = duration;
  state.counters["moves_per_s"] = benchmark::Counter(
      static_cast<double>(moves) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_FirmwareMarlinCube(benchmark::State& state) {
  plan_cube(state, {"firmware", {}, 0});
}
BENCHMARK(BM_FirmwareMarlinCube)->Unit(benchmark::kMillisecond);

void BM_FirmwareKlipperCube(benchmark::State& state) {
  plan_cube(state, {"firmware", {}, 0, {{"mode", "klipper"}}});
}
BENCHMARK(BM_FirmwareKlipperCube)->Unit(benchmark::kMillisecond);

// the baseline: the project's own time-optimal planner on the same cube
void BM_LspbMttCube(benchmark::State& state) {
  plan_cube(state, {"lspb_mtt", {}, 0});
}
BENCHMARK(BM_LspbMttCube)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
