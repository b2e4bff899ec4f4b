#include "cli/inspect.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <iterator>
#include <optional>

#include "core/error.hpp"
#include "kinematics/machine.hpp"
#include "planners/motion/firmware.hpp"

namespace depotwin {

namespace {

// arcs become chords within this sagitta (the default of a scenario's `chord_tolerance_mm`),
// as firmware cuts G2/G3 into short segments
constexpr double kChordTolerance_mm = 0.01;
// the limits asked of the machine: none of its own, so its joints' limits decide
constexpr double kUnbounded = 1e12;
// the most pieces one look-ahead chain holds before it is planned and emptied (a stop there):
// about 130 MB. A file of arcs that never stops is otherwise held whole: 10^5 circles of
// radius 500 mm (a 2 MB file, 5e7 chords) took 10 GB. A printer's own queue holds 16 to 64
// moves; the stop costs a deceleration and an acceleration every 2^20 pieces.
constexpr size_t kMaxChainPieces = size_t{1} << 20;
// the most chords per turn of an arc: arcs of radius above 34 m (1e9 mm is a number a file may
// hold) are cut coarser than kChordTolerance_mm, at 4096 chords per turn, which turn by
// 0.09 degrees each and keep the estimate's time; 1000 such circles otherwise took minutes
constexpr double kMaxChordsPerTurn = 4096.0;

// The time of one move of a look-ahead chain: a trapezoid from v0 to v1 under the cruise cap
// over what the junction blends leave of it, plus half of each blend (as FirmwarePlanner).
double move_time_s(const FirmwareMove& move, const FirmwareProfile& profile, size_t k) {
  const double v0 = profile.junction_speed_mm_s[k], v1 = profile.junction_speed_mm_s[k + 1];
  const double tau0 = profile.blend_time_s[k], tau1 = profile.blend_time_s[k + 1];
  const double a = move.accel_mm_s2;
  const double free_length = move.length_mm - 0.5 * v0 * tau0 - 0.5 * v1 * tau1;
  const double cap = profile.cruise_speed_mm_s[k];
  double peak = std::sqrt(std::min(cap * cap, 0.5 * (v0 * v0 + v1 * v1) + a * free_length));
  peak = std::max({peak, v0, v1});
  const double cruise_length =
      std::max(0.0, free_length - (2.0 * peak * peak - v0 * v0 - v1 * v1) / (2.0 * a));
  const double cruise_s = peak > 0.0 ? cruise_length / peak : 0.0;
  return 0.5 * tau0 + (peak - v0) / a + cruise_s + (peak - v1) / a + 0.5 * tau1;
}

// What the firmware plans a move with: its settings resolved over the axes' limits, the
// junction deviation and the axes' accelerations around its junctions. `file` (null: the
// machine's limits and the firmware's defaults alone) overrides them with the file's settings
// in force: M201 and M203 the axes' limits; Marlin's print acceleration for a move with E (its
// planner's esteps) and the travel acceleration for one without, Klipper's one acceleration
// for both; M205 J, or Marlin's classic jerks M205 X Y Z E when the file sets no M205 J, and
// Klipper's velocity, square-corner velocity and cruise ratio.
struct MovePlanning {
  MachineLimits limits;
  FirmwareSettings settings;
  double junction_deviation_mm = 0.0;
  Vec3 axis_accel = Vec3::Zero();
};
MovePlanning move_planning(const MachineLimits& machine_limits, FirmwareMode mode,
                           const FileMotionLimits* file, bool moves_extruder) {
  MovePlanning planning;
  planning.limits = machine_limits;
  FirmwareSettings given;
  given.mode = mode;
  if (file != nullptr) {
    for (int axis = 0; axis < 3; ++axis) {
      if (file->axis_accel_mm_s2[axis] > 0.0)
        planning.limits.axes[axis].a_max_mm_s2 = file->axis_accel_mm_s2[axis];
      if (file->axis_feed_mm_s[axis] > 0.0)
        planning.limits.axes[axis].v_max_mm_s = file->axis_feed_mm_s[axis];
    }
    const double print = file->print_accel_mm_s2, travel = file->travel_accel_mm_s2;
    double accel = moves_extruder ? print : travel;
    if (mode == FirmwareMode::klipper)  // M204 P and T: Klipper takes the smaller
      accel = print > 0.0 && travel > 0.0 ? std::min(print, travel) : std::max(print, travel);
    if (accel > 0.0) given.max_accel = accel;
    if (file->junction_deviation_mm > 0.0)
      given.junction_deviation_mm = file->junction_deviation_mm;
    // jerks set (M205 X or Y) and no junction deviation: a classic-jerk firmware (Prusa's, or
    // Marlin built with CLASSIC_JERK), Marlin's defaults for the jerks not set
    const double* jerk = file->jerk_mm_s;
    if (mode == FirmwareMode::marlin && !(file->junction_deviation_mm > 0.0) &&
        (jerk[0] > 0.0 || jerk[1] > 0.0))
      for (int axis = 0; axis < 4; ++axis)
        given.classic_jerk_mm_s[axis] =
            jerk[axis] > 0.0 ? jerk[axis] : kMarlinDefaultJerk_mm_s[axis];
    if (file->max_velocity_mm_s > 0.0) given.max_velocity = file->max_velocity_mm_s;
    if (!std::isnan(file->square_corner_velocity))
      given.square_corner_velocity = file->square_corner_velocity;
    if (!std::isnan(file->minimum_cruise_ratio))
      given.minimum_cruise_ratio = file->minimum_cruise_ratio;
    if (file->max_accel_to_decel > 0.0) given.max_accel_to_decel = file->max_accel_to_decel;
  }
  planning.settings =
      resolved_firmware_settings(given, planning.limits, planning.junction_deviation_mm);
  const double max_accel = planning.settings.max_accel;
  planning.axis_accel =
      Vec3(planning.limits.axes[0].a_max_mm_s2, planning.limits.axes[1].a_max_mm_s2,
           planning.limits.axes[2].a_max_mm_s2)
          .cwiseMin(max_accel > 0.0 ? max_accel : kUnbounded);
  return planning;
}

// What the firmware baseline predicts for the whole file: every move, printing or not, goes
// through one look-ahead queue as a printer's firmware plans it (Marlin and Klipper treat G0
// as G1 at the modal feed rate; before any F, the machine's top speed). The queue empties at
// dwells, E-only moves (retractions, primes) and jumps of the position (G92, G28), where the
// machine stands still; those pauses' own times are added. Each move's speed and acceleration
// are capped so no axis exceeds the machine's limits over the file's box, or with --limits
// file the file's settings in force at the move over them (move_planning).
double firmware_estimate_s(const GcodeProgram& program, const Machine& machine,
                           const std::string& mode, const std::string& limits_source,
                           const Box3& all_moves_bbox) {
  if (program.moves.empty()) {
    double pauses_s = 0.0;
    for (const GcodePause& pause : program.pauses) pauses_s += pause.duration_s;
    return pauses_s;
  }
  const MachineLimits machine_limits = machine.cartesian_limits(
      MachineLimits::uniform(kUnbounded, kUnbounded), all_moves_bbox.lo, all_moves_bbox.hi);
  // the firmware's configuration as the planner applies it: Marlin's junction deviation, or
  // Klipper's square-corner velocity and its max_accel, both at the x and y axes' acceleration;
  // with --limits file, per move under the file's settings in force
  const FirmwareMode firmware_mode =
      mode == "klipper" ? FirmwareMode::klipper : FirmwareMode::marlin;
  const bool file_limits = limits_source == "file";
  const std::vector<FileMotionLimits>& file_states = program.firmware_settings.motion_limits;
  // the planning of the last settings met, for a move with E and one without (moves come in
  // runs under one state; a file may change its settings at every move, so no table of all)
  std::optional<MovePlanning> recent[2];
  int recent_state[2] = {-1, -1};
  const auto planning_of = [&](const GcodeMove& move) -> const MovePlanning& {
    const int extruder = move.e_delta != 0.0 ? 1 : 0;
    const int state = file_limits ? move.motion_limits : 0;
    if (recent_state[extruder] != state) {
      recent[extruder] = move_planning(
          machine_limits, firmware_mode,
          file_limits ? &file_states[static_cast<size_t>(state)] : nullptr, extruder == 1);
      recent_state[extruder] = state;
    }
    return *recent[extruder];
  };

  double total_s = 0.0;
  std::vector<FirmwareMove> chain;
  // the junction settings the chain is planned under (its first move's)
  FirmwareSettings chain_settings;
  double chain_junction_deviation_mm = 0.0;
  const auto flush = [&] {
    if (chain.empty()) return;
    const FirmwareProfile profile =
        firmware_lookahead(chain, chain_settings, chain_junction_deviation_mm);
    for (size_t k = 0; k < chain.size(); ++k) total_s += move_time_s(chain[k], profile, k);
    chain.clear();
  };
  size_t next_pause = 0;
  Vec3 previous_end = program.moves.front().from_mm;
  for (size_t m = 0; m < program.moves.size(); ++m) {
    const GcodeMove& move = program.moves[m];
    // pauses before this move stop the queue
    bool stops = (move.from_mm - previous_end).norm() > kJoinTolerance_mm;
    for (; next_pause < program.pauses.size() && program.pauses[next_pause].before_move <= m;
         ++next_pause) {
      total_s += program.pauses[next_pause].duration_s;
      stops = true;
    }
    // the look-ahead plans a chain under one junction deviation (or classic jerks) and cruise
    // ratio: a change of them (M205 J or X Y Z E, Klipper's square-corner velocity) plans the
    // chain so far
    const MovePlanning& planning = planning_of(move);
    if (!chain.empty() &&
        (planning.junction_deviation_mm != chain_junction_deviation_mm ||
         planning.settings.minimum_cruise_ratio != chain_settings.minimum_cruise_ratio ||
         !std::equal(std::begin(planning.settings.classic_jerk_mm_s),
                     std::end(planning.settings.classic_jerk_mm_s),
                     std::begin(chain_settings.classic_jerk_mm_s))))
      stops = true;
    if (stops) flush();
    if (chain.empty()) {
      chain_settings = planning.settings;
      chain_junction_deviation_mm = planning.junction_deviation_mm;
    }
    previous_end = move.to_mm;
    // the move's straight pieces (an arc's chords)
    std::vector<Vec3> points{move.from_mm, move.to_mm};
    if (move.arc.is_arc()) {
      PrintPath arc_path;
      arc_path.points = points;
      arc_path.arcs = {move.arc};
      const Vec3 radial = move.from_mm - move.arc.center_mm;
      const double radius_mm = (radial - radial.dot(move.arc.axis) * move.arc.axis).norm();
      const double coarsest_mm = radius_mm * (1.0 - std::cos(kPi / kMaxChordsPerTurn));
      points = arc_path.chorded(std::max(kChordTolerance_mm, coarsest_mm)).points;
    }
    // the extruder's travel per mm along the move (classic jerk counts its speed)
    double move_length_mm = 0.0;
    for (size_t i = 0; i + 1 < points.size(); ++i)
      move_length_mm += (points[i + 1] - points[i]).norm();
    const double e_per_mm = move_length_mm > 1e-12 ? move.e_delta / move_length_mm : 0.0;
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const Vec3 step = points[i + 1] - points[i];
      const double length_mm = step.norm();
      if (length_mm <= 1e-12) continue;
      FirmwareMove piece;
      piece.length_mm = length_mm;
      piece.direction = step / length_mm;
      // no axis beyond its own speed and acceleration (Marlin's max_feedrate, max_acceleration),
      // and Klipper's max_accel the same in every direction, as the firmware planner has them
      double speed_cap = 0.0;
      move_caps(piece.direction, planning.limits, planning.settings.max_velocity,
                planning.settings.max_accel, speed_cap, piece.accel_mm_s2);
      piece.cruise_speed_mm_s =
          std::min(move.feed_mm_s > 0.0 ? move.feed_mm_s : kUnbounded, speed_cap);
      piece.blend_accel_mm_s2 = planning.axis_accel;
      piece.e_per_mm = e_per_mm;
      chain.push_back(piece);
      if (chain.size() >= kMaxChainPieces) flush();
    }
  }
  flush();
  for (; next_pause < program.pauses.size(); ++next_pause)
    total_s += program.pauses[next_pause].duration_s;
  return total_s;
}

// grow a box by a move's whole path (its arc's bulge included)
void grow(Box3& box, const GcodeMove& move) {
  if (box.empty) {
    box.lo = box.hi = move.from_mm;
    box.empty = false;
  }
  grow_arc_bounds(move.from_mm, move.to_mm, move.arc, box.lo, box.hi);
}

nlohmann::json box_json(const Box3& box) {
  if (box.empty) return nullptr;
  return {{"min", {box.lo.x(), box.lo.y(), box.lo.z()}},
          {"max", {box.hi.x(), box.hi.y(), box.hi.z()}}};
}

}  // namespace

