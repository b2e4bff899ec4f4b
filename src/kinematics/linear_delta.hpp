// Linear delta robot (Giberti et al., Fig. 8): three vertical carriages at 120 degrees,
// parallelogram rods to the platform. Analytic inverse kinematics, forward kinematics
// by trilateration.
//
// As in the paper (sec. 6.1: "the delta robot architecture capable to translate the
// platform where the extruded material is laid down", the extruder "installed on the top
// of the machine"), the platform carries the substrate under a fixed nozzle. The
// carriages run below the platform and the rods rise to it, so the space above the
// platform stays free for the nozzle.
//
// World frame as in models/linear_delta.xml: z up, the nozzle tip (the `nozzle` site) at
// the origin. With p the platform's rod-joint centre (world, mm) and the substrate surface
// `substrate_above_joints_mm` above it, the nozzle point in the substrate frame is
//   tcp = -p - (0, 0, substrate_above_joints_mm)        (p moves opposite to tcp)
// Arm i (column at angle theta_i, unit radial u_i) has its effective carriage point at
// C_i = (D u_i, H + q_i), D = carriage_radius - platform_radius, where q_i is the MJCF
// slide joint (carriage height from home) and H = -substrate_above_joints - sqrt(L^2 - D^2)
// the carriage joints' home height (tcp = 0). Every rod has length L, so
//   |p - C_i| = L   =>   q_i = p_z - sqrt(L^2 - |p_xy - D u_i|^2) - H   (inverse)
// and the forward kinematics is the upper intersection of three spheres (trilateration).
#pragma once

#include <array>
#include <memory>
#include <string>

#include "kinematics/machine.hpp"

namespace depotwin {

// Geometry, masses and limits; the defaults match models/linear_delta.xml.
struct LinearDeltaGeometry {
  // column angles (deg, from world +x, counter-clockwise seen from above)
  std::array<double, 3> column_angle_deg{90.0, 210.0, 330.0};
  double carriage_radius_mm = 210.0;  // axis to the carriage rod joints (pair centre)
  double platform_radius_mm = 50.0;   // platform centre to its rod joints (pair centre)
  double rod_length_mm = 350.0;       // joint centre to joint centre, all six rods
  double rod_spacing_mm = 50.0;       // distance between the two rods of a parallelogram
  double max_rod_angle_deg = 55.0;    // rod angle from vertical (joint range, stiffness)
  double carriage_min_mm = -200.0;    // carriage travel, from the home height
  double carriage_max_mm = 125.0;
  double substrate_above_joints_mm = 9.0;  // substrate surface above the platform joints
  double min_tcp_z_mm = -1.0;  // the nozzle may not go deeper below the substrate surface
  // carriage limits (each carriage), scenario `limits: {joint: {v_max, a_max}}`
  double carriage_v_max_mm_s = 200.0;
  double carriage_a_max_mm_s2 = 3000.0;
  // cartesian_limits() keeps carriages within this fraction of their limits
  double limit_margin = 0.95;
  // masses for the load feed-forward (kg): platform + substrate + half of the six rods;
  // one carriage + half of its two rods
  double platform_mass_kg = 0.66;
  double carriage_mass_kg = 0.27;
  // the part of the platform load MuJoCo's per-joint terms do not see (platform + substrate
  // bodies, without the rods, which hang from the carriages in the MJCF tree)
  double closure_mass_kg = 0.60;
  // one rod (uniform thin tube, six of them); closure_feedforward moves the part of the rods'
  // dynamics the MJCF tree puts on the carriages to where the closed chain puts it
  double rod_mass_kg = 0.02;
  double gravity_m_s2 = 9.81;

  // world z of the carriage rod joints at the home pose (all joints 0, tcp = 0)
  double home_carriage_height_mm() const;
  // "" when usable, else what is wrong
  std::string validate() const;
};

class LinearDelta final : public Machine {
 public:
  explicit LinearDelta(const LinearDeltaGeometry& geometry = LinearDeltaGeometry{});

  std::string name() const override { return "linear_delta"; }
  std::string model_file() const override { return "linear_delta.xml"; }
  int joint_count() const override { return 3; }
  // joints "carriage1".."carriage3" (MJCF slide joints and actuators, mm from home)
  const std::vector<JointLimit>& joint_limits() const override { return joint_limits_; }

