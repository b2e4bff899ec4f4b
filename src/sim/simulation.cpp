#include "sim/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "core/error.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/shutter.hpp"

namespace depotwin {

namespace {

constexpr double kMinTimestep_s = 1e-5;
constexpr double kMaxTimestep_s = 0.01;
// the names every model shares (see the header)
constexpr const char* kNozzleSite = "nozzle";
constexpr const char* kSubstrateBody = "substrate";
constexpr const char* kShutterJoint = "shutter";
// how often run() looks at the clock for progress reports
constexpr long kProgressCheckSteps = 256;
// how many steps' states run() buffers before handing them to on_step
constexpr size_t kCallbackChunkSteps = 64;
constexpr double kProgressPeriod_s = 0.1;

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

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
  // its regularisation speed capped at kFrictionFadeSpeed_si, and its rate B
  double friction_speed_si = 0.0;
  double friction_rate_per_s = 0.0;
};

// the friction feed-forward switches sign over at most this reference speed (SI), so a
// reversal does not kick the servo
constexpr double kFrictionFadeSpeed_si = 1e-4;

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

// a custom numeric's values; InputError when missing or too short
const mjtNum* require_numeric(const mjModel& model, const std::string& name, int size,
                              const std::string& path) {
  const int id = require_id(model, mjOBJ_NUMERIC, name, path, "the shutter's parameters");
  if (model.numeric_size[id] < size)
    throw InputError(path, 0, "custom numeric " + name,
                     "needs " + std::to_string(size) + " value(s)");
  return model.numeric_data + model.numeric_adr[id];
}

}  // namespace

long SimSettings::control_stride() const {
  return std::max(1L, std::lround(control_period_s / timestep_s));
}

std::string SimSettings::validate() const {
  if (!std::isfinite(timestep_s) || timestep_s < kMinTimestep_s || timestep_s > kMaxTimestep_s)
    return "timestep_s must be between " + format_number(kMinTimestep_s) + " and " +
           format_number(kMaxTimestep_s) + " s, got " + format_number(timestep_s);
  if (!std::isfinite(control_period_s) || control_period_s <= 0.0)
    return "control_period_s must be a positive number, got " + format_number(control_period_s);
  const double ratio = control_period_s / timestep_s;
  if (ratio > 1.0 && std::abs(ratio - std::round(ratio)) > 1e-6 * ratio)
    return "control_period_s (" + format_number(control_period_s) +
           " s) must be a whole number of timesteps (" + format_number(timestep_s) + " s)";
  if (!std::isfinite(kp_scale) || kp_scale <= 0.0)
    return "kp_scale must be a positive number, got " + format_number(kp_scale);
  if (!std::isfinite(settle_s) || settle_s < 0.0)
    return "settle_s must be >= 0, got " + format_number(settle_s);
  if (!std::isfinite(shutter_time_s) || shutter_time_s < 0.0)
    return "shutter_time_s must be >= 0 (0: the model's), got " + format_number(shutter_time_s);
  return "";
}

struct Simulation::Impl {
  std::string model_path;
  const Machine* machine = nullptr;
  SimSettings settings;
  ModelPtr model;
  DataPtr data;
  std::vector<Servo> joints;  // in Machine joint order
  std::vector<std::string> joint_names;
  bool has_shutter = false;
  Servo shutter;
  ShutterGeometry shutter_geometry;
  int nozzle_site = -1;
  int substrate_body = -1;
  long control_stride = 1;
  FeedForwardHook hook;
  // scratch reused by every controller update (no allocation in the step loop)
  std::vector<mjtNum> acceleration_reference;  // nv
  std::vector<mjtNum> inertia_force;           // nv
  std::vector<double> hook_force;              // joints

  void read_nozzle(Vec3& position_mm, Vec3& velocity_mm_s) const;
  double open_fraction(bool deposit_command) const;
  double constraint_violation_mm() const;
  void assemble_closures();
  void apply_servo(const Servo& servo, double q_si, double v_si, double extra_force) const;
};

