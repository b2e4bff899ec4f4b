// G-code importer for RS274/NGC (LinuxCNC) and RepRap/Marlin/Klipper files.
//
// Read: G0/G1, G2/G3 arcs (I/J/K offsets or R, R < 0 the long way; a full circle when an
// I/J/K arc ends where it starts; helical: the third axis moves linearly) in the G17/G18/G19
// planes, G90/G91 (and G90.1/G91.1 for arc centres), M82/M83, G92, G20/G21, G28 (to 0, or to
// what G28.1 stored; G30 to what G30.1 stored), G4 dwell
// (P milliseconds, S seconds, as Marlin and Klipper), F (modal, per minute), E, work systems
// (G54..G59.3 select, G10 L2/L20 set, G53 one line in the machine frame), saved positions
// (G60 S saves one; Marlin's G61 and RepRapFirmware's G0/G1 R return to it). Several G/M
// words may share a line (G17 G21 G90) and run in RS274/NGC order (F, M, modes, motion);
// axis words without a G word use the last motion mode. Spaces inside words are allowed
// (`G0 Z  15.000`), numbers as `Z.2` or `E-.8`, a lowercase exponent after a capital letter
// (`X1e3`; `X1E3` is X1 then E3, as firmware reads compact lines, and so is `x1e3` in a
// lowercase file). Comments `;...` and `(...)`, N words, `*checksums` and a line's leading
// `/` (block delete: the line runs, as with the switch off) are skipped, as are Klipper's
// extended commands (`PRINT_START ...`), the text commands (M117, M118, M23, ...) and every
// other G or M code, except the ones that would change the geometry and are not supported
// (G5 splines, canned cycles G73/G76/G81-G89, G93/G95 feed modes, G33 threading, cutter
// compensation, polar coordinates, G52 local offsets, scaling, mirroring, rotation) and
// RS274/NGC programming (O-word subroutines and control flow, # parameters, [ ]
// expressions; Fanuc's M98 P subprogram calls and G65/G66 macro calls), which are errors, as are
// binary files (a container, PrusaSlicer's .bgcode, a zip or gzip, is named). Lines end at LF, CR
// LF, or CR alone in a file without LF.
//
// Print rules decide which moves deposit: `e` (E increases), `shutter` (G1/G2/G3 while the
// open code is active (M3 and M4 both, where either is the open code) and the modal S, a laser's or
// spindle's power, is not 0), `feed` (G1/G2/G3 print, G0 travels) and `auto` (E values: e; else the
// open or close code present: shutter; else feed). Consecutive print moves at one feed rate form
// one print path; arcs stay exact (PrintPath::arcs) until a planner chords them. A path's layer is
// the z of the first point of its uninterrupted print run; layers are numbered 0, 1, ... by
// increasing z (levels within 1e-6 mm are one).
#pragma once

#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "core/toolpath.hpp"
#include "toolpath/gcode_settings.hpp"
#include "toolpath/slicer_notes.hpp"

