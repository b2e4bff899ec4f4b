// G-code importer: turns the print moves of a RepRap/Marlin-style G-code file into
// print paths. Understood: G0/G1 (X Y Z E F), G90/G91 (absolute/relative positions),
// M82/M83 (absolute/relative extrusion), G92 (set position, e.g. G92 E0), G20/G21
// (inch/mm), G28 (home: the named axes, or all, to 0). Arcs (G2/G3) are an error; every
// other command (M104, T0, M117 text, ...) is ignored. Comments (`;` to end of line and
// `( ... )`), line numbers (N) and checksums (*) are skipped.
//
// A move with an XYZ displacement whose E increases is a print move; consecutive print
// moves form one polyline, printed at the move's feed rate (F is modal, mm/min ->
// mm/s) or at the default speed while no F has been given. A move that changes
// position without extruding is a travel and ends the polyline; a change of feed rate
// starts a new path at the same point. Moves without displacement (retract/prime)
// change nothing. E is relative under M83 or G91 (Klipper's rule; Marlin agrees for
// slicer output, where M82/M83 follows G90).
#pragma once

#include <istream>
#include <string>
#include <vector>

#include "core/toolpath.hpp"

namespace depotwin {

struct GcodeImport {
  Toolpath toolpath;  // print paths in file order (source_index = position); start/end zero
  // per path, per point: the 1-based line of the move that reached the point (the first
  // point's entry is the line of the path's first print move), for messages
  std::vector<std::vector<int>> point_lines;
};

// Parse G-code text. `file_label` names the source in messages; `default_speed_mm_s`
// <= 0 means none (then a print move before any F is an error). Throws InputError
// listing every malformed line ("file:line: toolpath.gcode: ...").
GcodeImport parse_gcode(std::istream& in, const std::string& file_label, double default_speed_mm_s);

// Read and parse a file; a missing or unreadable file is an InputError naming it.
GcodeImport read_gcode(const std::string& path, double default_speed_mm_s);

// The print paths only (start and end left at the origin: the scenario sets them).
Toolpath import_gcode(const std::string& path, double default_speed_mm_s);

}  // namespace depotwin
