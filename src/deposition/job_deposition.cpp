#include "deposition/job_deposition.hpp"

#include <cmath>

namespace depotwin {

bool deposition_step(const StepState& before, const StepState& after, double job_end_s,
                     DepositionStep& step) {
  if (before.t_s >= job_end_s - 1e-12) return false;
  step.t0_s = before.t_s;
  step.t1_s = after.t_s;
  step.p0_mm = before.nozzle_mm;
  step.p1_mm = after.nozzle_mm;
  step.open0 = before.open_fraction;
  step.open1 = after.open_fraction;
  // the step that straddles the job's end is cut there (chord and flap linear in time)
  if (after.t_s > job_end_s) {
    const double f = (job_end_s - before.t_s) / (after.t_s - before.t_s);
    step.t1_s = job_end_s;
    step.p1_mm = before.nozzle_mm + f * (after.nozzle_mm - before.nozzle_mm);
    step.open1 = before.open_fraction + f * (after.open_fraction - before.open_fraction);
  }
  step.flow_command = before.deposit_command ? before.flow_fraction : 0.0;
  step.desired_speed_mm_s = before.desired_speed_mm_s;
  return true;
}

void deposit_remaining_flow(Process& process, const Vec3& nozzle_mm, double job_end_s) {
  const DepositionSettings& settings = process.settings();
  if (settings.type != ProcessType::extrusion || !(process.nozzle_flow_mm3_s() > 0.0)) return;
  DepositionStep ooze;
  ooze.t0_s = job_end_s;
  ooze.t1_s = job_end_s + 40.0 * settings.tau_s;  // exp(-40): the rest goes down at once
  ooze.p0_mm = ooze.p1_mm = nozzle_mm;
  process.advance(ooze);
}

double target_thickness_um(const Process& process, const Toolpath& toolpath) {
  // a straight line at its desired speed peaks at Q / (v sigma sqrt(2 pi)); extrusion's
  // nominal flow is v w h, so its peak is w h / (sigma sqrt(2 pi)) at any speed
  if (toolpath.paths.empty()) return 0.0;
  const DepositionSettings& s = process.settings();
  const double sigma = s.footprint_sigma_mm();
  const double root = sigma * std::sqrt(2.0 * kPi);
  if (s.type == ProcessType::aerosol)
    return 1000.0 * s.aerosol_flow_mm3_s() / (toolpath.paths.front().speed_mm_s * root);
  if (s.flow_mm3_s > 0.0) return 1000.0 * s.flow_mm3_s / (toolpath.paths.front().speed_mm_s * root);
  return 1000.0 * s.bead_width_mm * s.layer_height_mm / root;
}

}  // namespace depotwin
