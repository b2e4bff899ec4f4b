// A 6-DOF arm with the ABB IRB 120's dimensions carrying a deposition head on its flange
// (models/arm6.xml). Closed-form inverse kinematics of an "ortho-parallel arm with a spherical
// wrist" (OPW: Brandstoetter, Angerer & Hofbaur, "An analytical solution of the inverse
// kinematics problem of industrial serial manipulators with an ortho-parallel basis and a
// spherical wrist", 2014), derived below for ABB's zero and sign conventions.
//
// Geometry (ABB IRB 120 product specification, figures "main dimensions" and
// "working range"): joint 2 axis 290 mm above the base (joint 1) origin with no offset from
// the joint 1 axis, upper arm 270 mm (joint 2 to joint 3), elbow offset 70 mm (joint 3 axis to
// the forearm axis), forearm 302 mm (joint 3 to the wrist centre along the forearm axis), wrist
// centre to flange 72 mm. In OPW terms a1 = 0, a2 = 70 (forearm axis above joint 3 at the zero
// pose), b = 0, c1 = 290, c2 = 270, c3 = 302, c4 = 72.
// Ranges (deg): j1 +-165, j2 +-110, j3 -110 .. +70, j4 +-160, j5 +-120, j6 +-400. Speeds (deg/s):
// 250, 250, 250, 320, 320, 420. Accelerations are not in the datasheet: 4 x v_max per second
// (1000, 1000, 1000, 1280, 1280, 1680 deg/s^2). JointLimit holds them in rad, rad/s, rad/s^2.
//
// Frames (mm). Base frame: z up along joint 1, origin on the joint 1 axis at the base's
// foot (the MJCF world frame). ABB's zero: the upper arm vertical, the forearm horizontal along
// +x, wrist centre (302, 0, 630), flange (374, 0, 630) facing +x. With Rx, Ry, Rz the rotations
// about the base axes and Tr a translation, the link frames (the MJCF bodies link1..link6) are
//   T1 = Rz(q1)                        joint 1 about +z
//   T2 = T1 Tr(0, 0, c1) Ry(q2)        joint 2 about +y: positive tilts the upper arm forward
//   T3 = T2 Tr(0, 0, c2) Ry(q3)        joint 3 about +y: positive tilts the forearm down
//   T4 = T3 Tr(c3, 0, a2) Rx(q4)       joint 4 about the forearm axis (origin: wrist centre)
//   T5 = T4 Ry(q5)                     joint 5 about the wrist's y
//   T6 = T5 Rx(q6)                     joint 6 about the flange normal
//   flange (ABB tool0) = T6 Tr(c4, 0, 0) Ry(90 deg): z out of the flange, x down at zero.
//
// Tool (flange -> TCP, a fixed transform here and in the MJCF body `tool`): an aerosol /
// extrusion head, a cylinder (r 30 mm, 65 mm long) on the flange axis and a nozzle tilted
// 30 deg from the flange normal towards the flange's -x, its tip at (-40, 0, 113) mm in the
// flange frame (120 mm from the flange, 40 mm off the joint 6 axis). The TCP frame is
//   T_tool = [Ry(150 deg), (-40, 0, 113) mm]     (Ry(180 deg - tilt))
// its z (the tool axis, from the tip up into the head) is (sin 30, 0, -cos 30) in the flange
// frame. Because the nozzle is not coaxial with joint 6, the free roll about the nozzle axis
// moves joints 1-5: it is a real choice (Pose::roll_rad), not a joint 6 offset.
// With the nozzle vertical at roll 0 over the substrate the arm reaches down in front of
// itself with joints 4 and 6 near 0 and joint 5 near +50 deg (at the work origin
// q = (0, 68.0, 2.3, 0, 49.7, 0) deg): the flange faces 30 deg past straight down, towards the
// robot, the wrist centre 57.9 mm beyond the tip and 180.2 mm above it.
//
// Work frame: the `substrate` body, a translation of the base frame (no rotation) to the
// table surface in front of the robot: (360, 0, -50) mm, the robot standing on a 50 mm riser
// (Arm6Geometry::work_origin_mm). Chosen over a grid of origins so that a 150 x 130 mm part up
// to 40 mm high centred there is reached with the nozzle vertical at roll 0 (every joint at
// least 30 deg inside its range, |sin q5| >= 0.6) and tilted 45 deg any way with a suitable
// roll (16 deg, |sin q5| >= 0.54, wrist centre >= 139 mm off the joint 1 axis). A pose is
//   T_work_tcp = [tool_frame(pose.tool_axis, pose.roll_rad), pose.position_mm]
// and the flange T_base_flange = T_base_work T_work_tcp T_tool^-1.
//
// Inverse kinematics (derivation). The wrist centre c = p_flange - c4 z_flange.
//  - shoulder: q1 = atan2(c_y, c_x) (front) or that + pi (back, the arm reaching over its
//    own base). In the arm's plane, r = +-|c_xy| along the q1 direction and h = c_z - c1.
//  - elbow: the forearm's effective link from joint 3 to the wrist centre has length
//    L = sqrt(c3^2 + a2^2) and lies psi = atan2(a2, c3) above the forearm axis. With
//    gamma = q3 - psi + 90 deg the angle between upper arm and effective forearm, the wrist
//    centre is (r, h) = c2 (sin q2, cos q2) + L (sin(q2 + gamma), cos(q2 + gamma)), so
//    cos gamma = (r^2 + h^2 - c2^2 - L^2) / (2 c2 L), gamma = +-atan2(sin, cos) (the sine from
//    ((c2 + L)^2 - s)(s - (c2 - L)^2), exact near the stretched arm), and
//    q2 = atan2(r, h) - atan2(L sin gamma, c2 + L cos gamma).
//  - wrist: M = (Rz(q1) Ry(q2 + q3))^T R_06 = Rx(q4) Ry(q5) Rx(q6) (X-Y-X Euler angles), so
//    q5 = atan2(+-sqrt(M10^2 + M20^2), M00), q4 = atan2(+-M10, -+M20) and q6 the angle of
//    (Rx(q4) Ry(q5))^T M's second column (exact where q4 is ill-conditioned near q5 = 0); the
//    flipped wrist is (q4 + pi, -q5, q6 + pi). At q5 = 0 only q4 + q6 is defined (the hint's q4
//    is kept).
//  - joint 6 turns +-400 deg: q6 + 2 pi k for every k within the range.
// Branch index (branch_of, set_branch), three bits:
//   bit 0  shoulder back: the wrist centre behind the joint 1 direction (r < 0)
//   bit 1  elbow down: q3 below the stretched-arm angle psi - 90 deg = -76.95 deg (gamma < 0)
//   bit 2  wrist flipped: q5 < 0
// so branch 0 (shoulder front, elbow up, q5 > 0) is the natural posture and the default.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/collision_shape.hpp"
#include "kinematics/machine.hpp"

