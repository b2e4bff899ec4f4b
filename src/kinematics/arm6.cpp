#include "kinematics/arm6.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/toolpath.hpp"

namespace depotwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kHalfPi = 0.5 * kPi;
// below this |sin q5| the wrist is treated as exactly singular (q4 + q6 alone is defined)
constexpr double kWristSingular = 1e-12;
// below this distance (mm) of the wrist centre from the joint 1 axis, q1 is free
constexpr double kShoulderSingular_mm = 1e-9;
// a wrist centre this far (mm) outside the arm's annulus still counts as reached (rounding)
constexpr double kReachTolerance_mm = 1e-9;

// IRB 120 datasheet: ranges (deg), speeds (deg/s); accelerations 4 x v_max per second
struct JointSpec {
  const char* name;
  double min_deg, max_deg, v_max_deg_s;
};
constexpr JointSpec kJoints[6] = {{"j1", -165.0, 165.0, 250.0}, {"j2", -110.0, 110.0, 250.0},
                                  {"j3", -110.0, 70.0, 250.0},  {"j4", -160.0, 160.0, 320.0},
                                  {"j5", -120.0, 120.0, 320.0}, {"j6", -400.0, 400.0, 420.0}};
constexpr double kAccelerationPerSpeed_per_s = 4.0;

// the head of models/arm6.xml: a cylinder on the flange axis from the flange face, and the
// nozzle's collision cylinders (without the free tip: a 45 deg tilted nozzle on the surface
// keeps the thin end's rim 1 mm above it)
constexpr double kHeadLength_mm = 65.0;      // the head's end face in the flange frame
constexpr double kNozzleRadius_mm = 4.0;     // the stem
constexpr double kNozzleTipRadius_mm = 1.5;  // the thin end, up to kNozzleTipLength_mm
constexpr double kNozzleTipLength_mm = 15.0;
constexpr double kNozzleFreeTip_mm = 3.0;  // not a collision shape: it touches the part

const char* const kShoulderNames[2] = {"shoulder front", "shoulder back"};
const char* const kElbowNames[2] = {"elbow up", "elbow down"};
const char* const kWristNames[2] = {"wrist not flipped", "wrist flipped"};

double wrap(double angle) {
  return std::remainder(angle, kTwoPi);
}

// wrap for angles within (-3 pi, 3 pi] (sums and differences of atan2 results): the IK's hot
// path, where std::remainder cost a fifth of the time
double wrap_near(double angle) {
  if (angle > kPi) return angle - kTwoPi;
  if (angle <= -kPi) return angle + kTwoPi;
  return angle;
}

Eigen::Matrix3d rot_x(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}
Eigen::Matrix3d rot_y(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}
Eigen::Matrix3d rot_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string branch_name(int branch) {
  return std::string("branch ") + std::to_string(branch) + " (" + kShoulderNames[branch & 1] +
         ", " + kElbowNames[(branch >> 1) & 1] + ", " + kWristNames[(branch >> 2) & 1] + ")";
}

bool to_joints(const JointVector& joints, Arm6Joints& q) {
  if (joints.size() != 6) return false;
  std::copy(joints.begin(), joints.end(), q.begin());
  return true;
}

// The collision geoms of models/arm6.xml (links 2..6 and the tool), in mm and their body's
// frame; a cylinder or capsule along its local z turned by `turn_deg` about the body axis
// `turn_axis` (0 x, 1 y, 2 z), as the MJCF's single-axis `euler` does.
struct GeomSpec {
  const char* name;
  int link;
  CollisionShape::Type type;
  double size[3];
  double pos[3];
  int turn_axis;
  double turn_deg;
};

}  // namespace

