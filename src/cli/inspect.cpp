#include "cli/inspect.hpp"

#include <iostream>

namespace depotwin {

namespace {

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

GcodeFacts gcode_facts(const GcodeProgram& program, PrintRule rule) {
  GcodeFacts facts;
  const PrintRule resolved = resolve_print_rule(program, rule, &facts.rule_reason);
  facts.rule = print_rule_name(resolved);
  facts.n_lines = program.n_lines;
  facts.layer_z_values = print_layer_levels(program, resolved);
  facts.n_retractions = program.n_retractions;
  facts.extrusion_e_total = program.extrusion_e_total;
  facts.estimated_time_s = program.dwell_s;
  bool previous_printed = false;
  Vec3 previous_end = Vec3::Zero();
  // every move: print or travel, its length, boxes and time
  for (const GcodeMove& move : program.moves) {
    const bool prints = move_prints(move, resolved);
    grow(facts.all_moves_bbox, move);
    if (prints) {
      ++facts.n_print_moves;
      facts.print_length_mm += move.length_mm;
      facts.n_print_arcs += move.arc.is_arc() ? 1 : 0;
      grow(facts.print_bbox, move);
      const bool continues =
          previous_printed && (move.from_mm - previous_end).norm() <= kJoinTolerance_mm;
      facts.n_print_paths += continues ? 0 : 1;
    } else {
      ++facts.n_travel_moves;
      facts.travel_length_mm += move.length_mm;
    }
    previous_printed = prints;
    previous_end = move.to_mm;
    if (move.feed_mm_s > 0.0)
      facts.estimated_time_s += move.length_mm / move.feed_mm_s;
    else
      ++facts.n_moves_without_feed;
  }
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
  out["n_moves_without_feed"] = facts.n_moves_without_feed;
  return out;
}

void inspect_gcode_file(const std::string& path, const GcodeOptions& options) {
  const GcodeProgram program = read_gcode_program(path, options);
  std::cout << gcode_facts_json(gcode_facts(program, options.rule)).dump(2) << '\n';
}

}  // namespace depotwin
