#include "sim/joint_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "sim/servo_controller.hpp"
#include "sim/shutter.hpp"

namespace depotwin {

namespace {

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// the trajectory at step time t; after its end the final pose at rest, the shutter closed
TrajectorySample planned_sample(TrajectoryCursor& plan, double t, double duration_s) {
  TrajectorySample sample = plan.at(t);
  if (t > duration_s + 1e-12) {
    sample.velocity_mm_s.setZero();
    sample.acceleration_mm_s2.setZero();
    sample.angular_velocity_rad_s.setZero();
    sample.depositing = false;
    sample.path_index = -1;
    sample.desired_speed_mm_s = 0.0;
  }
  return sample;
}

// the joints of a sample's pose (the solution nearest to `seed` when given: continuous along
// the plan), within their travel; InputError naming the time otherwise
void joints_at(const Machine& machine, const TrajectorySample& sample, const JointVector* seed,
               JointVector& joints) {
  std::string why;
  // where in the plan, written only for a message: a print path's samples name it; a
  // transition leaves the toolpath's points, which the scenario check found reachable (a
  // planner's move overshoots them)
  const auto at = [&sample] {
    return "at t = " + format_number(sample.t_s) + " s (" +
           (sample.path_index >= 0 ? "printing path " + std::to_string(sample.path_index)
                                   : std::string("in a transition the planner added")) +
           "): ";
  };
  // in a transition, what helps: a move that leaves or enters a path at speed overshoots it
  const auto hint = [&sample] {
    return sample.path_index >= 0
               ? std::string()
               : std::string(
                     " (a move leaving or entering a path at speed overshoots its end: "
                     "keep the paths farther from the edge, raise limits.a_max (and "
                     "limits.j_max where one is set: a jerk-limited stop takes longer; this is "
                     "where the move first leaves the travel, not how far it goes), or plan with "
                     "stop_and_go, which starts and ends every path at rest, or uniform, which "
                     "does so where a move at speed would leave the travel)");
  };
  const bool solved = seed ? machine.inverse_near(sample.pose(), *seed, joints, &why)
                           : machine.inverse(sample.pose(), joints, &why);
  if (!solved) throw InputError("trajectory", at() + why + hint());
  const std::vector<JointLimit>& limits = machine.joint_limits();
  if (joints.size() != limits.size())
    throw InternalError("machine " + machine.name() + " returned " + std::to_string(joints.size()) +
                        " joints, expected " + std::to_string(limits.size()));
  for (size_t j = 0; j < joints.size(); ++j) {
    if (joints[j] < limits[j].min - 1e-9 || joints[j] > limits[j].max + 1e-9)
      throw InputError("trajectory", at() + "joint " + limits[j].name + " at " +
                                         format_number(joints[j]) + " is outside its travel [" +
                                         format_number(limits[j].min) + ", " +
                                         format_number(limits[j].max) + "]" + hint());
  }
}

}  // namespace

void check_trajectory_poses(const Machine& machine, const Trajectory& trajectory,
                            double timestep_s) {
  if (!(timestep_s > 0.0)) throw InternalError("check_trajectory_poses: timestep_s must be > 0");
  const double duration_s = trajectory.duration_s();
  // the steps up to the first past the end (after it the final pose only repeats)
  const long steps = static_cast<long>(std::ceil(duration_s / timestep_s - 1e-9)) + 1;
  JointVector joints, next_joints;
  TrajectoryCursor plan(trajectory);
  for (long k = 0; k <= steps; ++k) {
    if (k % 1024 == 0) throw_if_interrupted();
    const TrajectorySample sample =
        planned_sample(plan, static_cast<double>(k) * timestep_s, duration_s);
    joints_at(machine, sample, k == 0 ? nullptr : &joints, next_joints);
    joints.swap(next_joints);
  }
}

JointReferences plan_joint_references(const BoundModel& bound, const Trajectory& trajectory,
                                      long steps, RecordedRun& run) {
  const Machine& machine = *bound.machine;
  const double dt = bound.model->opt.timestep;
  const double duration_s = trajectory.duration_s();
  const long stride = bound.control_stride;
  JointReferences refs;
  refs.updates = steps / stride + 1;
  refs.joint_count = static_cast<int>(bound.joints.size());
  const int joint_count = refs.joint_count;
  refs.position.assign(refs.updates * joint_count, 0.0);
  refs.velocity.assign(refs.updates * joint_count, 0.0);
  refs.acceleration.assign(refs.updates * joint_count, 0.0);
  refs.flap.assign(refs.updates, 0.0);
  refs.flap_rate.assign(refs.updates, 0.0);
  refs.flap_acceleration.assign(refs.updates, 0.0);
  run.deposit_command.resize(steps + 1);
  run.flow_fraction.resize(steps + 1);
  run.path_index.resize(steps + 1);
  run.desired_speed_mm_s.resize(steps + 1);

  // every step: the plan's flags, and its pose checked against the machine; every control
  // period: the joint setpoints and the shutter blade's
  ShutterReference shutter_reference;
  if (bound.has_shutter)
    shutter_reference = ShutterReference(trajectory, bound.shutter_geometry.time_s,
                                         bound.shutter_geometry.overtravel);
  JointVector joints, next_joints;
  TrajectoryCursor plan(trajectory);  // the steps' times only grow
  for (long k = 0, u = 0; k <= steps; ++k) {
    // inverse kinematics of every step takes seconds on an arm: a signal that asked to stop
    // ends it (core/interrupt.hpp)
    if (k % 1024 == 0) throw_if_interrupted();
    const double t = static_cast<double>(k) * dt;
    const TrajectorySample sample = planned_sample(plan, t, duration_s);
    run.deposit_command[k] = sample.depositing ? 1 : 0;
    run.flow_fraction[k] = static_cast<float>(sample.flow_fraction);
    run.path_index[k] = sample.path_index;
    run.desired_speed_mm_s[k] = static_cast<float>(sample.desired_speed_mm_s);
    // each step's solution follows the previous one's (an arm's branch and joint wrap)
    joints_at(machine, sample, k == 0 ? nullptr : &joints, next_joints);
    joints.swap(next_joints);
    if (k % stride != 0) continue;

    for (int j = 0; j < joint_count; ++j)
      refs.position[u * joint_count + j] = joints[j] * bound.joints[j].user_to_si;
    // the start's joint velocity J^-1 v; later ones are differences of the setpoints (below)
    if (u == 0) {
      const JointVector velocity = machine.joint_velocity(
          joints, PoseRate(sample.velocity_mm_s, sample.angular_velocity_rad_s));
      for (int j = 0; j < joint_count; ++j)
        refs.velocity[j] = velocity[j] * bound.joints[j].user_to_si;
    }
    if (bound.has_shutter) {
      double fraction = 0.0, rate = 0.0;
      shutter_reference.at(t, fraction, rate);
      const ShutterGeometry& geometry = bound.shutter_geometry;
      refs.flap[u] = geometry.angle_at(fraction);
      refs.flap_rate[u] = rate * (geometry.open_angle_rad - geometry.closed_angle_rad);
    }
    ++u;
  }

  // velocity and acceleration feed-forward from the sampled setpoints, as a digital servo
  // forms them
  const double control_period_s = static_cast<double>(stride) * dt;
  sampled_setpoint_references(refs.position, refs.velocity, refs.acceleration, refs.updates,
                              joint_count, control_period_s);
  sampled_setpoint_references(refs.flap, refs.flap_rate, refs.flap_acceleration, refs.updates, 1,
                              control_period_s);

  // the largest acceleration the plan asks of each joint, as the servo is given it
  run.reference_peak_acceleration.assign(joint_count, 0.0);
  for (long update = 0; update < refs.updates; ++update)
    for (int j = 0; j < joint_count; ++j)
      run.reference_peak_acceleration[j] = std::max(
          run.reference_peak_acceleration[j],
          std::abs(refs.acceleration[update * joint_count + j]) / bound.joints[j].user_to_si);
  return refs;
}

}  // namespace depotwin
