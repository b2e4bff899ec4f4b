#include "kinematics/linear_delta.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/number_text.hpp"

namespace depotwin {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// horizontal position of arm i's effective column, D u_i (mm): the carriage joint
// minus the platform joint offset, so each arm acts on the platform centre p
Eigen::Vector2d column_point_mm(const LinearDeltaGeometry& geometry, int arm) {
  const double angle_rad = deg_to_rad(geometry.column_angle_deg[arm]);
  const double offset_mm = geometry.carriage_radius_mm - geometry.platform_radius_mm;
  return offset_mm * Eigen::Vector2d(std::cos(angle_rad), std::sin(angle_rad));
}

// the effective carriage point C_i = (D u_i, H + q_i)
Vec3 carriage_point_mm(const LinearDeltaGeometry& geometry, int arm, double joint_mm) {
  const Eigen::Vector2d column = column_point_mm(geometry, arm);
  return Vec3(column.x(), column.y(), geometry.home_carriage_height_mm() + joint_mm);
}

// q_i = p_z - sqrt(L^2 - |p_xy - D u_i|^2) - H, without the workspace check
double joint_for_platform_mm(const LinearDeltaGeometry& geometry, int arm,
                             const Vec3& platform_mm) {
  const double rod_mm = geometry.rod_length_mm;
  const double horizontal2_mm2 =
      (platform_mm.head<2>() - column_point_mm(geometry, arm)).squaredNorm();
  return platform_mm.z() - std::sqrt(rod_mm * rod_mm - horizontal2_mm2) -
         geometry.home_carriage_height_mm();
}

// largest horizontal distance from a column at which a rod stays within its angle limit
double max_reach_mm(const LinearDeltaGeometry& geometry) {
  return geometry.rod_length_mm * std::sin(deg_to_rad(geometry.max_rod_angle_deg));
}

// rod vectors w_i = p - C_i of the three arms at platform position p and carriage heights q
std::array<Vec3, 3> rod_vectors_mm(const LinearDeltaGeometry& geometry, const Vec3& platform_mm,
                                   const double* joints) {
  std::array<Vec3, 3> rods;
  for (int arm = 0; arm < 3; ++arm)
    rods[arm] = platform_mm - carriage_point_mm(geometry, arm, joints[arm]);
  return rods;
}

// Trilateration: the platform centre at distance L from the three effective carriage
// points, the solution above the carriages (the rods rise from the carriages). NaN when
// the spheres do not meet.
Vec3 trilaterate_mm(const LinearDeltaGeometry& geometry, const double* joints) {
  const double rod_mm = geometry.rod_length_mm;
  const Vec3 c1 = carriage_point_mm(geometry, 0, joints[0]);
  const Vec3 c2 = carriage_point_mm(geometry, 1, joints[1]);
  const Vec3 c3 = carriage_point_mm(geometry, 2, joints[2]);

  // local frame: ex along c1->c2, ey in the plane of the three points, ez normal to it
  const double d12_mm = (c2 - c1).norm();
  const Vec3 ex = (c2 - c1) / d12_mm;
  const double i_mm = ex.dot(c3 - c1);
  const Vec3 ey = (c3 - c1 - i_mm * ex).normalized();
  Vec3 ez = ex.cross(ey);
  if (ez.z() < 0.0) ez = -ez;  // the upper solution
  const double j_mm = ey.dot(c3 - c1);

  // equal sphere radii: x halfway between c1 and c2, y from the third sphere
  const double x_mm = 0.5 * d12_mm;
  const double y_mm = (0.5 * (i_mm * i_mm + j_mm * j_mm) - i_mm * x_mm) / j_mm;
  const double z2_mm2 = rod_mm * rod_mm - x_mm * x_mm - y_mm * y_mm;
  if (!(z2_mm2 > 0.0)) return Vec3(kNaN, kNaN, kNaN);
  Vec3 platform_mm = c1 + x_mm * ex + y_mm * ey + std::sqrt(z2_mm2) * ez;

  // two Newton steps on |p - C_i|^2 = L^2 remove the rounding of the frame construction
  for (int iteration = 0; iteration < 2; ++iteration) {
    Eigen::Matrix3d jacobian;
    Vec3 residual_mm2;
    const std::array<Vec3, 3> rods = rod_vectors_mm(geometry, platform_mm, joints);
    for (int arm = 0; arm < 3; ++arm) {
      jacobian.row(arm) = 2.0 * rods[arm].transpose();
      residual_mm2[arm] = rods[arm].squaredNorm() - rod_mm * rod_mm;
    }
    platform_mm -= jacobian.partialPivLu().solve(residual_mm2);
  }
  return platform_mm;
}

// nozzle point in the substrate frame from the platform centre (inverse of
// linear_delta_platform_position)
Vec3 tcp_from_platform_mm(const LinearDeltaGeometry& geometry, const Vec3& platform_mm) {
  return -platform_mm - Vec3(0.0, 0.0, geometry.substrate_above_joints_mm);
}

// carriage velocities from the rod vectors and the platform velocity:
// d/dt |p - C_i|^2 = 0  =>  q'_i = w_i . p' / w_iz
Vec3 carriage_velocity_mm_s(const std::array<Vec3, 3>& rods, const Vec3& platform_velocity) {
  Vec3 velocity;
  for (int arm = 0; arm < 3; ++arm)
    velocity[arm] = rods[arm].dot(platform_velocity) / rods[arm].z();
  return velocity;
}

// carriage accelerations, the time derivative of the velocity constraint:
// |p' - q'_i e_z|^2 + w_i . (p'' - q''_i e_z) = 0
//   =>  q''_i = (w_i . p'' + |p' - q'_i e_z|^2) / w_iz
Vec3 carriage_acceleration_mm_s2(const std::array<Vec3, 3>& rods, const Vec3& platform_velocity,
                                 const Vec3& platform_acceleration) {
  const Vec3 velocity = carriage_velocity_mm_s(rods, platform_velocity);
  Vec3 acceleration;
  for (int arm = 0; arm < 3; ++arm) {
    const Vec3 rod_rate = platform_velocity - Vec3(0.0, 0.0, velocity[arm]);
    acceleration[arm] =
        (rods[arm].dot(platform_acceleration) + rod_rate.squaredNorm()) / rods[arm].z();
  }
  return acceleration;
}

JointVector to_joints(const Vec3& values) {
  return JointVector{values[0], values[1], values[2]};
}

}  // namespace