namespace {

// (angular, linear) world velocity of the point at world position `point` moving with `body`:
// cvel is the body's velocity about its root's subtree centre of mass, moved to the point.
// The same arithmetic, in the same order, as mj_objectVelocity(.., flg_local = 0) through
// mju_transformSpatial: linear = v_com - (point - com) x w. Inline because it runs twice a
// step, where the library call's dispatch cost more than the six products.
void world_point_velocity(const mjModel& m, const mjData& d, int body, const mjtNum* point,
                          mjtNum velocity[6]) {
  const mjtNum* cvel = d.cvel + 6 * body;
  const mjtNum* com = d.subtree_com + 3 * m.body_rootid[body];
  const mjtNum dif[3] = {point[0] - com[0], point[1] - com[1], point[2] - com[2]};
  const mjtNum cross[3] = {dif[1] * cvel[2] - dif[2] * cvel[1], dif[2] * cvel[0] - dif[0] * cvel[2],
                           dif[0] * cvel[1] - dif[1] * cvel[0]};
  for (int i = 0; i < 3; ++i) {
    velocity[i] = cvel[i];
    velocity[3 + i] = cvel[3 + i] - cross[i];
  }
}

// force = M vec with MuJoCo's sparse joint-space inertia (qM, valid after mj_step1): the
// product mj_mulM forms, with the same operations in the same order (each dof's diagonal,
// then the entries shared with its ancestors), minus the call and the memset zeroing `force`
// whose wide stores stalled the first read of each entry (about 15 ns a step on the XY stage).
// A dof's ancestors come before it, so force[i] is still untouched when dof i starts: it
// starts from 0.0 + (diagonal term), exactly as mj_mulM's zeroed entry does.
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

}  // namespace

// nozzle site relative to the substrate frame, and its velocity relative to the substrate
void Simulation::Impl::read_nozzle(Vec3& position_mm, Vec3& velocity_mm_s) const {
  const mjModel* m = model.get();
  const mjData* d = data.get();
  const mjtNum* site = d->site_xpos + 3 * nozzle_site;
  const mjtNum* origin = d->xpos + 3 * substrate_body;
  const mjtNum* rotation = d->xmat + 9 * substrate_body;  // row-major, columns = body axes

  // velocity of the substrate point under the nozzle: v_origin + w x (p - origin)
  mjtNum site_velocity[6], body_velocity[6];
  world_point_velocity(*m, *d, m->site_bodyid[nozzle_site], site, site_velocity);
  world_point_velocity(*m, *d, substrate_body, origin, body_velocity);
  const Vec3 offset(site[0] - origin[0], site[1] - origin[1], site[2] - origin[2]);
  const Vec3 omega(body_velocity[0], body_velocity[1], body_velocity[2]);
  const Vec3 substrate_point_velocity =
      Vec3(body_velocity[3], body_velocity[4], body_velocity[5]) + omega.cross(offset);
  const Vec3 relative_velocity =
      Vec3(site_velocity[3], site_velocity[4], site_velocity[5]) - substrate_point_velocity;

  // both into the substrate frame: local = R^T world
  for (int axis = 0; axis < 3; ++axis) {
    double p = 0.0, v = 0.0;
    for (int row = 0; row < 3; ++row) {
      p += rotation[3 * row + axis] * offset[row];
      v += rotation[3 * row + axis] * relative_velocity[row];
    }
    position_mm[axis] = m_to_mm(p);
    velocity_mm_s[axis] = m_to_mm(v);
  }
}

double Simulation::Impl::open_fraction(bool deposit_command) const {
  if (!has_shutter) return deposit_command ? 1.0 : 0.0;
  return shutter_open_fraction(data->qpos[shutter.qpos_adr], shutter_geometry);
}

