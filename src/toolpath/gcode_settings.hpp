// The firmware settings a G-code file makes: the limits and factors its start block (or a
// slicer's per-feature lines) gives the printer, which a slicer's own time estimate follows.
// `inspect` lists them, so a file can be held against `--machine`'s limits, and estimates
// with those of motion (`--limits file`). Read as written, in the file's units (Marlin's M203
// is in mm/s, RepRapFirmware's in mm/min):
//   M201 X Y Z E        the axes' largest accelerations
//   M203 X Y Z E        the axes' largest feed rates
//   M204 P R T S        print, retract and travel accelerations (S: Marlin's older both,
//                       Klipper's one; Marlin 1.0 and older Prusa firmware read T as the
//                       retract acceleration)
//   M205 X Y Z E J S T B  jerks, junction deviation, least feed rates, least segment time
//   M220 S, M221 S      speed and flow factors (%)
//   M900 K              Linear Advance's factor
//   SET_VELOCITY_LIMIT  Klipper's VELOCITY, ACCEL, ACCEL_TO_DECEL, SQUARE_CORNER_VELOCITY,
//                       MINIMUM_CRUISE_RATIO
//   SET_PRESSURE_ADVANCE  Klipper's ADVANCE, SMOOTH_TIME
// Other parameters of these commands (M221 T, EXTRUDER=) are not settings read here.
#pragma once

#include <limits>
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

// The motion limits the file's settings give the firmware from some line on, as `inspect
// --limits file` estimates with them; 0 (NaN for the square-corner velocity and the cruise
// ratio, where 0 is a setting): not set, the machine's or the firmware's default holds. A
// value no firmware takes (negative, above 1e9, a cruise ratio of 1 or more) sets nothing,
// and a limit below 1e-6 is none.
struct FileMotionLimits {
  double axis_accel_mm_s2[3] = {0.0, 0.0, 0.0};  // M201 X Y Z
  double axis_feed_mm_s[3] = {0.0, 0.0, 0.0};    // M203 X Y Z (Marlin's mm/s)
  double print_accel_mm_s2 = 0.0;                // M204 P (and S); Klipper's ACCEL
  double travel_accel_mm_s2 = 0.0;               // M204 T (and S); Klipper's ACCEL
  double junction_deviation_mm = 0.0;            // M205 J
  double jerk_mm_s[4] = {0.0, 0.0, 0.0, 0.0};    // M205 X Y Z E: Marlin's classic jerks
  double max_velocity_mm_s = 0.0;                // Klipper's VELOCITY
  double square_corner_velocity = std::numeric_limits<double>::quiet_NaN();
  double minimum_cruise_ratio = std::numeric_limits<double>::quiet_NaN();  // Klipper's
  double max_accel_to_decel = 0.0;  // Klipper's older ACCEL_TO_DECEL
};

struct GcodeSettings {
  std::vector<GcodeSetting> settings;  // in the order the file first sets them
  // the motion limits in force, one entry per change that a move came under; entry 0 is the
  // file's start (nothing set)
  std::vector<FileMotionLimits> motion_limits{1};

  // one parameter read at `line`
  void set(const std::string& command, const std::string& parameter, double value, int line);
  // the index in motion_limits of those in force, for a move made now
  int motion_limits_for_move() {
    limits_taken_ = true;
    return static_cast<int>(motion_limits.size()) - 1;
  }

 private:
  // the limits in force, about to change: a new entry once a move came under the last
  FileMotionLimits& changing_limits();
  bool limits_taken_ = false;
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