GcodeFacts gcode_facts(const GcodeProgram& program, PrintRule rule,
                       const InspectBaseline& baseline) {
  // the baseline named must exist
  const std::unique_ptr<Machine> machine = make_machine(baseline.machine);
  if (!machine) {
    std::string known;
    for (const std::string& name : machine_names()) known += (known.empty() ? "" : ", ") + name;
    throw InputError("--machine",
                     "unknown machine '" + baseline.machine + "' (known: " + known + ")");
  }
  if (baseline.mode != "marlin" && baseline.mode != "klipper")
    throw InputError("--mode",
                     "unknown firmware mode '" + baseline.mode + "' (known: marlin, klipper)");
  if (baseline.limits != "machine" && baseline.limits != "file")
    throw InputError("--limits",
                     "unknown source of limits '" + baseline.limits + "' (known: machine, file)");
  GcodeFacts facts;
  facts.baseline_machine = baseline.machine;
  facts.baseline_mode = baseline.mode;
  facts.baseline_limits = baseline.limits;
  const PrintRule resolved = resolve_print_rule(program, rule, &facts.rule_reason);
  facts.rule = print_rule_name(resolved);
  facts.n_lines = program.n_lines;
  facts.layer_z_values = print_layer_levels(program, resolved);
  facts.n_retractions = program.n_retractions;
  facts.extrusion_e_total = program.extrusion_e_total;
  facts.feed_rate_time_s = program.dwell_s;
  facts.ignored_axis_codes = program.ignored_axis_codes;
  facts.program_end_line = program.program_end_line;
  facts.n_lines_after_end = program.n_lines_after_end;
  facts.slicer_notes = program.slicer_notes;
  facts.firmware_settings = program.firmware_settings.settings;
  const GcodeMove* previous_print = nullptr;  // the move before, where it printed
  // every move: print or travel, its length, boxes and time
  for (const GcodeMove& move : program.moves) {
    const bool prints = move_prints(move, resolved);
    grow(facts.all_moves_bbox, move);
    if (prints) {
      ++facts.n_print_moves;
      facts.print_length_mm += move.length_mm;
      facts.n_print_arcs += move.arc.is_arc() ? 1 : 0;
      grow(facts.print_bbox, move);
      // a print path as the import makes them: print moves in one run at one feed rate
      const bool continues = previous_print != nullptr &&
                             move.feed_mm_s == previous_print->feed_mm_s &&
                             continues_print_run(*previous_print, move);
      facts.n_print_paths += continues ? 0 : 1;
    } else {
      ++facts.n_travel_moves;
      facts.travel_length_mm += move.length_mm;
    }
    previous_print = prints ? &move : nullptr;
    if (move.feed_mm_s > 0.0)
      facts.feed_rate_time_s += move.length_mm / move.feed_mm_s;
    else
      ++facts.n_moves_without_feed;
  }
  // what the firmware baseline predicts for the whole file
  facts.estimated_time_s =
      firmware_estimate_s(program, *machine, baseline.mode, baseline.limits, facts.all_moves_bbox);
  return facts;
}

