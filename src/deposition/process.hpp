// Deposition processes: how much material leaves the nozzle in each simulation step and
// where it lands. The pipeline calls Process::advance once per step with the simulated
// nozzle chord and the shutter / flow command; the process writes into its
// ThicknessField and keeps a MaterialAccount.
//
//  aerosol   a continuous stream Q (mm^3/s) from job start to job end (every step passed
//            to advance emits Q dt); the shutter passes open(t) of it, linear in time
//            within a step; the rest is captured. Footprint: isotropic Gaussian, sigma.
//  extrusion commanded flow Qc = flow_command * Q_nominal, Q_nominal = desired speed x
//            bead width x layer height (or flow_mm3_s when given); the nozzle flow lags
//            it, dQ/dt = (Qc - Q) / tau (pressure build-up), so a path starts thin and
//            ooze keeps flowing after the command stops. A command below 0 (settings.retract:
//            the filament pulled back) draws Q down faster, and Q stops at 0. Nothing is
//            captured.
//            Bead profile: isotropic Gaussian with sigma = w / 4. Why: the same kernel and
//            line-width convention as aerosol (+-w/2 = +-2 sigma holds 95.4% of a steady
//            line), so metrics mean the same for both; round blobs where the nozzle
//            dwells; smooth, so the map does not depend on step or cell size; separable,
//            so it is as cheap as the aerosol kernel. A steady bead's cross-section has
//            area Q/v = w h and peak w h / (sigma sqrt(2 pi)) = 1.6 h.
//
// Both integrate their footprint exactly along the step's chord (gaussian_footprint.hpp)
// and conserve material: landed = field volume, emitted = landed + captured.
// Consecutive short steps are deposited together (step_batch.hpp: one quadrature per
// batch_length_sigmas of path, checked against the steps' exact moments), so a 1 ms step
// costs a fraction of a footprint box. field() deposits the steps still pending first, so
// reads are always complete; account() is kept per step and never waits for a batch.
#pragma once

#include <memory>
#include <string>

#include "core/types.hpp"
#include "deposition/gaussian_footprint.hpp"
#include "deposition/step_batch.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin {

enum class ProcessType { aerosol, extrusion };

// "aerosol" | "extrusion"; anything else is an InputError on key "process.type"
ProcessType process_type_from_name(const std::string& name);
const char* process_type_name(ProcessType type);

// The deposition's own copy of the scenario's process settings (the pipeline copies
// scenario.hpp's ProcessSpec into it; this module does not link the scenario loader).
struct DepositionSettings {
  ProcessType type = ProcessType::aerosol;
  // aerosol: stream flow; 0 = derived so a 3 mm/s line peaks at 2 um (see aerosol_flow_mm3_s)
  // extrusion: 0 = desired speed x bead width x layer height per step; > 0 = fixed nominal flow
  double flow_mm3_s = 0.0;
  double sigma_mm = 0.1;         // aerosol footprint standard deviation
  double line_width_mm = 0.0;    // 0 = 4 sigma (aerosol) or bead width (extrusion)
  double bead_width_mm = 0.4;    // extrusion
  double layer_height_mm = 0.2;  // extrusion
  double tau_s = 0.05;           // extrusion flow lag time constant (0 = no lag)
  // extrusion: a flow command below 0 is kept (the extruder retracts: the nozzle flow falls
  // faster, and stops at 0), not raised to 0
  bool retract = false;
  double truncation_sigmas = 5.0;  // footprint fades out at this many sigma (+-0.25; renormalised)
  // consecutive steps are deposited as one quadrature until their path would exceed this
  // many sigma (step_batch.hpp); 0 = every step on its own
  double batch_length_sigmas = 1.0;

  // throws InputError naming the process.* key of every bad value
  void validate() const;

  // the footprint's sigma: sigma_mm (aerosol) or bead_width / 4 (extrusion)
  double footprint_sigma_mm() const;
  // line width for the target region: line_width_mm, else 4 sigma (aerosol: +-2 sigma holds
  // 95.4% of a line's cross-section, the usual printed-line edge) or the bead width
  double resolved_line_width_mm() const;
  // aerosol stream: flow_mm3_s, else Q = peak * v * sigma * sqrt(2 pi) with peak = 2 um and
  // v = 3 mm/s (steady line peak thickness = Q / (v sigma sqrt(2 pi)))
  double aerosol_flow_mm3_s() const;
  // default field cell when sim.cell_mm is 0: sigma / 4 (aerosol) or bead width / 8
  double default_cell_mm() const;
};

constexpr double kAerosolReferenceSpeed_mm_s = 3.0;
constexpr double kAerosolReferencePeak_um = 2.0;

// One simulation step, as recorded by the pipeline (substrate frame, mm; z is ignored).
struct DepositionStep {
  double t0_s = 0.0;
  double t1_s = 0.0;
  Vec3 p0_mm = Vec3::Zero();  // nozzle at step start
  Vec3 p1_mm = Vec3::Zero();  // nozzle at step end
  // aerosol: shutter open fraction (0 closed .. 1 open) at step start / end, linear between
  double open0 = 0.0;
  double open1 = 0.0;
  // extrusion: commanded flow as a fraction of nominal (1 while the trajectory deposits)
  double flow_command = 0.0;
  double desired_speed_mm_s = 0.0;  // extrusion nominal flow = this x bead width x layer height
};

