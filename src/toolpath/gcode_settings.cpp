#include "toolpath/gcode_settings.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>

#include "toolpath/ascii_text.hpp"

namespace depotwin {

namespace {

using ascii::is_digit;
using ascii::is_letter;
using ascii::is_space;
using ascii::upper;

// the range of a setting that sets a motion limit (FileMotionLimits): the G-code reader's
// largest number, and the least limit taken as one
constexpr double kMostSettingValue = 1e9;
constexpr double kLeastLimitValue = 1e-6;

// Klipper's setting commands and the parameters of each read here
struct KlipperCommand {
  const char* name;
  std::vector<const char*> parameters;
};
const std::vector<KlipperCommand>& klipper_commands() {
  static const std::vector<KlipperCommand> commands = {
      {"SET_VELOCITY_LIMIT",
       {"VELOCITY", "ACCEL", "ACCEL_TO_DECEL", "SQUARE_CORNER_VELOCITY", "MINIMUM_CRUISE_RATIO"}},
      {"SET_PRESSURE_ADVANCE", {"ADVANCE", "SMOOTH_TIME"}}};
  return commands;
}

// a name as Klipper reads it: letters, digits and '_', upper case
std::string read_name(const char*& p, const char* end) {
  std::string name;
  while (p < end && (is_letter(*p) || is_digit(*p) || *p == '_')) name += upper(*p++);
  return name;
}

// the parameter letters an M code (in tenths: M204 is 2040) sets; nullptr for another code
const char* setting_letters(int m_code_tenths) {
  switch (m_code_tenths) {
    case 2010:  // M201
    case 2030:  // M203
      return "XYZE";
    case 2040:
      return "PRTS";
    case 2050:
      return "XYZEJSTB";
    case 2200:
    case 2210:
      return "S";
    case 9000:
      return "K";
    default:
      return nullptr;
  }
}

// a finite number at p that ends a word (at the line's end, a space, a comment or checksum),
// advancing p past it; nullopt otherwise
std::optional<double> read_number(const char*& p, const char* end) {
  const char* start = p < end && *p == '+' ? p + 1 : p;
  double value = 0.0;
  const auto [stop, error] = std::from_chars(start, end, value);
  if (error != std::errc() || stop == start || !std::isfinite(value)) return std::nullopt;
  if (stop != end && !is_space(*stop) && std::strchr(";#*(", *stop) == nullptr) return std::nullopt;
  p = stop;
  return value;
}

// past the word at p (to the next space or comment)
void skip_word(const char*& p, const char* end) {
  while (p < end && !is_space(*p) && std::strchr(";#*(", *p) == nullptr) ++p;
}

// Each word of an M code's parameters, from `begin` (just after its number) up to a `;`
// comment or `*` checksum, `(...)` comments skipped: visit(letter, value) with its letter in
// upper case ('\0' for a word that starts with none) and the finite number after it, if one
// is (`X1000`, `X 1000`)
template <typename Visit>
void for_each_m_word(const char* begin, const char* end, Visit visit) {
  const char* p = begin;
  while (p < end && *p != ';' && *p != '*') {
    if (is_space(*p)) {
      ++p;
    } else if (*p == '(') {  // a comment within the line
      p = std::find(p, end, ')');
      if (p < end) ++p;
    } else {
      const char letter = is_letter(*p) ? upper(*p) : '\0';
      ++p;
      const char* number = p;
      while (number < end && is_space(*number)) ++number;
      const std::optional<double> value = read_number(number, end);
      if (value) p = number;
      visit(letter, value);
      skip_word(p, end);
    }
  }
}

}  // namespace

FileMotionLimits& GcodeSettings::changing_limits() {
  if (limits_taken_) motion_limits.push_back(motion_limits.back());
  limits_taken_ = false;
  return motion_limits.back();
}

void GcodeSettings::set(const std::string& command, const std::string& parameter, double value,
                        int line) {
  // listed: the first value, the last and the changes between
  bool listed = false;
  for (GcodeSetting& setting : settings) {
    if (setting.command != command || setting.parameter != parameter) continue;
    if (value != setting.last_value) ++setting.n_changes;
    setting.last_value = value;
    listed = true;
    break;
  }
  if (!listed) settings.push_back({command, parameter, value, line, value, 0});
  // the motion limits from here on: a value no firmware takes (negative, above 1e9, NaN) sets
  // none; a limit below 1e-6 (0 among them) is no limit, the machine's holds (a feed rate of
  // 1e-300 mm/s would take the estimate's squared speeds to 0)
  if (!(value >= 0.0 && value <= kMostSettingValue)) return;
  const double limit = value >= kLeastLimitValue ? value : 0.0;
  const int axis = parameter == "X" ? 0 : parameter == "Y" ? 1 : parameter == "Z" ? 2 : -1;
  if ((command == "M201" || command == "M203") && axis >= 0) {
    FileMotionLimits& limits = changing_limits();
    (command == "M201" ? limits.axis_accel_mm_s2 : limits.axis_feed_mm_s)[axis] = limit;
  } else if (command == "M204" && (parameter == "P" || parameter == "S")) {
    changing_limits().print_accel_mm_s2 = limit;
    if (parameter == "S") motion_limits.back().travel_accel_mm_s2 = limit;
  } else if (command == "M204" && parameter == "T") {
    changing_limits().travel_accel_mm_s2 = limit;
  } else if (command == "M205" && parameter == "J") {
    changing_limits().junction_deviation_mm = limit;
  } else if (command == "M205" && (axis >= 0 || parameter == "E")) {
    changing_limits().jerk_mm_s[axis >= 0 ? axis : 3] = limit;
  } else if (command == "SET_VELOCITY_LIMIT") {
    if (parameter == "ACCEL") {
      changing_limits().print_accel_mm_s2 = limit;
      motion_limits.back().travel_accel_mm_s2 = limit;
    } else if (parameter == "VELOCITY") {
      changing_limits().max_velocity_mm_s = limit;
    } else if (parameter == "SQUARE_CORNER_VELOCITY") {
      changing_limits().square_corner_velocity = value;
    } else if (parameter == "MINIMUM_CRUISE_RATIO" && value < 1.0) {  // Klipper's range [0, 1)
      changing_limits().minimum_cruise_ratio = value;
    } else if (parameter == "ACCEL_TO_DECEL") {
      changing_limits().max_accel_to_decel = limit;
    }
  }
}

void read_klipper_settings(const char* begin, const char* end, int line, GcodeSettings& settings) {
  const char* p = begin;
  const std::string name = read_name(p, end);
  const KlipperCommand* command = nullptr;
  for (const KlipperCommand& known : klipper_commands())
    if (name == known.name) command = &known;
  if (command == nullptr) return;
  // NAME=VALUE words up to a comment
  while (p < end && *p != ';' && *p != '#') {
    if (is_space(*p)) {
      ++p;
      continue;
    }
    const std::string parameter = read_name(p, end);
    if (parameter.empty() || p == end || *p != '=') {  // not NAME=VALUE
      if (parameter.empty()) ++p;                      // ('(', '*', '=': one character on)
      skip_word(p, end);
      continue;
    }
    ++p;
    if (const std::optional<double> value = read_number(p, end))
      for (const char* known : command->parameters)
        if (parameter == known) settings.set(command->name, parameter, *value, line);
    skip_word(p, end);
  }
}

SpeedFactorWords read_speed_factor_words(const char* begin, const char* end) {
  SpeedFactorWords words;
  for_each_m_word(begin, end, [&](char letter, std::optional<double> value) {
    if (letter == 'S') {
      words.has_percent = true;
      words.percent = value.value_or(std::nan(""));
    }
    words.backup = words.backup || letter == 'B';
    words.restore = words.restore || letter == 'R';
  });
  return words;
}

void read_m_code_settings(int m_code_tenths, const char* begin, const char* end, int line,
                          GcodeSettings& settings) {
  const char* letters = setting_letters(m_code_tenths);
  if (letters == nullptr) return;
  const std::string command = "M" + std::to_string(m_code_tenths / 10);
  for_each_m_word(begin, end, [&](char letter, std::optional<double> value) {
    if (letter != '\0' && std::strchr(letters, letter) != nullptr && value)
      settings.set(command, std::string(1, letter), *value, line);
  });
}

}  // namespace depotwin
