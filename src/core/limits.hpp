// Kinematic limits: per joint (the machine's own, mm or rad) and per Cartesian TCP axis
// (x, y, z, what the planners honour). A machine whose joints are not its Cartesian axes
// (a linear delta, an arm) maps its joint limits to TCP limits that depend on where the tool
// is: TcpLimits asks it per move, as Klipper's kinematics limit each move (check_move).
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/pose.hpp"
#include "core/types.hpp"

namespace depotwin {

struct AxisLimits {
  double v_max_mm_s = 0.0;
  double a_max_mm_s2 = 0.0;
  double j_max_mm_s3 = 0.0;  // 0: no jerk limit
};

struct MachineLimits {
  std::array<AxisLimits, 3> axes{};  // x, y, z

  // the same limits on every axis
  static MachineLimits uniform(double v_max_mm_s, double a_max_mm_s2, double j_max_mm_s3 = 0.0);
  // "" when usable, else what is wrong (names the axis and field)
  std::string validate() const;
  // true when some axis has a jerk limit
  bool jerk_limited() const;
};

// One joint's range and limits, in its own units: mm, mm/s, mm/s^2, mm/s^3 for a prismatic
// joint, rad, rad/s, rad/s^2, rad/s^3 for a revolute one.
struct JointLimit {
  std::string name;  // the MJCF joint (and actuator) name
  double min = 0.0;  // position range
  double max = 0.0;
  double v_max = 0.0;
  double a_max = 0.0;
  double j_max = 0.0;     // 0: no jerk limit
  bool revolute = false;  // a hinge (rad) rather than a slide (mm)
};

// How far a prismatic joint may pass its range's end by rounding alone: a path that ends on the
// travel's end (a purge line to x = 100 on a +-100 mm bed) is sampled a few ulp beyond it.
constexpr double kTravelRounding_mm = 1e-9;

using JointVector = std::vector<double>;  // mm for prismatic joints, rad for revolute ones

// The machine's joints along a path, for planners that parametrise a path in time under the
// joints' own limits (the joint positions q(s) along the path give q'(s) and q''(s)). The
// planner still never sees the machine's geometry, only joint positions and limits.
struct JointMap {
  std::vector<JointLimit> limits;  // per joint
  // joints at each pose, each solution the one nearest to the previous pose's (continuous
  // along the path); false, saying why and at which pose index, when a pose is unreachable
  std::function<bool(const std::vector<Pose>& poses, std::vector<JointVector>& joints,
                     std::string* why)>
      solve;
  // the joints also turn the tool (an arm's wrist: more joints than the TCP's three axes), so
  // TCP limits over a box bound the translation only: a planner that moves the tool axis must
  // time the path on the joints themselves
  bool turns_tool = false;
  // false: the TCP is held at z = 0 (the XY stage), so a planner's travel lifts nothing
  bool moves_z = true;
};

// The TCP limits a planner must honour, which may depend on where the move is.
class TcpLimits {
 public:
  // limits under which no joint exceeds its own anywhere in the box [lo, hi]
  using BoxLimits = std::function<MachineLimits(const Vec3& lo_mm, const Vec3& hi_mm)>;

  TcpLimits() = default;
  // the same limits everywhere (a Cartesian machine, or a test)
  TcpLimits(const MachineLimits& limits);  // NOLINT: implicit on purpose
  // `requested` (the user's TCP limits, never exceeded) refined per box by the machine, and
  // optionally the machine's joint map
  TcpLimits(const MachineLimits& requested, BoxLimits over_box,
            std::shared_ptr<const JointMap> joint_map = nullptr);

  // the limits that hold everywhere in the axis-aligned box [lo, hi]
  MachineLimits over(const Vec3& lo_mm, const Vec3& hi_mm) const;
  // over a straight move from a to b (the box of its ends)
  MachineLimits along(const Vec3& a_mm, const Vec3& b_mm) const;
  // over a move from (a, va) to (b, vb) whose axes may overshoot their ends by up to the
  // stopping distance v^2 / (2 a_max) (minimum-time transitions): the box is padded until
  // the padding and the limits over it agree
  MachineLimits for_transition(const Vec3& a_mm, const Vec3& va_mm_s, const Vec3& b_mm,
                               const Vec3& vb_mm_s) const;
  // the user's limits: no box gives looser ones
  const MachineLimits& requested() const { return requested_; }
  // true when the limits are the same everywhere
  bool uniform() const { return !over_box_; }
  // true when the limits over every box are the same: uniform, or refined per box by a machine
  // whose refinement ignores the box (a Cartesian machine, an XY stage: each TCP axis one joint)
  bool same_everywhere() const { return !over_box_ || box_independent_; }
  // declares that over_box gives the same limits for every box (the machine knows)
  void set_box_independent(bool independent) { box_independent_ = independent; }
  // the machine's joints along a path; null when the limits come without a machine
  const JointMap* joint_map() const { return joint_map_.get(); }
  // the same, to share with limits derived from these
  const std::shared_ptr<const JointMap>& shared_joint_map() const { return joint_map_; }

 private:
  MachineLimits requested_;
  BoxLimits over_box_;
  std::shared_ptr<const JointMap> joint_map_;
  bool box_independent_ = false;
};

}  // namespace depotwin
