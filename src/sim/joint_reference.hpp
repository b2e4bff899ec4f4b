// The plan as the servos are given it (internal to sim/): every step's pose through the
// machine's inverse kinematics, the joint setpoints every control period, and their velocity
// and acceleration references as a digital servo forms them (sampled_setpoint_references);
// the shutter blade's reference beside them.
#pragma once

#include <vector>

#include "core/trajectory.hpp"
#include "sim/model_binding.hpp"
#include "sim/simulation.hpp"

namespace depotwin {

// per controller update, SI (m or rad), update-major (joint_count values per update)
struct JointReferences {
  long updates = 0;
  int joint_count = 0;
  std::vector<double> position, velocity, acceleration;
  std::vector<double> flap, flap_rate, flap_acceleration;  // the shutter blade (one each)

  const double* at(const std::vector<double>& values, long update) const {
    return values.data() + update * joint_count;
  }
};

// The references of a run of `steps` steps (steps + 1 states). Also writes the plan's
// per-step flags into `run` (deposit_command, flow_fraction, path_index, desired_speed_mm_s, sized
// steps + 1) and the plan's peak joint accelerations (reference_peak_acceleration). After
// the trajectory's end the machine holds its final pose with the shutter closed. The whole
// trajectory is checked first: InputError naming the time for a pose the machine cannot reach
// or a joint outside its travel.
JointReferences plan_joint_references(const BoundModel& bound, const Trajectory& trajectory,
                                      long steps, RecordedRun& run);

// The same check of the whole trajectory without a model: every step's pose (a step of
// timestep_s, the final pose after the end) through the machine's inverse kinematics, each
// solution seeded by the previous one as the simulation seeds it, and every joint within its
// travel; InputError("trajectory") naming the time, word for word what the simulation would
// say. What validate checks of each plan before anything is simulated (run and compare leave
// it to plan_joint_references).
void check_trajectory_poses(const Machine& machine, const Trajectory& trajectory,
                            double timestep_s);

}  // namespace depotwin
