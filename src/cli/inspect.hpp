// `depotwin inspect FILE`: facts of a G-code file under a print rule, as JSON, with the time the
// firmware baseline (planners/motion/firmware.hpp) plans for it on a machine's own limits.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.hpp"
#include "toolpath/gcode.hpp"

namespace depotwin {

// An axis-aligned box; empty until something is added.
struct Box3 {
  bool empty = true;
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
};

// What a G-code file does under a rule. A move is a G0-G3 whose path is longer than 1e-9 mm;
// an arc's length is helical, sqrt((r theta)^2 + h^2); boxes include arcs' bulges exactly.
struct GcodeFacts {
  std::string rule;         // the rule applied: e, shutter or feed
  std::string rule_reason;  // why (auto says which it chose)
  int n_lines = 0;
  int n_print_moves = 0;
  int n_travel_moves = 0;
  int n_print_paths = 0;  // connected print moves at one feed rate (as the import splits them)
  int n_print_arcs = 0;   // print moves that are G2/G3
  double print_length_mm = 0.0;
  double travel_length_mm = 0.0;
  std::vector<double> layer_z_values;  // z of each layer's print runs, ascending
  Box3 print_bbox;
  Box3 all_moves_bbox;
  int n_retractions = 0;           // runs of consecutive E decreases
  double extrusion_e_total = 0.0;  // net E over the file, mm of filament
  // what the firmware baseline (planners/motion/firmware.hpp) predicts for the whole file:
  // every move, printing or travelling, through one look-ahead queue at the modal feed rate
  // (the machine's top speed before any F), each axis within the machine's limits, arcs cut
  // into chords within 0.01 mm; the queue stops at dwells, E-only moves and position jumps,
  // whose times are added (an E-only move takes |dE| / F)
  double estimated_time_s = 0.0;
  // every move at the file's own feed rate plus the dwells; moves before any F are left out
  // and counted
  double feed_rate_time_s = 0.0;
  int n_moves_without_feed = 0;
  // G codes the reader does not know whose axis words it left alone (no move made there)
  std::vector<IgnoredAxisCode> ignored_axis_codes;
  // the line of M2, M30 or the closing `%` that ended the program (0: none), and how many
  // lines holding anything came after it, unread
  int program_end_line = 0;
  int n_lines_after_end = 0;
  // what the slicer's comments declare: who made the file, its time estimate, layer count and
  // filament length (toolpath/slicer_notes.hpp), each null in the JSON when not declared
  SlicerNotes slicer_notes;
  // M201-M205, M220, M221, M900 and Klipper's SET_VELOCITY_LIMIT and SET_PRESSURE_ADVANCE as
  // the file sets them (toolpath/gcode_settings.hpp)
  std::vector<GcodeSetting> firmware_settings;
  std::string baseline_machine;  // the machine, firmware mode and limits estimated_time_s
  std::string baseline_mode;     // assumes
  std::string baseline_limits;
};

// What `inspect` plans the file with: the `firmware` planner with its default parameters in
// this mode, under this registered machine's own limits (kinematics/registry.cpp).
struct InspectBaseline {
  std::string machine = "cartesian";
  std::string mode = "marlin";  // marlin | klipper
  // machine: the machine's limits and the firmware's defaults; file: over them, the file's
  // own settings in force at each move (M201, M203, M204, M205 J, SET_VELOCITY_LIMIT)
  std::string limits = "machine";
};

// Throws InputError naming --machine, --mode or --limits when the baseline names a machine,
// mode or source of limits that does not exist.
GcodeFacts gcode_facts(const GcodeProgram& program, PrintRule rule,
                       const InspectBaseline& baseline = {});

// the facts as the JSON `depotwin inspect` prints
nlohmann::json gcode_facts_json(const GcodeFacts& facts);

// the verb: parse `path`, print the JSON on stdout. Throws InputError on a bad file.
void inspect_gcode_file(const std::string& path, const GcodeOptions& options,
                        const InspectBaseline& baseline = {});

}  // namespace depotwin
