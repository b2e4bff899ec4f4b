#include "sim/servo_controller.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/types.hpp"
#include "sim/mujoco_boundary.hpp"

namespace depotwin {

Servo resolve_servo(const mjModel& model, const std::string& name, const std::string& path,
                    const std::string& purpose) {
  Servo servo;
  servo.name = name;
  servo.joint = require_id(model, mjOBJ_JOINT, name, path, purpose);
  const int type = model.jnt_type[servo.joint];
  if (type != mjJNT_SLIDE && type != mjJNT_HINGE)
    throw InputError(path, 0, "joint " + name, "must be a slide or a hinge joint");
  servo.user_to_si = type == mjJNT_SLIDE ? 1.0 / kMmPerM : 1.0;
  servo.unit = type == mjJNT_SLIDE ? "mm" : "rad";
  servo.qpos_adr = model.jnt_qposadr[servo.joint];
  servo.dof_adr = model.jnt_dofadr[servo.joint];
  servo.damping = model.dof_damping[servo.dof_adr];
  servo.friction = model.dof_frictionloss[servo.dof_adr];

  // the actuator of the same name must be a position servo on this joint
  servo.actuator = require_id(model, mjOBJ_ACTUATOR, name, path, "the servo driving joint " + name);
  const int a = servo.actuator;
  const mjtNum* gain = model.actuator_gainprm + a * mjNGAIN;
  const mjtNum* bias = model.actuator_biasprm + a * mjNBIAS;
  const bool position_servo =
      model.actuator_trntype[a] == mjTRN_JOINT && model.actuator_trnid[2 * a] == servo.joint &&
      model.actuator_dyntype[a] == mjDYN_NONE && model.actuator_gaintype[a] == mjGAIN_FIXED &&
      model.actuator_biastype[a] == mjBIAS_AFFINE && gain[0] > 0.0 && bias[0] == 0.0 &&
      std::abs(bias[1] + gain[0]) <= 1e-9 * gain[0] && bias[2] <= 0.0 &&
      std::abs(model.actuator_gear[6 * a] - 1.0) < 1e-12;
  if (!position_servo)
    throw InputError(path, 0, "actuator " + name,
                     "must be a position servo on joint '" + name +
                         "' with gear 1: <general gaintype=\"fixed\" gainprm=\"kp\" "
                         "biastype=\"affine\" biasprm=\"0 -kp -kv\"/> or <position kp=\"...\"/>");
  servo.kp = gain[0];
  servo.kv = -bias[2];
  return servo;
}

FrictionLaw friction_law(const mjModel& m, int dof, double frictionloss) {
  const mjtNum* solref = m.dof_solref + mjNREF * dof;
  const mjtNum* solimp = m.dof_solimp + mjNIMP * dof;
  const double d_min = std::clamp<double>(solimp[0], mjMINIMP, mjMAXIMP);
  const double d_max = std::clamp<double>(solimp[1], mjMINIMP, mjMAXIMP);
  FrictionLaw law;
  if (solref[0] > 0.0) {
    double timeconst = solref[0];
    if (!(m.opt.disableflags & mjDSBL_REFSAFE))
      timeconst = std::max(timeconst, 2.0 * m.opt.timestep);
    law.rate_per_s = 2.0 / (d_max * timeconst);
  } else {
    law.rate_per_s = -solref[1] / d_max;
  }
  const double regulariser =
      std::max<double>(mjMINVAL, (1.0 - d_min) / d_min * m.dof_invweight0[dof]);
  law.speed_si =
      law.rate_per_s > 0.0 ? frictionloss * regulariser / law.rate_per_s : kFrictionFadeSpeed_si;
  return law;
}

void fix_friction_law(const mjModel& m, Servo& servo) {
  if (!(servo.friction > 0.0)) return;
  const FrictionLaw law = friction_law(m, servo.dof_adr, servo.friction);
  servo.friction_speed_si = law.speed_si;  // (speed_si > 0: the regulariser is at least mjMINVAL)
  servo.friction_rate_per_s = law.rate_per_s;
}

void sampled_setpoint_references(const std::vector<double>& position, std::vector<double>& velocity,
                                 std::vector<double>& acceleration, long updates, int width,
                                 double period_s) {
  for (long u = updates - 1; u >= 1; --u)
    for (int j = 0; j < width; ++j)
      velocity[u * width + j] =
          (position[u * width + j] - position[(u - 1) * width + j]) / period_s;
  for (long u = 0; u < updates; ++u)
    for (int j = 0; j < width; ++j)
      acceleration[u * width + j] =
          u + 1 < updates ? (velocity[(u + 1) * width + j] - velocity[u * width + j]) / period_s
                          : 0.0;
}

void inertia_times(const mjModel& m, const mjData& d, const mjtNum* vec, mjtNum* force) {
  const mjtNum* inertia = d.qM;
  for (int i = 0; i < m.nv; ++i) {
    int adr = m.dof_Madr[i];
    if (m.dof_simplenum[i]) {
      force[i] = inertia[adr] * vec[i];
      continue;
    }
    force[i] = 0.0 + inertia[adr] * vec[i];
    ++adr;
    for (int j = m.dof_parentid[i]; j >= 0; j = m.dof_parentid[j], ++adr) {
      force[i] += inertia[adr] * vec[j];
      force[j] += inertia[adr] * vec[i];
    }
  }
}

namespace {

// What the servo must hold over the coming control period so that the plant tracks the
// setpoints: the controls are held for n = control_stride steps of h (T = n h), each a
// semi-implicit Euler step (force at the step's start). On the reference the velocity state
// at step j is the backward difference over h, v(t + j h) - a h / 2, so over the n steps, with
// v the reference velocity (the backward difference over T, sampled_setpoint_references) and
// a the acceleration over the period:
//   mean position   r + (v + a T / 2) h (n - 1) / 2 + a h^2 (n - 1)(2n - 1) / 12
//   mean velocity   v + a h (n - 1)          (what the servo's -kv qdot sees)
//   end velocity    v + a T                  (Euler integrates joint damping implicitly, at a
//                                             step's end velocity)
// With n = 1 these are the setpoint, v and the next v: the feed-forward matches the plant
// step by step. Without them the servo lagged by (kv + damping) a h / 2 / kp at every
// acceleration.
struct HeldReference {
  double position_si = 0.0;
  double velocity_si = 0.0;
  double end_velocity_si = 0.0;
};

HeldReference held_reference(const mjModel& m, long steps, double q_si, double v_si, double a_si) {
  const double h = m.opt.timestep;
  const double n = static_cast<double>(steps);
  const double period_s = n * h;
  HeldReference held;
  held.position_si = q_si + (v_si + 0.5 * a_si * period_s) * h * (n - 1.0) / 2.0 +
                     a_si * h * h * (n - 1.0) * (2.0 * n - 1.0) / 12.0;
  held.velocity_si = v_si + a_si * h * (n - 1.0);
  held.end_velocity_si = v_si + a_si * period_s;
  return held;
}

}  // namespace

// ctrl = q_held + f_ff / kp (see the header for f_ff), on the held references above. The
// friction term is the plant's friction law (friction_law) at the reference's velocity and
// acceleration, its own switching speed v_s included: the feed-forward switches when the
// plant's friction does, and as gradually (a switch over a narrower speed than the plant's,
// 0.1 mm/s against the XY stage's 0.21, left the y carriage up to 3.4 times its planned
// acceleration at velocity reversals).
void apply_servo(const mjModel& m, mjData& d, const Servo& servo, bool feedforward,
                 long control_stride, double q_si, double v_si, double a_si, double inertia_force,
                 double extra_force) {
  if (!feedforward) {
    d.ctrl[servo.actuator] = q_si;
    return;
  }
  const HeldReference held = held_reference(m, control_stride, q_si, v_si, a_si);
  double friction_force = 0.0;
  if (servo.friction > 0.0) {
    const double leading_si =
        held.velocity_si +
        (servo.friction_rate_per_s > 0.0 ? a_si / servo.friction_rate_per_s : 0.0);
    friction_force = servo.friction * std::clamp(leading_si / servo.friction_speed_si, -1.0, 1.0);
  }
  const double force = inertia_force + d.qfrc_bias[servo.dof_adr] + servo.kv * held.velocity_si +
                       servo.damping * held.end_velocity_si + friction_force + extra_force;
  d.ctrl[servo.actuator] = held.position_si + force / servo.kp;
}

}  // namespace depotwin