namespace depotwin {

enum class PrintRule { automatic, e, shutter, feed };

// "auto", "e", "shutter", "feed"
const char* print_rule_name(PrintRule rule);
// the rule of a name above, or nothing
std::optional<PrintRule> print_rule_from_name(const std::string& name);

struct GcodeOptions {
  PrintRule rule = PrintRule::automatic;
  // shutter rule: the code that opens (e.g. M106); M3 and M4 both open where either is given
  // (a spindle or laser switched on: clockwise or counter-clockwise, constant or dynamic power)
  std::string open_code = "M3";
  std::string close_code = "M5";    // and the one that closes (e.g. M107)
  double default_speed_mm_s = 0.0;  // <= 0: none (then a print move before any F is an error)
  int first_layer = 0;              // layers [first, last] are imported (0-based)
  int last_layer = -1;              // -1: to the last layer
};

// One G0-G3 of the file whose path is longer than 1e-9 mm, in the machine frame (mm).
struct GcodeMove {
  int line = 0;    // 1-based line in the file
  int motion = 0;  // 0, 1, 2, 3 for G0..G3
  Vec3 from_mm = Vec3::Zero();
  Vec3 to_mm = Vec3::Zero();
  EdgeArc arc;             // sweep 0 for G0/G1
  double length_mm = 0.0;  // helical for arcs
  double e_delta = 0.0;    // extruder change during the move (mm of filament)
  double feed_mm_s = 0.0;  // modal feed rate times M220's factor (0: no F given yet)
  bool has_e = false;      // an E word on the line
  bool open = false;       // the open code was the last of open/close, and the modal S not 0
  int layer_mark = 0;      // the slicer's layer marks read before it (GcodeProgram::n_layer_marks)
  // the file's motion settings in force (GcodeProgram::firmware_settings.motion_limits index)
  int motion_limits = 0;
};

// Where the machine stands still between moves: a G4 dwell, or an E-only move (a retraction
// or prime: the extruder alone moves |dE| at the feed rate). Firmware empties its move queue
// there, so the moves on either side start and end at rest.
struct GcodePause {
  size_t before_move = 0;  // index into GcodeProgram::moves of the next move
  double duration_s = 0.0;
  int line = 0;  // 1-based
};

// A G code the reader does not know (a firmware's own: Bambu's G380 probe and G29.1 z trim,
// G38.2 probing, G30), or Prusa's G80 mesh levelling with its area, on lines with axis words:
// those words are the command's parameters, so the position did not change there. `tenths`:
// G38.2 is 382.
struct IgnoredAxisCode {
  int tenths = 0;
  int n_lines = 0;
  int first_line = 0;  // 1-based
};

// Everything a file does, before a print rule is applied.
struct GcodeProgram {
  std::string file_label;
  std::vector<GcodeMove> moves;
  bool has_e_values = false;       // some G0-G3 carries E
  bool has_shutter_codes = false;  // the open or close code occurs
  // runs of consecutive E decreases (moving or not) or firmware retractions (a bare G10, up to
  // its G11)
  int n_retractions = 0;
  double extrusion_e_total = 0.0;  // net E over the file (G92 resets excluded), mm
  double dwell_s = 0.0;            // sum of G4 dwells
  // comment lines that mark a new layer as slicers write them: `;LAYER:3`, `;LAYER_CHANGE`,
  // `; CHANGE_LAYER`, `; layer 3, Z = 0.6` (a print run ends at one)
  int n_layer_marks = 0;
  SlicerNotes slicer_notes;         // what the slicer's comments declare (slicer_notes.hpp)
  GcodeSettings firmware_settings;  // M201-M205, ... as set (gcode_settings.hpp)
  std::vector<GcodePause> pauses;   // dwells and E-only moves, in file order
  int n_lines = 0;
  // lines that hold code (a letter and a number), not only comments, grbl's $ commands or
  // Klipper's named commands: none in a file that is no G-code (a README, a YAML file)
  int n_code_lines = 0;
  std::vector<IgnoredAxisCode> ignored_axis_codes;  // in order of first occurrence
  // the line that ended the program (M2 or M30 alone, or the `%` closing one that opened the
  // file, as RS274/NGC and grbl end it), 0 when none did; the lines after it that hold
  // anything are not read (LinuxCNC ignores them)
  int program_end_line = 0;
  int n_lines_after_end = 0;
  // moves whose feed rate an M220 speed factor other than 100 % scaled (GcodeMove::feed_mm_s
  // is F times the factor, as firmware runs it), and the line of the first such M220
  int n_speed_factor_moves = 0;
  int first_speed_factor_line = 0;
};

// "G41", "G51.1": a G code as written, from its number in tenths (IgnoredAxisCode::tenths)
std::string g_code_name(int tenths);

// "holds no G-code: none of its N lines has a G or M code (...)" ("is empty ..." when it has
// no line), or "" when the file has a line of code (GcodeProgram's n_lines, n_code_lines)
std::string no_code_problem(int n_lines, int n_code_lines);

// one thing wrong with a shutter rule's codes, and which code it is named at
struct ShutterCodeProblem {
  bool at_close = false;  // the close code's (else the open code's)
  std::string message;
};
// what is wrong with an open and close code as given, the open code's first: each that is no
// G or M code (such as M3, M106), then, when both are codes, their being one switch (the same
// code, or M3 and M4), named at the close code; none when both are fine. Every reader of the
// codes (the G-code options, the scenario loader, `inspect`) names these at its own keys.
std::vector<ShutterCodeProblem> shutter_code_problems(const std::string& open,
                                                      const std::string& close);

// Parse G-code text; `file_label` names the source in messages. Throws InputError listing
// the first 20 malformed lines ("file:line: toolpath.gcode: ...") and then how many more.
GcodeProgram parse_gcode_program(const std::string& text, const std::string& file_label,
                                 const GcodeOptions& options);
// read a file whole and parse it; a missing or unreadable file is an InputError naming it
GcodeProgram read_gcode_program(const std::string& path, const GcodeOptions& options);

// the rule `rule` means for this program (auto resolved), and why (e.g. "auto chose e: ...")
PrintRule resolve_print_rule(const GcodeProgram& program, PrintRule rule, std::string* reason);
// whether a move deposits under a resolved rule
bool move_prints(const GcodeMove& move, PrintRule resolved_rule);
// whether print move `next` prints on from `previous` in one run: it starts where `previous`
// ends, with no slicer's layer mark between them (both must print)
bool continues_print_run(const GcodeMove& previous, const GcodeMove& next);
// the z levels of the program's print runs under a resolved rule, ascending (file layers)
std::vector<double> print_layer_levels(const GcodeProgram& program, PrintRule resolved_rule);

struct GcodeImport {
  // print paths in file order (source_index = position); start/end zero; arcs exact.
  // PrintPath::layer counts from the first selected layer (0 = file layer first_layer).
  Toolpath toolpath;
  // per path, per point: the 1-based line of the move that reached the point (the first
  // point's entry is the line of the path's first print move), for messages
  std::vector<std::vector<int>> point_lines;
  PrintRule rule = PrintRule::e;       // the rule applied (never automatic)
  std::string rule_reason;             // e.g. "auto chose e: the file has E values"
  std::vector<double> layer_z_mm;      // z of every layer of the file, ascending
  int first_layer = 0;                 // file layer of toolpath layer 0
  std::optional<Vec3> first_point_mm;  // the first imported print point
  int n_lines = 0, n_code_lines = 0;   // the program's
  int n_speed_factor_moves = 0;        // the program's: moves an M220 factor scaled
  int first_speed_factor_line = 0;
};

// Print paths of a parsed program under the options' rule and layer selection.
GcodeImport import_gcode_program(const GcodeProgram& program, const GcodeOptions& options);

GcodeImport parse_gcode(std::istream& in, const std::string& file_label,
                        const GcodeOptions& options);
GcodeImport read_gcode(const std::string& path, const GcodeOptions& options);

// Earlier signatures: rule auto, every layer, the given default speed.
GcodeImport parse_gcode(std::istream& in, const std::string& file_label, double default_speed_mm_s);
GcodeImport read_gcode(const std::string& path, double default_speed_mm_s);
// the print paths only (start and end left at the origin: the scenario sets them)
Toolpath import_gcode(const std::string& path, double default_speed_mm_s);

}  // namespace depotwin
