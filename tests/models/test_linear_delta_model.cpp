// models/linear_delta.xml with raw MuJoCo against kinematics/linear_delta: the model
// loads without warnings, its geometry and masses match LinearDeltaGeometry, the
// carriage servos settle the platform where the forward kinematics says, and the closed
// chain holds together while the platform follows a 5 mm/s circle (Giberti et al., sec. 6.2).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "kinematics/linear_delta.hpp"
#include "models/mujoco_test_util.hpp"

namespace depotwin {
namespace {

using testing_models::DataDeleter;
using testing_models::ModelDeleter;

class DeltaModel : public ::testing::Test {
 protected:
  void SetUp() override {
    model_.reset(testing_models::load_test_model("linear_delta.xml"));
    ASSERT_TRUE(model_);
    data_.reset(mj_makeData(model_.get()));
    for (int arm = 0; arm < 3; ++arm) {
      const std::string name = delta_.joint_limits()[arm].name;
      joint_[arm] = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
      actuator_[arm] = mj_name2id(model_.get(), mjOBJ_ACTUATOR, name.c_str());
      ASSERT_GE(joint_[arm], 0) << name;
      ASSERT_GE(actuator_[arm], 0) << name;
    }
    substrate_ = mj_name2id(model_.get(), mjOBJ_BODY, "substrate");
    nozzle_ = mj_name2id(model_.get(), mjOBJ_SITE, "nozzle");
    ASSERT_GE(substrate_, 0);
    ASSERT_GE(nozzle_, 0);
  }

  void TearDown() override { testing_models::expect_no_warnings(data_.get()); }

  // the nozzle point in the substrate frame (mm)
  Vec3 simulated_tcp_mm() const {
    const mjtNum* frame = data_->xmat + 9 * substrate_;
    const mjtNum* origin = data_->xpos + 3 * substrate_;
    const mjtNum* nozzle = data_->site_xpos + 3 * nozzle_;
    Vec3 tcp_mm;
    for (int row = 0; row < 3; ++row) {
      tcp_mm[row] = 0.0;
      for (int k = 0; k < 3; ++k) tcp_mm[row] += frame[3 * k + row] * (nozzle[k] - origin[k]);
    }
    return m_to_mm(1.0) * tcp_mm;
  }

  JointVector simulated_joints_mm() const {
    JointVector joints(3);
    for (int arm = 0; arm < 3; ++arm)
      joints[arm] = m_to_mm(data_->qpos[model_->jnt_qposadr[joint_[arm]]]);
    return joints;
  }

  // largest distance between the two anchors of any <connect> (mm)
  double max_anchor_gap_mm() const {
    double worst_mm = 0.0;
    for (int eq = 0; eq < model_->neq; ++eq) {
      const int bodies[2] = {model_->eq_obj1id[eq], model_->eq_obj2id[eq]};
      mjtNum anchors[2][3];
      for (int side = 0; side < 2; ++side) {
        mju_rotVecMat(anchors[side], model_->eq_data + mjNEQDATA * eq + 3 * side,
                      data_->xmat + 9 * bodies[side]);
        mju_addTo3(anchors[side], data_->xpos + 3 * bodies[side]);
      }
      worst_mm = std::max(worst_mm, m_to_mm(mju_dist3(anchors[0], anchors[1])));
    }
    return worst_mm;
  }

  // position servo with velocity and load feed-forward:
  // ctrl = q_ref + ((kv + damping) q'_ref + F_ff) / kp
  void control(const Vec3& tcp_mm, const Vec3& velocity_mm_s, const Vec3& acceleration_mm_s2) {
    JointVector joints;
    std::string why;
    ASSERT_TRUE(delta_.inverse(tcp_mm, joints, &why)) << why;
    const JointVector joint_velocity = delta_.joint_velocity(joints, velocity_mm_s);
    const std::array<double, 3> forces_n = linear_delta_feedforward_forces_n(
        delta_.geometry(), tcp_mm, velocity_mm_s, acceleration_mm_s2);
    for (int arm = 0; arm < 3; ++arm) {
      const int actuator = actuator_[arm];
      const double kp = model_->actuator_gainprm[mjNGAIN * actuator];
      const double kv = -model_->actuator_biasprm[mjNBIAS * actuator + 2];
      const double damping = model_->dof_damping[model_->jnt_dofadr[joint_[arm]]];
      data_->ctrl[actuator] = mm_to_m(joints[arm]) +
                              ((kv + damping) * mm_to_m(joint_velocity[arm]) + forces_n[arm]) / kp;
    }
  }

