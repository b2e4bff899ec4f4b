// `depotwin run` / `compare`: plan -> simulate through the actuators -> deposit -> score
// -> write. Everything downstream of the plan reads the simulated nozzle, never the plan.
#pragma once

#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <string>

#include "deposition/job_deposition.hpp"
#include "deposition/layered_deposit.hpp"
#include "deposition/process.hpp"
#include "pipeline/job.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "render/state_samples.hpp"  // moving pictures: SimulatedRun::states
#include "sim/simulation.hpp"

namespace depotwin {

struct RunSettings {
  bool render = true;  // images and plots
  // moving pictures: run.mp4 in each run folder (the replay data is written always), at most
  // video_length_s long (sped up to fit)
  bool video = false;
  double video_length_s = 30.0;
  bool progress = true;  // a progress line on stderr for runs longer than a second
  // scene renderer shared by the runs of one verb, so its context is built once (null: one
  // per image)
  std::shared_ptr<SceneRenderer> scene_renderer;
};

// One planner's simulated run, kept whole so the outputs can be written from it.
struct SimulatedRun {
  PlannedRun plan;
  std::unique_ptr<Simulation> simulation;  // its final state feeds the scene render
  RecordedRun record;
  // the deposit, layer by layer (one process per layer, stacked; thickness along the surface
  // normal on a curved part): owns the thickness fields and the material accounts
  std::unique_ptr<LayeredDeposit> deposit;
  MotionSamples simulated;         // the simulated nozzle, one sample per recorded state
  MotionSamples planned_at_steps;  // the plan at the same times
  MetricsReport report;
  // moving pictures: MuJoCo's whole state sampled over the run, for the replay data
  std::shared_ptr<StateSamples> states;
};

// thickness along each print path's centreline, sampled every cell length, on the deposit of
// the path's own layer (the layers above and below would add theirs: with several layers,
// the stack read at a path is no line's profile)
std::vector<plots::LineProfile> centreline_profiles(const LayeredDeposit& deposit,
                                                    const Toolpath& toolpath);
// the scenario's deposition settings
DepositionSettings deposition_settings(const Scenario& scenario);
// the scenario's simulation settings
SimSettings sim_settings(const Scenario& scenario);
// The job's deposit before its first step: one process per layer and, on a part, the slope of
// its surface under each cell (n_z) that turns vertical thickness into thickness along the
// normal. InputError for bad process settings.
std::unique_ptr<LayeredDeposit> job_deposit(const PreparedJob& job);

// The load feed-forward of a machine with closed chains (Machine::closure_feedforward), at
// the TCP velocity and acceleration the servo's setpoints give: first and second
// differences of the TCP setpoints over the control period. Refers to machine and trajectory.
Simulation::FeedForwardHook closure_feedforward_hook(const Machine& machine,
                                                     const Trajectory& trajectory,
                                                     const SimSettings& sim);

SimulatedRun simulate_job(const PreparedJob& job, const PlannerSpec& spec,
                          const RunSettings& settings);

// the scene image the scenario asks for (outputs.image_width / image_height)
SceneRenderOptions scene_render_options(const Scenario& scenario);

// run_directory (DIR/<planner>): metrics.json, trajectory.csv, thickness.csv,
// thickness_field.png and, when rendering, scene.png, thickness.png and the plots.
// Staged: nothing half-written, an older result replaced only when complete.
void write_run(const PreparedJob& job, const SimulatedRun& run, const std::string& run_directory,
               const RunSettings& settings);

// write_run on worker threads, so that the next planner simulates while the previous ones'
// files and images are written. At most kWritesInFlight writes run at once: their scene
// renders take turns on the shared renderer while gnuplot and the data files proceed beside
// them. The job, run and settings of a write must outlive it (until wait() or destruction).
class BackgroundRunWriter {
 public:
  static constexpr size_t kWritesInFlight = 2;

  BackgroundRunWriter() = default;
  ~BackgroundRunWriter();  // waits; a failure not collected by wait() is dropped
  BackgroundRunWriter(const BackgroundRunWriter&) = delete;
  BackgroundRunWriter& operator=(const BackgroundRunWriter&) = delete;

  // with kWritesInFlight writes running, waits for the oldest (rethrowing its error); then
  // starts this one
  void submit(const PreparedJob& job, const SimulatedRun& run, std::string run_directory,
              const RunSettings& settings);
  // waits for every write in flight, oldest first; rethrows the first error
  void wait();

 private:
  // collect the oldest write; rethrows its error
  void wait_oldest();

  std::deque<std::future<void>> pending_;
};

// the field over its bounds as a dense grid, block-averaged to at most max_cells cells
constexpr size_t kMaxExportCells = 4000000;
HeightMap field_heightmap(const ThicknessField& field, size_t max_cells = kMaxExportCells);

}  // namespace depotwin
