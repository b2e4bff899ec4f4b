#include "metrics/run_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace depotwin {

namespace {

// a simulated peak above a joint's limit by more than rounding: a servo that tracks a speed
// planned at the limit reads it back a few ulp above (15 mm/s "above" 15 mm/s by 1e-10)
constexpr double kLimitRoundoff = 1e-9;

bool exceeds(double peak, double limit) {
  return limit > 0.0 && peak > limit * (1.0 + kLimitRoundoff);
}

}  // namespace

MotionSamples recorded_motion(const RecordedRun& record) {
  MotionSamples samples;
  samples.reserve(record.size());
  for (size_t k = 0; k < record.size(); ++k)
    samples.push_back(record.t_s[k], record.nozzle_mm[k], record.nozzle_velocity_mm_s[k],
                      record.deposit_command[k], record.path_index[k],
                      record.desired_speed_mm_s[k]);
  return samples;
}

MotionSamples trajectory_motion_at(const Trajectory& trajectory, const std::vector<double>& times) {
  MotionSamples samples;
  samples.reserve(times.size());
  for (double t : times) {
    const TrajectorySample s = trajectory.at(t);
    samples.push_back(t, s.position_mm, s.velocity_mm_s, s.depositing, s.path_index,
                      s.desired_speed_mm_s);
  }
  return samples;
}

ActuatorStats actuator_stats(const RecordedRun& record, const std::vector<JointLimit>& limits,
                             const std::vector<double>& force_limits) {
  ActuatorStats stats;
  for (int j = 0; j < record.joint_count; ++j) {
    double v = 0.0, a = 0.0, f = 0.0;
    for (size_t k = 0; k < record.size(); ++k) {
      v = std::max(v, std::abs(record.joint(record.joint_velocity, k, j)));
      a = std::max(a, std::abs(record.joint(record.joint_acceleration, k, j)));
      f = std::max(f, std::abs(record.joint(record.actuator_force, k, j)));
    }
    const bool known = j < static_cast<int>(limits.size());
    const double v_lim = known ? limits[j].v_max : 0.0;
    const double a_lim = known ? limits[j].a_max : 0.0;
    const double f_lim = j < static_cast<int>(force_limits.size()) ? force_limits[j] : 0.0;
    const double plan_a = j < static_cast<int>(record.reference_peak_acceleration.size())
                              ? record.reference_peak_acceleration[j]
                              : 0.0;
    // the limits are counted in the record's units; a hinge is reported in degrees
    if (exceeds(v, v_lim)) ++stats.limit_violations;
    if (exceeds(a, a_lim)) ++stats.limit_violations;
    if (exceeds(f, f_lim)) ++stats.limit_violations;
    const double scale = known && limits[j].revolute ? 180.0 / kPi : 1.0;
    stats.joint_names.push_back(record.joint_names[j]);
    stats.revolute.push_back(known && limits[j].revolute);
    stats.peak_vel.push_back(scale * v);
    stats.peak_acc.push_back(scale * a);
    stats.peak_force.push_back(f);
    stats.limit_vel.push_back(scale * v_lim);
    stats.limit_acc.push_back(scale * a_lim);
    stats.limit_force.push_back(f_lim);
    stats.plan_peak_acc.push_back(scale * plan_a);
    stats.peak_acc_over_plan.push_back(plan_a > 0.0 ? a / plan_a : 0.0);
  }
  return stats;
}

std::vector<std::string> actuator_limit_warnings(const ActuatorStats& stats) {
  std::vector<std::string> warnings;
  const auto number = [](double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return std::string(text);
  };
  for (std::size_t j = 0; j < stats.joint_names.size(); ++j) {
    const bool hinge = stats.revolute[j];
    // the same comparisons as limit_violations, in the units the report gives
    const struct {
      const char* what;
      double peak, limit;
      const char* unit;
    } quantities[] = {
        {"speed", stats.peak_vel[j], stats.limit_vel[j], hinge ? "deg/s" : "mm/s"},
        {"acceleration", stats.peak_acc[j], stats.limit_acc[j], hinge ? "deg/s^2" : "mm/s^2"},
        {"actuator force", stats.peak_force[j], stats.limit_force[j], hinge ? "N m" : "N"},
    };
    for (const auto& q : quantities)
      if (exceeds(q.peak, q.limit))
        warnings.push_back("joint " + stats.joint_names[j] + ": peak " + q.what + " " +
                           number(q.peak) + " " + q.unit + " above its limit " + number(q.limit) +
                           " " + q.unit + " (+" + number(100.0 * (q.peak / q.limit - 1.0)) +
                           " %) in the simulation");
  }
  return warnings;
}

