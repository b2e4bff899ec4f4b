// A one-axis motion made of phases of constant jerk: the shape of LSPB, minimum-time and
// trapezoidal moves (jerk 0, the acceleration stepping between phases) and of jerk-limited
// double-S moves (the acceleration continuous). Plain data, evaluated by time.
#pragma once

#include <cstddef>
#include <vector>

namespace depotwin {

struct Phase {
  double t_begin_s = 0.0;  // relative to the profile's start
  double duration_s = 0.0;
  double q0 = 0.0;    // position at the phase start (mm)
  double v0 = 0.0;    // velocity at the phase start (mm/s)
  double a0 = 0.0;    // acceleration at the phase start (mm/s^2)
  double jerk = 0.0;  // constant jerk (mm/s^3); 0 for a constant-acceleration phase

  double q_end() const;
  double v_end() const;
  double a_end() const { return a0 + jerk * duration_s; }
};

struct AxisState {
  double q = 0.0, v = 0.0, a = 0.0;
};

class AxisProfile {
 public:
  AxisProfile() = default;
  // an empty profile resting at q0 with velocity v0 and acceleration a0
  AxisProfile(double q0, double v0, double a0 = 0.0) : q_start_(q0), v_start_(v0), a_start_(a0) {}

  // append a phase of constant acceleration a (the acceleration may step here); zero-length
  // phases are dropped
  void append(double duration_s, double a);
  // append a phase of constant jerk, starting from the acceleration reached so far
  void append_jerk(double duration_s, double jerk);

  double duration_s() const;
  double q_start() const { return q_start_; }
  double v_start() const { return v_start_; }
  double a_start() const { return a_start_; }
  double q_end() const;
  double v_end() const;
  double a_end() const;
  const std::vector<Phase>& phases() const { return phases_; }

  // state at time t (relative to the profile's start); t is clamped to [0, duration]
  AxisState at(double t) const;
  // the same, with the phase searched forwards from `phase_hint` (the phase of the previous
  // call, updated): constant time per call when t only grows
  AxisState at(double t, size_t& phase_hint) const;
  double jerk_at(double t) const;
  // largest |v| (inside phases too), |a| and |jerk| over the profile
  double peak_speed() const;
  double peak_acceleration() const;
  double peak_jerk() const;

 private:
  void append_phase(double duration_s, double a0, double jerk);

  double q_start_ = 0.0;
  double v_start_ = 0.0;
  double a_start_ = 0.0;
  std::vector<Phase> phases_;
};

}  // namespace depotwin
