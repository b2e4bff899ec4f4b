// Shared by the simulation and render tests: hand-built trajectories and small MJCF models.
#pragma once

#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/trajectory.hpp"
#include "planners/motion/transition.hpp"

namespace depotwin {
namespace testing_util {

inline std::string xy_stage_model() {
  return std::string(DEPOTWIN_MODELS_DIR) + "/xy_stage.xml";
}

// One straight print path of `length_mm` at `speed_mm_s` along `direction` from `start`:
// a minimum-time transition piece from rest to the print velocity (constant acceleration,
// transition_piece of planners/transition.hpp), the constant-velocity print piece
// (PhaseMotion, depositing), and a transition piece back to rest.
struct StraightPrint {
  Trajectory trajectory;
  double print_begin_s = 0.0;  // t1: printing starts (constant speed from here)
  double print_end_s = 0.0;    // t2: printing ends
  Vec3 velocity_mm_s = Vec3::Zero();
};

inline StraightPrint straight_print(const Vec3& start_mm, const Vec3& direction, double speed_mm_s,
                                    double length_mm, const MachineLimits& limits) {
  StraightPrint result;
  const Vec3 unit = direction.normalized();
  const Vec3 velocity = unit * speed_mm_s;
  // constant acceleration from rest on the slowest axis: T = max |v_i| / a_max
  double ramp_s = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    ramp_s = std::max(ramp_s, std::abs(velocity[axis]) / limits.axes[axis].a_max_mm_s2);
  const Vec3 print_start = start_mm + 0.5 * ramp_s * velocity;
  std::vector<TrajectoryPiece> pieces;
  pieces.push_back(transition_piece(0.0, start_mm, Vec3::Zero(), print_start, velocity, limits));

  TrajectoryPiece print;
  print.t_begin_s = pieces.back().t_end_s;
  print.t_end_s = print.t_begin_s + length_mm / speed_mm_s;
  print.path_index = 0;
  print.depositing = true;
  print.desired_speed_mm_s = speed_mm_s;
  PhaseMotion motion;
  for (int axis = 0; axis < 3; ++axis) {
    AxisProfile profile(print_start[axis], velocity[axis]);
    profile.append(print.t_end_s - print.t_begin_s, 0.0);
    motion.axes[axis] = profile;
  }
  print.motion = motion;
  pieces.push_back(print);

  const Vec3 print_end = print_start + length_mm * unit;
  const Vec3 stop = print_end + 0.5 * ramp_s * velocity;
  pieces.push_back(
      transition_piece(print.t_end_s, print_end, velocity, stop, Vec3::Zero(), limits));
  result.print_begin_s = print.t_begin_s;
  result.print_end_s = print.t_end_s;
  result.velocity_mm_s = velocity;
  result.trajectory = Trajectory("hand", std::move(pieces));
  return result;
}

// A minimal XY machine in MJCF with the names Simulation needs; `omit` drops one part
// ("nozzle", "substrate", "y_joint", "y_actuator", "shutter") and `y_actuator` replaces
// the y servo (e.g. with a plain motor).
inline std::string small_xy_model(const std::string& omit = "",
                                  const std::string& y_actuator =
                                      "<general name=\"y\" joint=\"y\" gainprm=\"7e4\" "
                                      "biastype=\"affine\" biasprm=\"0 -7e4 -800\"/>",
                                  const std::string& x_gains =
                                      "gainprm=\"1.5e5\" "
                                      "biasprm=\"0 -1.5e5 -1800\"") {
  std::string xml = R"(<mujoco model="small_xy">
  <compiler angle="degree" autolimits="true"/>
  <option timestep="0.001"><flag contact="disable"/></option>
  <worldbody>
)";
  if (omit != "nozzle") xml += "    <site name=\"nozzle\" pos=\"0 0 0\"/>\n";
  xml += R"(    <body name="xc" pos="0 0 -0.03">
      <joint name="x" type="slide" axis="1 0 0" range="-0.06 0.06" damping="20"/>
      <geom type="box" size="0.05 0.05 0.01" mass="3"/>
      <body name="yc" pos="0 0 0.02">
)";
  if (omit != "y_joint")
    xml +=
        "        <joint name=\"y\" type=\"slide\" axis=\"0 1 0\" range=\"-0.06 0.06\" "
        "damping=\"20\"/>\n";
  xml += "        <geom type=\"box\" size=\"0.05 0.05 0.005\" mass=\"2\"/>\n";
  xml += std::string("        <body name=\"") + (omit == "substrate" ? "plate" : "substrate") +
         "\" pos=\"0 0 0.01\">\n";
  xml += R"(          <geom type="box" size="0.05 0.05 0.001" pos="0 0 -0.001" mass="0.5"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <general name="x" joint="x" biastype="affine" )" +
         x_gains + "/>\n";
  if (omit != "y_actuator" && omit != "y_joint") xml += "    " + y_actuator + "\n";
  xml += "  </actuator>\n</mujoco>\n";
  return xml;
}

}  // namespace testing_util
}  // namespace depotwin