Arm6::Arm6(const Arm6Geometry& geometry) : geometry_(geometry) {
  for (const JointSpec& spec : kJoints) {
    const double v_max = deg_to_rad(spec.v_max_deg_s);
    joint_limits_.push_back(JointLimit{spec.name, deg_to_rad(spec.min_deg),
                                       deg_to_rad(spec.max_deg), v_max,
                                       kAccelerationPerSpeed_per_s * v_max});
    joint_limits_.back().revolute = true;
  }
  const Arm6Geometry& g = geometry_;
  forearm_mm_ = std::hypot(g.c3_mm, g.a2_mm);
  forearm_angle_ = std::atan2(g.a2_mm, g.c3_mm);
  tool_.linear() = rot_y(kPi - deg_to_rad(g.nozzle_tilt_deg));
  tool_.translation() = g.tip_in_flange_mm;
  tool_inverse_ = tool_.inverse(Eigen::Isometry);
  work_in_base_.translation() = g.work_origin_mm;
  base_in_work_ = work_in_base_.inverse(Eigen::Isometry);

  // models/arm6.xml's collision geoms (keep both in step: tests/models/test_arm6_model.cpp)
  using Type = CollisionShape::Type;
  const GeomSpec specs[] = {
      {"link2_arm", 2, Type::box, {40, 50, 100}, {0, 0, 135}, 2, 0},
      {"link2_elbow", 2, Type::cylinder, {60, 60, 0}, {0, 0, 270}, 0, 90},
      {"link3_housing", 3, Type::box, {60, 55, 55}, {0, 0, 45}, 2, 0},
      {"link3_motor", 3, Type::cylinder, {45, 70, 0}, {0, 0, 70}, 1, 90},
      {"link4_tube", 4, Type::cylinder, {40, 70, 0}, {-130, 0, 0}, 1, 90},
      {"link4_fork", 4, Type::box, {25, 45, 32}, {-48, 0, 0}, 2, 0},
      {"link5_housing", 5, Type::cylinder, {33, 34, 0}, {0, 0, 0}, 0, 90},
      {"link5_nose", 5, Type::cylinder, {30, 25, 0}, {30, 0, 0}, 1, 90},
      {"link6_flange", 6, Type::cylinder, {20, 8.5, 0}, {63.5, 0, 0}, 1, 90},
      {"tool_body", 7, Type::cylinder, {30, 32.5, 0}, {0, 0, 32.5}, 2, 0},  // r 30, 65 long
  };
  for (const GeomSpec& spec : specs) {
    CollisionShape shape;
    shape.name = spec.name;
    shape.link = spec.link;
    shape.type = spec.type;
    shape.size_mm = Vec3(spec.size[0], spec.size[1], spec.size[2]);
    shape.in_link.translation() = Vec3(spec.pos[0], spec.pos[1], spec.pos[2]);
    shape.in_link.linear() =
        Eigen::AngleAxisd(deg_to_rad(spec.turn_deg), Vec3::Unit(spec.turn_axis)).toRotationMatrix();
    collision_shapes_.push_back(shape);
  }
  // the nozzle along the tool axis from the tip: a thin end (3 .. 15 mm: the last 3 mm touch
  // the part by design and are left out) and the wider stem up to the head's end face
  const Vec3 nozzle_axis = tool_.linear().col(2);  // from the tip up into the head
  const double stem_top_mm =
      (g.tip_in_flange_mm.z() - kHeadLength_mm) / std::cos(deg_to_rad(g.nozzle_tilt_deg));
  const auto nozzle_part = [&](const char* name, double radius_mm, double from_mm, double to_mm) {
    CollisionShape part;
    part.name = name;
    part.link = 7;
    part.type = Type::cylinder;
    part.size_mm = Vec3(radius_mm, 0.5 * (to_mm - from_mm), 0.0);
    part.in_link.translation() = g.tip_in_flange_mm + 0.5 * (from_mm + to_mm) * nozzle_axis;
    part.in_link.linear() = tool_.linear();
    collision_shapes_.push_back(part);
  };
  nozzle_part("tool_nozzle_tip", kNozzleTipRadius_mm, kNozzleFreeTip_mm, kNozzleTipLength_mm);
  nozzle_part("tool_nozzle", kNozzleRadius_mm, kNozzleTipLength_mm, stem_top_mm);
}

void Arm6::set_branch(int branch) {
  if (branch < 0 || branch > 7)
    throw std::out_of_range("arm6 branch " + std::to_string(branch) + " is not in 0..7");
  branch_ = branch;
}

// ---------------------------------------------------------------------------------------------
// forward kinematics

Eigen::Isometry3d Arm6::flange_in_base(const Arm6Joints& q) const {
  const Arm6Geometry& g = geometry_;
  const Eigen::Matrix3d r03 = rot_z(q[0]) * rot_y(q[1] + q[2]);
  const Eigen::Matrix3d r06 = r03 * rot_x(q[3]) * rot_y(q[4]) * rot_x(q[5]);
  Eigen::Isometry3d flange = Eigen::Isometry3d::Identity();
  // tool0 = link 6 turned 90 deg about y: z = link 6's x, y = its y, x = -its z
  flange.linear().col(0) = -r06.col(2);
  flange.linear().col(1) = r06.col(1);
  flange.linear().col(2) = r06.col(0);
  flange.translation() = wrist_centre_in_base(q) + g.c4_mm * r06.col(0);
  return flange;
}

Vec3 Arm6::wrist_centre_in_base(const Arm6Joints& q) const {
  const Arm6Geometry& g = geometry_;
  const double q23 = q[1] + q[2];
  // in the arm's plane: r along the joint 1 direction, z up
  const double r = g.c2_mm * std::sin(q[1]) + g.c3_mm * std::cos(q23) + g.a2_mm * std::sin(q23);
  const double z =
      g.c1_mm + g.c2_mm * std::cos(q[1]) - g.c3_mm * std::sin(q23) + g.a2_mm * std::cos(q23);
  return Vec3(r * std::cos(q[0]), r * std::sin(q[0]), z);
}

