#include "kinematics/xy_stage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/number_text.hpp"

namespace depotwin {

namespace {

// the stage of models/xy_stage.xml: +-50 mm soft travel (hard stops at +-52 mm in the MJCF),
// direct-drive linear motors far faster than any print job needs
constexpr double kTravel_mm = 50.0;
constexpr double kJointVelocityMax_mm_s = 200.0;
constexpr double kJointAccelerationMax_mm_s2 = 2000.0;
// the nozzle point in the plate frame when both carriages are at 0 (models/xy_stage.xml)
constexpr double kNozzleX_mm = 0.0;
constexpr double kNozzleY_mm = 0.0;
// the plate cannot move in z: a TCP off the substrate plane is unreachable
constexpr double kPlaneTolerance_mm = 1e-6;

class XyStage : public Machine {
 public:
  XyStage()
      : limits_{
            {"x", -kTravel_mm, kTravel_mm, kJointVelocityMax_mm_s, kJointAccelerationMax_mm_s2},
            {"y", -kTravel_mm, kTravel_mm, kJointVelocityMax_mm_s, kJointAccelerationMax_mm_s2}} {}

  std::string name() const override { return "xy_stage"; }
  std::string model_file() const override { return "xy_stage.xml"; }
  int joint_count() const override { return 2; }
  const std::vector<JointLimit>& joint_limits() const override { return limits_; }

  // the plate moves under a fixed nozzle: tcp = nozzle - carriage, so carriage = nozzle - tcp
  bool inverse(const Pose& pose, JointVector& joints, std::string* why) const override {
    const Vec3& tcp_mm = pose.position_mm;
    joints.resize(2);
    joints[0] = kNozzleX_mm - tcp_mm.x();
    joints[1] = kNozzleY_mm - tcp_mm.y();
    if (!tcp_mm.allFinite()) {
      if (why) *why = "the TCP position is not a finite number";
      return false;
    }
    if (const std::string tilted = vertical_axis_problem(name(), pose); !tilted.empty()) {
      if (why) *why = tilted;
      return false;
    }
    if (std::abs(tcp_mm.z()) > kPlaneTolerance_mm) {
      if (why)
        *why = "the XY stage has no z axis: the TCP must lie on the substrate (z = 0), got z = " +
               message_number(tcp_mm.z(), 4) + " mm";
      return false;
    }
    static const char* kTcpAxis[2] = {"x", "y"};
    for (int i = 0; i < 2; ++i) {
      const JointLimit& limit = limits_[i];
      if (joints[i] < limit.min - kTravelRounding_mm ||
          joints[i] > limit.max + kTravelRounding_mm) {
        if (why)
          *why = "joint " + limit.name + " at " +
                 message_number_outside(joints[i], limit.min, limit.max, 4) +
                 " mm is outside its travel [" + message_number(limit.min, 4) + ", " +
                 message_number(limit.max, 4) + "] mm, by " +
                 message_number(std::max(limit.min - joints[i], joints[i] - limit.max), 4) +
                 " mm (TCP " + kTcpAxis[i] + " = " + message_number(tcp_mm[i], 4) + " mm)";
        return false;
      }
    }
    return true;
  }

  Pose forward(const JointVector& joints) const override {
    return Pose(Vec3(kNozzleX_mm - joints.at(0), kNozzleY_mm - joints.at(1), 0.0));
  }

  // the Jacobian is -I on x and y; nothing turns the tool
  Jacobian jacobian(const JointVector& /*joints*/) const override {
    Jacobian j = Jacobian::Zero(6, 2);
    j(0, 0) = -1.0;
    j(1, 1) = -1.0;
    return j;
  }
  JointVector joint_velocity(const JointVector& /*joints*/, const PoseRate& rate) const override {
    return JointVector{-rate.linear_mm_s.x(), -rate.linear_mm_s.y()};
  }

  // each TCP axis is one carriage: the per-axis limits are the tighter of the two;
  // nothing moves in z, so z keeps what was asked for
  MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& /*lo*/,
                                 const Vec3& /*hi*/) const override {
    MachineLimits limits = requested;
    for (int i = 0; i < 2; ++i) {
      AxisLimits& axis = limits.axes[i];
      axis.v_max_mm_s = std::min(requested.axes[i].v_max_mm_s, limits_[i].v_max);
      axis.a_max_mm_s2 = std::min(requested.axes[i].a_max_mm_s2, limits_[i].a_max);
      // a jerk limit of 0 is none: the tighter of the two that are set
      const double joint_jerk = limits_[i].j_max;
      if (joint_jerk > 0.0)
        axis.j_max_mm_s3 =
            axis.j_max_mm_s3 > 0.0 ? std::min(axis.j_max_mm_s3, joint_jerk) : joint_jerk;
    }
    return limits;
  }

  bool limits_ignore_position() const override { return true; }

  std::string set_joint_limits(const AxisLimits& joint) override {
    for (JointLimit& limit : limits_) {
      limit.v_max = joint.v_max_mm_s;
      limit.a_max = joint.a_max_mm_s2;
      limit.j_max = joint.j_max_mm_s3;
    }
    return "";
  }

 private:
  std::vector<JointLimit> limits_;
};

}  // namespace

std::unique_ptr<Machine> make_xy_stage() {
  return std::make_unique<XyStage>();
}

}  // namespace depotwin
