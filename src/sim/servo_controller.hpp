// The servo controller of every machine joint (internal to sim/, MuJoCo-typed): one
// position servo per joint, resolved once from the model, driven by
//   ctrl = q_held + f_ff / kp
//   f_ff = (M a_ref)_j + qfrc_bias_j + kv_j v_held_j + damping_j v_end_j
//          + frictionloss_j clamp((v_ref_j + a_ref_j / B_j) / v_s_j, -1, 1) + hook_j
// where the references come from the sampled position setpoints as a digital servo forms
// them (sampled_setpoint_references) and q_held, v_held, v_end are what the plant's
// semi-implicit Euler steps see over the held period (held_reference). The friction term is
// the model's own friction-loss law (friction_law: Coulomb above v_s, a velocity servo of
// rate B below, the plant's own v_s: a narrower switch kicks the axis at every velocity
// reversal). So the actuator force
// kp (ctrl - q) - kv qdot = kp (q_held - q) + kv (v_held - qdot) + f_ff: PD on the reference
// plus inertia, bias (gravity, Coriolis), viscous, Coulomb friction and an optional
// machine-specific load feed-forward.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

namespace depotwin {

// one servo-driven joint, resolved once at load time
struct Servo {
  std::string name;
  int joint = -1;
  int actuator = -1;
  int qpos_adr = -1;
  int dof_adr = -1;
  double user_to_si = 1.0;  // mm -> m for slides, 1 for hinges
  const char* unit = "rad";
  double kp = 0.0;        // N/m or N m/rad
  double kv = 0.0;        // N s/m or N m s/rad (actuator velocity gain)
  double damping = 0.0;   // joint damping, same units as kv
  double friction = 0.0;  // joint Coulomb friction (frictionloss), N or N m
  // the plant's friction law on this dof (friction_law), fixed once the timestep is set:
  // its regularisation speed v_s and its rate B
  double friction_speed_si = 0.0;
  double friction_rate_per_s = 0.0;
};

// the friction feed-forward's switching speed (SI) where the model's friction law has no rate
// to give one (friction_law)
constexpr double kFrictionFadeSpeed_si = 1e-4;

// The joint `name` and its actuator of the same name, which must be a position servo on it
// with gear 1; InputError naming the model file and the element otherwise. `purpose` says
// why the joint is needed, for the message.
Servo resolve_servo(const mjModel& model, const std::string& name, const std::string& path,
                    const std::string& purpose);

// MuJoCo's friction-loss constraint on a dof, as the solver applies it at zero violation:
// the force F clamp((J qacc + B v) R^-1 / F), a velocity servo of rate B (1/s) and
// regulariser R, saturated at the friction loss F. B = 2 / (d_max timeconst) (timeconst at
// least two timesteps unless refsafe is off; solref's direct form: B = -damping / d_max),
// R = (1 - d) / d invweight0 (d = solimp's d_min). For a motion at acceleration a the force
// is F clamp((v + a / B) / v_s) with v_s = F R / B: Coulomb friction above the speed v_s,
// leading the velocity by 1 / B.
struct FrictionLaw {
  double speed_si = 0.0;    // v_s
  double rate_per_s = 0.0;  // B
};

FrictionLaw friction_law(const mjModel& m, int dof, double frictionloss);

// the servo's friction feed-forward from the plant's law; depends on the timestep, so it is
// fixed once that is set
void fix_friction_law(const mjModel& m, Servo& servo);

// Velocity and acceleration references from the sampled position setpoints r_u (one per
// control update, `width` values each), as a digital servo forms its feed-forward: the
// velocity v_u = (r_u - r_{u-1}) / T, the velocity state a plant stepped by semi-implicit Euler
// (q_{k+1} = q_k + h v_{k+1}) has at t_u when it is on the setpoints (v_0 stays the plan's,
// the state the run starts from), and a_u = (v_{u+1} - v_u) / T, which takes it exactly to
// the next one. The analytic mean (v(t + T) - v(t)) / T is half a step late for such a plant:
// at every acceleration step of the plan it fed a wrong impulse, and the servo rang.
void sampled_setpoint_references(const std::vector<double>& position, std::vector<double>& velocity,
                                 std::vector<double>& acceleration, long updates, int width,
                                 double period_s);

// force = M vec with MuJoCo's sparse joint-space inertia (qM, valid after mj_step1): the
// product mj_mulM forms, with the same operations in the same order (each dof's diagonal,
// then the entries shared with its ancestors), minus the call and the memset zeroing `force`
// whose wide stores stalled the first read of each entry (about 15 ns a step on the XY stage).
// A dof's ancestors come before it, so force[i] is still untouched when dof i starts: it
// starts from 0.0 + (diagonal term), exactly as mj_mulM's zeroed entry does.
void inertia_times(const mjModel& m, const mjData& d, const mjtNum* vec, mjtNum* force);

// One servo's control at an update: ctrl = q_held + f_ff / kp (see the top of this file), for
// the setpoint q_si, its velocity v_si and acceleration a_si, held for `control_stride`
// steps; `inertia_force` is (M a_ref) at this servo's dof, `extra_force` a machine's load
// feed-forward. Without feed-forward the setpoint alone (plain PD).
void apply_servo(const mjModel& m, mjData& d, const Servo& servo, bool feedforward,
                 long control_stride, double q_si, double v_si, double a_si, double inertia_force,
                 double extra_force);

}  // namespace depotwin