Pose Arm6::forward(const Arm6Joints& q) const {
  const Eigen::Isometry3d tcp = base_in_work_ * flange_in_base(q) * tool_;
  const Eigen::Matrix3d frame = tcp.linear();
  return Pose(tcp.translation(), frame.col(2), roll_of_frame(frame));
}

Pose Arm6::forward(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return Pose(Vec3(kNaN, kNaN, kNaN), Vec3(kNaN, kNaN, kNaN), kNaN);
  return forward(q);
}

std::vector<Eigen::Isometry3d> Arm6::link_frames(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return {};
  const Arm6Geometry& g = geometry_;
  std::vector<Eigen::Isometry3d> frames(8, Eigen::Isometry3d::Identity());
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  frames[0] = t;
  t.linear() = rot_z(q[0]);
  frames[1] = t;
  t.translate(Vec3(0, 0, g.c1_mm));
  t.linear() = t.linear() * rot_y(q[1]);
  frames[2] = t;
  t.translate(Vec3(0, 0, g.c2_mm));
  t.linear() = t.linear() * rot_y(q[2]);
  frames[3] = t;
  t.translate(Vec3(g.c3_mm, 0, g.a2_mm));
  t.linear() = t.linear() * rot_x(q[3]);
  frames[4] = t;
  t.linear() = t.linear() * rot_y(q[4]);
  frames[5] = t;
  t.linear() = t.linear() * rot_x(q[5]);
  frames[6] = t;
  t.translate(Vec3(g.c4_mm, 0, 0));
  t.linear() = t.linear() * rot_y(kHalfPi);
  frames[7] = t;
  for (Eigen::Isometry3d& frame : frames) frame = base_in_work_ * frame;
  return frames;
}

Eigen::Matrix<double, 6, 6> Arm6::jacobian(const Arm6Joints& q) const {
  const Arm6Geometry& g = geometry_;
  const Eigen::Matrix3d r1 = rot_z(q[0]);
  const Eigen::Matrix3d r03 = r1 * rot_y(q[1] + q[2]);
  const Eigen::Matrix3d r04 = r03 * rot_x(q[3]);
  const Eigen::Matrix3d r05 = r04 * rot_y(q[4]);
  const Vec3 shoulder(0, 0, g.c1_mm);
  const Vec3 elbow = shoulder + r1 * rot_y(q[1]) * Vec3(0, 0, g.c2_mm);
  const Vec3 wrist = wrist_centre_in_base(q);
  const Vec3 tcp = (flange_in_base(q) * tool_).translation();
  const std::array<Vec3, 6> axis{Vec3::UnitZ(), r1.col(1),  r1.col(1),
                                 r03.col(0),    r04.col(1), r05.col(0)};
  const std::array<Vec3, 6> origin{Vec3::Zero(), shoulder, elbow, wrist, wrist, wrist};
  const Eigen::Matrix3d to_work = base_in_work_.linear();
  Eigen::Matrix<double, 6, 6> j;
  for (int i = 0; i < 6; ++i) {
    j.block<3, 1>(0, i) = to_work * axis[i].cross(tcp - origin[i]);
    j.block<3, 1>(3, i) = to_work * axis[i];
  }
  return j;
}

Jacobian Arm6::jacobian(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return Jacobian::Constant(6, 6, kNaN);
  return jacobian(q);
}

JointVector Arm6::joint_velocity(const JointVector& joints, const PoseRate& rate) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return JointVector(6, kNaN);
  Eigen::Matrix<double, 6, 1> task;
  task << rate.linear_mm_s, rate.angular_rad_s;
  const Eigen::Matrix<double, 6, 1> q_rate = jacobian(q).partialPivLu().solve(task);
  return JointVector(q_rate.data(), q_rate.data() + 6);
}

// ---------------------------------------------------------------------------------------------
// inverse kinematics

void Arm6::flange_of(const Pose& pose, Eigen::Matrix3d& rotation, Vec3& position) const {
  const Eigen::Matrix3d tcp_rotation =
      work_in_base_.linear() * tool_frame(pose.tool_axis, pose.roll_rad);
  const Vec3 tcp_position = work_in_base_ * pose.position_mm;
  // T_base_flange = T_base_tcp T_tool^-1
  rotation = tcp_rotation * tool_inverse_.linear();
  position = tcp_position + tcp_rotation * tool_inverse_.translation();
}

