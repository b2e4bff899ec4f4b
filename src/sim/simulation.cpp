// The step loop: the bound model (model_binding) follows the joint references
// (joint_reference) through the servo controller (servo_controller), closed chains assembled
// first (closures); the nozzle is read from MuJoCo at every step.
#include "sim/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/input_ranges.hpp"
#include "core/interrupt.hpp"
#include "sim/closures.hpp"
#include "sim/joint_reference.hpp"
#include "sim/model_binding.hpp"
#include "sim/mujoco_access.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/servo_controller.hpp"

namespace depotwin {

namespace {

// the bounds the scenario schema also gives (one source: core/input_ranges.hpp)
constexpr double kMinTimestep_s = input_ranges::kMinTimestep_s;
constexpr double kMaxTimestep_s = input_ranges::kMaxTimestep_s;
// contacts followed per step for the contact log (more are counted, not followed as pairs)
constexpr size_t kMaxLoggedContacts = 256;
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

}  // namespace

long SimSettings::control_stride() const {
  return std::max(1L, std::lround(control_period_s / timestep_s));
}

std::string SimSettings::validate(const std::string& machine) const {
  if (!std::isfinite(timestep_s) || timestep_s < kMinTimestep_s || timestep_s > kMaxTimestep_s)
    return "timestep_s must be between " + format_number(kMinTimestep_s) + " and " +
           format_number(kMaxTimestep_s) + " s, got " + format_number(timestep_s);
  if (!std::isfinite(control_period_s) || control_period_s <= 0.0)
    return "control_period_s must be a positive number, got " + format_number(control_period_s);
  const double ratio = control_period_s / timestep_s;
  if (ratio > 1.0 && std::abs(ratio - std::round(ratio)) > 1e-6 * ratio)
    return "control_period_s (" + format_number(control_period_s) +
           " s) must be a whole number of timesteps (" + format_number(timestep_s) + " s)";
  if (!std::isfinite(kp_scale) || kp_scale < input_ranges::kMinKpScale ||
      kp_scale > input_ranges::kMaxKpScale)
    return "kp_scale must be between " + format_number(input_ranges::kMinKpScale) + " and " +
           format_number(input_ranges::kMaxKpScale) + ", got " + format_number(kp_scale);
  const double stiffness = kp_scale * std::pow(timestep_s / input_ranges::kReferenceTimestep_s, 2);
  const double max_stiffness = input_ranges::max_servo_stiffness_per_step(machine);
  if (stiffness > max_stiffness * (1.0 + 1e-12))
    return "timestep_s " + format_number(timestep_s) + " s with kp_scale " +
           format_number(kp_scale) +
           " makes the servos unstable: kp_scale * (timestep_s / 1 ms)^2 = " +
           format_number(stiffness) + ", at most " + format_number(max_stiffness) +
           (machine.empty() ? std::string() : " on " + machine);
  if (!std::isfinite(settle_s) || settle_s < 0.0 || settle_s > input_ranges::kMaxSettle_s)
    return "settle_s must be between 0 and " + format_number(input_ranges::kMaxSettle_s) +
           " s, got " + format_number(settle_s);
  if (!std::isfinite(shutter_time_s) || shutter_time_s < 0.0)
    return "shutter_time_s must be >= 0 (0: the model's), got " + format_number(shutter_time_s);
  return "";
}

struct Simulation::Impl {
  BoundModel bound;
  FeedForwardHook hook;
  // scratch reused by every controller update (no allocation in the step loop)
  std::vector<mjtNum> acceleration_reference;  // nv
  std::vector<mjtNum> inertia_force;           // nv
  std::vector<double> hook_force;              // joints
  // the contacting geom pairs of this step and the previous one (reserved: no allocation)
  std::vector<std::pair<int, int>> contact_pairs, previous_contact_pairs;
  int machine_root = -1;  // the body tree that carries the nozzle

  // a MuJoCo warning during a run (the state diverged: NaN or huge values) is reported as
  // what the user can change: the step, the servo gains, the plan's limits
  void check_run_warnings(const mjData& d, double t) const;

