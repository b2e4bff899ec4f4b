#include "kinematics/cartesian.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/number_text.hpp"

namespace depotwin {

namespace {

// the gantry of models/cartesian.xml: soft travel here, hard stops 2 mm beyond it in the MJCF.
// Speeds and accelerations as a desktop printer's firmware sets them (Klipper's
// max_velocity 300, max_accel 3000; max_z_velocity 15, max_z_accel 300)
constexpr double kTravelXY_mm = 100.0;
constexpr double kTravelZMin_mm = -10.0;
constexpr double kTravelZMax_mm = 150.0;
// the bed's top is z = 0: the nozzle may go no deeper into it than this (as the delta's
// min_tcp_z); the z travel below it is the bed's, for the MJCF's hard stop and homing
constexpr double kMinTcpZ_mm = -1.0;
constexpr double kVelocityXY_mm_s = 300.0;
constexpr double kAccelerationXY_mm_s2 = 3000.0;
constexpr double kVelocityZ_mm_s = 15.0;
constexpr double kAccelerationZ_mm_s2 = 300.0;

class Cartesian : public Machine {
 public:
  Cartesian()
      : limits_{{"x", -kTravelXY_mm, kTravelXY_mm, kVelocityXY_mm_s, kAccelerationXY_mm_s2},
                {"y", -kTravelXY_mm, kTravelXY_mm, kVelocityXY_mm_s, kAccelerationXY_mm_s2},
                {"z", kTravelZMin_mm, kTravelZMax_mm, kVelocityZ_mm_s, kAccelerationZ_mm_s2}} {}

  std::string name() const override { return "cartesian"; }
  std::string model_file() const override { return "cartesian.xml"; }
  int joint_count() const override { return 3; }
  const std::vector<JointLimit>& joint_limits() const override { return limits_; }

  // identity within the travel: each joint is the TCP's coordinate on its axis
  bool inverse(const Pose& pose, JointVector& joints, std::string* why) const override {
    const Vec3& tcp_mm = pose.position_mm;
    joints.assign({tcp_mm.x(), tcp_mm.y(), tcp_mm.z()});
    if (!tcp_mm.allFinite()) {
      if (why) *why = "the TCP position is not a finite number";
      return false;
    }
    if (const std::string tilted = vertical_axis_problem(name(), pose); !tilted.empty()) {
      if (why) *why = tilted;
      return false;
    }
    for (int i = 0; i < 3; ++i) {
      const JointLimit& limit = limits_[i];
      if (joints[i] < limit.min - kTravelRounding_mm ||
          joints[i] > limit.max + kTravelRounding_mm) {
        if (why)
          *why = "the cartesian machine's " + limit.name + " axis at " +
                 message_number_outside(joints[i], limit.min, limit.max, 4) +
                 " mm is outside its travel [" + message_number(limit.min, 4) + ", " +
                 message_number(limit.max, 4) + "] mm, by " +
                 message_number(std::max(limit.min - joints[i], joints[i] - limit.max), 4) + " mm";
        return false;
      }
    }
    if (const std::string deep =
            below_surface_problem(tcp_mm.z(), kMinTcpZ_mm, "bed (its top is z = 0)");
        !deep.empty()) {
      if (why) *why = deep;
      return false;
    }
    return true;
  }

  Pose forward(const JointVector& joints) const override {
    return Pose(Vec3(joints.at(0), joints.at(1), joints.at(2)));
  }

  // the Jacobian is the identity on x, y and z; nothing turns the tool
  Jacobian jacobian(const JointVector& /*joints*/) const override {
    Jacobian j = Jacobian::Zero(6, 3);
    for (int i = 0; i < 3; ++i) j(i, i) = 1.0;
    return j;
  }
  JointVector joint_velocity(const JointVector& /*joints*/, const PoseRate& rate) const override {
    return JointVector{rate.linear_mm_s.x(), rate.linear_mm_s.y(), rate.linear_mm_s.z()};
  }

  // each TCP axis is one joint: the per-axis limits are the tighter of the two (a jerk limit
  // of 0 is none: the tighter of those that are set)
  MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& /*lo*/,
                                 const Vec3& /*hi*/) const override {
    MachineLimits limits = requested;
    for (int i = 0; i < 3; ++i) {
      AxisLimits& axis = limits.axes[i];
      axis.v_max_mm_s = std::min(requested.axes[i].v_max_mm_s, limits_[i].v_max);
      axis.a_max_mm_s2 = std::min(requested.axes[i].a_max_mm_s2, limits_[i].a_max);
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

std::unique_ptr<Machine> make_cartesian() {
  return std::make_unique<Cartesian>();
}

}  // namespace depotwin
