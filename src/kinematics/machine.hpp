// Per-machine kinematics behind one interface (Klipper's kin_*.c): tool poses in the work
// frame <-> joint positions, the Jacobian, joint limits, and the mapping of joint limits to
// the TCP limits the planners honour over each move. No MuJoCo here.
//
// Work frame: the substrate's frame, mm, z up, substrate surface at z = 0 for planar work.
// The "TCP" is the nozzle point expressed in that frame (on the XY stage the substrate moves
// under a fixed nozzle, so the TCP moves opposite to the carriages); the tool axis points
// from the nozzle tip up into the tool (core/pose.hpp).
//
// Adding a machine: one file pair here implementing this interface, one entry in
// registry.cpp, one MJCF model in models/ (see docs/ARCHITECTURE.md, "Adding a machine").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/pose.hpp"
#include "core/types.hpp"

namespace depotwin {

// 6 x joint_count: rows 0-2 the TCP velocity (mm/s), rows 3-5 the tool's angular velocity
// (rad/s) per unit joint rate
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

class Machine {
 public:
  virtual ~Machine() = default;

  // the registry name (the kinematics family)
  virtual std::string name() const = 0;
  // the MJCF model shipped for this machine, relative to models/
  virtual std::string model_file() const = 0;
  virtual int joint_count() const = 0;
  virtual const std::vector<JointLimit>& joint_limits() const = 0;

  // pose -> joints. Returns false and says why when the pose is not reachable (outside the
  // travel or the workspace, or a tool axis the machine cannot hold). A machine with several
  // solutions returns the one of its configured branch (see inverse_near).
  virtual bool inverse(const Pose& pose, JointVector& joints, std::string* why = nullptr) const = 0;
  // pose -> the joints nearest to `seed` among the pose's solutions, for continuity along a
  // path (an arm's branch and joint wrap follow the seed). The default: inverse().
  virtual bool inverse_near(const Pose& pose, const JointVector& seed, JointVector& joints,
                            std::string* why = nullptr) const;
  // joints -> pose
  virtual Pose forward(const JointVector& joints) const = 0;
  // d(pose)/d(joints) at a joint position (see Jacobian)
  virtual Jacobian jacobian(const JointVector& joints) const = 0;
  // joint velocities that give a pose rate (least squares over the task rows the machine
  // can move; the roll about the tool axis is free). The default solves with the Jacobian.
  virtual JointVector joint_velocity(const JointVector& joints, const PoseRate& rate) const;

  // TCP per-axis limits under which no joint exceeds its own velocity and acceleration
  // limits anywhere in the box [lo, hi], given the user's TCP limits (the result is never
  // looser than `requested`).
  virtual MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                         const Vec3& hi) const = 0;
  // true when cartesian_limits ignores its box (each TCP axis driven by one joint): the TCP
  // limits are then the same everywhere (TcpLimits::same_everywhere)
  virtual bool limits_ignore_position() const { return false; }
  // false for a machine that cannot move the TCP in z (the XY stage): the TCP's z row of the
  // Jacobian at the work frame's origin is zero
  bool moves_tcp_z() const;
  // the user's TCP limits, refined per move by cartesian_limits, with the machine's joint map
  // (joint positions along a path by inverse_near; the machine must outlive it)
  TcpLimits tcp_limits(const MachineLimits& requested) const;

  // scenario `limits: {joint: {v_max, a_max, j_max}}`: the same limits on every joint.
  // "" when applied, else why the machine cannot honour them.
  virtual std::string set_joint_limits(const AxisLimits& limits) = 0;

  // Feed-forward joint forces (N or N m, `joint_force` has joint_count() entries, added to)
  // for loads that reach the joints through closed kinematic chains, which a simulator's
  // per-joint rigid-body terms (M a + bias of each joint's own subtree) do not see: e.g.
  // the platform a linear delta's rods carry. Serial machines have none. No allocation.
  virtual bool has_closures() const { return false; }
  virtual void closure_feedforward(const Vec3& /*tcp_mm*/, const Vec3& /*tcp_velocity_mm_s*/,
                                   const Vec3& /*tcp_acceleration_mm_s2*/,
                                   double* /*joint_force*/) const {}
};

// A machine that holds the nozzle vertical (translation only): "" when the pose's tool axis
// is vertical, else why not. For the translational machines' inverse().
std::string vertical_axis_problem(const std::string& machine, const Pose& pose);

// A machine whose nozzle may go at most -min_z_mm below the work surface (z = 0): "" when the
// TCP's z is at or above min_z_mm, else "z = ... mm puts the nozzle more than ... mm into the
// <surface>". For the translational machines' inverse().
std::string below_surface_problem(double z_mm, double min_z_mm, const std::string& surface);

// One registered machine: its name (the scenario's `machine:` and an MJCF's `kinematics:`),
// a line of description, and a factory with default geometry and limits.
struct MachineInfo {
  std::string name;
  std::string description;
  std::unique_ptr<Machine> (*make)();
};

// every registered machine, in a stable order: the only list of machine names
const std::vector<MachineInfo>& machine_registry();
// the named machine; nullptr for an unknown name
std::unique_ptr<Machine> make_machine(const std::string& name);
// the registered names
std::vector<std::string> machine_names();

}  // namespace depotwin