bool Arm6::solve_flange(const Eigen::Matrix3d& rotation, const Vec3& position, double q1_hint,
                        double q4_hint, Arm6Branches& out, double* distance_mm) const {
  const Arm6Geometry& g = geometry_;
  // link 6's frame: x the flange normal, y the flange's y, z minus the flange's x
  const Vec3 normal = rotation.col(2);
  const Vec3 link6_y = rotation.col(1);
  const Vec3 centre = position - g.c4_mm * normal;

  // shoulder: q1 along the wrist centre (free on the joint 1 axis: the hint)
  const double radial = std::sqrt(centre.x() * centre.x() + centre.y() * centre.y());
  double q1_front, c1, s1;
  if (radial > kShoulderSingular_mm) {
    q1_front = std::atan2(centre.y(), centre.x());
    c1 = centre.x() / radial;
    s1 = centre.y() / radial;
  } else {
    q1_front = wrap(q1_hint);
    c1 = std::cos(q1_front);
    s1 = std::sin(q1_front);
  }
  const double r = c1 * centre.x() + s1 * centre.y();
  const double h = centre.z() - g.c1_mm;

  // elbow: the triangle upper arm c2, effective forearm L, shoulder to wrist centre d
  const double c2 = g.c2_mm, l = forearm_mm_;
  const double s = r * r + h * h;
  const double distance = std::sqrt(s);
  if (distance_mm) *distance_mm = distance;
  if (!(distance <= c2 + l + kReachTolerance_mm) ||
      !(distance >= std::abs(c2 - l) - kReachTolerance_mm))
    return false;
  const double outer = std::max(0.0, (c2 + l) * (c2 + l) - s);
  const double inner = std::max(0.0, s - (c2 - l) * (c2 - l));
  // gamma's cosine and sine times 2 c2 L (the sine exact near the stretched arm)
  const double cos_gamma_2c2l = s - c2 * c2 - l * l, sin_gamma_2c2l = std::sqrt(outer * inner);
  const double gamma = std::atan2(sin_gamma_2c2l, cos_gamma_2c2l);
  // alpha = atan2(r, h), the wrist centre seen from the shoulder; beta = atan2(L sin gamma,
  // c2 + L cos gamma), the upper arm's angle from it, whose vector has length d
  const double alpha = std::atan2(r, h);
  const double l_cos_gamma = cos_gamma_2c2l / (2.0 * c2), l_sin_gamma = sin_gamma_2c2l / (2.0 * c2);
  const double beta = std::atan2(l_sin_gamma, c2 + l_cos_gamma);
  const double cos_alpha = h / distance, sin_alpha = r / distance;
  const double cos_beta = (c2 + l_cos_gamma) / distance, sin_beta = l_sin_gamma / distance;
  const double cos_gamma = l_cos_gamma / l, sin_gamma = l_sin_gamma / l;
  const double cos_psi = g.c3_mm / l, sin_psi = g.a2_mm / l;

  for (int arm = 0; arm < 4; ++arm) {
    const bool back = arm & 1, down = arm & 2;
    // the back shoulder mirrors r (alpha), the lower elbow gamma (and so beta)
    const double sign_a = back ? -1.0 : 1.0, sign_g = down ? -1.0 : 1.0;
    const double q1 = back ? wrap_near(q1_front + kPi) : q1_front;
    const double q3 = wrap_near(sign_g * gamma + forearm_angle_ - kHalfPi);
    const double q2 = wrap_near(sign_a * alpha - sign_g * beta);
    // cos and sin of q2 + q3 from those of alpha, beta, gamma and psi (no trigonometry):
    // q3 = gamma' + psi - 90 deg, q2 = alpha' - beta'
    const double cos3 = sign_g * sin_gamma * cos_psi + cos_gamma * sin_psi;
    const double sin3 = sign_g * sin_gamma * sin_psi - cos_gamma * cos_psi;
    const double cos2 = cos_alpha * cos_beta + sign_a * sign_g * sin_alpha * sin_beta;
    const double sin2 = sign_a * sin_alpha * cos_beta - sign_g * cos_alpha * sin_beta;
    const double c23 = cos2 * cos3 - sin2 * sin3, s23 = sin2 * cos3 + cos2 * sin3;

    // wrist: M = R03^T R06 = Rx(q4) Ry(q5) Rx(q6)
    const double ca = back ? -c1 : c1, sa = back ? -s1 : s1;
    const Vec3 x3(ca * c23, sa * c23, -s23), y3(-sa, ca, 0.0), z3(ca * s23, sa * s23, c23);
    const double m00 = x3.dot(normal), m10 = y3.dot(normal), m20 = z3.dot(normal);
    const double m01 = x3.dot(link6_y), m11 = y3.dot(link6_y), m21 = z3.dot(link6_y);
    // q5 and q4 from the flange normal (M's first column); q4 free at q5 = 0 or pi
    const double sin5 = std::sqrt(m10 * m10 + m20 * m20);
    const double q5 = std::atan2(sin5, m00);
    double q4, c4, s4;
    if (sin5 > kWristSingular) {
      q4 = std::atan2(m10, -m20);
      c4 = -m20 / sin5;
      s4 = m10 / sin5;
    } else {
      q4 = wrap(q4_hint);
      c4 = std::cos(q4);
      s4 = std::sin(q4);
    }
    // q6 from what Rx(q4) Ry(q5) leaves of M's second column, so that the three reproduce M
    // to rounding even where q4 alone is ill-conditioned (near q5 = 0); M's first column is a
    // unit vector, so cos q5 = m00 and sin q5 = sin5 to rounding
    const double c5 = m00;
    const double q6 = std::atan2(sin5 * m01 - s4 * c5 * m11 + c4 * c5 * m21, c4 * m11 + s4 * m21);
    Arm6Joints& plain = out[arm];
    plain = {q1, q2, q3, q4, q5, q6};
    Arm6Joints& flipped = out[arm + 4];
    if (sin5 > kWristSingular)
      flipped = {q1, q2, q3, wrap_near(q4 + kPi), -q5, wrap_near(q6 + kPi)};
    else
      flipped = plain;
  }
  return true;
}