  // the nozzle stays vertical: a tilted tool axis is unreachable
  bool inverse(const Pose& pose, JointVector& joints, std::string* why = nullptr) const override;
  // NaN components when no platform position fits the three carriage heights
  Pose forward(const JointVector& joints) const override;
  // d tcp / dq = -(dq/dp)^-1, dq_i/dp = w_i^T / w_iz (the platform moves opposite to the TCP)
  Jacobian jacobian(const JointVector& joints) const override;
  JointVector joint_velocity(const JointVector& joints, const PoseRate& rate) const override;
  // exact carriage accelerations q'' = J a + (dJ/dt) v at a pose (mm/s^2)
  JointVector joint_acceleration(const JointVector& joints, const Vec3& tcp_velocity,
                                 const Vec3& tcp_acceleration) const;

  // Per-axis limits with a closed-form bound over the reachable part of the box:
  //   |q'_i|  <= (Wx Vx + Wy Vy) / S + Vz
  //   |q''_i| <= (Wx Ax + Wy Ay) / S + Az + (Vx^2 + Vy^2 + ((Wx Vx + Wy Vy) / S)^2) / S
  // with Wx, Wy the largest |p_x - c_x|, |p_y - c_y| and S the smallest rod height
  // sqrt(L^2 - d^2) of arm i over the box (all at box corners; d capped at the rod-angle
  // limit). Velocities are scaled first, so the centripetal term stays under half of
  // the carriage acceleration; then the accelerations take what is left. The carriages
  // stay within limit_margin of their limits; never looser than `requested`.
  MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                 const Vec3& hi) const override;

  // scenario `limits: {joint: {v_max, a_max}}`: the same limits on every carriage
  void set_carriage_limits(double v_max_mm_s, double a_max_mm_s2);
  // a carriage jerk limit is refused: cartesian_limits bounds carriage speed and
  // acceleration only (set the TCP's limits.j_max instead)
  std::string set_joint_limits(const AxisLimits& limits) override;
  // What the simulator's per-joint terms (each carriage's subtree, carriage + its two rods,
  // translating with the carriage: m (q'' + g)) miss of the closed chain's rigid-body
  // dynamics, at the TCP's position, velocity and acceleration: the platform's load
  // (closure_mass_kg: platform + substrate) through the rods by the Jacobian transpose, and
  // the rods' true motion (each end follows its own joint: a thin rod's kinetic energy
  // m/6 (|v_a|^2 + v_a . v_b + |v_b|^2), half its weight at either end) instead of riding
  // on the carriage
  bool has_closures() const override { return true; }
  void closure_feedforward(const Vec3& tcp_mm, const Vec3& tcp_velocity_mm_s,
                           const Vec3& tcp_acceleration_mm_s2, double* joint_force) const override;
  const LinearDeltaGeometry& geometry() const { return geometry_; }

 private:
  LinearDeltaGeometry geometry_;
  std::vector<JointLimit> joint_limits_;
};

// the rod-joint centre of the platform (world, mm) that puts the nozzle at `tcp_mm`
Vec3 linear_delta_platform_position(const LinearDeltaGeometry& geometry, const Vec3& tcp_mm);

// Carriage feed-forward forces (N, +z up, one per carriage) that hold the platform and
// carriages against gravity and give them the accelerations of the TCP motion: the
// platform force m_p (p'' + g e_z) mapped through the Jacobian transpose (virtual work,
// massless rods with half their mass lumped at each end) plus m_c (q''_i + g) per carriage.
// Add to the servo's force (or divide by kp and add to a position servo's ctrl).
// No allocation: safe to call every simulation step.
std::array<double, 3> linear_delta_feedforward_forces_n(const LinearDeltaGeometry& geometry,
                                                        const Vec3& tcp_mm,
                                                        const Vec3& tcp_velocity_mm_s,
                                                        const Vec3& tcp_acceleration_mm_s2);

// the machine with default geometry and limits
std::unique_ptr<Machine> make_linear_delta();
// the machine with the given geometry (e.g. with scenario carriage limits)
std::unique_ptr<LinearDelta> make_linear_delta(const LinearDeltaGeometry& geometry);

}  // namespace depotwin