// largest residual of the equality constraints (connect closures), mm
double Simulation::Impl::constraint_violation_mm() const {
  const mjData* d = data.get();
  double largest = 0.0;
  for (int row = 0; row < d->nefc; ++row)
    if (d->efc_type[row] == mjCNSTR_EQUALITY)
      largest = std::max(largest, std::abs(d->efc_pos[row]));
  return m_to_mm(largest);
}

// Close the equality constraints (a linear delta's rods on its platform) around the servo
// joints as they are set: the other joints (rod hinges, the platform's free joint) start from
// the model's reference pose, which matches the servo joints only at home. Gauss-Newton on
// the constraint residuals over the other degrees of freedom (least-norm steps), then their
// velocities so the constraints' rates vanish too. Without it a run starting away from home
// would start with the chain torn open by tens of mm and snap it shut in the first steps.
void Simulation::Impl::assemble_closures() {
  const mjModel* m = model.get();
  mjData* d = data.get();
  if (m->neq == 0) return;
  std::vector<bool> held(m->nv, false);
  for (const Servo& servo : joints) held[servo.dof_adr] = true;
  if (has_shutter) held[shutter.dof_adr] = true;
  std::vector<int> free_dofs;
  for (int dof = 0; dof < m->nv; ++dof)
    if (!held[dof]) free_dofs.push_back(dof);
  if (free_dofs.empty()) return;

  // the equality rows of the constraint Jacobian (dense or sparse), split into held / free
  Eigen::MatrixXd jacobian_free, jacobian_held;
  Eigen::VectorXd residual;
  const auto equality_rows = [&]() {
    mj_fwdPosition(m, d);
    std::vector<int> rows;
    for (int row = 0; row < d->nefc; ++row)
      if (d->efc_type[row] == mjCNSTR_EQUALITY) rows.push_back(row);
    const int n = static_cast<int>(rows.size());
    Eigen::MatrixXd full = Eigen::MatrixXd::Zero(n, m->nv);
    residual.resize(n);
    for (int i = 0; i < n; ++i) {
      const int row = rows[i];
      residual[i] = d->efc_pos[row];
      if (mj_isSparse(m)) {
        for (int k = 0; k < d->efc_J_rownnz[row]; ++k)
          full(i, d->efc_J_colind[d->efc_J_rowadr[row] + k]) = d->efc_J[d->efc_J_rowadr[row] + k];
      } else {
        for (int col = 0; col < m->nv; ++col) full(i, col) = d->efc_J[row * m->nv + col];
      }
    }
    jacobian_free.resize(n, static_cast<int>(free_dofs.size()));
    for (size_t c = 0; c < free_dofs.size(); ++c) jacobian_free.col(c) = full.col(free_dofs[c]);
    jacobian_held = full;
    return n;
  };

  // positions: dq = -J_free^+ r until the residual is below 1e-12 m
  std::vector<mjtNum> step(m->nv, 0.0);
  for (int iteration = 0; iteration < 50; ++iteration) {
    if (equality_rows() == 0 || residual.cwiseAbs().maxCoeff() < 1e-12) break;
    const Eigen::VectorXd dq = -jacobian_free.completeOrthogonalDecomposition().solve(residual);
    std::fill(step.begin(), step.end(), 0.0);
    for (size_t c = 0; c < free_dofs.size(); ++c) step[free_dofs[c]] = dq[c];
    mj_integratePos(m, d->qpos, step.data(), 1.0);
  }

  // velocities: J_free v_free = -J_held v_held (least norm)
  if (equality_rows() == 0) return;
  Eigen::VectorXd held_velocity = Eigen::VectorXd::Zero(m->nv);
  for (int dof = 0; dof < m->nv; ++dof)
    if (held[dof]) held_velocity[dof] = d->qvel[dof];
  const Eigen::VectorXd v_free =
      -jacobian_free.completeOrthogonalDecomposition().solve(jacobian_held * held_velocity);
  for (size_t c = 0; c < free_dofs.size(); ++c) d->qvel[free_dofs[c]] = v_free[c];
}

