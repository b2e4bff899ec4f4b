#include "core/profile.hpp"

#include <algorithm>
#include <cmath>

namespace depotwin {

namespace {

// a phase's state at local time tau; a constant-acceleration phase keeps the quadratic form
AxisState state_at(const Phase& phase, double tau) {
  if (phase.jerk == 0.0)
    return AxisState{phase.q0 + phase.v0 * tau + 0.5 * phase.a0 * tau * tau,
                     phase.v0 + phase.a0 * tau, phase.a0};
  return AxisState{phase.q0 + tau * (phase.v0 + tau * (0.5 * phase.a0 + tau * phase.jerk / 6.0)),
                   phase.v0 + tau * (phase.a0 + 0.5 * phase.jerk * tau),
                   phase.a0 + phase.jerk * tau};
}

// a phase's state at profile time t, held at its end beyond it
AxisState phase_state(const Phase& phase, double t) {
  return state_at(phase, std::min(t - phase.t_begin_s, phase.duration_s));
}

}  // namespace

double Phase::q_end() const {
  return state_at(*this, duration_s).q;
}

double Phase::v_end() const {
  return state_at(*this, duration_s).v;
}

void AxisProfile::append_phase(double duration_s, double a0, double jerk) {
  if (!(duration_s > 0.0)) return;
  Phase phase;
  phase.t_begin_s = this->duration_s();
  phase.duration_s = duration_s;
  phase.q0 = q_end();
  phase.v0 = v_end();
  phase.a0 = a0;
  phase.jerk = jerk;
  phases_.push_back(phase);
}

void AxisProfile::append(double duration_s, double a) {
  append_phase(duration_s, a, 0.0);
}

void AxisProfile::append_jerk(double duration_s, double jerk) {
  append_phase(duration_s, a_end(), jerk);
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

double AxisProfile::a_end() const {
  return phases_.empty() ? a_start_ : phases_.back().a_end();
}

AxisState AxisProfile::at(double t) const {
  if (phases_.empty()) return AxisState{q_start_, v_start_, a_start_};
  if (t <= 0.0) return AxisState{q_start_, v_start_, phases_.front().a0};
  // last phase starting at or before t (phases are sorted by start time)
  auto it = std::upper_bound(phases_.begin(), phases_.end(), t,
                             [](double time, const Phase& p) { return time < p.t_begin_s; });
  return phase_state(*(it - 1), t);
}

AxisState AxisProfile::at(double t, size_t& phase_hint) const {
  if (phases_.empty()) return AxisState{q_start_, v_start_, a_start_};
  if (t <= 0.0) return AxisState{q_start_, v_start_, phases_.front().a0};
  // the same phase as at(t): the last one starting at or before t
  if (phase_hint >= phases_.size() || t < phases_[phase_hint].t_begin_s) phase_hint = 0;
  while (phase_hint + 1 < phases_.size() && !(t < phases_[phase_hint + 1].t_begin_s)) ++phase_hint;
  return phase_state(phases_[phase_hint], t);
}

double AxisProfile::jerk_at(double t) const {
  if (phases_.empty()) return 0.0;
  auto it = std::upper_bound(phases_.begin(), phases_.end(), t,
                             [](double time, const Phase& p) { return time < p.t_begin_s; });
  return it == phases_.begin() ? phases_.front().jerk : (it - 1)->jerk;
}

double AxisProfile::peak_speed() const {
  double peak = std::abs(v_start_);
  for (const Phase& p : phases_) {
    peak = std::max({peak, std::abs(p.v0), std::abs(p.v_end())});
    // inside a constant-jerk phase the velocity peaks where the acceleration crosses zero
    if (p.jerk != 0.0) {
      const double t = -p.a0 / p.jerk;
      if (t > 0.0 && t < p.duration_s) peak = std::max(peak, std::abs(p.v0 + 0.5 * p.a0 * t));
    }
  }
  return peak;
}

double AxisProfile::peak_acceleration() const {
  double peak = phases_.empty() ? std::abs(a_start_) : 0.0;
  for (const Phase& p : phases_) peak = std::max({peak, std::abs(p.a0), std::abs(p.a_end())});
  return peak;
}

double AxisProfile::peak_jerk() const {
  double peak = 0.0;
  for (const Phase& p : phases_) peak = std::max(peak, std::abs(p.jerk));
  return peak;
}

}  // namespace depotwin