std::string arm_collision_warning(const ArmStats& arm, const ContactLog& contacts) {
  if (arm.collisions <= 0) return "";
  std::string warning =
      "collisions in the simulation: " + std::to_string(arm.collisions) + " contact event(s), " +
      std::to_string(arm.table_contacts) + " with the table, " + std::to_string(arm.part_contacts) +
      " with the part, " + std::to_string(arm.self_contacts) + " of the arm with itself";
  if (!contacts.first.empty()) warning += " (the first MuJoCo contact at " + contacts.first + ")";
  return warning;
}

std::string thickness_coverage_warning(const ThicknessStats& stats) {
  // the scores' cells and samples leave out half a line width at every path's end
  const bool few_cells = stats.cells < kFewestScoredCells;
  const bool few_samples = stats.line_samples < kFewestScoredSamples;
  if (!few_cells && !few_samples) return "";
  const auto counted = [](size_t count, const char* what) {
    return count == 0 ? std::string("no ") + what : "only " + std::to_string(count) + " " + what;
  };
  std::string scores;
  if (few_cells)
    scores =
        "thickness mean_um, cv, min_rel and max_rel (" + counted(stats.cells, "target cells") + ")";
  if (few_samples)
    scores += (scores.empty() ? "thickness line_cv (" : " and line_cv (") +
              counted(stats.line_samples, "centreline samples") + ")";
  return scores +
         " measure too little to score the deposit: they leave out half a line width at each "
         "path's end, and the paths are hardly longer than the line is wide (a 0 there is no "
         "perfect score)";
}

namespace {

ThicknessSummary thickness_summary(const ThicknessStats& stats) {
  ThicknessSummary thickness;
  thickness.mean_um = stats.mean_um;
  thickness.cv = stats.cv;
  thickness.line_cv = stats.line_cv;
  thickness.min_rel = stats.min_rel;
  thickness.max_rel = stats.max_rel;
  return thickness;
}

// volumes, and the waste as fractions of what was emitted
void material_and_waste(const MaterialSplit& m, MetricsReport& r) {
  MaterialStats material;
  material.emitted = m.emitted_mm3;
  material.on_target = m.on_target_mm3;
  material.overspray = m.overspray_mm3;
  material.captured = m.captured_mm3;
  r.material = material;
  WasteStats waste;
  waste.fraction = m.fraction;
  waste.shutter_captured = m.emitted_mm3 > 0 ? m.captured_mm3 / m.emitted_mm3 : 0.0;
  waste.overspray = m.emitted_mm3 > 0 ? m.overspray_mm3 / m.emitted_mm3 : 0.0;
  waste.closed_time_s = m.closed_time_s;
  r.waste = waste;
}

SimStats sim_stats(const RecordedRun& record) {
  SimStats sim;
  sim.steps = record.steps;
  sim.timestep_s = record.timestep_s;
  sim.wall_s = record.wall_s;
  const double simulated_s = record.t_s.empty() ? 0.0 : record.t_s.back();
  sim.realtime_factor = record.wall_s > 0 ? simulated_s / record.wall_s : 0.0;
  sim.max_constraint_violation_mm = record.max_constraint_violation_mm;
  return sim;
}

}  // namespace

MotionSamples only_layer(const MotionSamples& samples, const Toolpath& toolpath, int layer) {
  MotionSamples kept = samples;
  for (size_t k = 0; k < kept.size(); ++k) {
    const int path = kept.path_index[k];
    if (path < 0 || toolpath.paths[static_cast<size_t>(path)].layer != layer)
      kept.depositing[k] = 0;
  }
  return kept;
}