namespace {

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

// Velocity and acceleration references from the sampled position setpoints r_u (one per
// control update, `width` values each), as a digital servo forms its feed-forward: the
// velocity v_u = (r_u - r_{u-1}) / T, the velocity state a plant stepped by semi-implicit Euler
// (q_{k+1} = q_k + h v_{k+1}) has at t_u when it is on the setpoints (v_0 stays the plan's,
// the state the run starts from), and a_u = (v_{u+1} - v_u) / T, which takes it exactly to
// the next one. The analytic mean (v(t + T) - v(t)) / T is half a step late for such a plant:
// at every acceleration step of the plan it fed a wrong impulse, and the servo rang.
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
// acceleration, its regularisation speed capped at kFrictionFadeSpeed_si: a sharp
// (near-Coulomb) guide friction gets a sharp feed-forward, switching when the plant's does.
void Simulation::Impl::apply_servo(const Servo& servo, double q_si, double v_si,
                                   double extra_force) const {
  const mjModel* m = model.get();
  mjData* d = data.get();
  if (!settings.feedforward) {
    d->ctrl[servo.actuator] = q_si;
    return;
  }
  const double a_si = acceleration_reference[servo.dof_adr];
  const HeldReference held = held_reference(*m, control_stride, q_si, v_si, a_si);
  double friction_force = 0.0;
  if (servo.friction > 0.0) {
    const double leading_si =
        held.velocity_si +
        (servo.friction_rate_per_s > 0.0 ? a_si / servo.friction_rate_per_s : 0.0);
    friction_force = servo.friction * std::clamp(leading_si / servo.friction_speed_si, -1.0, 1.0);
  }
  const double force = inertia_force[servo.dof_adr] + d->qfrc_bias[servo.dof_adr] +
                       servo.kv * held.velocity_si + servo.damping * held.end_velocity_si +
                       friction_force + extra_force;
  d->ctrl[servo.actuator] = held.position_si + force / servo.kp;
}

Simulation::Simulation(const std::string& model_path, const Machine& machine,
                       const SimSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  const std::string problem = settings.validate();
  if (!problem.empty()) throw InputError("sim", problem);
  s.model_path = model_path;
  s.machine = &machine;
  s.settings = settings;
  s.model = load_model(model_path);
  mjModel& m = *s.model;

  // the TCP site and the work frame
  s.nozzle_site = require_id(m, mjOBJ_SITE, kNozzleSite, model_path,
                             "the TCP: where material meets the substrate");
  s.substrate_body =
      require_id(m, mjOBJ_BODY, kSubstrateBody, model_path, "the work frame the TCP is read in");

  // one position servo per machine joint, its range covering the machine's travel
  for (const JointLimit& limit : machine.joint_limits()) {
    Servo servo = resolve_servo(m, limit.name, model_path,
                                "machine " + machine.name() + " drives a joint of this name");
    if (m.jnt_limited[servo.joint]) {
      const double lo = m.jnt_range[2 * servo.joint] / servo.user_to_si;
      const double hi = m.jnt_range[2 * servo.joint + 1] / servo.user_to_si;
      if (lo > limit.min + 1e-9 || hi < limit.max - 1e-9)
        throw InputError(model_path, 0, "joint " + limit.name,
                         "range [" + format_number(lo) + ", " + format_number(hi) + "] " +
                             servo.unit + " is narrower than the machine's travel [" +
                             format_number(limit.min) + ", " + format_number(limit.max) + "] " +
                             servo.unit);
    }
    // kp_scale stiffens the servo; kv follows with the square root (same damping ratio)
    mjtNum* gain = m.actuator_gainprm + servo.actuator * mjNGAIN;
    mjtNum* bias = m.actuator_biasprm + servo.actuator * mjNBIAS;
    gain[0] *= settings.kp_scale;
    bias[1] *= settings.kp_scale;
    bias[2] *= std::sqrt(settings.kp_scale);
    servo.kp = gain[0];
    servo.kv = -bias[2];
    s.joint_names.push_back(limit.name);
    s.joints.push_back(std::move(servo));
  }

  // the optional shutter blade
  if (mj_name2id(&m, mjOBJ_JOINT, kShutterJoint) >= 0) {
    s.has_shutter = true;
    s.shutter = resolve_servo(m, kShutterJoint, model_path, "the shutter blade");
    if (m.jnt_type[s.shutter.joint] != mjJNT_HINGE)
      throw InputError(model_path, 0, "joint shutter", "must be a hinge joint");
    const mjtNum* travel_deg = require_numeric(m, "shutter_travel_deg", 2, model_path);
    const mjtNum* overtravel = require_numeric(m, "shutter_overtravel", 1, model_path);
    const mjtNum* time_s = require_numeric(m, "shutter_time_s", 1, model_path);
    ShutterGeometry& geometry = s.shutter_geometry;
    geometry.closed_angle_rad = deg_to_rad(travel_deg[0]);
    geometry.open_angle_rad = deg_to_rad(travel_deg[1]);
    geometry.overtravel = overtravel[0];
    geometry.time_s = settings.shutter_time_s > 0.0 ? settings.shutter_time_s : time_s[0];
    if (!(std::abs(travel_deg[1] - travel_deg[0]) > 1e-9))
      throw InputError(model_path, 0, "custom numeric shutter_travel_deg",
                       "the closed and open angles must differ");
    if (!(geometry.overtravel >= 0.0))
      throw InputError(model_path, 0, "custom numeric shutter_overtravel", "must be >= 0");
    if (!(geometry.time_s > 0.0))
      throw InputError(model_path, 0, "custom numeric shutter_time_s", "must be > 0");
    // the rest positions must lie inside the hinge's stops
    const double rest_closed = geometry.angle_at(-geometry.overtravel);
    const double rest_open = geometry.angle_at(1.0 + geometry.overtravel);
    if (m.jnt_limited[s.shutter.joint] &&
        (std::min(rest_closed, rest_open) < m.jnt_range[2 * s.shutter.joint] ||
         std::max(rest_closed, rest_open) > m.jnt_range[2 * s.shutter.joint + 1]))
      throw InputError(model_path, 0, "joint shutter",
                       "range does not contain the blade's rest positions (travel plus "
                       "overtravel)");
  }

  m.opt.timestep = settings.timestep_s;
  s.control_stride = settings.control_stride();
  // the friction law depends on the timestep: fixed here, not per control update
  const auto fix_friction_law = [&m](Servo& servo) {
    if (!(servo.friction > 0.0)) return;
    const FrictionLaw law = friction_law(m, servo.dof_adr, servo.friction);
    servo.friction_speed_si = std::min(kFrictionFadeSpeed_si, law.speed_si);
    servo.friction_rate_per_s = law.rate_per_s;
  };
  for (Servo& servo : s.joints) fix_friction_law(servo);
  if (s.has_shutter) fix_friction_law(s.shutter);
  s.data = make_data(m);
  s.acceleration_reference.assign(m.nv, 0.0);
  s.inertia_force.assign(m.nv, 0.0);
  s.hook_force.assign(s.joints.size(), 0.0);
  mj_forward(s.model.get(), s.data.get());
  check_warnings(*s.data, "after loading the model");
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::set_feedforward_hook(FeedForwardHook hook) {
  impl_->hook = std::move(hook);
}
const std::string& Simulation::model_path() const {
  return impl_->model_path;
}
const std::vector<std::string>& Simulation::joint_names() const {
  return impl_->joint_names;
}
std::vector<double> Simulation::actuator_force_limits() const {
  const mjModel& m = *impl_->model;
  std::vector<double> limits;
  for (const Servo& servo : impl_->joints) {
    const int a = servo.actuator;
    limits.push_back(m.actuator_forcelimited[a]
                         ? std::max(std::abs(m.actuator_forcerange[2 * a]),
                                    std::abs(m.actuator_forcerange[2 * a + 1]))
                         : 0.0);
  }
  return limits;
}
bool Simulation::has_shutter() const {
  return impl_->has_shutter;
}
double Simulation::shutter_time_s() const {
  return impl_->has_shutter ? impl_->shutter_geometry.time_s : 0.0;
}
double Simulation::shutter_open_fraction_at(double flap_angle_rad) const {
  return shutter_open_fraction(flap_angle_rad, impl_->shutter_geometry);
}
const mjModel& Simulation::model() const {
  return *impl_->model;
}
const mjData& Simulation::data() const {
  return *impl_->data;
}

RecordedRun Simulation::run(const Trajectory& trajectory, const StepCallback& on_step,
                            const ProgressCallback& progress) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point wall_start = Clock::now();
  Impl& s = *impl_;
  const mjModel* m = s.model.get();
  mjData* d = s.data.get();
  const Machine& machine = *s.machine;
  if (trajectory.pieces().empty()) throw InputError("trajectory", "the trajectory is empty");

  const double dt = m->opt.timestep;
  const double duration_s = trajectory.duration_s();
  const long steps =
      std::max(1L, static_cast<long>(std::ceil((duration_s + s.settings.settle_s) / dt - 1e-9)));
  const long stride = s.control_stride;
  const long updates = steps / stride + 1;
  const int joint_count = static_cast<int>(s.joints.size());
  const size_t entries = static_cast<size_t>(steps) + 1;

  RecordedRun run;
  run.joint_count = joint_count;
  run.joint_names = s.joint_names;
  run.timestep_s = dt;
  run.steps = steps;
  run.t_s.resize(entries);
  run.nozzle_mm.resize(entries);
  run.nozzle_velocity_mm_s.resize(entries);
  run.open_fraction.resize(entries);
  run.deposit_command.resize(entries);
  run.path_index.resize(entries);
  run.desired_speed_mm_s.resize(entries);
  run.joint_position.resize(entries * joint_count);
  run.joint_velocity.resize(entries * joint_count);
  run.joint_acceleration.resize(entries * joint_count);
  run.actuator_force.resize(entries * joint_count);

  // plan -> joint references for every controller update (SI), plan flags for every step;
  // the whole trajectory is checked against the travel before anything is simulated
  std::vector<double> q_ref(updates * joint_count), v_ref(updates * joint_count),
      a_ref(updates * joint_count, 0.0), flap_ref(updates, 0.0), flap_rate(updates, 0.0),
      flap_acceleration(updates, 0.0);
  ShutterReference shutter_reference;
  if (s.has_shutter)
    shutter_reference =
        ShutterReference(trajectory, s.shutter_geometry.time_s, s.shutter_geometry.overtravel);
  JointVector joints;
  std::string why;
  const std::vector<JointLimit>& limits = machine.joint_limits();
  long next_reference_k = 0, u = -1;  // controller updates every `stride` steps
  TrajectoryCursor plan(trajectory);  // the steps' times only grow
  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    TrajectorySample sample = plan.at(t);
    // after the end the machine holds the final point with the shutter closed
    if (t > duration_s + 1e-12) {
      sample.velocity_mm_s.setZero();
      sample.acceleration_mm_s2.setZero();
      sample.depositing = false;
      sample.path_index = -1;
      sample.desired_speed_mm_s = 0.0;
    }
    run.deposit_command[k] = sample.depositing ? 1 : 0;
    run.path_index[k] = sample.path_index;
    run.desired_speed_mm_s[k] = static_cast<float>(sample.desired_speed_mm_s);

    why.clear();
    if (!machine.inverse(sample.position_mm, joints, &why))
      throw InputError("trajectory", "at t = " + format_number(t) + " s: " + why);
    if (static_cast<int>(joints.size()) != joint_count)
      throw InternalError("machine " + machine.name() + " returned " +
                          std::to_string(joints.size()) + " joints, expected " +
                          std::to_string(joint_count));
    for (int j = 0; j < joint_count; ++j) {
      if (joints[j] < limits[j].min - 1e-9 || joints[j] > limits[j].max + 1e-9)
        throw InputError("trajectory", "at t = " + format_number(t) + " s: joint " +
                                           limits[j].name + " at " + format_number(joints[j]) +
                                           " is outside its travel [" +
                                           format_number(limits[j].min) + ", " +
                                           format_number(limits[j].max) + "]");
    }
    if (k != next_reference_k) continue;
    next_reference_k += stride;
    ++u;

    for (int j = 0; j < joint_count; ++j)
      q_ref[u * joint_count + j] = joints[j] * s.joints[j].user_to_si;
    // the start's joint velocity J v; later ones are differences of the setpoints (below)
    if (u == 0) {
      const JointVector velocity = machine.joint_velocity(joints, sample.velocity_mm_s);
      for (int j = 0; j < joint_count; ++j) v_ref[j] = velocity[j] * s.joints[j].user_to_si;
    }
    if (s.has_shutter) {
      double fraction = 0.0, rate = 0.0;
      shutter_reference.at(t, fraction, rate);
      const ShutterGeometry& geometry = s.shutter_geometry;
      flap_ref[u] = geometry.angle_at(fraction);
      flap_rate[u] = rate * (geometry.open_angle_rad - geometry.closed_angle_rad);
    }
  }