bool Arm6::branch_solutions(const Pose& pose, Arm6Branches& out) const {
  if (!pose.position_mm.allFinite() || !pose.tool_axis.allFinite() || !std::isfinite(pose.roll_rad))
    return false;
  Eigen::Matrix3d rotation;
  Vec3 position;
  flange_of(pose, rotation, position);
  return solve_flange(rotation, position, 0.0, 0.0, out, nullptr);
}

bool Arm6::in_range(const Arm6Joints& q) const {
  for (int j = 0; j < 6; ++j)
    if (!(q[j] >= joint_limits_[j].min && q[j] <= joint_limits_[j].max)) return false;
  return true;
}

std::string Arm6::range_problem(const Arm6Joints& q) const {
  for (int j = 0; j < 6; ++j) {
    const JointLimit& limit = joint_limits_[j];
    if (q[j] >= limit.min && q[j] <= limit.max) continue;
    return "joint " + limit.name + " would be at " + format("%.2f", rad_to_deg(q[j])) +
           " deg, outside its range [" + format("%.0f", rad_to_deg(limit.min)) + ", " +
           format("%.0f", rad_to_deg(limit.max)) + "] deg";
  }
  return "";
}

std::string Arm6::pose_problem(const Pose& pose) const {
  if (!pose.position_mm.allFinite()) return "the TCP position is not finite";
  if (!pose.tool_axis.allFinite()) return "the tool axis is not finite";
  if (!std::isfinite(pose.roll_rad)) return "the roll about the tool axis is not finite";
  const double norm = pose.tool_axis.norm();
  if (std::abs(norm - 1.0) > 1e-9)
    return "the tool axis (" + format("%.6g", pose.tool_axis.x()) + ", " +
           format("%.6g", pose.tool_axis.y()) + ", " + format("%.6g", pose.tool_axis.z()) +
           ") is not a unit vector (length " + format("%.6g", norm) + ")";
  return "";
}

bool Arm6::below_table(const Vec3& tip_mm) const {
  // the work frame's z = 0 is the table's top: a nozzle tip below it is inside the table
  return tip_mm.z() < -kWorkSurfaceTolerance_mm;
}

std::string Arm6::reach_problem(double distance_mm) const {
  const double outer = geometry_.c2_mm + forearm_mm_;
  const double inner = std::abs(geometry_.c2_mm - forearm_mm_);
  if (distance_mm > outer)
    return "out of reach: the wrist centre would be " + format("%.1f", distance_mm) +
           " mm from the shoulder (joint 2 axis), " + format("%.1f", distance_mm - outer) +
           " mm beyond the arm's reach of " + format("%.1f", outer) + " mm";
  return "out of reach: the wrist centre would be " + format("%.2f", distance_mm) +
         " mm from the shoulder (joint 2 axis), " + format("%.2f", inner - distance_mm) +
         " mm inside the arm's smallest reach of " + format("%.2f", inner) + " mm";
}

bool Arm6::solve_pose(const Pose& pose, double q1_hint, double q4_hint, Arm6Branches& branches,
                      std::string* why) const {
  std::string problem = pose_problem(pose);
  if (problem.empty()) {
    Eigen::Matrix3d rotation;
    Vec3 position;
    flange_of(pose, rotation, position);
    double distance_mm = 0.0;
    if (solve_flange(rotation, position, q1_hint, q4_hint, branches, &distance_mm)) return true;
    problem = reach_problem(distance_mm);
  }
  if (why) *why = problem;
  return false;
}

