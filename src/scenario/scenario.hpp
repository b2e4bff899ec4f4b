// A scenario file loaded into plain structs. Only scenario/ includes yaml-cpp.
// Schema and defaults: src/scenario/SCHEMA.md (summarised in README.md, "Scenario files").
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/limits.hpp"
#include "core/toolpath.hpp"
#include "core/triangle_mesh.hpp"
#include "kinematics/machine.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/planner.hpp"
#include "posture/arm_posture.hpp"
#include "toolpath/surface_projection.hpp"

namespace depotwin {

// `process:` — how material leaves the nozzle.
struct ProcessSpec {
  std::string type = "aerosol";  // aerosol | extrusion
  // aerosol: continuous stream from job start to job end, Gaussian footprint; its flow, 0:
  // derived from the target thickness (see README). Extrusion: a fixed nominal flow (a
  // constant-rate extruder), 0: speed x bead width x layer height
  double flow_mm3_s = 0.0;
  double sigma_mm = 0.1;         // footprint standard deviation
  double line_width_mm = 0.0;    // 0: 4 sigma (aerosol) or bead width (extrusion)
  double shutter_time_s = 0.02;  // flap open/close time
  // extrusion: commanded flow with first-order lag
  double bead_width_mm = 0.4;
  double layer_height_mm = 0.2;
  double tau_s = 0.05;
  // extrusion: the flow command may go below 0 (the extruder pulls the filament back), as
  // Klipper's pressure advance does in decelerations; the nozzle flow stops at 0
  bool retract = false;
};

// `sim:` — simulation and deposition-grid settings.
struct SimSpec {
  double timestep_s = 0.001;
  double control_period_s = 0.001;  // servo update period, a multiple of timestep_s (default:
                                    // the multiple nearest to 1 ms)
  double cell_mm = 0.0;             // 0: sigma / 4 (aerosol) or bead width / 8 (extrusion)
  double kp_scale = 1.0;            // multiply the model's default servo gains
  double settle_s = 0.0;            // extra simulated time after the trajectory ends
  // the most physics steps a run may take (core/input_ranges.hpp): a job needing more is
  // refused before anything is allocated (pipeline/job_check.hpp)
  long long max_steps = 10000000;
};

// `outputs:` — what a run writes besides metrics.
struct OutputSpec {
  bool render = true;
  int image_width = 640;
  int image_height = 480;
};

// `toolpath: {surface: ...}` — conformal hatching on a part's top surface (Shembekar et al.,
// Algorithm 1): where the part came from, how it was placed and hatched (toolpath/hatching.hpp).
struct SurfaceToolpath {
  std::string file;          // the STL file, resolved against the scenario's directory
  double mm_per_unit = 1.0;  // units: mm (1) or inch (25.4)
  Vec3 offset_mm = Vec3::Zero();
  Vec3 rotation_deg = Vec3::Zero();  // about x, then y, then z (fixed axes), before the offset
  double hatch_mm = 0.5;
  std::vector<double> angles_deg{0.0, 90.0};
  int layers = 1;
  double layer_height_mm = 0.5;
  double alpha = 0.5;
  std::string layer_offset = "normal";  // normal | z
  double chord_tolerance_mm = 0.05;     // chords refined where the surface rises above them
  int line = 0;                         // the `surface:` key's line, for messages
  // per print path (in the scenario's order, PrintPath::source_index): its layer, its grid
  // line and each point's index along that line, for messages naming a point
  struct PathOrigin {
    int layer = 0, line = 0;
    std::vector<int> point_index;
  };
  std::vector<PathOrigin> origins;

