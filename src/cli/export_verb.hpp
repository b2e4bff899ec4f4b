// `depotwin export`: a scenario's planned motion written back as G-code.
//
// The planned trajectory is sampled every `sample_period_s`. Transitions become one G0 to
// their end point, at the feed rate that takes their planned time. Each depositing piece is
// cut into runs of nearly constant speed (within `speed_tolerance` of the piece's desired
// speed), and each run is simplified (Douglas-Peucker) so that every planned sample lies
// within `chord_tolerance_mm` of the written G1 lines. A G1's F is its length over its planned
// duration (mm/min), so the file at its own feed rates takes the planned time.
//
// Process codes: extrusion writes M83 and a relative E on every print move, E = the commanded
// volume over the move (the integral of flow fraction x nominal flow, nominal flow =
// process.flow_mm3_s or desired speed x bead width x layer height) / filament cross-section;
// at the desired speed and full flow this is bead width x layer height x length / filament
// area. Aerosol writes the open code (M3) before each run of depositing pieces and the close
// code (M5) after it.
#pragma once

#include <string>

#include "core/trajectory.hpp"

namespace depotwin {

struct GcodeExportSettings {
  double chord_tolerance_mm = 0.005;   // every planned sample within this of the written lines
  double speed_tolerance = 0.01;       // a G1's speed band, fraction of the desired speed
  double sample_period_s = 0.001;      // the plan is sampled this often
  double filament_diameter_mm = 1.75;  // extrusion: E is filament length
  std::string open_code = "M3";        // aerosol: shutter open
  std::string close_code = "M5";       // aerosol: shutter closed
};

// What the header names and how material is commanded.
struct GcodeExportJob {
  std::string scenario_name;
  std::string scenario_file;
  std::string planner;  // the run's label
  std::string machine;
  std::string process = "aerosol";  // aerosol | extrusion
  double flow_mm3_s = 0.0;          // extrusion: 0 = desired speed x bead x layer
  double bead_width_mm = 0.4;
  double layer_height_mm = 0.2;
};

// The G-code text of a planned trajectory (deterministic: same input, same bytes).
std::string trajectory_gcode(const Trajectory& trajectory, const GcodeExportJob& job,
                             const GcodeExportSettings& settings);

// the depotwin version written into the header
const char* depotwin_version();

struct ExportOptions {
  std::string scenario;
  std::string planner;  // a run label of the scenario; empty: its only planner
  std::string out;      // the .gcode file
  GcodeExportSettings settings;
  bool no_wait = false;  // another writer of --out holds its lock: exit 2 instead of waiting
  bool quiet = false;    // the job's long steps not shown (pipeline/step_heartbeat.hpp)
};

// Plans the scenario with one planner and writes the G-code atomically. InputError (exit 2)
// for a bad --out, a planner the scenario does not list, several planners and none chosen,
// or a conformal scenario (3-axis G-code cannot carry a tilted tool axis).
int export_verb(const ExportOptions& options);

}  // namespace depotwin