  // velocity and acceleration feed-forward from the sampled setpoints, as a digital servo
  // forms them (sampled_setpoint_references, next to apply_servo)
  const double control_period_s = static_cast<double>(stride) * dt;
  sampled_setpoint_references(q_ref, v_ref, a_ref, updates, joint_count, control_period_s);
  // the largest acceleration the plan asks of each joint, as the servo is given it
  run.reference_peak_acceleration.assign(joint_count, 0.0);
  for (long update = 0; update < updates; ++update)
    for (int j = 0; j < joint_count; ++j)
      run.reference_peak_acceleration[j] =
          std::max(run.reference_peak_acceleration[j],
                   std::abs(a_ref[update * joint_count + j]) / s.joints[j].user_to_si);
  sampled_setpoint_references(flap_ref, flap_rate, flap_acceleration, updates, 1, control_period_s);

  // start from a reset state exactly on the reference
  mj_resetData(m, d);
  clear_warnings(*d);
  for (int j = 0; j < joint_count; ++j) {
    d->qpos[s.joints[j].qpos_adr] = q_ref[j];
    d->qvel[s.joints[j].dof_adr] = v_ref[j];
  }
  if (s.has_shutter) {
    d->qpos[s.shutter.qpos_adr] = flap_ref[0];
    d->qvel[s.shutter.dof_adr] = flap_rate[0];
  }
  s.assemble_closures();