namespace depotwin {

// joint positions of the arm without allocation (rad), j1..j6
using Arm6Joints = std::array<double, 6>;

// one inverse-kinematics solution and its branch (bits as above)
struct Arm6Solution {
  Arm6Joints q{};
  int branch = 0;
};

// at most 8 branches times 3 turns of joint 6 (its range spans 800 deg)
constexpr int kArm6MaxSolutions = 24;
using Arm6Solutions = std::array<Arm6Solution, kArm6MaxSolutions>;
// the eight branches' solutions of one pose, joint 6 nearest 0, index = branch
using Arm6Branches = std::array<Arm6Joints, 8>;

// Dimensions (mm); the defaults are the IRB 120 and the head of models/arm6.xml.
struct Arm6Geometry {
  double c1_mm = 290.0;  // base to shoulder (joint 2 axis)
  double c2_mm = 270.0;  // upper arm
  double c3_mm = 302.0;  // forearm, joint 3 to the wrist centre along the forearm axis
  double c4_mm = 72.0;   // wrist centre to flange
  double a2_mm = 70.0;   // elbow offset: the forearm axis above the joint 3 axis at q = 0
  // the tool: nozzle tilt from the flange normal (about the flange's y) and the tip
  double nozzle_tilt_deg = 30.0;
  Vec3 tip_in_flange_mm = Vec3(-40.0, 0.0, 113.0);
  // the work frame (substrate body) origin in the base frame: on the table surface in front
  Vec3 work_origin_mm = Vec3(360.0, 0.0, -50.0);
  // cartesian_limits keeps the joints within this fraction of their limits
  double limit_margin = 0.9;
};

class Arm6 final : public Machine {
 public:
  explicit Arm6(const Arm6Geometry& geometry = Arm6Geometry{});