namespace {

// only_layer restricted to the samples that can affect a layer's scores: from one sample
// before its first printing sample to one after its last (each sample's time weight and
// each ramp's span reach one neighbour on either side), so every score is the same, sum for
// sum, as over the whole run's samples, at a cost in the layer's own samples
MotionSamples layer_window(const MotionSamples& samples, const Toolpath& toolpath, int layer) {
  const auto prints_layer = [&](size_t k) {
    const int path = samples.path_index[k];
    return samples.depositing[k] && path >= 0 &&
           toolpath.paths[static_cast<size_t>(path)].layer == layer;
  };
  const size_t n = samples.size();
  size_t first = 0;
  while (first < n && !prints_layer(first)) ++first;
  if (first == n) return MotionSamples{};  // the layer is never printed: nothing to score
  size_t last = n - 1;
  while (!prints_layer(last)) --last;
  const size_t begin = first > 0 ? first - 1 : 0;
  const size_t end = std::min(n, last + 2);
  MotionSamples window;
  window.reserve(end - begin);
  for (size_t k = begin; k < end; ++k)
    window.push_back(samples.t_s[k], samples.position_mm[k], samples.velocity_mm_s[k],
                     prints_layer(k), samples.path_index[k], samples.desired_speed_mm_s[k]);
  return window;
}

}  // namespace

std::vector<LayerReport> layer_reports(const Toolpath& toolpath, const MotionSamples& planned,
                                       const MotionSamples& simulated,
                                       const LayeredDeposit& deposit) {
  std::vector<LayerReport> reports;
  const double period_s = planned.size() > 1 ? planned.t_s[1] - planned.t_s[0] : 0.0;
  for (int layer = 0; layer < toolpath.layer_count(); ++layer) {
    LayerReport r;
    r.layer = layer;
    // the layer's own paths, joined where they touch (as for the whole job)
    Toolpath paths;
    for (const PrintPath& path : toolpath.paths) {
      if (path.layer != layer) continue;
      ++r.paths;
      r.print_length_mm += path.length_mm();
      paths.paths.push_back(path);
    }
    // motion: the samples printing this layer
    const MotionSamples planned_here = layer_window(planned, toolpath, layer);
    for (size_t k = 0; k + 1 < planned_here.size(); ++k)
      if (planned_here.depositing[k]) r.print_s += period_s;
    const std::vector<TimeSpan> ramps = speed_ramps(planned_here);
    r.planned_velocity_error = velocity_error(planned_here);
    r.planned_velocity_error_steady = velocity_error(planned_here, ramps);
    r.planned_path_error = path_error(planned_here, toolpath);
    if (!simulated.t_s.empty()) {
      const MotionSamples simulated_here = layer_window(simulated, toolpath, layer);
      r.velocity_error = velocity_error(simulated_here);
      r.velocity_error_steady = velocity_error(simulated_here, ramps);
      r.path_error = path_error(simulated_here, toolpath);
      // the layer's deposit: thickness along the normal, volumes from its own process
      if (!paths.paths.empty()) {
        const Toolpath merged = merge_joined_paths(paths);
        const ThicknessField& vertical = deposit.layer(layer).field();
        const TargetRegion region(merged, deposit.line_width_mm(), vertical.cell_mm());
        r.thickness =
            thickness_summary(thickness_stats(deposit.layer_normal_field(layer), region, merged));
        MetricsReport split;
        material_and_waste(split_material(vertical, region, deposit.layer(layer).account()), split);
        r.waste = split.waste;
        r.material = split.material;
      }
    }
    reports.push_back(std::move(r));
  }
  return reports;
}

void add_simulated_metrics(MetricsReport& r, const RecordedRun& record,
                           const MotionSamples& simulated, const Toolpath& toolpath,
                           const DepositionMetrics& deposited) {
  r.velocity_error = velocity_error(simulated);
  r.velocity_error_steady = velocity_error(simulated, r.speed_ramps);
  r.path_error = path_error(simulated, toolpath);
  r.thickness = thickness_summary(deposited.thickness);
  if (const std::string warning = thickness_coverage_warning(deposited.thickness); !warning.empty())
    r.warnings.push_back(warning);
  material_and_waste(deposited.material, r);
  r.sim = sim_stats(record);
}

}  // namespace depotwin
