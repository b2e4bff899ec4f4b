// A one-axis motion made of constant-acceleration phases (the shape of LSPB,
// minimum-time and trapezoidal moves). Plain data, evaluated by time.
#pragma once

#include <cstddef>
#include <vector>

namespace depotwin {

struct Phase {
  double t_begin_s = 0.0;  // relative to the profile's start
  double duration_s = 0.0;
  double q0 = 0.0;  // position at the phase start (mm)
  double v0 = 0.0;  // velocity at the phase start (mm/s)
  double a = 0.0;   // constant acceleration (mm/s^2)

  double q_end() const { return q0 + v0 * duration_s + 0.5 * a * duration_s * duration_s; }
  double v_end() const { return v0 + a * duration_s; }
};

struct AxisState {
  double q = 0.0, v = 0.0, a = 0.0;
};

class AxisProfile {
 public:
  AxisProfile() = default;
  // an empty profile resting at q0 with velocity v0
  AxisProfile(double q0, double v0) : q_start_(q0), v_start_(v0) {}

  // append a phase of the given duration and constant acceleration; zero-length phases are dropped
  void append(double duration_s, double a);

  double duration_s() const;
  double q_start() const { return q_start_; }
  double v_start() const { return v_start_; }
  double q_end() const;
  double v_end() const;
  const std::vector<Phase>& phases() const { return phases_; }

  // state at time t (relative to the profile's start); t is clamped to [0, duration]
  AxisState at(double t) const;
  // the same, with the phase searched forwards from `phase_hint` (the phase of the previous
  // call, updated): constant time per call when t only grows
  AxisState at(double t, size_t& phase_hint) const;
  // largest |v| and |a| over the profile
  double peak_speed() const;
  double peak_acceleration() const;

 private:
  double q_start_ = 0.0;
  double v_start_ = 0.0;
  std::vector<Phase> phases_;
};

}  // namespace depotwin