  // the step loop: state after mj_step1, controls, mj_step2 (no allocation in here), with
  // subnormals flushed (a servo at rest decays into them and MuJoCo slows to a crawl on
  // them); callbacks run in the caller's floating-point mode
  FlushSubnormalsScope flush_subnormals;
  // on_step runs on chunks of buffered states (the first is the last chunk's end), so the
  // floating-point mode switches once per chunk rather than twice a step
  std::vector<StepState> pending_states;
  if (on_step) pending_states.reserve(kCallbackChunkSteps + 1);
  const auto deliver_pending_states = [&]() {
    flush_subnormals.suspend();
    for (size_t i = 1; i < pending_states.size(); ++i)
      on_step(pending_states[i - 1], pending_states[i]);
    flush_subnormals.resume();
    pending_states.front() = pending_states.back();
    pending_states.resize(1);
  };
  StepState after;
  double max_violation_mm = 0.0;
  Clock::time_point last_progress = wall_start;
  long next_update_k = 0, update = 0;  // controller updates every `stride` steps
  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    d->time = t;
    mj_step1(m, d);

    // the state at t: nozzle from MuJoCo, flags from the plan
    after.t_s = t;
    s.read_nozzle(after.nozzle_mm, after.nozzle_velocity_mm_s);
    after.deposit_command = run.deposit_command[k] != 0;
    after.open_fraction = s.open_fraction(after.deposit_command);
    after.desired_speed_mm_s = run.desired_speed_mm_s[k];
    after.path_index = run.path_index[k];
    run.t_s[k] = t;
    run.nozzle_mm[k] = after.nozzle_mm;
    run.nozzle_velocity_mm_s[k] = after.nozzle_velocity_mm_s;
    run.open_fraction[k] = static_cast<float>(after.open_fraction);
    for (int j = 0; j < joint_count; ++j) {
      const Servo& servo = s.joints[j];
      run.joint_position[k * joint_count + j] = d->qpos[servo.qpos_adr] / servo.user_to_si;
      run.joint_velocity[k * joint_count + j] = d->qvel[servo.dof_adr] / servo.user_to_si;
    }
    if (m->neq > 0)  // only equality constraints have rows to measure
      max_violation_mm = std::max(max_violation_mm, s.constraint_violation_mm());
    if (on_step) {
      pending_states.push_back(after);  // capacity reserved: no allocation
      if (pending_states.size() == kCallbackChunkSteps + 1 || k == steps) deliver_pending_states();
    }