// Material bookkeeping (mm^3): emitted = landed + captured.
struct MaterialAccount {
  double emitted_mm3 = 0.0;
  double captured_mm3 = 0.0;   // blocked by the closed (part-closed) shutter
  double landed_mm3 = 0.0;     // reached the substrate (= field volume)
  double closed_time_s = 0.0;  // integral of (1 - open fraction) dt: aerosol shutter-closed time
};

class Process {
 public:
  // cell_mm <= 0 uses settings.default_cell_mm(); the cell must lie in [sigma/64, sigma]
  // of the footprint (InputError "sim.cell_mm" otherwise)
  Process(const DepositionSettings& settings, double cell_mm);
  virtual ~Process() = default;
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  // integrate one step; steps must come in time order (t1 >= t0). No allocation except
  // the first time material reaches a new 64 x 64-cell tile.
  virtual void advance(const DepositionStep& step) = 0;
  // flow leaving the nozzle now (mm^3/s): aerosol stream Q, extrusion lagged flow
  virtual double nozzle_flow_mm3_s() const = 0;
  // forget every step: the field back to 0 (the memory of up to kRestartKeptTiles tiles kept
  // for reuse), the account and the process' own state as new (a scratch process predicting
  // one deposit after another)
  virtual void restart();
  static constexpr size_t kRestartKeptTiles = 16;
  // as if the step's flow command had been held long enough to settle (extrusion: the lagged
  // flow equals it; aerosol: nothing to settle); nothing is deposited
  virtual void start_steady(const DepositionStep& /*step*/) {}
  // the same nozzle goes on in this process (the next layer): the flow still leaving it
  // (extrusion's lag tail) moves over from `previous`, which then has none; nothing is
  // deposited, and no material is lost or counted twice
  virtual void take_nozzle_flow_from(Process& /*previous*/) {}

  // the deposit of every step advanced so far (pending batched steps are put down first;
  // not thread-safe while steps are pending: call flush() before sharing the process)
  const ThicknessField& field() const {
    flush_pending();
    return field_;
  }
  // deposit the batched steps now (field() does it when needed; the pipeline calls this
  // once after the run so the field is complete before anyone reads it)
  void flush() { flush_pending(); }
  // exact after every advance, batched or not
  const MaterialAccount& account() const { return account_; }
  // put the two steps a failed batch comes down to in one call (StepBatch::pair_short_steps):
  // for predictions, a little less exact on curves for half the calls there
  void pair_short_steps(bool on) { batch_.pair_short_steps(on); }
  // deposit only the region's cells from now on (ThicknessField::limit_writes: a prediction read
  // at a few cells); kept by restart()
  void limit_writes(ThicknessField::WriteRegion region) { field_.limit_writes(std::move(region)); }
  // how the steps were batched so far
  const StepBatch::Stats& batch_stats() const { return batch_.stats(); }
  const DepositionSettings& settings() const { return settings_; }
  double line_width_mm() const { return settings_.resolved_line_width_mm(); }
  double footprint_sigma_mm() const { return settings_.footprint_sigma_mm(); }

 protected:
  // reject steps the simulator should never produce (InternalError)
  static void check_step(const DepositionStep& step);
  // put down one step's volume along its chord with the given rate shape (batched)
  void deposit_step(const DepositionStep& step, double volume_mm3, const StepRate& rate);

  DepositionSettings settings_;
  // the field and the deposition machinery are mutable: field() completes pending
  // batches, which changes no observable value (the steps were already taken)
  mutable ThicknessField field_;
  mutable GaussianFootprint footprint_;
  mutable StepBatch batch_;
  MaterialAccount account_;

 private:
  void flush_pending() const {
    if (batch_.pending_steps() > 0) batch_.flush(footprint_, field_);
  }
};

class AerosolProcess : public Process {
 public:
  AerosolProcess(const DepositionSettings& settings, double cell_mm);
  void advance(const DepositionStep& step) override;
  double nozzle_flow_mm3_s() const override { return flow_mm3_s_; }

 private:
  double flow_mm3_s_;
};

class ExtrusionProcess : public Process {
 public:
  ExtrusionProcess(const DepositionSettings& settings, double cell_mm);
  void advance(const DepositionStep& step) override;
  void start_steady(const DepositionStep& step) override;
  void restart() override;
  void take_nozzle_flow_from(Process& previous) override;
  double nozzle_flow_mm3_s() const override { return flow_mm3_s_; }

 private:
  double command_mm3_s(const DepositionStep& step) const;  // the step's commanded flow
  double flow_mm3_s_ = 0.0;          // lagged nozzle flow at the end of the last step
  double peak_command_mm3_s_ = 0.0;  // largest commanded flow so far (for the ooze cut-off)
};

// the process the settings name (validated), with cell_mm as in Process
std::unique_ptr<Process> make_process(const DepositionSettings& settings, double cell_mm = 0.0);

}  // namespace depotwin