double LinearDeltaGeometry::home_carriage_height_mm() const {
  const double offset_mm = carriage_radius_mm - platform_radius_mm;
  return -substrate_above_joints_mm -
         std::sqrt(rod_length_mm * rod_length_mm - offset_mm * offset_mm);
}

std::string LinearDeltaGeometry::validate() const {
  const auto positive = [](double value) { return std::isfinite(value) && value > 0.0; };
  if (!positive(rod_length_mm - (carriage_radius_mm - platform_radius_mm)))
    return "rod_length_mm must exceed carriage_radius_mm - platform_radius_mm";
  if (!positive(carriage_radius_mm - platform_radius_mm) || !positive(platform_radius_mm))
    return "carriage_radius_mm must exceed platform_radius_mm > 0";
  if (!(max_rod_angle_deg > 0.0 && max_rod_angle_deg < 85.0))
    return "max_rod_angle_deg must be in (0, 85)";
  if (!(carriage_max_mm > carriage_min_mm)) return "carriage_max_mm must exceed carriage_min_mm";
  if (!positive(carriage_v_max_mm_s)) return "carriage v_max must be positive";
  if (!positive(carriage_a_max_mm_s2)) return "carriage a_max must be positive";
  if (!(limit_margin > 0.0 && limit_margin <= 1.0)) return "limit_margin must be in (0, 1]";
  if (!(platform_mass_kg >= 0.0) || !(carriage_mass_kg >= 0.0)) return "masses must be >= 0";
  return "";
}