    // servo controls at the controller rate, held in between
    if (k == next_update_k) {
      next_update_k += stride;
      const long u = update++;
      const double* q = &q_ref[u * joint_count];
      const double* v = &v_ref[u * joint_count];
      const double* a = &a_ref[u * joint_count];
      if (s.settings.feedforward) {
        std::fill(s.acceleration_reference.begin(), s.acceleration_reference.end(), 0.0);
        for (int j = 0; j < joint_count; ++j) s.acceleration_reference[s.joints[j].dof_adr] = a[j];
        if (s.has_shutter) s.acceleration_reference[s.shutter.dof_adr] = flap_acceleration[u];
        inertia_times(*m, *d, s.acceleration_reference.data(), s.inertia_force.data());
        std::fill(s.hook_force.begin(), s.hook_force.end(), 0.0);
        if (s.hook) {
          flush_subnormals.suspend();
          s.hook(*m, *d, JointReference{t, joint_count, q, v, a}, s.hook_force.data());
          flush_subnormals.resume();
        }
      }
      for (int j = 0; j < joint_count; ++j) s.apply_servo(s.joints[j], q[j], v[j], s.hook_force[j]);
      if (s.has_shutter) s.apply_servo(s.shutter, flap_ref[u], flap_rate[u], 0.0);
    }

    // integrate; the last state is only evaluated (for its acceleration and forces)
    if (k < steps)
      mj_step2(m, d);
    else
      mj_forward(m, d);
    for (int j = 0; j < joint_count; ++j) {
      const Servo& servo = s.joints[j];
      run.joint_acceleration[k * joint_count + j] = d->qacc[servo.dof_adr] / servo.user_to_si;
      run.actuator_force[k * joint_count + j] = d->actuator_force[servo.actuator];
    }
    check_warnings(*d, "in the simulation", t);

    if (progress && k % kProgressCheckSteps == 0) {
      const Clock::time_point now = Clock::now();
      if (std::chrono::duration<double>(now - last_progress).count() >= kProgressPeriod_s) {
        last_progress = now;
        flush_subnormals.suspend();
        progress(static_cast<double>(k) / static_cast<double>(steps));
        flush_subnormals.resume();
      }
    }
  }
  flush_subnormals.suspend();
  if (progress) progress(1.0);

  run.max_constraint_violation_mm = max_violation_mm;
  run.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return run;
}

}  // namespace depotwin
