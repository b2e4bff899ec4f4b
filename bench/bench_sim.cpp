// What the twin costs per step on the XY stage, and what a scene image costs.
//   BM_RawStep          bare mj_step on models/xy_stage.xml (servos holding position)
//   BM_FullRun          Simulation::run: plan sampling and IK, controller, recording and an
//                       on_step callback, on the same model, per step
//   BM_FullOverRaw      both on the same number of steps, reported as a ratio
//   BM_RenderScene      one 640 x 480 scene.png worth of rendering (context, scene, read back)
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>

#include "kinematics/xy_stage.hpp"
#include "planners/motion/transition.hpp"
#include "render/scene.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

const std::string kModel = std::string(DEPOTWIN_MODELS_DIR) + "/xy_stage.xml";

// a straight print at 3 mm/s along x with transitions from and to rest, about `seconds` long
Trajectory straight_print(double seconds) {
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  const Vec3 velocity(3.0, 0.0, 0.0);
  const double length_mm = 3.0 * (seconds - 0.2);
  const Vec3 start(-0.5 * length_mm - 0.15, 0.0, 0.0);
  const Vec3 print_start = start + Vec3(0.15, 0, 0);
  std::vector<TrajectoryPiece> pieces;
  pieces.push_back(transition_piece(0.0, start, Vec3::Zero(), print_start, velocity, limits));
  TrajectoryPiece print;
  print.t_begin_s = pieces.back().t_end_s;
  print.t_end_s = print.t_begin_s + length_mm / 3.0;
  print.path_index = 0;
  print.depositing = true;
  print.desired_speed_mm_s = 3.0;
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) {
    AxisProfile profile(print_start[axis], velocity[axis]);
    profile.append(print.t_end_s - print.t_begin_s, 0.0);
    motion.axes[axis] = profile;
  }
  print.motion = motion;
  pieces.push_back(print);
  const Vec3 print_end = print_start + Vec3(length_mm, 0, 0);
  pieces.push_back(transition_piece(print.t_end_s, print_end, velocity,
                                    print_end + Vec3(0.15, 0, 0), Vec3::Zero(), limits));
  return Trajectory("bench", std::move(pieces));
}

// the chord length walked by the nozzle: a cheap stand-in for the deposition callback
struct ChordSum {
  double length_mm = 0.0;
  void operator()(const StepState& before, const StepState& after) {
    length_mm += (after.nozzle_mm - before.nozzle_mm).norm();
  }
};

double raw_steps_seconds(long steps) {
  ModelPtr model = load_model(kModel);
  DataPtr data = make_data(*model);
  const auto start = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k) mj_step(model.get(), data.get());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BM_RawStep(benchmark::State& state) {
  ModelPtr model = load_model(kModel);
  DataPtr data = make_data(*model);
  for (auto _ : state) mj_step(model.get(), data.get());
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RawStep)->UseRealTime();

void BM_FullRun(benchmark::State& state) {
  const auto machine = make_xy_stage();
  Simulation simulation(kModel, *machine);
  const Trajectory trajectory = straight_print(10.0);
  long steps = 0;
  for (auto _ : state) {
    ChordSum chord;
    const RecordedRun run = simulation.run(trajectory, std::ref(chord));
    benchmark::DoNotOptimize(chord.length_mm);
    steps += run.steps;
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["time_per_step"] = benchmark::Counter(
      static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert,
      benchmark::Counter::kIs1000);
}
BENCHMARK(BM_FullRun)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FullOverRaw(benchmark::State& state) {
  const auto machine = make_xy_stage();
  Simulation simulation(kModel, *machine);
  const Trajectory trajectory = straight_print(10.0);
  double raw_s = 0.0, full_s = 0.0;
  long steps = 0;
  for (auto _ : state) {
    ChordSum chord;
    const auto start = std::chrono::steady_clock::now();
    const RecordedRun run = simulation.run(trajectory, std::ref(chord));
    full_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    raw_s += raw_steps_seconds(run.steps);
    steps += run.steps;
  }
  state.counters["raw_steps_per_s"] = steps / raw_s;
  state.counters["full_steps_per_s"] = steps / full_s;
  state.counters["full_over_raw"] = full_s / raw_s;
}
BENCHMARK(BM_FullOverRaw)->Unit(benchmark::kMillisecond)->Iterations(5);

// the deposit of a 10 mm line on a 0.05 mm grid around it
HeightMap line_deposit() {
  HeightMap map;
  map.cell_mm = 0.05;
  map.nx = 280;
  map.ny = 120;
  map.origin_x_mm = -7.0;
  map.origin_y_mm = -3.0;
  map.thickness_um.assign(static_cast<size_t>(map.nx) * map.ny, 0.0f);
  for (int iy = 0; iy < map.ny; ++iy)
    for (int ix = 0; ix < map.nx; ++ix) {
      const double x = map.origin_x_mm + ix * map.cell_mm, y = map.origin_y_mm + iy * map.cell_mm;
      if (std::abs(x) < 5.0)
        map.thickness_um[static_cast<size_t>(iy) * map.nx + ix] =
            static_cast<float>(2.0 * std::exp(-y * y / 0.02));
    }
  return map;
}

// the xy_stage after printing a 10 mm line, and that line's deposit
struct LineJob {
  std::unique_ptr<Machine> machine = make_xy_stage();
  Simulation simulation{kModel, *machine};
  HeightMap deposit = line_deposit();
  LineJob() { simulation.run(straight_print(3.0)); }
};

// seconds per image (wall)
void count_time_per_image(benchmark::State& state) {
  state.counters["time_per_image"] = benchmark::Counter(
      static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::kIs1000);
}

// one image with fresh GL and MuJoCo contexts (what a single render costs)
void BM_RenderScene(benchmark::State& state) {
  const LineJob job;
  const SceneRenderOptions options;  // 640 x 480
  for (auto _ : state) {
    const auto rgb = render_scene_rgb(job.simulation, job.deposit, options);
    benchmark::DoNotOptimize(rgb.data());
  }
  count_time_per_image(state);
}
BENCHMARK(BM_RenderScene)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// one more image on the contexts kept from the previous one (each planner after the first
// in `run` and `compare`)
void BM_RenderSceneReused(benchmark::State& state) {
  const LineJob job;
  const SceneRenderOptions options;  // 640 x 480
  SceneRenderer renderer;
  renderer.render_rgb(job.simulation, job.deposit,
                      options);  // contexts built
  for (auto _ : state) {
    const auto rgb = renderer.render_rgb(job.simulation, job.deposit, options);
    benchmark::DoNotOptimize(rgb.data());
  }
  count_time_per_image(state);
}
BENCHMARK(BM_RenderSceneReused)->Unit(benchmark::kMillisecond)->Iterations(10)->UseRealTime();

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
