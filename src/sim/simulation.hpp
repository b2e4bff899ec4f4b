// The machine in MuJoCo following a planned trajectory through its actuators.
//
// trajectory --Machine::inverse/joint_velocity--> joint references (q, v, a)
//   --servo controller at 1 kHz (position servos in the MJCF + feed-forward)--> ctrl
//   --mj_step1 / ctrl / mj_step2--> simulated nozzle pose, read from MuJoCo.
//
// What a model must provide (any machine, found by name once):
// - one joint per Machine::joint_limits()[i].name (slide: mm, hinge: rad), driven by an
//   actuator of the same name that is a position servo on that joint: <general> with
//   gaintype fixed, biastype affine, gainprm kp, biasprm "0 -kp -kv", gear 1 (or <position>);
// - site `nozzle` (the TCP: where material meets the substrate) and body `substrate` (the
//   work frame); the nozzle pose is site_xpos relative to the substrate frame, never the plan;
// - optionally a shutter: hinge `shutter` with a servo `shutter` and custom numerics
//   `shutter_travel_deg` (closed open), `shutter_overtravel`, `shutter_time_s` (shutter.hpp).
//   Without one the open fraction is the trajectory's depositing flag.
// Equality constraints (<connect> closures of a linear delta) are allowed; their largest
// position violation is recorded.
//
// Controller per servo joint: position servos with inertia, bias, viscous, friction and
// machine-specific load feed-forward on references formed as a digital servo forms them
// (sim/servo_controller.hpp has the law). Controls are held between updates (zero-order hold).
//
// Inside sim/: model_binding (the model loaded and its names resolved), joint_reference (the
// plan through the inverse kinematics), servo_controller, closures (closed chains), and this
// file's step loop. No MuJoCo type appears in this header; sim/mujoco_access.hpp gives the
// renderer the model and state.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/recorded_run.hpp"
#include "core/trajectory.hpp"
#include "core/types.hpp"
#include "kinematics/machine.hpp"

namespace depotwin {

struct SimSettings {
  double timestep_s = 0.001;        // physics step (replaces the model's <option timestep>)
  double control_period_s = 0.001;  // servo update period (1 kHz), a whole number of steps;
                                    // shorter than the timestep: every step
  double kp_scale = 1.0;  // multiplies the machine servos' kp (kv by sqrt: same damping ratio)
  double settle_s = 0.0;  // simulated time after the trajectory ends
  double shutter_time_s = 0.0;  // flap open/close time; 0: the model's `shutter_time_s`
  bool feedforward = true;      // false: plain PD on the joint reference (servo lag shows)

  // "" when usable, else what is wrong (names the field); `machine`: the registered machine
  // (kinematics family) whose servo loop's stability bound applies ("": the largest)
  std::string validate(const std::string& machine = "") const;
  // physics steps per servo update: control_period_s in whole timesteps, at least one
  long control_stride() const;
};

// Joint references of one controller update, SI units (m or rad), in Machine joint order;
// `velocity` is the setpoints' backward difference (q(t) - q(t - T_c)) / T_c (the plan's at
// t = 0), `acceleration` the next one's change over T_c: (v_ref(t + T_c) - v_ref(t)) / T_c.
struct JointReference {
  double t_s = 0.0;
  int count = 0;
  const double* position = nullptr;
  const double* velocity = nullptr;
  const double* acceleration = nullptr;
};

// What Simulation's constructor would refuse, found without simulating: the settings checked,
// the model loaded and compiled by MuJoCo, and every name the machine needs resolved (all of
// them, not the first missing). The problems name the model file and the element; none when
// the model binds.
std::vector<Problem> check_simulation_model(const std::string& model_path, const Machine& machine,
                                            const SimSettings& settings = {},
                                            const std::string& model_text = {});

class Simulation {
 public:
  using StepCallback = std::function<void(const StepState& before, const StepState& after)>;
  using ProgressCallback = std::function<void(double fraction)>;
  // adds a machine-specific feed-forward force per Machine joint (SI: N or N m) to `force`
  // (count entries, zero on entry); called at every controller update with that update's
  // references (e.g. a linear delta's platform load, Machine::closure_feedforward)
  using FeedForwardHook = std::function<void(const JointReference& reference, double* force)>;

  // Loads the model and resolves every name once. InputError (naming the file and the
  // element) for a missing or malformed model, a missing `nozzle` site or `substrate` body,
  // missing joints/actuators, an actuator that is not a position servo, a joint range
  // narrower than the machine's travel, or bad settings. `machine` must outlive the
  // Simulation.
  // `model_text`, when given, is compiled in place of the file's own text (the model with the
  // job's part added, sim/part_model.hpp); relative paths in it resolve against model_path.
  Simulation(const std::string& model_path, const Machine& machine,
             const SimSettings& settings = {}, const std::string& model_text = {});
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Checks the whole trajectory against the joint travel first (InputError naming the time
  // and the joint), then starts on the reference at t = 0 and steps until the trajectory's
  // end + settle_s. on_step(before, after) is called once per step, in step order, in chunks
  // of up to 64 steps between physics steps; progress(fraction) at most about ten times a
  // second. Callbacks run in the caller's floating-point mode (the physics flushes
  // subnormals, see FlushSubnormalsScope). A MuJoCo warning (divergence) throws InternalError.
  // Each run starts from a reset state: the same trajectory gives the same RecordedRun.
  RecordedRun run(const Trajectory& trajectory, const StepCallback& on_step = {},
                  const ProgressCallback& progress = {});

  void set_feedforward_hook(FeedForwardHook hook);

  const std::string& model_path() const;
  const std::vector<std::string>& joint_names() const;
  // each machine joint's actuator force limit (N or N m, the MJCF forcerange); 0: unlimited
  std::vector<double> actuator_force_limits() const;
  bool has_shutter() const;
  double shutter_time_s() const;  // the open/close time in use; 0 without a shutter
  // the shutter's blade geometry (meaningful only with a shutter)
  double shutter_open_fraction_at(double flap_angle_rad) const;

  // (the MuJoCo model and state: SimulationAccess in sim/mujoco_access.hpp)
  friend class SimulationAccess;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace depotwin