  // a rest-to-rest move along a straight line with a smoothstep profile, then a hold
  void move_to(const Vec3& from_mm, const Vec3& to_mm, double duration_s, double hold_s) {
    const double step_s = model_->opt.timestep;
    const int move_steps = static_cast<int>(std::lround(duration_s / step_s));
    const int hold_steps = static_cast<int>(std::lround(hold_s / step_s));
    for (int step = 0; step < move_steps + hold_steps; ++step) {
      const double u = std::min(1.0, data_->time / duration_s);
      const double shape = u * u * (3 - 2 * u);
      const double rate = u < 1.0 ? 6 * u * (1 - u) / duration_s : 0.0;
      const double curvature = u < 1.0 ? 6 * (1 - 2 * u) / (duration_s * duration_s) : 0.0;
      const Vec3 delta_mm = to_mm - from_mm;
      control(from_mm + shape * delta_mm, rate * delta_mm, curvature * delta_mm);
      mj_step(model_.get(), data_.get());
    }
  }

  void follow_circle(const Vec3& centre_mm, double radius_mm, double speed_mm_s,
                     double max_error_mm);

  LinearDelta delta_;
  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  int joint_[3] = {-1, -1, -1}, actuator_[3] = {-1, -1, -1};
  int substrate_ = -1, nozzle_ = -1;
};

TEST_F(DeltaModel, StructureMatchesTheKinematics) {
  // 3 carriages + 6 rods x 2 hinges + a free platform, closed by 6 connects: 3 DOF left
  EXPECT_EQ(model_->nv, 3 + 12 + 6);
  EXPECT_EQ(model_->neq, 6);
  EXPECT_EQ(model_->nu, 3);
  EXPECT_GE(mj_name2id(model_.get(), mjOBJ_CAMERA, "render_cam"), 0);
  EXPECT_GT(model_->vis.global.offwidth, 640);

  // travel: the MJCF hard stops lie just outside the kinematic soft limits
  const LinearDeltaGeometry& g = delta_.geometry();
  for (int arm = 0; arm < 3; ++arm) {
    const mjtNum* range = model_->jnt_range + 2 * joint_[arm];
    EXPECT_TRUE(model_->jnt_limited[joint_[arm]]);
    EXPECT_LT(m_to_mm(range[0]), g.carriage_min_mm);
    EXPECT_GT(m_to_mm(range[1]), g.carriage_max_mm);
  }

  // masses: the feed-forward's lumped masses are the model's, half of each rod at either end
  const auto body_mass = [&](const char* name) {
    const int body = mj_name2id(model_.get(), mjOBJ_BODY, name);
    EXPECT_GE(body, 0) << name;
    return body >= 0 ? model_->body_mass[body] : 0.0;
  };
  const double rod_kg = body_mass("rod1a");
  for (const char* rod : {"rod1b", "rod2a", "rod2b", "rod3a", "rod3b"})
    EXPECT_DOUBLE_EQ(body_mass(rod), rod_kg);
  EXPECT_NEAR(body_mass("platform") + body_mass("substrate") + 3 * rod_kg, g.platform_mass_kg,
              1e-12);
  for (const char* carriage : {"carriage1", "carriage2", "carriage3"})
    EXPECT_NEAR(body_mass(carriage) + rod_kg, g.carriage_mass_kg, 1e-12);

  // home pose (qpos0): the chain is closed, the nozzle sits on the substrate origin, the
  // rod tips are where the kinematics puts the platform's ball joints
  mj_forward(model_.get(), data_.get());
  EXPECT_LT(max_anchor_gap_mm(), 1e-6);
  EXPECT_LT(simulated_tcp_mm().norm(), 1e-6);
  const Vec3 platform_mm = linear_delta_platform_position(g, Vec3::Zero());
  for (int eq = 0; eq < model_->neq; ++eq) {
    const int rod = model_->eq_obj1id[eq];
    mjtNum tip[3];
    mju_rotVecMat(tip, model_->eq_data + mjNEQDATA * eq, data_->xmat + 9 * rod);
    mju_addTo3(tip, data_->xpos + 3 * rod);
    const Vec3 tip_mm = m_to_mm(1.0) * Vec3(tip[0], tip[1], tip[2]);
    // on the platform's joint plane, platform_radius from the axis in the pair's direction,
    // half the rod spacing to the side
    const Vec3 offset_mm = tip_mm - platform_mm;
    EXPECT_NEAR(offset_mm.z(), 0.0, 1e-6);
    const double radius_mm = std::hypot(g.platform_radius_mm, 0.5 * g.rod_spacing_mm);
    EXPECT_NEAR(offset_mm.head<2>().norm(), radius_mm, 1e-6);
    // and L from its carriage joint, which is at the carriage's home height
    const int carriage = model_->body_parentid[rod];
    EXPECT_NEAR(m_to_mm(data_->xpos[3 * carriage + 2]), g.home_carriage_height_mm(), 1e-6);
    EXPECT_NEAR(m_to_mm(mju_dist3(tip, data_->xpos + 3 * rod)), g.rod_length_mm, 1e-6);
  }
}

TEST_F(DeltaModel, ServosSettleThePlatformAtTheForwardKinematics) {
  const Vec3 targets_mm[] = {Vec3(0, 0, 0), Vec3(60, -30, 5), Vec3(-80, 70, 40), Vec3(20, 100, 120),
                             Vec3(-110, -40, 10)};
  Vec3 from_mm = Vec3::Zero();
  double worst_target_mm = 0.0, worst_forward_mm = 0.0;
  for (const Vec3& target_mm : targets_mm) {
    data_->time = 0.0;
    move_to(from_mm, target_mm, 1.0, 0.5);
    from_mm = target_mm;
    mj_kinematics(model_.get(), data_.get());  // positions of the final state
    const Vec3 tcp_mm = simulated_tcp_mm();
    const double to_target_mm = (tcp_mm - target_mm).norm();
    const double to_forward_mm =
        (tcp_mm - delta_.forward(simulated_joints_mm()).position_mm).norm();
    EXPECT_LT(to_target_mm, 0.05) << target_mm.transpose();
    EXPECT_LT(to_forward_mm, 0.05) << target_mm.transpose();
    EXPECT_LT(max_anchor_gap_mm(), 0.01);
    worst_target_mm = std::max(worst_target_mm, to_target_mm);
    worst_forward_mm = std::max(worst_forward_mm, to_forward_mm);
  }
  std::printf("settled: max |tcp - target| %.4f mm, max |tcp - FK(q)| %.4f mm\n", worst_target_mm,
              worst_forward_mm);
}

// At rest the drives carry exactly the load feed-forward: the static forces of
// linear_delta_feedforward_forces_n (masses, Jacobian transpose) are MuJoCo's, to within
// the guides' Coulomb friction.
TEST_F(DeltaModel, DriveForcesAtRestMatchTheLoadFeedForward) {
  const Vec3 targets_mm[] = {Vec3(0, 0, 0), Vec3(90, -40, 20), Vec3(-60, -90, 100)};
  Vec3 from_mm = Vec3::Zero();
  double worst_n = 0.0;
  for (const Vec3& target_mm : targets_mm) {
    data_->time = 0.0;
    move_to(from_mm, target_mm, 1.0, 0.5);
    from_mm = target_mm;
    const std::array<double, 3> expected_n =
        linear_delta_feedforward_forces_n(delta_.geometry(), target_mm, Vec3::Zero(), Vec3::Zero());
    for (int arm = 0; arm < 3; ++arm) {
      const double friction_n = model_->dof_frictionloss[model_->jnt_dofadr[joint_[arm]]];
      const double force_n = data_->actuator_force[actuator_[arm]];
      EXPECT_NEAR(force_n, expected_n[arm], friction_n) << target_mm.transpose() << " arm " << arm;
      worst_n = std::max(worst_n, std::abs(force_n - expected_n[arm]));
    }
  }
  std::printf("drive force at rest vs load feed-forward: max difference %.5f N\n", worst_n);
}

// Follow a circle at constant speed after a speed ramp; the largest distance between the
// simulated TCP and the reference must stay under `max_error_mm`, every <connect> closed
// to 0.01 mm.
void DeltaModel::follow_circle(const Vec3& centre_mm, double radius_mm, double speed_mm_s,
                               double max_error_mm) {
  const double ramp_s = 0.5;
  const Vec3 start_mm = centre_mm + Vec3(radius_mm, 0, 0);
  move_to(Vec3::Zero(), start_mm, 1.0, 0.3);

  // angle with a smooth speed ramp (constant angular acceleration), then one full turn
  const double omega = speed_mm_s / radius_mm;
  const double turn_s = 2 * kPi / omega + ramp_s;
  const double step_s = model_->opt.timestep;
  const int steps = static_cast<int>(std::lround(turn_s / step_s));
  double worst_path_mm = 0.0, worst_gap_mm = 0.0, sum_path_mm = 0.0;
  int counted = 0;
  const auto wall_start = std::chrono::steady_clock::now();
  for (int step = 0; step < steps; ++step) {
    const double t_s = step * step_s;
    const double rate = t_s < ramp_s ? omega * t_s / ramp_s : omega;
    const double angle = t_s < ramp_s ? 0.5 * omega * t_s * t_s / ramp_s
                                      : 0.5 * omega * ramp_s + omega * (t_s - ramp_s);
    const double angular_acc = t_s < ramp_s ? omega / ramp_s : 0.0;
    const Vec3 radial(std::cos(angle), std::sin(angle), 0),
        tangent(-std::sin(angle), std::cos(angle), 0);
    const Vec3 reference_mm = centre_mm + radius_mm * radial;
    const Vec3 velocity_mm_s = radius_mm * rate * tangent;
    const Vec3 acceleration_mm_s2 = radius_mm * (angular_acc * tangent - rate * rate * radial);
    control(reference_mm, velocity_mm_s, acceleration_mm_s2);
    mj_step(model_.get(), data_.get());
    // mj_step leaves xpos/site_xpos at the state the step started from (it integrates
    // qpos after computing them), so compare with the reference of that time
    const double error_mm = (simulated_tcp_mm() - reference_mm).norm();
    worst_path_mm = std::max(worst_path_mm, error_mm);
    sum_path_mm += error_mm;
    ++counted;
    worst_gap_mm = std::max(worst_gap_mm, max_anchor_gap_mm());
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  EXPECT_LT(worst_gap_mm, 0.01);
  EXPECT_LT(worst_path_mm, max_error_mm);
  std::printf(
      "circle r %.0f mm at %.0f mm/s: platform error max %.4f mm, mean %.4f mm; "
      "max anchor gap %.5f mm; %d steps in %.3f s = %.0f steps/s\n",
      radius_mm, speed_mm_s, worst_path_mm, sum_path_mm / counted, worst_gap_mm, steps, wall_s,
      steps / wall_s);
}

// the paper's test: a circle at a constant 5 mm/s (Giberti et al., sec. 6.2, Fig. 11)
TEST_F(DeltaModel, FollowsA5MmPerSecondCircle) {
  follow_circle(Vec3(10, -5, 2), 20.0, 5.0, 0.05);
}

// 150 mm/s on a 30 mm radius (750 mm/s^2 centripetal): the inertial part of the load
// feed-forward keeps the error at the friction floor of the slow circle (without it,
// static load feed-forward only: 0.069 mm)
TEST_F(DeltaModel, FollowsA150MmPerSecondCircle) {
  follow_circle(Vec3(-40, 30, 10), 30.0, 150.0, 0.04);
}

}  // namespace
}  // namespace depotwin