  std::string name() const override { return "arm6"; }
  std::string model_file() const override { return "arm6.xml"; }
  int joint_count() const override { return 6; }
  // joints "j1".."j6" (MJCF hinges and actuators)
  const std::vector<JointLimit>& joint_limits() const override { return joint_limits_; }

  // The configured branch's solution (set_branch; default 0), joint 6 nearest 0. False with a
  // reason for a non-finite pose, a tool axis that is not a unit vector, a pose out of reach
  // (by how much) or a joint outside its range (which joint, at what angle, and which other
  // branches would reach the pose). Singular poses are solved (q5 = 0: q4 = 0).
  bool inverse(const Pose& pose, JointVector& joints, std::string* why = nullptr) const override;
  // The solution nearest to `seed` (Euclidean in joint space) over all branches and turns of
  // joint 6 within the ranges: continuity along a path. At q5 = 0 the seed's q4 is kept.
  bool inverse_near(const Pose& pose, const JointVector& seed, JointVector& joints,
                    std::string* why = nullptr) const override;
  // TCP position, tool axis and roll (roll_of_frame) in the work frame; NaN for a wrong size
  Pose forward(const JointVector& joints) const override;
  Pose forward(const Arm6Joints& q) const;
  // Geometric Jacobian in the work frame: rows 0-2 the TCP velocity (mm/s per rad/s), rows 3-5
  // the tool's angular velocity
  Jacobian jacobian(const JointVector& joints) const override;
  Eigen::Matrix<double, 6, 6> jacobian(const Arm6Joints& q) const;
  // the exact solve of the square Jacobian (the roll rate is part of the angular velocity)
  JointVector joint_velocity(const JointVector& joints, const PoseRate& rate) const override;

  // TCP per-axis limits for moves with the nozzle vertical, configured branch, roll 0. At the
  // box's corners and centre (and a grid point every 40 mm or less along a longer side, up to
  // 6 per axis) the joint rates of a TCP velocity v are q' = G v, G the first three columns of
  // J^-1, so |q'_j| <= sum_i |G_ji| V_i; the accelerations q'' = G a - J^-1 (J'q')(G v), whose
  // second (centripetal) part is a quadratic form in v with coefficients C_jkl from the
  // Jacobian's rate (closed form, polarised), so |q''_j| <= sum_i |G_ji| A_i +
  // sum_kl |C_jkl| V_k V_l. The largest |G|, |C| over the samples are used. Velocities are
  // scaled first so that every joint keeps within limit_margin of its speed and the
  // centripetal part within half of its acceleration; accelerations take the rest. Never
  // looser than `requested`. About 35 us for a 10 mm box, 200 us for a 150 x 130 x 40 mm one.
  MachineLimits cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                 const Vec3& hi) const override;
  // scenario `limits: {joint: {v_max, a_max}}` in deg/s and deg/s^2 on every joint; a joint
  // j_max is refused (the Cartesian mapping bounds speed and acceleration only)
  std::string set_joint_limits(const AxisLimits& limits) override;

  // every solution within the joint ranges (all branches and turns of joint 6), sorted by
  // branch; returns the count. No allocation.
  int solutions(const Pose& pose, Arm6Solutions& out) const;
  // the eight branch solutions (joint 6 nearest 0, ranges not checked); false when the pose is
  // out of reach or not finite. No allocation: the benchmarked hot path.
  bool branch_solutions(const Pose& pose, Arm6Branches& out) const;
  // whether a nozzle tip at this work-frame point is below the table's top (z = 0, where the
  // part stands; kWorkSurfaceTolerance_mm of rounding allowed). The kinematics do not refuse
  // such a pose (a plan's transition may graze the table: the simulation counts contacts);
  // the toolpath's points are checked with it (posture/arm_posture.cpp)
  bool below_table(const Vec3& tip_mm) const;
  // the branch (bits above) of a joint position
  int branch_of(const JointVector& joints) const;
  int branch_of(const Arm6Joints& q) const;
  // the branch inverse() returns; throws std::out_of_range outside 0..7
  void set_branch(int branch);
  int branch() const { return branch_; }