nlohmann::json gcode_facts_json(const GcodeFacts& facts) {
  nlohmann::json out;
  out["rule"] = facts.rule;
  out["rule_reason"] = facts.rule_reason;
  out["n_lines"] = facts.n_lines;
  out["n_print_moves"] = facts.n_print_moves;
  out["n_travel_moves"] = facts.n_travel_moves;
  out["n_print_paths"] = facts.n_print_paths;
  out["print_length_mm"] = facts.print_length_mm;
  out["travel_length_mm"] = facts.travel_length_mm;
  out["n_layers"] = facts.layer_z_values.size();
  out["layer_z_values"] = facts.layer_z_values;
  out["print_bbox"] = box_json(facts.print_bbox);
  out["all_moves_bbox"] = box_json(facts.all_moves_bbox);
  out["n_print_arcs"] = facts.n_print_arcs;
  out["n_retractions"] = facts.n_retractions;
  out["extrusion_e_total"] = facts.extrusion_e_total;
  out["estimated_time_s"] = facts.estimated_time_s;
  out["baseline"] = {{"planner", "firmware"},
                     {"mode", facts.baseline_mode},
                     {"machine", facts.baseline_machine},
                     {"limits", facts.baseline_limits}};
  out["feed_rate_time_s"] = facts.feed_rate_time_s;
  out["n_moves_without_feed"] = facts.n_moves_without_feed;
  out["ignored_axis_words"] = nlohmann::json::array();
  for (const IgnoredAxisCode& code : facts.ignored_axis_codes)
    out["ignored_axis_words"].push_back({{"code", g_code_name(code.tenths)},
                                         {"n_lines", code.n_lines},
                                         {"first_line", code.first_line}});
  // null when nothing ended the program before the file's end
  out["program_end_line"] =
      facts.program_end_line > 0 ? nlohmann::json(facts.program_end_line) : nlohmann::json();
  out["n_lines_after_end"] = facts.n_lines_after_end;
  // the slicer's own declarations, to set beside the facts above
  const auto or_null = [](const auto& value) {
    return value ? nlohmann::json(*value) : nlohmann::json();
  };
  const SlicerNotes& notes = facts.slicer_notes;
  out["slicer_notes"] = {{"slicer", or_null(notes.slicer)},
                         {"estimated_time_s", or_null(notes.estimated_time_s)},
                         {"layer_count", or_null(notes.layer_count)},
                         {"filament_used_mm", or_null(notes.filament_used_mm)}};
  // the firmware settings the file makes, to set beside --machine's limits
  out["firmware_settings"] = nlohmann::json::array();
  for (const GcodeSetting& setting : facts.firmware_settings)
    out["firmware_settings"].push_back({{"command", setting.command},
                                        {"parameter", setting.parameter},
                                        {"value", setting.value},
                                        {"line", setting.line},
                                        {"last_value", setting.last_value},
                                        {"n_changes", setting.n_changes}});
  return out;
}

void inspect_gcode_file(const std::string& path, const GcodeOptions& options,
                        const InspectBaseline& baseline) {
  // the shutter codes, named by their options
  for (const ShutterCodeProblem& problem :
       shutter_code_problems(options.open_code, options.close_code))
    throw InputError(problem.at_close ? "--close" : "--open", problem.message);
  const GcodeProgram program = read_gcode_program(path, options);
  // no facts of a file that holds no code: zeros would read as an empty print
  if (const std::string problem = no_code_problem(program.n_lines, program.n_code_lines);
      !problem.empty())
    throw InputError(path, 0, "", problem);
  std::cout << gcode_facts_json(gcode_facts(program, options.rule, baseline)).dump(2) << '\n';
}

}  // namespace depotwin
