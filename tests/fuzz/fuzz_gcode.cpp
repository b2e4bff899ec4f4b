// Fuzz target: the G-code importer (toolpath/gcode.hpp) on arbitrary text, as a scenario's
// `gcode:` file goes through it: parse, import under every print rule, chord the arcs; and
// `inspect`'s facts (cli/inspect.hpp), whose time estimate plans every move under the file's
// own limits. Bad input must be an InputError; whatever is imported must be finite, with
// positive speeds, and the estimate a finite time.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cli/inspect.hpp"
#include "core/error.hpp"
#include "fuzz/fuzz_check.hpp"
#include "toolpath/gcode.hpp"

namespace {

using depotwin::fuzz::is_finite;
using depotwin::fuzz::require;

void check_import(const depotwin::GcodeImport& imported) {
  require(imported.rule != depotwin::PrintRule::automatic, "the rule applied is never auto");
  require(imported.point_lines.size() == imported.toolpath.paths.size(), "one line list a path");
  for (std::size_t i = 0; i < imported.toolpath.paths.size(); ++i) {
    const depotwin::PrintPath& path = imported.toolpath.paths[i];
    require(path.points.size() >= 2, "a print path has two points at least");
    require(imported.point_lines[i].size() == path.points.size(), "a line per point");
    require(path.arcs.empty() || path.arcs.size() + 1 == path.points.size(), "an arc per edge");
    require(is_finite(path.speed_mm_s) && path.speed_mm_s > 0.0, "a finite positive speed");
    for (const depotwin::Vec3& point : path.points) require(point.allFinite(), "finite points");
    for (const depotwin::EdgeArc& arc : path.arcs)
      require(arc.center_mm.allFinite() && is_finite(arc.sweep_rad), "finite arcs");
    require(is_finite(path.length_mm()), "a finite length");
    // arcs become chords as the scenario loader makes them (0.01 mm, its default)
    const depotwin::PrintPath chorded = path.chorded(0.01);
    require(chorded.points.size() >= path.points.size(), "chording adds points");
    for (const depotwin::Vec3& point : chorded.points) require(point.allFinite(), "finite chords");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  depotwin::GcodeOptions options;
  depotwin::GcodeProgram program;
  try {
    program = depotwin::parse_gcode_program(text, "fuzz.gcode", options);
  } catch (const depotwin::InputError&) {
    return 0;  // rejected with a message: expected
  }
  require(
      program.n_lines >= 0 && is_finite(program.dwell_s) && is_finite(program.extrusion_e_total),
      "finite program totals");
  const auto& motion_limits = program.firmware_settings.motion_limits;
  for (const depotwin::GcodeMove& move : program.moves) {
    require(move.from_mm.allFinite() && move.to_mm.allFinite() && is_finite(move.length_mm) &&
                move.length_mm > 0.0 && is_finite(move.e_delta),
            "finite moves");
    // the feed rate times M220's factor: finite, and none or at least the least F read
    require(is_finite(move.feed_mm_s) && (move.feed_mm_s == 0.0 || move.feed_mm_s >= 1e-10),
            "a finite feed rate, none or one to move at");
    require(move.motion_limits >= 0 &&
                static_cast<std::size_t>(move.motion_limits) < motion_limits.size(),
            "each move under motion limits the program holds");
  }
  // the firmware settings: as written, finite; the motion limits taken from them in range
  for (const depotwin::GcodeSetting& setting : program.firmware_settings.settings)
    require(is_finite(setting.value) && is_finite(setting.last_value) && setting.line >= 1,
            "finite settings");
  for (const depotwin::FileMotionLimits& limits : motion_limits) {
    std::vector<double> values = {limits.print_accel_mm_s2, limits.travel_accel_mm_s2,
                                  limits.junction_deviation_mm, limits.max_velocity_mm_s};
    for (int axis = 0; axis < 3; ++axis) {
      values.push_back(limits.axis_accel_mm_s2[axis]);
      values.push_back(limits.axis_feed_mm_s[axis]);
    }
    for (const double jerk : limits.jerk_mm_s) values.push_back(jerk);
    for (const double value : values)
      require(value == 0.0 || (value >= 1e-6 && value <= 1e9), "motion limits in range");
  }
  // inspect's facts: the firmware's time estimate under the file's own limits, Marlin's (with
  // its junction deviation or classic jerks) and Klipper's
  for (const char* mode : {"marlin", "klipper"}) {
    depotwin::InspectBaseline baseline;
    baseline.mode = mode;
    baseline.limits = "file";
    try {
      const depotwin::GcodeFacts facts =
          depotwin::gcode_facts(program, depotwin::PrintRule::automatic, baseline);
      require(is_finite(facts.estimated_time_s) && facts.estimated_time_s >= 0.0,
              "a finite estimate");
      (void)depotwin::gcode_facts_json(facts).dump();
    } catch (const depotwin::InputError&) {
      // refused with a message: expected
    }
  }
  // every rule, every layer; then the last layer alone, with a default speed (as a scenario's
  // toolpath.speed gives)
  for (const depotwin::PrintRule rule : {depotwin::PrintRule::automatic, depotwin::PrintRule::e,
                                         depotwin::PrintRule::shutter, depotwin::PrintRule::feed}) {
    options.rule = rule;
    for (const double default_speed_mm_s : {0.0, 10.0}) {
      options.default_speed_mm_s = default_speed_mm_s;
      options.first_layer = 0;
      options.last_layer = -1;
      try {
        check_import(depotwin::import_gcode_program(program, options));
        const std::size_t layers =
            depotwin::print_layer_levels(program,
                                         depotwin::resolve_print_rule(program, rule, nullptr))
                .size();
        if (layers < 2) continue;
        options.first_layer = options.last_layer = static_cast<int>(layers) - 1;
        check_import(depotwin::import_gcode_program(program, options));
      } catch (const depotwin::InputError&) {
        // e.g. a print move before any feed rate: expected
      }
    }
  }
  return 0;
}
