// MuJoCo's whole state (qpos) sampled over a simulated run, for replays (run.mp4, `depotwin
// view`): the RecordedRun holds the machine's actuated joints only, but a replay must also
// place the passive ones (a delta's rods and free platform, the shutter's flap).
//
// Simulation::run hands its states to on_step in chunks of 64 steps (the first of one step),
// between physics steps: the last state of a chunk is the simulation's current state, so its
// qpos is read there exactly (1 ms in, then every 64 ms at 1 ms steps). In between, the samples are
// interpolated linearly (quaternions renormalised), and the machine's joints are taken from the
// record at the time itself (linear between its 1 ms steps), so the nozzle is where the run put it.
#pragma once

#include <vector>

#include "core/recorded_run.hpp"

namespace depotwin {

class Simulation;

class StateSamples {
 public:
  // resolves the machine's joints (the record's joint_names) in the simulation's model
  explicit StateSamples(const Simulation& simulation);

  // from Simulation::run's on_step(before, after): samples qpos when `after` is the
  // simulation's current state. The simulation must outlive the run.
  void on_step(const StepState& after);

  int nq() const { return nq_; }
  size_t sample_count() const { return times_s_.size(); }
  // qpos (SI units, the model's order) at t_s into `qpos` (nq values); before the first
  // sample the first is held (the model's qpos0 without any)
  void qpos_at(double t_s, const RecordedRun& record, double* qpos) const;

 private:
  const Simulation* simulation_;
  int nq_ = 0;
  std::vector<double> qpos0_;
  std::vector<double> times_s_;
  std::vector<double> samples_;  // sample-major, nq_ each
  // the record's joints: qpos address and user-unit -> SI factor (mm -> m for slides)
  std::vector<int> machine_qpos_adr_;
  std::vector<double> machine_to_si_;
  std::vector<int> quaternion_adr_;  // first qpos of each ball / free joint's quaternion
};

}  // namespace depotwin
