// Per-machine kinematics behind one interface (Klipper's kin_*.c): TCP position in the
// work frame <-> joint positions, joint limits, and the mapping of joint limits to the
// Cartesian limits the planners honour. No MuJoCo here.
//
// Work frame: the substrate's frame, mm, z up, substrate surface at z = 0. The "TCP" is
// the nozzle point expressed in that frame (on the XY stage the substrate moves under a
// fixed nozzle, so the TCP moves opposite to the carriages).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/types.hpp"

namespace depotwin {

using JointVector = std::vector<double>;  // mm for prismatic joints, rad for revolute ones

struct JointLimit {
  std::string name;          // the MJCF joint name
  double min = 0.0;          // position range (mm or rad)
  double max = 0.0;
  double v_max = 0.0;        // mm/s or rad/s
  double a_max = 0.0;        // mm/s^2 or rad/s^2
};

class Machine {
 public:
  virtual ~Machine() = default;

  virtual std::string name() const = 0;
  // the MJCF model shipped for this machine, relative to models/
  virtual std::string model_file() const = 0;
  virtual int joint_count() const = 0;
  virtual const std::vector<JointLimit>& joint_limits() const = 0;

  // TCP (mm, work frame) -> joints. Returns false and says why when the point is not
  // reachable (outside the travel or the workspace).
  virtual bool inverse(const Vec3& tcp_mm, JointVector& joints, std::string* why = nullptr) const = 0;
  // joints -> TCP (mm, work frame)
  virtual Vec3 forward(const JointVector& joints) const = 0;
  // joint velocities for a TCP velocity at a pose (the Jacobian applied), for feed-forward
  virtual JointVector joint_velocity(const JointVector& joints, const Vec3& tcp_velocity) const = 0;

  // Cartesian per-axis limits under which no joint exceeds its own velocity and
  // acceleration limits anywhere in the box [lo, hi] (the toolpath's bounds), given the
  // user's Cartesian limits (the result is never looser than `requested`).
  virtual MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                         const Vec3& hi) const = 0;

  // scenario `limits: {joint: {v_max, a_max}}`: the same limits on every joint
  virtual void set_joint_limits(double v_max, double a_max) = 0;

  // Feed-forward joint forces (N or N m, `joint_force` has joint_count() entries, added to)
  // for loads that reach the joints through closed kinematic chains, which a simulator's
  // per-joint rigid-body terms (M a + bias of each joint's own subtree) do not see: e.g.
  // the platform a linear delta's rods carry. Serial machines have none. No allocation.
  virtual bool has_closures() const { return false; }
  virtual void closure_feedforward(const Vec3& /*tcp_mm*/, const Vec3& /*tcp_velocity_mm_s*/,
                                   const Vec3& /*tcp_acceleration_mm_s2*/,
                                   double* /*joint_force*/) const {}
};

// "xy_stage" | "linear_delta"; nullptr for an unknown name
std::unique_ptr<Machine> make_machine(const std::string& name);
// the machine names make_machine knows
std::vector<std::string> machine_names();

}  // namespace depotwin