bool Arm6::inverse(const Pose& pose, JointVector& joints, std::string* why) const {
  const auto fail = [why](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  Arm6Branches branches;
  if (!solve_pose(pose, 0.0, 0.0, branches, why)) return false;
  const Arm6Joints& q = branches[branch_];
  if (in_range(q)) {
    joints.assign(q.begin(), q.end());
    return true;
  }
  if (!why) return false;
  std::string others;
  for (int b = 0; b < 8; ++b)
    if (b != branch_ && in_range(branches[b]))
      others += (others.empty() ? "" : ", ") + std::to_string(b);
  if (!others.empty())
    return fail(
        range_problem(q) + " on the configured " + branch_name(branch_) + "; " +
        (others.size() > 1 ? "branches " + others + " reach" : "branch " + others + " reaches") +
        " this pose");
  return fail(every_branch_problem(branches));
}

std::string Arm6::every_branch_problem(const Arm6Branches& branches) const {
  std::string reason = "no branch reaches this pose within the joint ranges: ";
  for (int b = 0; b < 8; ++b)
    reason += (b ? "; branch " : "branch ") + std::to_string(b) +
              (b == branch_ ? " (configured): " : ": ") + range_problem(branches[b]);
  return reason;
}

bool Arm6::inverse_near(const Pose& pose, const JointVector& seed, JointVector& joints,
                        std::string* why) const {
  if (seed.size() != 6 ||
      !std::all_of(seed.begin(), seed.end(), [](double v) { return std::isfinite(v); }))
    return inverse(pose, joints, why);
  Arm6Branches branches;
  if (!solve_pose(pose, seed[0], seed[3], branches, why)) return false;
  const JointLimit& limit6 = joint_limits_[5];
  double best = std::numeric_limits<double>::infinity();
  int best_branch = -1;
  double best_q6 = 0.0;
  for (int b = 0; b < 8; ++b) {
    const Arm6Joints& q = branches[b];
    double distance = 0.0;
    bool inside = true;
    for (int j = 0; j < 5 && inside; ++j) {
      inside = q[j] >= joint_limits_[j].min && q[j] <= joint_limits_[j].max;
      distance += (q[j] - seed[j]) * (q[j] - seed[j]);
    }
    if (!inside) continue;
    // joint 6: the turn nearest to the seed within its range
    const double turns = std::round((seed[5] - q[5]) / kTwoPi);
    for (double k = turns - 1.0; k <= turns + 1.0; k += 1.0) {
      const double q6 = q[5] + k * kTwoPi;
      if (q6 < limit6.min || q6 > limit6.max) continue;
      const double total = distance + (q6 - seed[5]) * (q6 - seed[5]);
      if (total < best) {
        best = total;
        best_branch = b;
        best_q6 = q6;
      }
    }
  }
  if (best_branch < 0) {
    if (why) *why = every_branch_problem(branches);
    return false;
  }
  const Arm6Joints& q = branches[best_branch];
  joints.assign(q.begin(), q.end());
  joints[5] = best_q6;
  return true;
}

int Arm6::solutions(const Pose& pose, Arm6Solutions& out) const {
  if (!pose_problem(pose).empty()) return 0;
  Arm6Branches branches;
  if (!branch_solutions(pose, branches)) return 0;
  const JointLimit& limit6 = joint_limits_[5];
  int count = 0;
  for (int b = 0; b < 8; ++b) {
    Arm6Joints q = branches[b];
    q[5] = 0.0;
    if (!in_range(q)) continue;
    for (int k = -2; k <= 2; ++k) {
      const double q6 = branches[b][5] + k * kTwoPi;
      if (q6 < limit6.min || q6 > limit6.max) continue;
      q[5] = q6;
      out[count].q = q;
      out[count].branch = b;
      ++count;
    }
  }
  return count;
}

int Arm6::branch_of(const Arm6Joints& q) const {
  const Arm6Geometry& g = geometry_;
  const double q23 = q[1] + q[2];
  const double r = g.c2_mm * std::sin(q[1]) + g.c3_mm * std::cos(q23) + g.a2_mm * std::sin(q23);
  const double gamma = wrap(q[2] - forearm_angle_ + kHalfPi);
  return (r < 0.0 ? 1 : 0) | (gamma < 0.0 ? 2 : 0) | (q[4] < 0.0 ? 4 : 0);
}

int Arm6::branch_of(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return -1;
  return branch_of(q);
}

// ---------------------------------------------------------------------------------------------
// measures

double Arm6::manipulability(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return kNaN;
  Eigen::Matrix<double, 6, 6> j = jacobian(q);
  j.topRows<3>() *= mm_to_m(1.0);  // m/s per rad/s
  // square: sqrt(det(J J^T)) = |det J|
  return std::abs(j.determinant());
}

double Arm6::wrist_centre_offset_mm(const JointVector& joints) const {
  Arm6Joints q;
  if (!to_joints(joints, q)) return kNaN;
  return wrist_centre_in_base(q).head<2>().norm();
}

double Arm6::wrist_alignment(const JointVector& joints) const {
  if (joints.size() != 6) return kNaN;
  return std::abs(std::sin(joints[4]));
}

double Arm6::joint_margin_rad(const JointVector& joints) const {
  if (joints.size() != 6) return kNaN;
  double margin = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 6; ++j)
    margin = std::min(margin,
                      std::min(joints[j] - joint_limits_[j].min, joint_limits_[j].max - joints[j]));
  return margin;
}