  // Singularity and limit measures for the pipeline to judge a posture:
  // Yoshikawa's manipulability sqrt(det(J J^T)) = |det J| with the linear rows in m/s per
  // rad/s (so that they weigh like the angular rows); 0 at any singularity
  double manipulability(const JointVector& joints) const;
  // distance of the wrist centre from the joint 1 axis (mm): 0 at the shoulder singularity
  double wrist_centre_offset_mm(const JointVector& joints) const;
  // |sin q5|: 0 at the wrist singularity (joints 4 and 6 aligned)
  double wrist_alignment(const JointVector& joints) const;
  // the smallest distance of any joint to an end of its range (rad); negative outside
  double joint_margin_rad(const JointVector& joints) const;

  // Link frames in the work frame (mm): 0 the base, 1..6 the moving links (the MJCF bodies
  // link1..link6, origins as in the chain above), 7 the flange (the MJCF body `tool`).
  std::vector<Eigen::Isometry3d> link_frames(const JointVector& joints) const;
  // The MJCF collision geoms of links 2..6 and of the tool, by link_frames index, without the
  // last 3 mm of the nozzle (which touches the part by design)
  const std::vector<CollisionShape>& collision_shapes() const { return collision_shapes_; }

  const Arm6Geometry& geometry() const { return geometry_; }
  // flange -> TCP (mm)
  const Eigen::Isometry3d& tool_transform() const { return tool_; }
  // the work frame in the base frame (mm)
  const Eigen::Isometry3d& work_in_base() const { return work_in_base_; }
  // base-frame flange and wrist centre of a joint position (mm)
  Eigen::Isometry3d flange_in_base(const Arm6Joints& q) const;
  Vec3 wrist_centre_in_base(const Arm6Joints& q) const;

 private:
  // the eight branches of a base-frame flange pose; q1_hint at the shoulder singularity,
  // q4_hint at the wrist singularity. False when out of reach; `distance_mm` is the wrist
  // centre's distance from the shoulder in the arm's plane.
  bool solve_flange(const Eigen::Matrix3d& rotation, const Vec3& position, double q1_hint,
                    double q4_hint, Arm6Branches& out, double* distance_mm) const;
  // base-frame flange of a work-frame pose (the pose must be finite with a unit axis)
  void flange_of(const Pose& pose, Eigen::Matrix3d& rotation, Vec3& position) const;
  // the eight branches of a work-frame pose (hints as in solve_flange); false, with why
  // (bad pose or out of reach) when there are none
  bool solve_pose(const Pose& pose, double q1_hint, double q4_hint, Arm6Branches& branches,
                  std::string* why) const;
  // "" when the pose is finite with a unit axis, else why not
  std::string pose_problem(const Pose& pose) const;
  std::string reach_problem(double distance_mm) const;
  // the first joint of q outside its range ("" when none), joint 6 as given
  std::string range_problem(const Arm6Joints& q) const;
  // why no branch is within the ranges: the first joint outside on each
  std::string every_branch_problem(const Arm6Branches& branches) const;
  bool in_range(const Arm6Joints& q) const;

  Arm6Geometry geometry_;
  std::vector<JointLimit> joint_limits_;
  std::vector<CollisionShape> collision_shapes_;
  Eigen::Isometry3d tool_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d tool_inverse_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d work_in_base_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d base_in_work_ = Eigen::Isometry3d::Identity();
  double forearm_mm_ = 0.0;     // L = sqrt(c3^2 + a2^2)
  double forearm_angle_ = 0.0;  // psi = atan2(a2, c3)
  int branch_ = 0;
};

std::unique_ptr<Machine> make_arm6();

}  // namespace depotwin
