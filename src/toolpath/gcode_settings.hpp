// The firmware settings a G-code file makes: the limits and factors its start block (or a
// slicer's per-feature lines) gives the printer, which a slicer's own time estimate follows.
// `inspect` lists them, so a file can be held against `--machine`'s limits. Read as written,
// in the file's units (Marlin's M203 is in mm/s, RepRapFirmware's in mm/min):
//   M201 X Y Z E        the axes' largest accelerations
//   M203 X Y Z E        the axes' largest feed rates
//   M204 P R T S        print, retract and travel accelerations (S: Marlin's older both,
//                       Klipper's one)
//   M205 X Y Z E J S T B  jerks, junction deviation, least feed rates, least segment time
//   M220 S, M221 S      speed and flow factors (%)
//   M900 K              Linear Advance's factor
//   SET_VELOCITY_LIMIT  Klipper's VELOCITY, ACCEL, ACCEL_TO_DECEL, SQUARE_CORNER_VELOCITY,
//                       MINIMUM_CRUISE_RATIO
//   SET_PRESSURE_ADVANCE  Klipper's ADVANCE, SMOOTH_TIME
// Other parameters of these commands (M221 T, EXTRUDER=) are not settings read here.
#pragma once

#include <string>
#include <vector>

namespace depotwin {

// One parameter of a setting command, over the file.
struct GcodeSetting {
  std::string command;    // "M204", "SET_VELOCITY_LIMIT"
  std::string parameter;  // "P", "ACCEL"
  double value = 0.0;     // its first value
  int line = 0;           // 1-based line of that first value
  double last_value = 0.0;
  int n_changes = 0;  // later lines that set it to another value (a slicer's per-feature M204)
};

struct GcodeSettings {
  std::vector<GcodeSetting> settings;  // in the order the file first sets them

  // one parameter read at `line`
  void set(const std::string& command, const std::string& parameter, double value, int line);
};

// Read an M code's parameters (`begin` just after its number, `end` the line's end): for the
// codes listed above, each of their letters with a finite number (`X1000`, `X 1000`, up to a
// `;` comment or `*` checksum; `(...)` comments skipped); other codes, other letters and
// values that are not one number (RepRapFirmware's `E5000:5000`) set nothing.
void read_m_code_settings(int m_code_tenths, const char* begin, const char* end, int line,
                          GcodeSettings& settings);

// M220's words (Marlin, Klipper, RepRapFirmware): S the speed factor in percent, which
// scales the feed rate of every move after it; Marlin's B saves the factor and R restores
// the saved one (B, then R, then S, as Marlin applies them).
struct SpeedFactorWords {
  bool has_percent = false;
  double percent = 0.0;  // S as written (NaN when S is not one finite number)
  bool backup = false;   // B
  bool restore = false;  // R
};
SpeedFactorWords read_speed_factor_words(const char* begin, const char* end);

// Read a Klipper command line (`begin` at its name, `end` its end without the line break):
// SET_VELOCITY_LIMIT's and SET_PRESSURE_ADVANCE's NAME=VALUE parameters (case ignored, a
// comment after `;` or `#` left out); any other command, or a value that does not read as a
// finite number, sets nothing.
void read_klipper_settings(const char* begin, const char* end, int line, GcodeSettings& settings);

}  // namespace depotwin