LinearDelta::LinearDelta(const LinearDeltaGeometry& geometry) : geometry_(geometry) {
  for (int arm = 0; arm < 3; ++arm) {
    joint_limits_.push_back(JointLimit{
        "carriage" + std::to_string(arm + 1), geometry_.carriage_min_mm, geometry_.carriage_max_mm,
        geometry_.carriage_v_max_mm_s, geometry_.carriage_a_max_mm_s2});
  }
}

void LinearDelta::set_carriage_limits(double v_max_mm_s, double a_max_mm_s2) {
  geometry_.carriage_v_max_mm_s = v_max_mm_s;
  geometry_.carriage_a_max_mm_s2 = a_max_mm_s2;
  for (JointLimit& limit : joint_limits_) {
    limit.v_max = v_max_mm_s;
    limit.a_max = a_max_mm_s2;
  }
}

void LinearDelta::closure_feedforward(const Vec3& tcp_mm, const Vec3& tcp_velocity_mm_s,
                                      const Vec3& tcp_acceleration_mm_s2,
                                      double* joint_force) const {
  // the pose from the inverse kinematics (no workspace check), exact carriage accelerations
  const Vec3 platform_mm = linear_delta_platform_position(geometry_, tcp_mm);
  std::array<double, 3> joints;
  for (int arm = 0; arm < 3; ++arm)
    joints[arm] = joint_for_platform_mm(geometry_, arm, platform_mm);
  const std::array<Vec3, 3> rods = rod_vectors_mm(geometry_, platform_mm, joints.data());
  const Vec3 carriage_acceleration =
      carriage_acceleration_mm_s2(rods, -tcp_velocity_mm_s, -tcp_acceleration_mm_s2);

  // forces to supply at the platform joints (SI, N): the platform's m_p (p'' + g e_z), and
  // per rod, with end a on the carriage (a_a = q''_i e_z) and end b on the platform
  // (a_b = p''): the inertial force m_r (a_a / 6 + a_b / 3) plus half the weight at b, and
  // m_r (a_a / 3 + a_b / 6) plus half the weight at a, of which the simulator's tree model
  // already supplies m_r (q''_i + g) on the carriage
  const double g_m_s2 = geometry_.gravity_m_s2;
  const double rod_kg = geometry_.rod_mass_kg;
  const Vec3 up(0.0, 0.0, 1.0);
  const Vec3 platform_acceleration_m_s2 = -mm_to_m(1.0) * tcp_acceleration_mm_s2;
  Vec3 platform_force_n = geometry_.closure_mass_kg * (platform_acceleration_m_s2 + g_m_s2 * up);
  std::array<double, 3> carriage_force_n{};
  for (int arm = 0; arm < 3; ++arm) {
    const double carriage_acceleration_m_s2 = mm_to_m(carriage_acceleration[arm]);
    const double rods_kg = 2.0 * rod_kg;  // a parallelogram pair: both rods move alike
    platform_force_n += rods_kg * (carriage_acceleration_m_s2 / 6.0 * up +
                                   platform_acceleration_m_s2 / 3.0 + 0.5 * g_m_s2 * up);
    carriage_force_n[arm] = rods_kg * (carriage_acceleration_m_s2 / 3.0 +
                                       platform_acceleration_m_s2.z() / 6.0 + 0.5 * g_m_s2) -
                            rods_kg * (carriage_acceleration_m_s2 + g_m_s2);
  }

  // the platform-side forces through the rods by virtual work: J^T f = F, J's rows w_i / w_iz
  Eigen::Matrix3d jacobian;
  for (int arm = 0; arm < 3; ++arm) jacobian.row(arm) = rods[arm].transpose() / rods[arm].z();
  const Vec3 rod_forces_n = jacobian.transpose().partialPivLu().solve(platform_force_n);
  for (int arm = 0; arm < 3; ++arm) joint_force[arm] += rod_forces_n[arm] + carriage_force_n[arm];
}