  // "layer 3, line 12, point 40" for point `point` of the path with this source index, given
  // the path's first point as printed (a sequencer may have reversed it)
  std::string describe_point(int source_index, size_t point, size_t point_count,
                             bool reversed) const;
};

// `toolpath: {gcode: ...}` — a G-code file and how it was read (toolpath/gcode.hpp): its print
// rule, layers, what to do with feed rates above the machine's limits, and the chord tolerance
// its arcs were chorded within. `gcode: FILE` is the same with every default.
struct GcodeToolpath {
  std::string file;                  // resolved against the scenario's directory
  std::string rule = "auto";         // auto | e | shutter | feed, as given
  std::string rule_applied;          // the rule used (auto resolved): e | shutter | feed
  std::string rule_reason;           // e.g. "auto chose e: the file has E values"
  std::string open_code = "M3";      // shutter rule: opens
  std::string close_code = "M5";     // shutter rule: closes
  int first_layer = 0;               // `layers: [from, to]`, 0-based, inclusive
  int last_layer = -1;               // -1: to the last
  std::string feed = "clamp";        // clamp | error
  double chord_tolerance_mm = 0.01;  // arcs become chords within this sagitta
  int print_moves = 0;               // print moves imported (after chording: chords of one move
                                     // count once)
  int clamped_moves = 0;             // of those, slowed to the machine's limits (feed: clamp)
  std::vector<double> layer_z_mm;    // z of every layer of the file, ascending
  int line = 0;                      // the `gcode:` key's line
};

// Where a print path was given, for messages: the file (the scenario, or an imported G-code
// file), the dotted key (`toolpath.segments[3]`, `toolpath.polylines[0]`, `toolpath.gcode`) and
// each point's line in that file.
struct PathSource {
  std::string file;
  std::string key;
  std::vector<int> point_lines;
};

// the machine of a scenario that names none
inline constexpr const char* kDefaultMachine = "xy_stage";

struct Scenario {
  std::string file;       // the scenario file as given
  std::string directory;  // its directory: relative paths resolve against it
  std::string name;
  // a registered machine (kinematics/registry.cpp): `machine: NAME`, or
  // `machine: {model: FILE.xml, kinematics: NAME}` for an MJCF model of one's own
  std::string machine = kDefaultMachine;
  int machine_line = 0;           // where it was given, for messages
  std::string model_path;         // the resolved MJCF file of `machine: {model: ...}`; "" for the
                                  // machine's shipped model
  MachineLimits limits;           // Cartesian TCP limits for the planners
  bool has_joint_limits = false;  // `limits: {joint: {...}}` given (every joint alike)
  AxisLimits joint_limits;
  int joint_limits_line = 0;  // where `limits.joint` was given, for messages
  ProcessSpec process;
  // the print paths; a G-code file's arcs are chords within its chord_tolerance_mm here
  Toolpath toolpath;
  // the same paths (one for one, same start and end) with the G-code file's arcs exact, for
  // the planners that consume arcs (PlannerInfo::consumes_arcs); empty when no path has arcs
  Toolpath exact_toolpath;
  // per print path, by its PrintPath::source_index: where it was given
  std::vector<PathSource> path_sources;
  int toolpath_line = 0;  // the `toolpath:` key's line
  int start_line = 0;     // `toolpath.start:` / `end:` lines; 0: not given (defaults)
  int end_line = 0;
  // conformal work: the surface toolpath's settings and the part, placed in the work frame
  // (mm); null / empty for planar toolpaths
  std::shared_ptr<const SurfaceToolpath> surface;
  // a G-code toolpath's settings and what the import found; null for other toolpaths
  std::shared_ptr<const GcodeToolpath> gcode;
  // what every run of this scenario reports in metrics.json's warnings (e.g. the rule `auto`
  // chose, moves slowed to the machine's limits)
  std::vector<std::string> notes;
  std::shared_ptr<const TriangleMesh> part;
  // ray casting onto the part, built once for its hatch and kept for the run (`part` is its
  // mesh); null with `part`
  std::shared_ptr<const SurfaceProjector> part_projector;
  // `arm:` — how a 6-DOF arm chooses its roll and branch along the toolpath (arm6 only)
  std::optional<ArmPostureSettings> arm;
  int arm_line = 0;
  OrderSpec order;
  std::vector<PlannerSpec> planners;
  SimSpec sim;
  OutputSpec outputs;
  // the line of every map key the file gives outside lists ("sim.timestep_s", "limits.a_max",
  // "toolpath.speed", ...), for problems found after loading that name a key
  std::map<std::string, int> key_lines;

