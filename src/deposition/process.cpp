#include "deposition/process.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/input_ranges.hpp"

namespace depotwin {

namespace {

constexpr double kMmPerUm = 1e-3;
// footprint sigma per cell: coarser than one cell per sigma aliases the Gaussian, finer than
// 64 cells per sigma makes a step touch ~400k cells
// (one source with the scenario schema: core/input_ranges.hpp)
constexpr double kMaxCellSigmas = input_ranges::kMaxCellSigmas;
constexpr double kMinCellSigmas = input_ranges::kMinCellSigmas;
// once the ooze after a stop falls below this fraction of the largest commanded flow, its
// remaining tail (Q tau) is put down in that step and the flow snaps to zero
constexpr double kOozeCutoff = 1e-12;

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

double clamp_unit(double value) {
  return std::min(1.0, std::max(0.0, value));
}

// validate settings and resolve the cell before any member uses them
double resolve_cell_mm(const DepositionSettings& settings, double cell_mm) {
  settings.validate();
  const double cell = cell_mm > 0.0 ? cell_mm : settings.default_cell_mm();
  const double sigma = settings.footprint_sigma_mm();
  if (!std::isfinite(cell) || cell > kMaxCellSigmas * sigma * (1.0 + 1e-12) ||
      cell < kMinCellSigmas * sigma * (1.0 - 1e-12))
    throw InputError("sim.cell_mm", "cell " + number(cell) +
                                        " mm must lie between sigma/64 and sigma of the "
                                        "footprint (sigma = " +
                                        number(sigma) + " mm)");
  return cell;
}

}  // namespace

ProcessType process_type_from_name(const std::string& name) {
  if (name == "aerosol") return ProcessType::aerosol;
  if (name == "extrusion") return ProcessType::extrusion;
  throw InputError("process.type", "unknown process '" + name + "' (aerosol | extrusion)");
}

const char* process_type_name(ProcessType type) {
  return type == ProcessType::aerosol ? "aerosol" : "extrusion";
}

void DepositionSettings::validate() const {
  std::vector<Problem> problems;
  auto require = [&](bool ok, const char* key, const std::string& message) {
    if (!ok) problems.push_back(Problem{"", 0, key, message});
  };
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  require(finite_nonneg(flow_mm3_s), "process.flow_mm3_s",
          "must be >= 0, got " + number(flow_mm3_s));
  require(finite_nonneg(line_width_mm), "process.line_width_mm",
          "must be >= 0 (0 = default), got " + number(line_width_mm));
  require(truncation_sigmas >= 3.0 && truncation_sigmas <= 12.0, "process.truncation_sigmas",
          "must lie in [3, 12], got " + number(truncation_sigmas));
  require(batch_length_sigmas >= 0.0 && batch_length_sigmas <= 2.0, "process.batch_length_sigmas",
          "must lie in [0, 2] (0 = no batching), got " + number(batch_length_sigmas));
  if (type == ProcessType::aerosol) {
    require(positive(sigma_mm), "process.sigma_mm", "must be > 0, got " + number(sigma_mm));
  } else {
    require(positive(bead_width_mm), "process.bead_width_mm",
            "must be > 0, got " + number(bead_width_mm));
    require(positive(layer_height_mm), "process.layer_height_mm",
            "must be > 0, got " + number(layer_height_mm));
    require(finite_nonneg(tau_s), "process.tau_s", "must be >= 0, got " + number(tau_s));
  }
  if (!problems.empty()) throw InputError(std::move(problems));
}

double DepositionSettings::footprint_sigma_mm() const {
  return type == ProcessType::aerosol ? sigma_mm : 0.25 * bead_width_mm;
}

double DepositionSettings::resolved_line_width_mm() const {
  if (line_width_mm > 0.0) return line_width_mm;
  return type == ProcessType::aerosol ? 4.0 * sigma_mm : bead_width_mm;
}

double DepositionSettings::aerosol_flow_mm3_s() const {
  if (flow_mm3_s > 0.0) return flow_mm3_s;
  // steady line: peak = Q / (v sigma sqrt(2 pi))  =>  Q = peak v sigma sqrt(2 pi)
  return kAerosolReferencePeak_um * kMmPerUm * kAerosolReferenceSpeed_mm_s * sigma_mm *
         std::sqrt(2.0 * kPi);
}

double DepositionSettings::default_cell_mm() const {
  return type == ProcessType::aerosol ? 0.25 * sigma_mm : 0.125 * bead_width_mm;
}

Process::Process(const DepositionSettings& settings, double cell_mm)
    : settings_(settings),
      field_(resolve_cell_mm(settings, cell_mm)),
      footprint_(settings.footprint_sigma_mm(), field_.cell_mm(), settings.truncation_sigmas,
                 settings.batch_length_sigmas),
      batch_(settings.footprint_sigma_mm(),
             settings.batch_length_sigmas * settings.footprint_sigma_mm()) {}

void Process::deposit_step(const DepositionStep& step, double volume_mm3, const StepRate& rate) {
  BatchStep batch_step;
  batch_step.t0_s = step.t0_s;
  batch_step.t1_s = step.t1_s;
  batch_step.x0_mm = step.p0_mm.x();
  batch_step.y0_mm = step.p0_mm.y();
  batch_step.x1_mm = step.p1_mm.x();
  batch_step.y1_mm = step.p1_mm.y();
  batch_step.volume_mm3 = volume_mm3;
  batch_step.rate = rate;
  batch_.add(footprint_, field_, batch_step);
}

void Process::restart() {
  batch_.discard();
  // the memory of a few tiles is kept for the next deposit; a field grown larger is freed
  if (field_.allocated_tiles() <= kRestartKeptTiles)
    field_.zero();
  else
    field_.clear();
  account_ = MaterialAccount{};
}

void Process::check_step(const DepositionStep& step) {
  const bool finite = std::isfinite(step.t0_s) && std::isfinite(step.t1_s) &&
                      step.p0_mm.allFinite() && step.p1_mm.allFinite() &&
                      std::isfinite(step.open0) && std::isfinite(step.open1) &&
                      std::isfinite(step.flow_command) && std::isfinite(step.desired_speed_mm_s);
  if (!finite)
    throw InternalError("deposition: non-finite step at t = " + number(step.t0_s) +
                        " s (simulator diverged?)");
  if (step.t1_s < step.t0_s)
    throw InternalError("deposition: step ends before it starts (t0 = " + number(step.t0_s) +
                        " s, t1 = " + number(step.t1_s) + " s)");
}

AerosolProcess::AerosolProcess(const DepositionSettings& settings, double cell_mm)
    : Process(settings, cell_mm), flow_mm3_s_(settings.aerosol_flow_mm3_s()) {}

void AerosolProcess::advance(const DepositionStep& step) {
  check_step(step);
  const double dt_s = step.t1_s - step.t0_s;
  const double open0 = clamp_unit(step.open0);
  const double open1 = clamp_unit(step.open1);
  const double mean_open = 0.5 * (open0 + open1);

  // the stream always runs; the shutter passes the mean open fraction, captures the rest
  const double emitted_mm3 = flow_mm3_s_ * dt_s;
  const double landed_mm3 = emitted_mm3 * mean_open;
  account_.emitted_mm3 += emitted_mm3;
  account_.landed_mm3 += landed_mm3;
  account_.captured_mm3 += emitted_mm3 - landed_mm3;
  account_.closed_time_s += dt_s * (1.0 - mean_open);

  // the flap moves linearly within the step: the rate along the chord is linear too
  StepRate rate;
  rate.constant = open0;
  rate.slope = open1 - open0;
  deposit_step(step, landed_mm3, rate);
}

ExtrusionProcess::ExtrusionProcess(const DepositionSettings& settings, double cell_mm)
    : Process(settings, cell_mm) {}

// commanded flow: a fraction of the nominal bead flow (speed x width x height)
double ExtrusionProcess::command_mm3_s(const DepositionStep& step) const {
  const double nominal_mm3_s = settings_.flow_mm3_s > 0.0
                                   ? settings_.flow_mm3_s
                                   : std::max(0.0, step.desired_speed_mm_s) *
                                         settings_.bead_width_mm * settings_.layer_height_mm;
  // a command below 0 retracts only where the extruder may (settings.retract)
  return (settings_.retract ? step.flow_command : std::max(0.0, step.flow_command)) * nominal_mm3_s;
}

void ExtrusionProcess::restart() {
  Process::restart();
  flow_mm3_s_ = 0.0;
  peak_command_mm3_s_ = 0.0;
}

void ExtrusionProcess::take_nozzle_flow_from(Process& previous) {
  auto* extruder = dynamic_cast<ExtrusionProcess*>(&previous);
  if (extruder == nullptr || extruder == this) return;
  flow_mm3_s_ += extruder->flow_mm3_s_;
  peak_command_mm3_s_ = std::max(peak_command_mm3_s_, extruder->peak_command_mm3_s_);
  extruder->flow_mm3_s_ = 0.0;
}

void ExtrusionProcess::start_steady(const DepositionStep& step) {
  check_step(step);
  flow_mm3_s_ = std::max(0.0, command_mm3_s(step));
  peak_command_mm3_s_ = std::max(peak_command_mm3_s_, flow_mm3_s_);
}

void ExtrusionProcess::advance(const DepositionStep& step) {
  check_step(step);
  const double dt_s = step.t1_s - step.t0_s;
  const double command_mm3_s = this->command_mm3_s(step);
  peak_command_mm3_s_ = std::max(peak_command_mm3_s_, command_mm3_s);

  // first-order lag, exact over the step: Q(t) = Qc + (Q0 - Qc) exp(-(t - t0) / tau)
  const double flow0_mm3_s = flow_mm3_s_;
  const double tau_s = settings_.tau_s;
  double flow1_mm3_s = command_mm3_s;
  double volume_mm3 = command_mm3_s * dt_s;
  double decay_per_step = 0.0;  // dt / tau, the exponent of the lag over the whole step
  if (tau_s > 0.0) {
    decay_per_step = dt_s / tau_s;
    flow1_mm3_s = command_mm3_s + (flow0_mm3_s - command_mm3_s) * std::exp(-decay_per_step);
    volume_mm3 += (flow0_mm3_s - command_mm3_s) * tau_s * -std::expm1(-decay_per_step);
    // ooze tail below the cut-off: put the rest (integral Q tau) down now
    if (command_mm3_s == 0.0 && flow1_mm3_s < kOozeCutoff * peak_command_mm3_s_) {
      volume_mm3 += flow1_mm3_s * tau_s;
      flow1_mm3_s = 0.0;
    }
  }
  // a retracting command (settings.retract) draws the flow down faster; it stops at 0, at
  // u = ln((Q0 - Qc) / -Qc) / (dt / tau) of the step, having put down Qc u dt + Q0 tau
  double flowing_share = 1.0;  // the share of the step the nozzle flows in
  if (command_mm3_s < 0.0) {
    if (flow0_mm3_s <= 0.0 || tau_s <= 0.0) {
      flowing_share = 0.0;
      volume_mm3 = 0.0;
    } else if (flow1_mm3_s < 0.0) {
      flowing_share = std::log((flow0_mm3_s - command_mm3_s) / -command_mm3_s) / decay_per_step;
      volume_mm3 = command_mm3_s * flowing_share * dt_s + flow0_mm3_s * tau_s;
    }
    flow1_mm3_s = std::max(0.0, flow1_mm3_s);
  }
  flow_mm3_s_ = flow1_mm3_s;
  volume_mm3 = std::max(0.0, volume_mm3);

  // everything that leaves the nozzle lands
  account_.emitted_mm3 += volume_mm3;
  account_.landed_mm3 += volume_mm3;
  if (flowing_share <= 0.0) return;

  // rate within the step: Qc + (Q0 - Qc) exp(-u dt / tau), over the part of the chord the
  // nozzle flows along (all of it unless a retraction stopped the flow)
  StepRate rate;
  rate.constant = command_mm3_s;
  rate.decaying = tau_s > 0.0 ? flow0_mm3_s - command_mm3_s : 0.0;
  rate.decay = decay_per_step;
  if (flowing_share >= 1.0) {
    deposit_step(step, volume_mm3, rate);
    return;
  }
  DepositionStep flowing = step;
  flowing.t1_s = step.t0_s + flowing_share * dt_s;
  flowing.p1_mm = step.p0_mm + flowing_share * (step.p1_mm - step.p0_mm);
  rate.decay = decay_per_step * flowing_share;
  deposit_step(flowing, volume_mm3, rate);
}

std::unique_ptr<Process> make_process(const DepositionSettings& settings, double cell_mm) {
  if (settings.type == ProcessType::aerosol)
    return std::make_unique<AerosolProcess>(settings, cell_mm);
  return std::make_unique<ExtrusionProcess>(settings, cell_mm);
}

}  // namespace depotwin
