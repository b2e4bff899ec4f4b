// A machine's MJCF model bound to its kinematics (internal to sim/, MuJoCo-typed): the model
// loaded once, every name resolved once (the machine's servo joints, the optional shutter,
// the `nozzle` site and the `substrate` body), the settings applied (timestep, kp_scale,
// shutter time), and the nozzle read back in the work frame.
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"
#include "kinematics/machine.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/servo_controller.hpp"
#include "sim/shutter.hpp"
#include "sim/simulation.hpp"

namespace depotwin {

struct BoundModel {
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
};

// Loads the model (its file, or `model_text` in its place when given: sim/part_model.hpp) and
// resolves every name (see Simulation's constructor for the InputErrors); the state is
// mj_forward-ed at the model's reference pose.
BoundModel bind_model(const std::string& model_path, const Machine& machine,
                      const SimSettings& settings, const std::string& model_text = {});

// the nozzle site relative to the substrate frame, and its velocity relative to the substrate
void read_nozzle(const BoundModel& bound, Vec3& position_mm, Vec3& velocity_mm_s);
// the shutter's open fraction from its blade angle; without a shutter, the command itself
double open_fraction(const BoundModel& bound, bool deposit_command);

}  // namespace depotwin
