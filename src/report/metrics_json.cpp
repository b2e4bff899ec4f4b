#include "report/metrics_json.hpp"

#include <vector>

namespace depotwin {

using Json = nlohmann::ordered_json;

namespace {

// The units every number is written with (the values of metrics.json's "units" block)
namespace unit {
constexpr const char* s = "s";
constexpr const char* mm = "mm";
constexpr const char* um = "µm";
constexpr const char* mm3 = "mm^3";
constexpr const char* deg = "deg";
constexpr const char* fraction = "fraction";  // of a whole, 0..1 (0.01 = 1 %)
constexpr const char* ratio = "ratio";        // dimensionless, e.g. std/mean
constexpr const char* count = "count";
constexpr const char* index = "index";  // 0-based
}  // namespace unit

// A metrics.json object and its units, built together so that no number is written without
// its unit: `values` is the object, `units` the same keys with every number's unit (an
// array of numbers: one unit per element; a nested object: its own units object).
struct Section {
  Json values = Json::object();
  Json units = Json::object();

  Section& number(const char* key, double value, const char* u) {
    values[key] = value;
    units[key] = u;
    return *this;
  }
  Section& integer(const char* key, long value, const char* u) {
    values[key] = value;
    units[key] = u;
    return *this;
  }
  // null when absent
  Section& optional_number(const char* key, const std::optional<double>& value, const char* u) {
    values[key] = value ? Json(*value) : Json(nullptr);
    units[key] = u;
    return *this;
  }
  // one unit per element
  Section& numbers(const char* key, const std::vector<double>& value,
                   const std::vector<std::string>& element_units) {
    values[key] = value;
    units[key] = element_units;
    return *this;
  }
  // no unit: strings, flags, lists of names
  Section& plain(const char* key, Json value) {
    values[key] = std::move(value);
    return *this;
  }
  Section& section(const char* key, const Section& inner) {
    values[key] = inner.values;
    units[key] = inner.units;
    return *this;
  }
};

Section velocity_section(const VelocityErrorStats& v) {
  Section s;
  s.number("max_rel", v.max_rel, unit::fraction)
      .number("rms_rel", v.rms_rel, unit::fraction)
      .number("p95_rel", v.p95_rel, unit::fraction)
      .number("frac_len_over_1pct", v.frac_len_over_1pct, unit::fraction);
  return s;
}

// a steady error: its keys null where every printed sample is in a ramp (n/a, not 0)
Section steady_velocity_section(const VelocityErrorStats& v) {
  if (v.counted_s > 0.0) return velocity_section(v);
  Section s;
  for (const char* key : {"max_rel", "rms_rel", "p95_rel", "frac_len_over_1pct"})
    s.optional_number(key, std::nullopt, unit::fraction);
  return s;
}

Section path_section(const PathErrorStats& p) {
  Section s;
  s.number("max", p.max_mm, unit::mm).number("rms", p.rms_mm, unit::mm);
  return s;
}

Section thickness_section(const ThicknessSummary& t) {
  Section s;
  s.number("mean_um", t.mean_um, unit::um)
      .number("cv", t.cv, unit::ratio)
      .number("line_cv", t.line_cv, unit::ratio)
      .number("min_rel", t.min_rel, unit::ratio)
      .number("max_rel", t.max_rel, unit::ratio);
  return s;
}

Section waste_section(const WasteStats& w) {
  Section s;
  s.number("fraction", w.fraction, unit::fraction)
      .number("shutter_captured", w.shutter_captured, unit::fraction)
      .number("overspray", w.overspray, unit::fraction)
      .number("closed_time_s", w.closed_time_s, unit::s);
  return s;
}

Section material_section(const MaterialStats& m) {
  Section s;
  s.number("emitted", m.emitted, unit::mm3)
      .number("on_target", m.on_target, unit::mm3)
      .number("overspray", m.overspray, unit::mm3)
      .number("captured", m.captured, unit::mm3);
  return s;
}

// the ramps the steady errors leave out: how many and how long in all
Section ramps_section(const std::vector<TimeSpan>& ramps) {
  Section s;
  s.integer("count", static_cast<long>(ramps.size()), unit::count)
      .number("time_s", total_time_s(ramps), unit::s)
      .number("tolerance_rel", kRampTolerance_rel, unit::fraction);
  return s;
}

// the motion errors: simulated (the contract's keys) and planned, each whole and steady
void add_motion_errors(Section& j, const std::optional<VelocityErrorStats>& simulated,
                       const std::optional<VelocityErrorStats>& simulated_steady,
                       const VelocityErrorStats& planned, const VelocityErrorStats& planned_steady,
                       const std::optional<PathErrorStats>& simulated_path,
                       const PathErrorStats& planned_path) {
  if (simulated) j.section("velocity_error", velocity_section(*simulated));
  if (simulated_steady)
    j.section("velocity_error_steady", steady_velocity_section(*simulated_steady));
  j.section("planned_velocity_error", velocity_section(planned));
  j.section("planned_velocity_error_steady", steady_velocity_section(planned_steady));
  if (simulated_path) j.section("path_error_mm", path_section(*simulated_path));
  j.section("planned_path_error_mm", path_section(planned_path));
}

Section layer_section(const LayerReport& l) {
  Section j;
  j.integer("layer", l.layer, unit::index)
      .integer("paths", l.paths, unit::count)
      .number("print_length_mm", l.print_length_mm, unit::mm);
  Section time;
  time.number("print", l.print_s, unit::s);
  j.section("time_s", time);
  add_motion_errors(j, l.velocity_error, l.velocity_error_steady, l.planned_velocity_error,
                    l.planned_velocity_error_steady, l.path_error, l.planned_path_error);
  if (l.thickness) j.section("thickness", thickness_section(*l.thickness));
  if (l.waste) j.section("waste", waste_section(*l.waste));
  if (l.material) j.section("material_mm3", material_section(*l.material));
  return j;
}

Section posture_section(const ArmPostureStats& p) {
  Section s;
  s.number("min_joint_margin_deg", p.min_joint_margin_deg, unit::deg)
      .number("min_manipulability", p.min_manipulability, "m^3")
      .number("min_wrist_centre_offset_mm", p.min_wrist_centre_offset_mm, unit::mm)
      .number("min_wrist_alignment", p.min_wrist_alignment, unit::ratio)
      .number("min_clearance_mm", p.min_clearance_mm, unit::mm)
      .plain("nearest_shape", p.nearest_shape);
  return s;
}

Section arm_section(const ArmStats& a) {
  // the contract's keys first (the simulated run), then the details
  Section j;
  j.number("min_joint_margin_deg", a.run.min_joint_margin_deg, unit::deg)
      .number("min_manipulability", a.run.min_manipulability, "m^3")
      .number("min_clearance_mm", a.run.min_clearance_mm, unit::mm)
      .integer("collisions", a.collisions, unit::count)
      .integer("branch_changes", a.branch_changes, unit::count)
      .number("min_wrist_centre_offset_mm", a.run.min_wrist_centre_offset_mm, unit::mm)
      .number("min_wrist_alignment", a.run.min_wrist_alignment, unit::ratio)
      .plain("nearest_shape", a.run.nearest_shape);
  Section contacts;
  contacts.integer("part", a.part_contacts, unit::count)
      .integer("table", a.table_contacts, unit::count)
      .integer("self", a.self_contacts, unit::count);
  j.section("contacts", contacts);
  j.integer("branch", a.branch, unit::index);
  j.number("clearance_period_s", a.clearance_period_s, unit::s);
  const auto fixed = [](const FixedRollComparison& f) {
    Section s = posture_section(f.stats);
    s.number("roll_deg", f.roll_deg, unit::deg)
        .integer("branch", f.branch, unit::index)
        .plain("feasible", f.feasible)
        .plain("problem", f.problem)
        .optional_number("mean_cost",
                         f.feasible ? std::optional<double>(f.mean_cost) : std::nullopt,
                         unit::ratio)
        .number("joint_travel_deg", f.joint_travel_deg, unit::deg);
    return s;
  };
  Section chosen = posture_section(a.chosen_roll);
  chosen.number("mean_cost", a.chosen_mean_cost, unit::ratio)
      .number("joint_travel_deg", a.chosen_joint_travel_deg, unit::deg);
  Section roll;
  roll.plain("strategy", a.roll_strategy)
      .number("fixed_roll_deg", a.fixed_roll_deg, unit::deg)
      .section("chosen", chosen)
      .section("roll_zero", fixed(a.roll_zero))
      .section("best_fixed", fixed(a.best_fixed));
  j.section("roll", roll);
  return j;
}

// per joint: a slide in mm, a hinge in deg (ActuatorStats)
Section actuator_section(const ActuatorStats& a) {
  std::vector<std::string> vel, acc, force, ratio;
  for (size_t i = 0; i < a.joint_names.size(); ++i) {
    const bool hinge = i < a.revolute.size() && a.revolute[i];
    vel.push_back(hinge ? "deg/s" : "mm/s");
    acc.push_back(hinge ? "deg/s^2" : "mm/s^2");
    force.push_back(hinge ? "N m" : "N");
    ratio.push_back(unit::ratio);
  }
  Section s;
  s.plain("joints", a.joint_names)
      .numbers("peak_vel", a.peak_vel, vel)
      .numbers("peak_acc", a.peak_acc, acc)
      .numbers("peak_force", a.peak_force, force)
      .numbers("limit_vel", a.limit_vel, vel)
      .numbers("limit_acc", a.limit_acc, acc)
      .numbers("limit_force", a.limit_force, force)
      .numbers("plan_peak_acc", a.plan_peak_acc, acc)
      .numbers("peak_acc_over_plan", a.peak_acc_over_plan, ratio)
      .integer("limit_violations", a.limit_violations, unit::count);
  return s;
}

Section report_section(const MetricsReport& r) {
  Section j;
  j.plain("scenario", r.scenario)
      .plain("machine", r.machine)
      .plain("planner", r.planner)
      .plain("run", r.label.empty() ? r.planner : r.label)
      .plain("sequencer", r.sequencer);
  Section time;
  time.number("total", r.time.total_s, unit::s)
      .number("print", r.time.print_s, unit::s)
      .number("transition", r.time.transition_s, unit::s);
  j.section("time_s", time);
  add_motion_errors(j, r.velocity_error, r.velocity_error_steady, r.planned_velocity_error,
                    r.planned_velocity_error_steady, r.path_error, r.planned_path_error);
  j.section("speed_ramps", ramps_section(r.speed_ramps));
  if (r.thickness) j.section("thickness", thickness_section(*r.thickness));
  if (r.waste) j.section("waste", waste_section(*r.waste));
  if (r.material) j.section("material_mm3", material_section(*r.material));
  if (r.actuators) j.section("actuators", actuator_section(*r.actuators));
  if (r.order) {
    const OrderStats& o = *r.order;
    Section order;
    order.plain("method", o.method)
        .plain("refine", o.refine.empty() ? Json(nullptr) : Json(o.refine))
        .plain("cost_model", o.cost_model)
        .number("cost_s", o.cost_s, unit::s)
        .optional_number("lower_bound_s", o.lower_bound_s, unit::s);
    j.section("order", order);
  }
  j.plain("warnings", r.warnings);
  if (!r.planner_decisions.empty()) {
    // one object per decision; every decision's figures share one units object
    Json decisions = Json::array();
    Json decision_units = Json::object();
    for (const PlanDecision& d : r.planner_decisions) {
      Section one;
      one.integer("path", d.path_index, unit::index)
          .integer("point", d.point_index, unit::index)
          .plain("kind", d.kind)
          .plain("choice", d.choice);
      for (const PlanFigure& figure : d.figures)
        one.number(figure.name.c_str(), figure.value, figure.unit.c_str());
      decisions.push_back(one.values);
      decision_units.update(one.units);
    }
    Section planner;
    planner.values["decisions"] = decisions;
    planner.units["decisions"] = decision_units;
    j.section("planner", planner);
  }
  if (r.sim) {
    const SimStats& s = *r.sim;
    Section sim;
    sim.integer("steps", s.steps, unit::count)
        .number("timestep_s", s.timestep_s, unit::s)
        .number("wall_s", s.wall_s, unit::s)
        .number("realtime_factor", s.realtime_factor, unit::ratio)
        .number("max_constraint_violation_mm", s.max_constraint_violation_mm, unit::mm);
    j.section("sim", sim);
  }
  if (r.arm) j.section("arm", arm_section(*r.arm));
  if (!r.layers.empty()) {
    // every layer has the same units: one object describes them all
    Json layers = Json::array();
    Json layer_units = Json::object();
    for (const LayerReport& layer : r.layers) {
      Section one = layer_section(layer);
      layers.push_back(one.values);
      layer_units.update(one.units);  // a later layer may add its simulated blocks' units
    }
    j.plain("layers", layers);
    j.units["layers"] = layer_units;
  }
  return j;
}

}  // namespace

Json to_json(const VelocityErrorStats& stats) {
  return velocity_section(stats).values;
}

Json to_json(const MetricsReport& report) {
  Section s = report_section(report);
  s.values["units"] = s.units;
  return s.values;
}

std::string metrics_json_text(const MetricsReport& report) {
  return to_json(report).dump(2) + "\n";
}

}  // namespace depotwin
