#include "render/state_samples.hpp"

#include <algorithm>
#include <cmath>

#include "sim/mujoco_access.hpp"

namespace depotwin {

StateSamples::StateSamples(const Simulation& simulation) : simulation_(&simulation) {
  const mjModel& model = SimulationAccess::model(simulation);
  nq_ = model.nq;
  qpos0_.assign(model.qpos0, model.qpos0 + model.nq);
  // the machine's joints, as the record names them; quaternions to renormalise
  for (const std::string& name : simulation.joint_names()) {
    const int joint = mj_name2id(&model, mjOBJ_JOINT, name.c_str());
    machine_qpos_adr_.push_back(joint >= 0 ? model.jnt_qposadr[joint] : -1);
    machine_to_si_.push_back(joint >= 0 && model.jnt_type[joint] == mjJNT_SLIDE ? 1e-3 : 1.0);
  }
  for (int joint = 0; joint < model.njnt; ++joint) {
    if (model.jnt_type[joint] == mjJNT_FREE)
      quaternion_adr_.push_back(model.jnt_qposadr[joint] + 3);
    if (model.jnt_type[joint] == mjJNT_BALL) quaternion_adr_.push_back(model.jnt_qposadr[joint]);
  }
}

void StateSamples::on_step(const StepState& after) {
  // only the chunk's last state is the simulation's current one
  const mjData& data = SimulationAccess::data(*simulation_);
  if (after.t_s != data.time) return;
  if (!times_s_.empty() && after.t_s <= times_s_.back()) return;
  times_s_.push_back(after.t_s);
  samples_.insert(samples_.end(), data.qpos, data.qpos + nq_);
}

void StateSamples::qpos_at(double t_s, const RecordedRun& record, double* qpos) const {
  // the samples on either side, linearly (held beyond the first and the last)
  if (times_s_.empty()) {
    std::copy(qpos0_.begin(), qpos0_.end(), qpos);
  } else {
    const size_t upper = static_cast<size_t>(
        std::upper_bound(times_s_.begin(), times_s_.end(), t_s) - times_s_.begin());
    const size_t hi = std::min(upper, times_s_.size() - 1);
    const size_t lo = upper == 0 ? 0 : upper - 1;
    const double span = times_s_[hi] - times_s_[lo];
    const double w = span > 0.0 ? std::clamp((t_s - times_s_[lo]) / span, 0.0, 1.0) : 0.0;
    const double* a = samples_.data() + lo * nq_;
    const double* b = samples_.data() + hi * nq_;
    for (int i = 0; i < nq_; ++i) qpos[i] = (1.0 - w) * a[i] + w * b[i];
    for (const int adr : quaternion_adr_) {
      double norm = 0.0;
      for (int i = 0; i < 4; ++i) norm += qpos[adr + i] * qpos[adr + i];
      norm = std::sqrt(norm);
      if (norm > 0.0)
        for (int i = 0; i < 4; ++i) qpos[adr + i] /= norm;
    }
  }

  // the machine's joints from the record at t itself, linear between its steps
  if (record.size() == 0 || record.joint_count != static_cast<int>(machine_qpos_adr_.size()))
    return;
  const size_t last = record.size() - 1;
  const double dt = record.timestep_s > 0.0 ? record.timestep_s : 1.0;
  const double position =
      std::clamp((t_s - record.t_s.front()) / dt, 0.0, static_cast<double>(last));
  const size_t k = std::min(static_cast<size_t>(position), last);
  const size_t k1 = std::min(k + 1, last);
  const double w = position - static_cast<double>(k);
  for (int j = 0; j < record.joint_count; ++j) {
    if (machine_qpos_adr_[j] < 0) continue;
    const double user = (1.0 - w) * record.joint(record.joint_position, k, j) +
                        w * record.joint(record.joint_position, k1, j);
    qpos[machine_qpos_adr_[j]] = user * machine_to_si_[j];
  }
}

}  // namespace depotwin
