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
  if (r.thickness) {
    const ThicknessSummary& t = *r.thickness;
    j["thickness"] = Json{{"mean_um", t.mean_um},
                          {"cv", t.cv},
                          {"line_cv", t.line_cv},
                          {"min_rel", t.min_rel},
                          {"max_rel", t.max_rel}};
  }
  if (r.waste) {
    const WasteStats& w = *r.waste;
    j["waste"] = Json{{"fraction", w.fraction},
                      {"shutter_captured", w.shutter_captured},
                      {"overspray", w.overspray},
                      {"closed_time_s", w.closed_time_s}};
  }
  if (r.material) {
    const MaterialStats& m = *r.material;
    j["material_mm3"] = Json{{"emitted", m.emitted},
                             {"on_target", m.on_target},
                             {"overspray", m.overspray},
                             {"captured", m.captured}};
  }
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
  return j;
}

std::string metrics_json_text(const MetricsReport& report) {
  return to_json(report).dump(2) + "\n";
}

}  // namespace depotwin
