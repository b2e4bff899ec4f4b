// A simulated run as plain data: the state at every step (nozzle in the work frame, shutter,
// the plan's flags, joints). The simulation (sim/) writes it; deposition and metrics read it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace depotwin {

// The simulated state at one step (user units, substrate frame).
struct StepState {
  double t_s = 0.0;
  Vec3 nozzle_mm = Vec3::Zero();             // nozzle site in the substrate frame
  Vec3 nozzle_velocity_mm_s = Vec3::Zero();  // its velocity relative to the substrate
  double open_fraction = 0.0;                // shutter: 0 closed .. 1 open (from the flap angle)
  bool deposit_command = false;              // the trajectory's depositing flag at t
  double flow_fraction = 0.0;       // the trajectory's commanded flow / nominal at t (extrusion)
  double desired_speed_mm_s = 0.0;  // the trajectory piece's desired speed (0: transition)
  int path_index = -1;              // the trajectory piece's print path (-1: transition)
};

// MuJoCo contacts over a run: between the machine's own parts (self: both geoms on bodies
// of the tree that carries the nozzle) and with anything else (the table, the world). An
// event is a pair of geoms starting to touch; steps count the states with any such contact.
struct ContactLog {
  int self_events = 0, other_events = 0;
  long self_steps = 0, other_steps = 0;
  std::string first;  // "t = 1.234 s: link3 / table" for the first event, "" without any
};

// A whole run as a struct of arrays: entry k is the state at t = k * timestep_s,
// k = 0 .. steps (the initial state plus one entry per step).
struct RecordedRun {
  std::vector<double> t_s;
  std::vector<Vec3> nozzle_mm, nozzle_velocity_mm_s;
  std::vector<float> open_fraction;
  std::vector<uint8_t> deposit_command;
  std::vector<float> flow_fraction;
  std::vector<int> path_index;
  std::vector<float> desired_speed_mm_s;
  // step-major, joint_count per entry, user units: mm, mm/s, mm/s^2, N for slides and
  // rad, rad/s, rad/s^2, N m for hinges. Acceleration and force are MuJoCo's qacc and
  // actuator force at that state under that step's control.
  int joint_count = 0;
  std::vector<std::string> joint_names;
  std::vector<double> joint_position, joint_velocity, joint_acceleration, actuator_force;
  // per joint, the largest |acceleration| of the joint reference the servo is given (the
  // setpoints' second differences, JointReference::acceleration), user units
  std::vector<double> reference_peak_acceleration;
  double timestep_s = 0.0;
  double wall_s = 0.0;                       // wall-clock time of run()
  long steps = 0;                            // physics steps taken (entries - 1)
  double max_constraint_violation_mm = 0.0;  // largest equality-constraint residual; 0 without
  ContactLog contacts;

  size_t size() const { return t_s.size(); }
  double joint(const std::vector<double>& values, size_t entry, int joint_index) const {
    return values[entry * static_cast<size_t>(joint_count) + joint_index];
  }
};

}  // namespace depotwin
