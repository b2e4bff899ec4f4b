#include "core/profile.hpp"

#include <algorithm>
#include <cmath>

namespace depotwin {

void AxisProfile::append(double duration_s, double a) {
  if (!(duration_s > 0.0)) return;
  Phase phase;
  phase.t_begin_s = this->duration_s();
  phase.duration_s = duration_s;
  phase.q0 = q_end();
  phase.v0 = v_end();
  phase.a = a;
  phases_.push_back(phase);
}

double AxisProfile::duration_s() const {
  return phases_.empty() ? 0.0 : phases_.back().t_begin_s + phases_.back().duration_s;
}

double AxisProfile::q_end() const {
  return phases_.empty() ? q_start_ : phases_.back().q_end();
}

double AxisProfile::v_end() const {
  return phases_.empty() ? v_start_ : phases_.back().v_end();
}

namespace {

// a phase's state at local time tau, held at its end beyond it
AxisState phase_state(const Phase& phase, double t) {
  const double tau = std::min(t - phase.t_begin_s, phase.duration_s);
  return AxisState{phase.q0 + phase.v0 * tau + 0.5 * phase.a * tau * tau, phase.v0 + phase.a * tau,
                   phase.a};
}

}  // namespace

AxisState AxisProfile::at(double t) const {
  if (phases_.empty()) return AxisState{q_start_, v_start_, 0.0};
  if (t <= 0.0) return AxisState{q_start_, v_start_, phases_.front().a};
  // last phase starting at or before t (phases are sorted by start time)
  auto it = std::upper_bound(phases_.begin(), phases_.end(), t,
                             [](double time, const Phase& p) { return time < p.t_begin_s; });
  return phase_state(*(it - 1), t);
}

AxisState AxisProfile::at(double t, size_t& phase_hint) const {
  if (phases_.empty()) return AxisState{q_start_, v_start_, 0.0};
  if (t <= 0.0) return AxisState{q_start_, v_start_, phases_.front().a};
  // the same phase as at(t): the last one starting at or before t
  if (phase_hint >= phases_.size() || t < phases_[phase_hint].t_begin_s) phase_hint = 0;
  while (phase_hint + 1 < phases_.size() && !(t < phases_[phase_hint + 1].t_begin_s)) ++phase_hint;
  return phase_state(phases_[phase_hint], t);
}

double AxisProfile::peak_speed() const {
  double peak = std::abs(v_start_);
  for (const Phase& p : phases_) peak = std::max({peak, std::abs(p.v0), std::abs(p.v_end())});
  return peak;
}

double AxisProfile::peak_acceleration() const {
  double peak = 0.0;
  for (const Phase& p : phases_) peak = std::max(peak, std::abs(p.a));
  return peak;
}

}  // namespace depotwin
