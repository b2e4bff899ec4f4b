// What the cartesian gantry's twin costs (issue 14): a multi-layer G-code print (a 20 mm
// square wall, 10 layers of 0.2 mm at 30 mm/s) simulated on
// models/cartesian.xml through simulate_job (plan, simulate, deposit layer on layer, score),
// against bare mj_step on the same model at the same timestep. Target: a realtime factor of at
// least 500 with a simulated path error within 0.05 mm of the plan's.
//   BM_CartesianRawStep/T     bare mj_step, timestep T us: simulated seconds per wall second
//   BM_CartesianPrint/T       simulate_job with sim.timestep_s = control_period_s = T us:
//                             realtime_factor, path_error_mm (simulated max),
//                             planned_path_error_mm, tracking_mm (the difference)
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "pipeline/run.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;

// a 20 mm square, 10 layers, absolute E, 30 mm/s prints and 100 mm/s travels
std::string square_wall_gcode() {
  std::string text = "G21\nG90\nM82\nG92 E0\n";
  double e = 0.0;
  for (int layer = 0; layer < 10; ++layer) {
    text += "G1 Z" + std::to_string(0.2 * (layer + 1)) + " F600\nG0 X-10 Y-10 F6000\n";
    const char* corners[4] = {"X10 Y-10", "X10 Y10", "X-10 Y10", "X-10 Y-10"};
    for (int k = 0; k < 4; ++k) {
      e += 0.8;
      text += std::string("G1 ") + corners[k] + " E" + std::to_string(e) + " F1800\n";
    }
  }
  return text;
}

// the scenario at a timestep (the servo updated every step), written once per timestep
std::string scenario_file(long timestep_us) {
  const fs::path dir = fs::temp_directory_path() / "depotwin_bench_cartesian";
  fs::create_directories(dir);
  std::ofstream(dir / "wall.gcode") << square_wall_gcode();
  const double timestep_s = timestep_us * 1e-6;
  const fs::path path = dir / ("wall_" + std::to_string(timestep_us) + ".yaml");
  std::ofstream(path) << "name: cartesian_wall\nmachine: cartesian\n"
                         "limits: {v_max: 200, a_max: 3000}\n"
                         "process: {type: extrusion, bead_width_mm: 0.4, layer_height_mm: 0.2}\n"
                         "toolpath: {gcode: wall.gcode}\nplanners: [lspb_mtt]\n"
                         "sim: {timestep_s: "
                      << timestep_s << ", control_period_s: " << timestep_s << "}\n";
  return path.string();
}

void BM_CartesianRawStep(benchmark::State& state) {
  const PreparedJob job = prepare_job(load_scenario(scenario_file(state.range(0))));
  ModelPtr model = load_model(job.model_path);
  model->opt.timestep = state.range(0) * 1e-6;
  DataPtr data = make_data(*model);
  for (auto _ : state) mj_step(model.get(), data.get());
  state.counters["realtime_factor"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * model->opt.timestep, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CartesianRawStep)->Arg(1000)->Arg(2000)->Arg(3000)->Arg(4000)->UseRealTime();

void BM_CartesianPrint(benchmark::State& state) {
  const PreparedJob job = prepare_job(load_scenario(scenario_file(state.range(0))));
  RunSettings settings;
  settings.render = false;
  settings.progress = false;
  double simulated_s = 0.0, wall_s = 0.0, path_error_mm = 0.0, planned_mm = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const SimulatedRun run = simulate_job(job, job.scenario.planners.front(), settings);
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    simulated_s += run.record.t_s.back();
    path_error_mm = run.report.path_error ? run.report.path_error->max_mm : -1.0;
    planned_mm = run.report.planned_path_error.max_mm;
  }
  state.counters["simulated_s"] = simulated_s / state.iterations();
  state.counters["realtime_factor"] = simulated_s / wall_s;
  state.counters["path_error_mm"] = path_error_mm;
  state.counters["planned_path_error_mm"] = planned_mm;
  state.counters["tracking_mm"] = path_error_mm - planned_mm;
}
BENCHMARK(BM_CartesianPrint)
    ->Arg(1000)
    ->Arg(2000)
    ->Arg(3000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2)
    ->UseRealTime();

}  // namespace
}  // namespace depotwin

BENCHMARK_MAIN();
