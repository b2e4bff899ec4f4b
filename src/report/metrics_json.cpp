#include "report/metrics_json.hpp"

namespace depotwin {

using Json = nlohmann::ordered_json;

Json to_json(const VelocityErrorStats& s) {
  return Json{{"max_rel", s.max_rel},
              {"rms_rel", s.rms_rel},
              {"p95_rel", s.p95_rel},
              {"frac_len_over_1pct", s.frac_len_over_1pct}};
}

namespace {

Json to_json(const PathErrorStats& s) {
  return Json{{"max", s.max_mm}, {"rms", s.rms_mm}};
}

Json to_json(const ThicknessSummary& t) {
  return Json{{"mean_um", t.mean_um},
              {"cv", t.cv},
              {"line_cv", t.line_cv},
              {"min_rel", t.min_rel},
              {"max_rel", t.max_rel}};
}

Json to_json(const WasteStats& w) {
  return Json{{"fraction", w.fraction},
              {"shutter_captured", w.shutter_captured},
              {"overspray", w.overspray},
              {"closed_time_s", w.closed_time_s}};
}

Json to_json(const MaterialStats& m) {
  return Json{{"emitted", m.emitted},
              {"on_target", m.on_target},
              {"overspray", m.overspray},
              {"captured", m.captured}};
}

Json to_json(const LayerReport& l) {
  Json j;
  j["layer"] = l.layer;
  j["paths"] = l.paths;
  j["print_length_mm"] = l.print_length_mm;
  j["time_s"] = Json{{"print", l.print_s}};
  if (l.velocity_error) j["velocity_error"] = to_json(*l.velocity_error);
  j["planned_velocity_error"] = to_json(l.planned_velocity_error);
  j["path_error_mm"] = to_json(l.path_error);
  if (l.thickness) j["thickness"] = to_json(*l.thickness);
  if (l.waste) j["waste"] = to_json(*l.waste);
  if (l.material) j["material_mm3"] = to_json(*l.material);
  return j;
}

Json to_json(const ArmPostureStats& p) {
  return Json{{"min_joint_margin_deg", p.min_joint_margin_deg},
              {"min_manipulability", p.min_manipulability},
              {"min_wrist_centre_offset_mm", p.min_wrist_centre_offset_mm},
              {"min_wrist_alignment", p.min_wrist_alignment},
              {"min_clearance_mm", p.min_clearance_mm},
              {"nearest_shape", p.nearest_shape}};
}

Json to_json(const ArmStats& a) {
  // the contract's keys first (the simulated run), then the details
  Json j{{"min_joint_margin_deg", a.run.min_joint_margin_deg},
         {"min_manipulability", a.run.min_manipulability},
         {"min_clearance_mm", a.run.min_clearance_mm},
         {"collisions", a.collisions},
         {"branch_changes", a.branch_changes}};
  j["min_wrist_centre_offset_mm"] = a.run.min_wrist_centre_offset_mm;
  j["min_wrist_alignment"] = a.run.min_wrist_alignment;
  j["nearest_shape"] = a.run.nearest_shape;
  j["contacts"] =
      Json{{"part", a.part_contacts}, {"table", a.table_contacts}, {"self", a.self_contacts}};
  j["branch"] = a.branch;
  j["clearance_period_s"] = a.clearance_period_s;
  const auto fixed = [](const FixedRollComparison& f) {
    Json j = to_json(f.stats);
    j["roll_deg"] = f.roll_deg;
    j["branch"] = f.branch;
    j["feasible"] = f.feasible;
    j["problem"] = f.problem;
    j["mean_cost"] = f.feasible ? Json(f.mean_cost) : Json(nullptr);
    j["joint_travel_deg"] = f.joint_travel_deg;
    return j;
  };
  Json chosen = to_json(a.chosen_roll);
  chosen["mean_cost"] = a.chosen_mean_cost;
  chosen["joint_travel_deg"] = a.chosen_joint_travel_deg;
  j["roll"] = Json{{"strategy", a.roll_strategy},
                   {"fixed_roll_deg", a.fixed_roll_deg},
                   {"chosen", chosen},
                   {"roll_zero", fixed(a.roll_zero)},
                   {"best_fixed", fixed(a.best_fixed)}};
  return j;
}

}  // namespace

Json to_json(const MetricsReport& r) {
  Json j;
  j["scenario"] = r.scenario;
  j["machine"] = r.machine;
  j["planner"] = r.planner;
  j["run"] = r.label.empty() ? r.planner : r.label;
  j["sequencer"] = r.sequencer;
  j["time_s"] = Json{
      {"total", r.time.total_s}, {"print", r.time.print_s}, {"transition", r.time.transition_s}};
  if (r.velocity_error) j["velocity_error"] = to_json(*r.velocity_error);
  j["planned_velocity_error"] = to_json(r.planned_velocity_error);
  j["path_error_mm"] = to_json(r.path_error);
  if (r.planned_path_error) j["planned_path_error_mm"] = to_json(*r.planned_path_error);
  if (r.thickness) j["thickness"] = to_json(*r.thickness);
  if (r.waste) j["waste"] = to_json(*r.waste);
  if (r.material) j["material_mm3"] = to_json(*r.material);
  if (r.actuators) {
    const ActuatorStats& a = *r.actuators;
    j["actuators"] = Json{{"joints", a.joint_names},
                          {"peak_vel", a.peak_vel},
                          {"peak_acc", a.peak_acc},
                          {"peak_force", a.peak_force},
                          {"limit_vel", a.limit_vel},
                          {"limit_acc", a.limit_acc},
                          {"limit_force", a.limit_force},
                          {"plan_peak_acc", a.plan_peak_acc},
                          {"peak_acc_over_plan", a.peak_acc_over_plan},
                          {"limit_violations", a.limit_violations}};
  }
  if (r.order) {
    const OrderStats& o = *r.order;
    j["order"] = Json{{"method", o.method},
                      {"refine", o.refine},
                      {"cost_model", o.cost_model},
                      {"cost_s", o.cost_s},
                      {"lower_bound_s", o.lower_bound_s ? Json(*o.lower_bound_s) : Json(nullptr)}};
  }
  j["warnings"] = r.warnings;
  if (r.sim) {
    const SimStats& s = *r.sim;
    j["sim"] = Json{{"steps", s.steps},
                    {"timestep_s", s.timestep_s},
                    {"wall_s", s.wall_s},
                    {"realtime_factor", s.realtime_factor},
                    {"max_constraint_violation_mm", s.max_constraint_violation_mm}};
  }
  if (r.arm) j["arm"] = to_json(*r.arm);
  if (!r.layers.empty()) {
    Json layers = Json::array();
    for (const LayerReport& layer : r.layers) layers.push_back(to_json(layer));
    j["layers"] = layers;
  }
  return j;
}

std::string metrics_json_text(const MetricsReport& report) {
  return to_json(report).dump(2) + "\n";
}

}  // namespace depotwin