  // a reset state exactly on the first reference, closed chains assembled around it
  void start_on(const JointReferences& refs);
  // the recorded state at step k (the plan's flags are already in `run`)
  void record_state(long k, RecordedRun& run, StepState& state) const;
  // the contacts MuJoCo found at this state, as events and steps
  void log_contacts(double t, ContactLog& log);
  // the servos' controls for update u at time t, held until the next update
  void update_controls(const JointReferences& refs, long u, double t,
                       FlushSubnormalsScope& flush_subnormals);
};

Simulation::Simulation(const std::string& model_path, const Machine& machine,
                       const SimSettings& settings, const std::string& model_text)
    : impl_(std::make_unique<Impl>()) {
  const std::string problem = settings.validate(machine.name());
  if (!problem.empty()) throw InputError("sim", problem);
  Impl& s = *impl_;
  s.bound = bind_model(model_path, machine, settings, model_text);
  const int nv = s.bound.model->nv;
  s.acceleration_reference.assign(nv, 0.0);
  s.inertia_force.assign(nv, 0.0);
  s.hook_force.assign(s.bound.joints.size(), 0.0);
  s.contact_pairs.reserve(kMaxLoggedContacts);
  s.previous_contact_pairs.reserve(kMaxLoggedContacts);
  const mjModel& m = *s.bound.model;
  s.machine_root = m.body_rootid[m.site_bodyid[s.bound.nozzle_site]];
}

std::vector<Problem> check_simulation_model(const std::string& model_path, const Machine& machine,
                                            const SimSettings& settings,
                                            const std::string& model_text) {
  const std::string problem = settings.validate(machine.name());
  if (!problem.empty()) return {Problem{"", 0, "sim", problem}};
  try {
    bind_model(model_path, machine, settings, model_text);
  } catch (const InputError& e) {
    return e.problems();
  } catch (const InternalError& e) {
    // a warning while computing the model's reference pose: the model, not the program
    return {Problem{model_path, 0, "model", e.what()}};
  }
  return {};
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::set_feedforward_hook(FeedForwardHook hook) {
  impl_->hook = std::move(hook);
}
const std::string& Simulation::model_path() const {
  return impl_->bound.model_path;
}
const std::vector<std::string>& Simulation::joint_names() const {
  return impl_->bound.joint_names;
}
std::vector<double> Simulation::actuator_force_limits() const {
  const mjModel& m = *impl_->bound.model;
  std::vector<double> limits;
  for (const Servo& servo : impl_->bound.joints) {
    const int a = servo.actuator;
    limits.push_back(m.actuator_forcelimited[a]
                         ? std::max(std::abs(m.actuator_forcerange[2 * a]),
                                    std::abs(m.actuator_forcerange[2 * a + 1]))
                         : 0.0);
  }
  return limits;
}
bool Simulation::has_shutter() const {
  return impl_->bound.has_shutter;
}
double Simulation::shutter_time_s() const {
  return impl_->bound.has_shutter ? impl_->bound.shutter_geometry.time_s : 0.0;
}
double Simulation::shutter_open_fraction_at(double flap_angle_rad) const {
  return shutter_open_fraction(flap_angle_rad, impl_->bound.shutter_geometry);
}

const mjModel& SimulationAccess::model(const Simulation& simulation) {
  return *simulation.impl_->bound.model;
}
const mjData& SimulationAccess::data(const Simulation& simulation) {
  return *simulation.impl_->bound.data;
}

void Simulation::Impl::check_run_warnings(const mjData& d, double t) const {
  try {
    check_warnings(d, "in the simulation", t);
  } catch (const InternalError& e) {
    const SimSettings& settings = bound.settings;
    throw InputError(
        "sim", std::string(e.what()) + ". The servos could not follow the plan at sim.timestep_s " +
                   format_number(settings.timestep_s) + " s with sim.kp_scale " +
                   format_number(settings.kp_scale) +
                   ": lower sim.timestep_s, bring sim.kp_scale towards 1, or lower the limits "
                   "(v_max, a_max) so the plan asks less of the machine");
  }
}

void Simulation::Impl::start_on(const JointReferences& refs) {
  const mjModel* m = bound.model.get();
  mjData* d = bound.data.get();
  mj_resetData(m, d);
  clear_warnings(*d);
  for (int j = 0; j < refs.joint_count; ++j) {
    d->qpos[bound.joints[j].qpos_adr] = refs.position[j];
    d->qvel[bound.joints[j].dof_adr] = refs.velocity[j];
  }
  if (bound.has_shutter) {
    d->qpos[bound.shutter.qpos_adr] = refs.flap[0];
    d->qvel[bound.shutter.dof_adr] = refs.flap_rate[0];
  }
  assemble_closures(bound);
}

void Simulation::Impl::record_state(long k, RecordedRun& run, StepState& state) const {
  const mjData* d = bound.data.get();
  const int joint_count = run.joint_count;
  // the state at t: nozzle from MuJoCo, flags from the plan
  state.t_s = run.t_s[k];
  read_nozzle(bound, state.nozzle_mm, state.nozzle_velocity_mm_s);
  state.deposit_command = run.deposit_command[k] != 0;
  state.flow_fraction = run.flow_fraction[k];
  state.open_fraction = open_fraction(bound, state.deposit_command);
  state.desired_speed_mm_s = run.desired_speed_mm_s[k];
  state.path_index = run.path_index[k];
  run.nozzle_mm[k] = state.nozzle_mm;
  run.nozzle_velocity_mm_s[k] = state.nozzle_velocity_mm_s;
  run.open_fraction[k] = static_cast<float>(state.open_fraction);
  for (int j = 0; j < joint_count; ++j) {
    const Servo& servo = bound.joints[j];
    run.joint_position[k * joint_count + j] = d->qpos[servo.qpos_adr] / servo.user_to_si;
    run.joint_velocity[k * joint_count + j] = d->qvel[servo.dof_adr] / servo.user_to_si;
  }
}

void Simulation::Impl::log_contacts(double t, ContactLog& log) {
  const mjModel& m = *bound.model;
  const mjData& d = *bound.data;
  previous_contact_pairs.swap(contact_pairs);
  contact_pairs.clear();
  bool self = false, other = false;
  const auto on_machine = [&](int geom) {
    const int body = m.geom_bodyid[geom];
    return body != 0 && m.body_rootid[body] == machine_root;
  };
  for (int c = 0; c < d.ncon; ++c) {
    const int g1 = std::min(d.contact[c].geom1, d.contact[c].geom2);
    const int g2 = std::max(d.contact[c].geom1, d.contact[c].geom2);
    const bool is_self = on_machine(g1) && on_machine(g2);
    self = self || is_self;
    other = other || !is_self;
    if (contact_pairs.size() == contact_pairs.capacity()) continue;
    const std::pair<int, int> pair(g1, g2);
    if (std::find(contact_pairs.begin(), contact_pairs.end(), pair) != contact_pairs.end())
      continue;
    contact_pairs.push_back(pair);
    // a pair that did not touch at the previous state: a new event
    if (std::find(previous_contact_pairs.begin(), previous_contact_pairs.end(), pair) !=
        previous_contact_pairs.end())
      continue;
    ++(is_self ? log.self_events : log.other_events);
    if (log.first.empty()) {
      const char* name1 = mj_id2name(&m, mjOBJ_GEOM, g1);
      const char* name2 = mj_id2name(&m, mjOBJ_GEOM, g2);
      char text[256];
      std::snprintf(text, sizeof text, "t = %.4g s: %s / %s", t,
                    name1 ? name1 : ("geom " + std::to_string(g1)).c_str(),
                    name2 ? name2 : ("geom " + std::to_string(g2)).c_str());
      log.first = text;
    }
  }
  log.self_steps += self ? 1 : 0;
  log.other_steps += other ? 1 : 0;
}

void Simulation::Impl::update_controls(const JointReferences& refs, long u, double t,
                                       FlushSubnormalsScope& flush_subnormals) {
  const mjModel* m = bound.model.get();
  mjData* d = bound.data.get();
  const int joint_count = refs.joint_count;
  const double* q = refs.at(refs.position, u);
  const double* v = refs.at(refs.velocity, u);
  const double* a = refs.at(refs.acceleration, u);
  const bool feedforward = bound.settings.feedforward;
  // the feed-forward: M a_ref over every servo dof, and the machine's load through its hook
  if (feedforward) {
    std::fill(acceleration_reference.begin(), acceleration_reference.end(), 0.0);
    for (int j = 0; j < joint_count; ++j) acceleration_reference[bound.joints[j].dof_adr] = a[j];
    if (bound.has_shutter)
      acceleration_reference[bound.shutter.dof_adr] = refs.flap_acceleration[u];
    inertia_times(*m, *d, acceleration_reference.data(), inertia_force.data());
    std::fill(hook_force.begin(), hook_force.end(), 0.0);
    if (hook) {
      flush_subnormals.suspend();
      hook(JointReference{t, joint_count, q, v, a}, hook_force.data());
      flush_subnormals.resume();
    }
  }
  for (int j = 0; j < joint_count; ++j) {
    const Servo& servo = bound.joints[j];
    apply_servo(*m, *d, servo, feedforward, bound.control_stride, q[j], v[j], a[j],
                inertia_force[servo.dof_adr], hook_force[j]);
  }
  if (bound.has_shutter)
    apply_servo(*m, *d, bound.shutter, feedforward, bound.control_stride, refs.flap[u],
                refs.flap_rate[u], refs.flap_acceleration[u], inertia_force[bound.shutter.dof_adr],
                0.0);
}

namespace {

// a run's arrays for steps + 1 states
RecordedRun allocate_record(const BoundModel& bound, long steps) {
  const int joint_count = static_cast<int>(bound.joints.size());
  const size_t entries = static_cast<size_t>(steps) + 1;
  RecordedRun run;
  run.joint_count = joint_count;
  run.joint_names = bound.joint_names;
  run.timestep_s = bound.model->opt.timestep;
  run.steps = steps;
  run.t_s.resize(entries);
  run.nozzle_mm.resize(entries);
  run.nozzle_velocity_mm_s.resize(entries);
  run.open_fraction.resize(entries);
  run.joint_position.resize(entries * joint_count);
  run.joint_velocity.resize(entries * joint_count);
  run.joint_acceleration.resize(entries * joint_count);
  run.actuator_force.resize(entries * joint_count);
  for (size_t k = 0; k < entries; ++k) run.t_s[k] = static_cast<double>(k) * run.timestep_s;
  return run;
}

}  // namespace

RecordedRun Simulation::run(const Trajectory& trajectory, const StepCallback& on_step,
                            const ProgressCallback& progress) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point wall_start = Clock::now();
  Impl& s = *impl_;
  const mjModel* m = s.bound.model.get();
  mjData* d = s.bound.data.get();
  if (trajectory.pieces().empty()) throw InputError("trajectory", "the trajectory is empty");

  // the plan as joint references, checked whole before anything is simulated; the step count
  // is bounded before it becomes an integer (pipeline/job_check.hpp refuses a job of more
  // than sim.max_steps long before this)
  const double dt = m->opt.timestep;
  const double steps_needed =
      std::ceil((trajectory.duration_s() + s.bound.settings.settle_s) / dt - 1e-9);
  if (!(steps_needed <= input_ranges::kMaxMaxSteps))
    throw InputError("sim.max_steps",
                     "the run would take " + format_number(steps_needed) + " physics steps (" +
                         format_number(trajectory.duration_s()) + " s of motion + " +
                         format_number(s.bound.settings.settle_s) + " s settling at " +
                         format_number(dt) + " s), more than any run may");
  const long steps = std::max(1L, static_cast<long>(steps_needed));
  const long stride = s.bound.control_stride;
  const int joint_count = static_cast<int>(s.bound.joints.size());
  RecordedRun run = allocate_record(s.bound, steps);
  const JointReferences refs = plan_joint_references(s.bound, trajectory, steps, run);
  s.start_on(refs);

  // the step loop: state after mj_step1, controls, mj_step2 (no allocation in here), with
  // subnormals flushed (a servo at rest decays into them and MuJoCo slows to a crawl on
  // them); callbacks run in the caller's floating-point mode
  FlushSubnormalsScope flush_subnormals;
  // on_step runs on chunks of buffered states (the first is the last chunk's end), so the
  // floating-point mode switches once per chunk rather than twice a step; the first chunk is
  // one step, so a caller sees the simulation's own state (its passive joints: a delta's
  // platform) 1 ms in rather than only a chunk in
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
  for (long k = 0; k <= steps; ++k) {
    // a signal asked to stop (SIGINT, SIGTERM): one atomic load per step
    throw_if_interrupted();
    const double t = run.t_s[k];
    d->time = t;
    mj_step1(m, d);
    s.record_state(k, run, after);
    if (d->ncon > 0 || !s.contact_pairs.empty()) s.log_contacts(t, run.contacts);
    if (m->neq > 0)  // only equality constraints have rows to measure
      max_violation_mm = std::max(max_violation_mm, constraint_violation_mm(*d));
    if (on_step) {
      pending_states.push_back(after);  // capacity reserved: no allocation
      if (pending_states.size() == kCallbackChunkSteps + 1 || k == steps || k == 1)
        deliver_pending_states();
    }

    // servo controls at the controller rate, held in between
    if (k % stride == 0) s.update_controls(refs, k / stride, t, flush_subnormals);

    // integrate; the last state is only evaluated (for its acceleration and forces)
    if (k < steps)
      mj_step2(m, d);
    else
      mj_forward(m, d);
    for (int j = 0; j < joint_count; ++j) {
      const Servo& servo = s.bound.joints[j];
      run.joint_acceleration[k * joint_count + j] = d->qacc[servo.dof_adr] / servo.user_to_si;
      run.actuator_force[k * joint_count + j] = d->actuator_force[servo.actuator];
    }
    s.check_run_warnings(*d, t);

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
