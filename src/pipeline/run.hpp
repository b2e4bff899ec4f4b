// `depotwin run` / `compare`: plan -> simulate through the actuators -> deposit -> score
// -> write. Everything downstream of the plan reads the simulated nozzle, never the plan.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "deposition/process.hpp"
#include "pipeline/job.hpp"
#include "plots/plots.hpp"
#include "sim/simulation.hpp"

namespace depotwin {

struct RunSettings {
  bool render = true;  // images and plots
  bool progress = true;  // a progress line on stderr for runs longer than a second
};

// One planner's simulated run, kept whole so the outputs can be written from it.
struct SimulatedRun {
  PlannedRun plan;
  std::unique_ptr<Simulation> simulation;  // its final state feeds the scene render
  RecordedRun record;
  std::unique_ptr<Process> process;  // owns the thickness field and the material account
  MotionSamples simulated;           // the simulated nozzle, one sample per recorded state
  MotionSamples planned_at_steps;    // the plan at the same times
  MetricsReport report;
};

// thickness along each print path's centreline, sampled every cell length
std::vector<plots::LineProfile> centreline_profiles(const ThicknessField& field,
                                                   const Toolpath& toolpath);
// the centreline thickness of a straight line printed at the first path's desired speed
double target_thickness_um(const Process& process, const Toolpath& toolpath);

// the scenario's deposition settings
DepositionSettings deposition_settings(const Scenario& scenario);

SimulatedRun simulate_job(const PreparedJob& job, const PlannerSpec& spec,
                          const RunSettings& settings);

// run_directory (DIR/<planner>): metrics.json, trajectory.csv, thickness.csv,
// thickness_field.png and, when rendering, scene.png, thickness.png and the plots.
// Staged: nothing half-written, an older result replaced only when complete.
void write_run(const PreparedJob& job, const SimulatedRun& run, const std::string& run_directory,
               const RunSettings& settings);

// the field over its bounds as a dense grid, block-averaged to at most max_cells cells
constexpr size_t kMaxExportCells = 4000000;
HeightMap field_heightmap(const ThicknessField& field, size_t max_cells = kMaxExportCells);

}  // namespace depotwin