// ---------------------------------------------------------------------------------------------
// limits

std::string Arm6::set_joint_limits(const AxisLimits& limits) {
  if (limits.j_max_mm_s3 > 0.0)
    return "a joint j_max is not supported on the arm6 (its TCP limits bound joint speed and "
           "acceleration only); set the TCP's limits.j_max instead";
  if (!(limits.v_max_mm_s > 0.0) || !(limits.a_max_mm_s2 > 0.0) ||
      !std::isfinite(limits.v_max_mm_s) || !std::isfinite(limits.a_max_mm_s2))
    return "the arm6's joint v_max (deg/s) and a_max (deg/s^2) must be positive numbers";
  for (JointLimit& limit : joint_limits_) {
    limit.v_max = deg_to_rad(limits.v_max_mm_s);
    limit.a_max = deg_to_rad(limits.a_max_mm_s2);
    limit.j_max = 0.0;
  }
  return "";
}

namespace {

// J'q' of the geometric Jacobian at zero joint acceleration: the TCP's acceleration and the
// tool's angular acceleration from the joint rates alone (base frame). Axis i rides on link
// i - 1, whose angular velocity is w_(i-1) = sum_(k<i) a_k q'_k; the point o_i moves with
// link i - 1 too.
Eigen::Matrix<double, 6, 1> velocity_product(const std::array<Vec3, 6>& axis,
                                             const std::array<Vec3, 6>& origin, const Vec3& tcp,
                                             const Eigen::Matrix<double, 6, 1>& rate) {
  Vec3 omega = Vec3::Zero();  // angular velocity of the link carrying axis i
  Vec3 tcp_velocity = Vec3::Zero();
  for (int i = 0; i < 6; ++i) tcp_velocity += rate[i] * axis[i].cross(tcp - origin[i]);
  Vec3 linear = Vec3::Zero(), angular = Vec3::Zero();
  for (int i = 0; i < 6; ++i) {
    // velocity of the point o_i (on link i - 1)
    Vec3 origin_velocity = Vec3::Zero();
    for (int k = 0; k < i; ++k) origin_velocity += rate[k] * axis[k].cross(origin[i] - origin[k]);
    const Vec3 axis_rate = omega.cross(axis[i]);
    linear += rate[i] *
              (axis_rate.cross(tcp - origin[i]) + axis[i].cross(tcp_velocity - origin_velocity));
    angular += rate[i] * axis_rate;
    omega += rate[i] * axis[i];
  }
  Eigen::Matrix<double, 6, 1> product;
  product << linear, angular;
  return product;
}

}  // namespace