bool LinearDelta::inverse(const Pose& pose, JointVector& joints, std::string* why) const {
  const auto fail = [why](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  const Vec3& tcp_mm = pose.position_mm;
  if (!tcp_mm.allFinite()) return fail("the point is not finite");
  if (const std::string tilted = vertical_axis_problem(name(), pose); !tilted.empty())
    return fail(tilted);
  if (const std::string deep =
          below_surface_problem(tcp_mm.z(), geometry_.min_tcp_z_mm, "substrate");
      !deep.empty())
    return fail(deep);

  // each arm: q_i = p_z - sqrt(L^2 - |p_xy - D u_i|^2) - H
  const Vec3 platform_mm = linear_delta_platform_position(geometry_, tcp_mm);
  const double rod_mm = geometry_.rod_length_mm;
  const double reach_mm = max_reach_mm(geometry_);
  joints.assign(3, 0.0);
  for (int arm = 0; arm < 3; ++arm) {
    const double horizontal_mm = (platform_mm.head<2>() - column_point_mm(geometry_, arm)).norm();
    const std::string arm_name = "carriage" + std::to_string(arm + 1);
    if (horizontal_mm > reach_mm) {
      const double angle_deg =
          horizontal_mm < rod_mm ? rad_to_deg(std::asin(horizontal_mm / rod_mm)) : 90.0;
      return fail("the rods of " + arm_name + " would lean " +
                  message_number_beside(angle_deg, geometry_.max_rod_angle_deg, 4) +
                  " deg from vertical, beyond the " +
                  message_number(geometry_.max_rod_angle_deg, 4) + " deg limit (" +
                  message_number(horizontal_mm - reach_mm, 4) +
                  " mm outside the reachable region)");
    }
    const double joint_mm = joint_for_platform_mm(geometry_, arm, platform_mm);
    if (joint_mm < geometry_.carriage_min_mm - kTravelRounding_mm ||
        joint_mm > geometry_.carriage_max_mm + kTravelRounding_mm) {
      return fail(arm_name + " would be at " + message_number(joint_mm, 4) +
                  " mm, outside its travel [" + message_number(geometry_.carriage_min_mm, 4) +
                  ", " + message_number(geometry_.carriage_max_mm, 4) + "] mm, by " +
                  message_number(std::max(geometry_.carriage_min_mm - joint_mm,
                                          joint_mm - geometry_.carriage_max_mm),
                                 4) +
                  " mm");
    }
    joints[arm] = joint_mm;
  }
  return true;
}

Pose LinearDelta::forward(const JointVector& joints) const {
  if (joints.size() != 3) return Pose(Vec3(kNaN, kNaN, kNaN));
  return Pose(tcp_from_platform_mm(geometry_, trilaterate_mm(geometry_, joints.data())));
}

Jacobian LinearDelta::jacobian(const JointVector& joints) const {
  Jacobian j = Jacobian::Zero(6, 3);
  if (joints.size() != 3) return Jacobian::Constant(6, 3, kNaN);
  const Vec3 platform_mm = trilaterate_mm(geometry_, joints.data());
  const std::array<Vec3, 3> rods = rod_vectors_mm(geometry_, platform_mm, joints.data());
  // q' = M p' with rows w_i / w_iz, and tcp' = -p'
  Eigen::Matrix3d joint_rate_per_platform;
  for (int arm = 0; arm < 3; ++arm)
    joint_rate_per_platform.row(arm) = rods[arm].transpose() / rods[arm].z();
  j.topRows<3>() = -joint_rate_per_platform.inverse();
  return j;
}

JointVector LinearDelta::joint_velocity(const JointVector& joints, const PoseRate& rate) const {
  if (joints.size() != 3) return JointVector(3, kNaN);
  const Vec3 platform_mm = trilaterate_mm(geometry_, joints.data());
  // the platform moves opposite to the TCP
  return to_joints(carriage_velocity_mm_s(rod_vectors_mm(geometry_, platform_mm, joints.data()),
                                          -rate.linear_mm_s));
}

std::string LinearDelta::set_joint_limits(const AxisLimits& limits) {
  if (limits.j_max_mm_s3 > 0.0)
    return "a carriage j_max is not supported on the linear_delta (its TCP limits bound carriage "
           "speed and acceleration only); set the TCP's limits.j_max instead";
  set_carriage_limits(limits.v_max_mm_s, limits.a_max_mm_s2);
  return "";
}

JointVector LinearDelta::joint_acceleration(const JointVector& joints, const Vec3& tcp_velocity,
                                            const Vec3& tcp_acceleration) const {
  if (joints.size() != 3) return JointVector(3, kNaN);
  const Vec3 platform_mm = trilaterate_mm(geometry_, joints.data());
  return to_joints(carriage_acceleration_mm_s2(
      rod_vectors_mm(geometry_, platform_mm, joints.data()), -tcp_velocity, -tcp_acceleration));
}

MachineLimits LinearDelta::cartesian_limits(const MachineLimits& requested, const Vec3& lo,
                                            const Vec3& hi) const {
  const double rod_mm = geometry_.rod_length_mm;
  const double reach_mm = max_reach_mm(geometry_);

  // platform x/y range of the box (the platform moves opposite to the TCP)
  const Eigen::Vector2d platform_lo(-std::max(lo.x(), hi.x()), -std::max(lo.y(), hi.y()));
  const Eigen::Vector2d platform_hi(-std::min(lo.x(), hi.x()), -std::min(lo.y(), hi.y()));

  // per arm: the largest |w_x|, |w_y| and the smallest rod height S over the box. Each
  // is a convex function's maximum (or a concave one's minimum) of p_xy, so box corners
  // attain it; every reachable point has d <= reach, which caps them.
  std::array<double, 3> reach_x_mm{}, reach_y_mm{}, rod_height_mm{};
  for (int arm = 0; arm < 3; ++arm) {
    const Eigen::Vector2d column = column_point_mm(geometry_, arm);
    double max_x_mm = 0.0, max_y_mm = 0.0, max_distance_mm = 0.0;
    for (int corner = 0; corner < 4; ++corner) {
      const Eigen::Vector2d platform((corner & 1) ? platform_hi.x() : platform_lo.x(),
                                     (corner & 2) ? platform_hi.y() : platform_lo.y());
      const Eigen::Vector2d offset = platform - column;
      max_x_mm = std::max(max_x_mm, std::abs(offset.x()));
      max_y_mm = std::max(max_y_mm, std::abs(offset.y()));
      max_distance_mm = std::max(max_distance_mm, offset.norm());
    }
    max_distance_mm = std::min(max_distance_mm, reach_mm);
    reach_x_mm[arm] = std::min(max_x_mm, max_distance_mm);
    reach_y_mm[arm] = std::min(max_y_mm, max_distance_mm);
    rod_height_mm[arm] = std::sqrt(rod_mm * rod_mm - max_distance_mm * max_distance_mm);
  }

  // worst carriage velocity |q'| <= (Wx Vx + Wy Vy) / S + Vz over the arms
  const auto velocity_gain = [&](const Vec3& v) {
    double worst = 0.0;
    for (int arm = 0; arm < 3; ++arm)
      worst = std::max(
          worst, (reach_x_mm[arm] * v.x() + reach_y_mm[arm] * v.y()) / rod_height_mm[arm] + v.z());
    return worst;
  };
  // worst centripetal part of q'': |p' - q'_i e_z|^2 / S with
  // |p' - q'_i e_z|^2 = |v_xy|^2 + (w_xy . v_xy / S)^2
  const auto centripetal = [&](const Vec3& v) {
    double worst = 0.0;
    for (int arm = 0; arm < 3; ++arm) {
      const double sideways =
          (reach_x_mm[arm] * v.x() + reach_y_mm[arm] * v.y()) / rod_height_mm[arm];
      worst = std::max(worst,
                       (v.x() * v.x() + v.y() * v.y() + sideways * sideways) / rod_height_mm[arm]);
    }
    return worst;
  };

  Vec3 velocity_mm_s, acceleration_mm_s2;
  for (int axis = 0; axis < 3; ++axis) {
    velocity_mm_s[axis] = requested.axes[axis].v_max_mm_s;
    acceleration_mm_s2[axis] = requested.axes[axis].a_max_mm_s2;
  }
  const double carriage_v_mm_s = geometry_.limit_margin * geometry_.carriage_v_max_mm_s;
  const double carriage_a_mm_s2 = geometry_.limit_margin * geometry_.carriage_a_max_mm_s2;

  // velocities: scale so the worst carriage velocity fits, then so the centripetal
  // term takes at most half of the carriage acceleration (it grows with v^2)
  const double gain = velocity_gain(velocity_mm_s);
  if (gain > carriage_v_mm_s) velocity_mm_s *= carriage_v_mm_s / gain;
  const double centripetal_mm_s2 = centripetal(velocity_mm_s);
  if (centripetal_mm_s2 > 0.5 * carriage_a_mm_s2)
    velocity_mm_s *= std::sqrt(0.5 * carriage_a_mm_s2 / centripetal_mm_s2);

  // accelerations: the rest of the carriage budget, (Wx Ax + Wy Ay) / S + Az
  const double budget_mm_s2 = carriage_a_mm_s2 - centripetal(velocity_mm_s);
  const double acceleration_gain = velocity_gain(acceleration_mm_s2);
  if (acceleration_gain > budget_mm_s2) acceleration_mm_s2 *= budget_mm_s2 / acceleration_gain;

  MachineLimits limits = requested;
  for (int axis = 0; axis < 3; ++axis) {
    limits.axes[axis].v_max_mm_s = velocity_mm_s[axis];
    limits.axes[axis].a_max_mm_s2 = acceleration_mm_s2[axis];
  }
  return limits;
}

Vec3 linear_delta_platform_position(const LinearDeltaGeometry& geometry, const Vec3& tcp_mm) {
  return -Vec3(0.0, 0.0, geometry.substrate_above_joints_mm) - tcp_mm;
}

std::array<double, 3> linear_delta_feedforward_forces_n(const LinearDeltaGeometry& geometry,
                                                        const Vec3& tcp_mm,
                                                        const Vec3& tcp_velocity_mm_s,
                                                        const Vec3& tcp_acceleration_mm_s2) {
  // the pose from the inverse kinematics, without the workspace check
  const Vec3 platform_mm = linear_delta_platform_position(geometry, tcp_mm);
  std::array<double, 3> joints;
  for (int arm = 0; arm < 3; ++arm) joints[arm] = joint_for_platform_mm(geometry, arm, platform_mm);
  const std::array<Vec3, 3> rods = rod_vectors_mm(geometry, platform_mm, joints.data());
  const Vec3 platform_acceleration_mm_s2 = -tcp_acceleration_mm_s2;
  const Vec3 carriage_acceleration =
      carriage_acceleration_mm_s2(rods, -tcp_velocity_mm_s, platform_acceleration_mm_s2);

  // force the rods must apply to the platform: m_p (p'' + g e_z), N
  const Vec3 gravity_m_s2(0.0, 0.0, geometry.gravity_m_s2);
  const Vec3 platform_force_n =
      geometry.platform_mass_kg * (mm_to_m(1.0) * platform_acceleration_mm_s2 + gravity_m_s2);

  // virtual work with q'_i = (w_i / w_iz) . p': J^T F = f, J's rows w_i^T / w_iz
  Eigen::Matrix3d jacobian;
  for (int arm = 0; arm < 3; ++arm) jacobian.row(arm) = rods[arm].transpose() / rods[arm].z();
  const Vec3 rod_forces_n = jacobian.transpose().partialPivLu().solve(platform_force_n);

  // plus each carriage's own weight and inertia
  std::array<double, 3> forces_n;
  for (int arm = 0; arm < 3; ++arm) {
    forces_n[arm] =
        rod_forces_n[arm] +
        geometry.carriage_mass_kg * (mm_to_m(carriage_acceleration[arm]) + geometry.gravity_m_s2);
  }
  return forces_n;
}

std::unique_ptr<Machine> make_linear_delta() {
  return std::make_unique<LinearDelta>();
}

std::unique_ptr<LinearDelta> make_linear_delta(const LinearDeltaGeometry& geometry) {
  return std::make_unique<LinearDelta>(geometry);
}

}  // namespace depotwin