  // the line of a key as given, else of its nearest given parent ("sim.settle_s" -> "sim"),
  // else the top of the file (1)
  int line_of(const std::string& key) const;
  // a problem found after loading, placed in this file at its key's line
  Problem problem_at(const std::string& key, const std::string& message) const;
  // problems without a file (e.g. thrown by a downstream check that names only a key) placed
  // in this file at their key's line; one that names a print path by its source index
  // ("toolpath.paths[7].speed", as the ordering does) at that path's own source: its YAML
  // entry, its G-code line or its hatch line (path_problem)
  std::vector<Problem> located(std::vector<Problem> problems) const;
};

// The problem `message` about point `point` (0-based, as given in the file) of the print path
// with this source index, placed at that point's file, line and key (e.g.
// "scenario.yaml:12: toolpath.segments[3]: point 1 (60, 0, 0) mm ..."); a surface
// toolpath's points are named by layer, line and point.
Problem path_point_problem(const Scenario& scenario, int source_index, std::size_t point,
                           const std::string& message);

// The problem `message` about the whole print path with this source index, `detail` the key
// below it the message is about ("speed", or ""): at the path's YAML entry ("toolpath.paths[2]"
// or "toolpath.segments[5]"), at its first move's line in a G-code file, or at the `surface:`
// key with its layer and hatch line ("layer 0, line 12: ...").
Problem path_problem(const Scenario& scenario, int source_index, const std::string& detail,
                     const std::string& message);

// The files a scenario reads besides itself (its G-code or STL file, its MJCF model), as
// resolved: an output folder must not hold them (report/output_dir.hpp)
std::vector<std::string> scenario_input_files(const Scenario& scenario);

// Every toolpath pose (start, end, each point) a machine that holds the nozzle as the paths
// say cannot reach, as problems at the point's file, line and key; at most `max_listed`
// listed, then one counting the rest. Not for the arm, whose reach depends on the roll its
// posture chooses (posture/).
std::vector<Problem> unreachable_points(const Scenario& scenario, const Machine& machine,
                                        std::size_t max_listed = 20);

// Load and validate a scenario file. Throws InputError listing every problem
// found ("file:line: key: what is wrong"), not only the first: what the file says (types,
// ranges, names: the tables of scenario/schema.hpp) and, on what could be read, what the
// machine makes of it (joint limits it cannot honour, points out of its travel or
// workspace, print speeds above its joint limits mapped to each segment, a planner that
// ignores a jerk limit in force); problems of the scenario file in line order (file = `path` as
// given, line 1-based, key a dotted path such as `toolpath.segments[2]` or `limits.x.v_max`), then
// those of an imported G-code file. Relative paths in the file (machine MJCF, gcode) resolve
// against its directory. Full schema and defaults: src/scenario/SCHEMA.md.
Scenario load_scenario(const std::string& path);

// What a scenario file says and every problem the loader found in it, without throwing: the
// scenario holds what could be read (defaults where a value was bad), so checks made after
// loading (pipeline/job_check.hpp: the MJCF model, the job's size) can add their problems to
// the same list. Problems are in the order load_scenario reports them.
struct ScenarioReading {
  Scenario scenario;
  std::vector<Problem> problems;
  bool document_read = false;  // false: not even a YAML map (nothing else can be checked)
};
ScenarioReading read_scenario(const std::string& path);

// For `depotwin validate`: every problem load_scenario would report, or an empty list
// when the file loads. Never throws InputError.
std::vector<Problem> validate_scenario_file(const std::string& path);

// The problems in the order every verb reports them: the scenario file's by line, then those
// of other files (an imported G-code file, an MJCF model) in the order found.
void sort_problems(std::vector<Problem>& problems, const std::string& scenario_file);

}  // namespace depotwin