MachineLimits Arm6::cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                     const Vec3& hi) const {
  const Arm6Geometry& g = geometry_;
  Vec3 velocity, acceleration;
  for (int axis = 0; axis < 3; ++axis) {
    velocity[axis] = requested.axes[axis].v_max_mm_s;
    acceleration[axis] = requested.axes[axis].a_max_mm_s2;
  }

  // per joint: the worst velocity gain sum_i |G_ji| V_i / v_max, acceleration gain
  // sum_i |G_ji| A_i, centripetal coefficients sum |C_jkl| per (k, l) over the samples
  std::array<Eigen::Matrix<double, 3, 1>, 6> gain_worst;
  std::array<Eigen::Matrix3d, 6> centripetal_worst;
  for (int j = 0; j < 6; ++j) {
    gain_worst[j].setZero();
    centripetal_worst[j].setZero();
  }
  // a grid over the box: corners and centre, and a point every 40 mm or less along an axis
  constexpr double kGridStep_mm = 40.0;
  std::array<int, 3> count;
  for (int axis = 0; axis < 3; ++axis)
    count[axis] = std::clamp(
        static_cast<int>(std::ceil(std::abs(hi[axis] - lo[axis]) / kGridStep_mm)) + 1, 2, 6);
  const Vec3 centre = 0.5 * (lo + hi);
  int sampled = 0;
  const int grid = count[0] * count[1] * count[2];
  for (int index = 0; index <= grid; ++index) {
    Vec3 point = centre;
    if (index < grid) {
      const int ijk[3] = {index % count[0], (index / count[0]) % count[1],
                          index / (count[0] * count[1])};
      for (int axis = 0; axis < 3; ++axis)
        point[axis] = lo[axis] + (hi[axis] - lo[axis]) * ijk[axis] / (count[axis] - 1);
    }
    Eigen::Matrix3d rotation;
    Vec3 position;
    flange_of(Pose(point), rotation, position);
    Arm6Branches branches;
    if (!solve_flange(rotation, position, 0.0, 0.0, branches, nullptr)) continue;
    const Arm6Joints& q = branches[branch_];
    const Eigen::Matrix<double, 6, 6> jac = jacobian(q);  // work frame
    const Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> lu(jac);
    const Eigen::Matrix<double, 6, 6> inverse = lu.inverse();
    if (!inverse.allFinite()) continue;
    const Eigen::Matrix<double, 6, 3> g_map = inverse.leftCols<3>();

    // the axes of the chain (base frame) for J'q'; TCP velocity directions in the work frame
    // map to base-frame joint rates identically (joint rates have no frame)
    const Eigen::Matrix3d r1 = rot_z(q[0]);
    const Eigen::Matrix3d r03 = r1 * rot_y(q[1] + q[2]);
    const Eigen::Matrix3d r04 = r03 * rot_x(q[3]);
    const Eigen::Matrix3d r05 = r04 * rot_y(q[4]);
    const Vec3 shoulder(0, 0, g.c1_mm);
    const Vec3 wrist = wrist_centre_in_base(q);
    const std::array<Vec3, 6> axes{Vec3::UnitZ(), r1.col(1),  r1.col(1),
                                   r03.col(0),    r04.col(1), r05.col(0)};
    const std::array<Vec3, 6> origins{
        Vec3::Zero(), shoulder, shoulder + r1 * rot_y(q[1]) * Vec3(0, 0, g.c2_mm),
        wrist,        wrist,    wrist};
    const Vec3 tcp = (flange_in_base(q) * tool_).translation();
    // q'' = G a - J^-1 (J'q')(G v): the quadratic form's coefficients by polarisation
    const Eigen::Matrix3d to_base = work_in_base_.linear();
    std::array<Eigen::Matrix<double, 6, 1>, 3> single;
    Eigen::Matrix<double, 6, 1> pair_term[3][3];
    for (int k = 0; k < 3; ++k) {
      Eigen::Matrix<double, 6, 1> product =
          velocity_product(axes, origins, tcp, g_map.col(k).eval());
      product.head<3>() = to_base.transpose() * product.head<3>().eval();
      product.tail<3>() = to_base.transpose() * product.tail<3>().eval();
      single[k] = -inverse * product;
    }
    for (int k = 0; k < 3; ++k) {
      pair_term[k][k] = single[k];
      for (int l = k + 1; l < 3; ++l) {
        Eigen::Matrix<double, 6, 1> product =
            velocity_product(axes, origins, tcp, (g_map.col(k) + g_map.col(l)).eval());
        product.head<3>() = to_base.transpose() * product.head<3>().eval();
        product.tail<3>() = to_base.transpose() * product.tail<3>().eval();
        // the symmetric coefficient of v_k v_l (each appears twice in the form)
        pair_term[k][l] = pair_term[l][k] = 0.5 * (-inverse * product - single[k] - single[l]);
      }
    }
    for (int j = 0; j < 6; ++j) {
      for (int i = 0; i < 3; ++i)
        gain_worst[j][i] = std::max(gain_worst[j][i], std::abs(g_map(j, i)));
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l)
          centripetal_worst[j](k, l) =
              std::max(centripetal_worst[j](k, l), std::abs(pair_term[k][l][j]));
    }
    ++sampled;
  }
  if (sampled == 0) return requested;  // nowhere reachable: inverse() will say why

  const double margin = g.limit_margin;
  const auto centripetal = [&](const Vec3& v, int j) { return v.dot(centripetal_worst[j] * v); };
  // velocities: every joint within margin of its speed, the centripetal part within half of
  // its acceleration
  for (int j = 0; j < 6; ++j) {
    const double rate = gain_worst[j].dot(velocity);
    const double allowed = margin * joint_limits_[j].v_max;
    if (rate > allowed) velocity *= allowed / rate;
  }
  for (int j = 0; j < 6; ++j) {
    const double term = centripetal(velocity, j);
    const double allowed = 0.5 * margin * joint_limits_[j].a_max;
    if (term > allowed) velocity *= std::sqrt(allowed / term);
  }
  // accelerations: the rest of each joint's budget
  for (int j = 0; j < 6; ++j) {
    const double budget = margin * joint_limits_[j].a_max - centripetal(velocity, j);
    const double demand = gain_worst[j].dot(acceleration);
    if (demand > budget) acceleration *= budget / demand;
  }

  MachineLimits limits = requested;
  for (int axis = 0; axis < 3; ++axis) {
    limits.axes[axis].v_max_mm_s = std::min(requested.axes[axis].v_max_mm_s, velocity[axis]);
    limits.axes[axis].a_max_mm_s2 = std::min(requested.axes[axis].a_max_mm_s2, acceleration[axis]);
  }
  return limits;
}

std::unique_ptr<Machine> make_arm6() {
  return std::make_unique<Arm6>();
}

}  // namespace depotwin
