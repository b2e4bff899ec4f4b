// The machine registry: the only list of machine names. A new machine is one line here.
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/number_text.hpp"
#include "kinematics/arm6.hpp"
#include "kinematics/cartesian.hpp"
#include "kinematics/linear_delta.hpp"
#include "kinematics/machine.hpp"
#include "kinematics/xy_stage.hpp"

namespace depotwin {

const std::vector<MachineInfo>& machine_registry() {
  static const std::vector<MachineInfo> registry{
      {"xy_stage", "Thompson & Yoon's XY aerosol stage: the substrate moves under a fixed nozzle",
       &make_xy_stage},
      {"linear_delta",
       "Giberti et al.'s linear delta: three vertical carriages carry the substrate platform",
       &make_linear_delta},
      {"arm6", "6-DOF arm (ABB IRB 120) carrying a tilted-nozzle head over a table", &make_arm6},
      {"cartesian",
       "XYZ gantry printer (Klipper's cartesian): the head moves in x and y, the bed drops in z",
       &make_cartesian},
  };
  return registry;
}

std::unique_ptr<Machine> make_machine(const std::string& name) {
  for (const MachineInfo& info : machine_registry())
    if (info.name == name) return info.make();
  return nullptr;
}

std::vector<std::string> machine_names() {
  std::vector<std::string> names;
  for (const MachineInfo& info : machine_registry()) names.push_back(info.name);
  return names;
}

JointVector Machine::joint_velocity(const JointVector& joints, const PoseRate& rate) const {
  // least squares over the six task rows: the roll about the tool axis is free, so the
  // angular velocity's component along the axis is what the joints' solution gives
  const Jacobian j = jacobian(joints);
  Eigen::Matrix<double, 6, 1> task;
  task << rate.linear_mm_s, rate.angular_rad_s;
  const Eigen::VectorXd q_rate = j.completeOrthogonalDecomposition().solve(task);
  return JointVector(q_rate.data(), q_rate.data() + q_rate.size());
}

bool Machine::inverse_near(const Pose& pose, const JointVector& /*seed*/, JointVector& joints,
                           std::string* why) const {
  return inverse(pose, joints, why);
}

bool Machine::moves_tcp_z() const {
  // the TCP's z row of the Jacobian at the work frame's origin: zero for a machine without z
  JointVector joints;
  if (!inverse(Pose(Vec3::Zero()), joints)) return true;
  return jacobian(joints).row(2).norm() > 0.0;
}

TcpLimits Machine::tcp_limits(const MachineLimits& requested) const {
  auto joint_map = std::make_shared<JointMap>();
  joint_map->limits = joint_limits();
  joint_map->turns_tool = joint_count() > 3;
  joint_map->moves_z = moves_tcp_z();
  joint_map->solve = [this](const std::vector<Pose>& poses, std::vector<JointVector>& joints,
                            std::string* why) {
    joints.resize(poses.size());
    for (size_t i = 0; i < poses.size(); ++i) {
      std::string reason;
      const bool solved = i == 0 ? inverse(poses[i], joints[i], &reason)
                                 : inverse_near(poses[i], joints[i - 1], joints[i], &reason);
      if (!solved) {
        if (why) *why = "pose " + std::to_string(i) + ": " + reason;
        return false;
      }
    }
    return true;
  };
  TcpLimits limits(
      requested,
      [this, requested](const Vec3& lo, const Vec3& hi) {
        return cartesian_limits(requested, lo, hi);
      },
      std::move(joint_map));
  limits.set_box_independent(limits_ignore_position());
  return limits;
}

std::string vertical_axis_problem(const std::string& machine, const Pose& pose) {
  if (!pose.tool_axis.allFinite() || std::abs(pose.tool_axis.norm() - 1.0) > 1e-9)
    return "the tool axis is not a finite unit vector";
  const double tilt_deg = rad_to_deg(axis_angle_rad(pose.tool_axis, vertical_tool_axis()));
  if (tilt_deg <= 1e-7) return "";
  char text[160];
  std::snprintf(text, sizeof text,
                "the %s holds the nozzle vertical: tool axis (%.4g, %.4g, %.4g) is tilted %.4g deg",
                machine.c_str(), pose.tool_axis.x(), pose.tool_axis.y(), pose.tool_axis.z(),
                tilt_deg);
  return text;
}

std::string below_surface_problem(double z_mm, double min_z_mm, const std::string& surface) {
  if (z_mm >= min_z_mm) return "";
  // (z to the digits that tell it from the limit: -1.0001, not -1)
  return "z = " +
         message_number_outside(z_mm, min_z_mm, std::numeric_limits<double>::infinity(), 4) +
         " mm puts the nozzle more than " + message_number(-min_z_mm, 4) + " mm into the " +
         surface;
}

}  // namespace depotwin
