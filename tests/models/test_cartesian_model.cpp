// models/cartesian.xml with raw MuJoCo against kinematics/cartesian: the model loads without
// warnings, has the joints, servos, site, body and camera the simulation needs, its nozzle in
// the bed frame is the joints (the identity map), and the servos hold a commanded point.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <memory>
#include <string>

#include "kinematics/cartesian.hpp"
#include "models/mujoco_test_util.hpp"

namespace depotwin {
namespace {

using testing_models::DataDeleter;
using testing_models::ModelDeleter;

class CartesianModel : public ::testing::Test {
 protected:
  void SetUp() override {
    model_.reset(testing_models::load_test_model("cartesian.xml"));
    ASSERT_TRUE(model_);
    data_.reset(mj_makeData(model_.get()));
    for (int axis = 0; axis < 3; ++axis) {
      const std::string name = machine_->joint_limits()[axis].name;
      joint_[axis] = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
      actuator_[axis] = mj_name2id(model_.get(), mjOBJ_ACTUATOR, name.c_str());
      ASSERT_GE(joint_[axis], 0) << name;
      ASSERT_GE(actuator_[axis], 0) << name;
    }
    substrate_ = mj_name2id(model_.get(), mjOBJ_BODY, "substrate");
    nozzle_ = mj_name2id(model_.get(), mjOBJ_SITE, "nozzle");
    ASSERT_GE(substrate_, 0);
    ASSERT_GE(nozzle_, 0);
    ASSERT_GE(mj_name2id(model_.get(), mjOBJ_CAMERA, "render_cam"), 0);
  }
  void TearDown() override { testing_models::expect_no_warnings(data_.get()); }

  // the nozzle point in the bed frame (mm); the bed only translates
  Vec3 simulated_tcp_mm() const {
    Vec3 tcp_mm;
    for (int k = 0; k < 3; ++k)
      tcp_mm[k] = 1000.0 * (data_->site_xpos[3 * nozzle_ + k] - data_->xpos[3 * substrate_ + k]);
    return tcp_mm;
  }

  std::unique_ptr<Machine> machine_ = make_cartesian();
  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  int joint_[3] = {-1, -1, -1}, actuator_[3] = {-1, -1, -1};
  int substrate_ = -1, nozzle_ = -1;
};

// forward kinematics in MuJoCo: the nozzle in the bed frame is (x, y, z) for any joints
TEST_F(CartesianModel, NozzleInTheBedFrameIsTheJoints) {
  const JointVector points[] = {{0, 0, 0}, {35, -20, 0.2}, {-100, 100, 150}, {100, -100, -10}};
  for (const JointVector& q : points) {
    for (int axis = 0; axis < 3; ++axis)
      data_->qpos[model_->jnt_qposadr[joint_[axis]]] = q[axis] / 1000.0;
    mj_kinematics(model_.get(), data_.get());
    const Vec3 expected = machine_->forward(q).position_mm;
    EXPECT_LT((simulated_tcp_mm() - expected).norm(), 1e-9);
  }
}

// the hard stops lie beyond the kinematics' soft travel on every axis
TEST_F(CartesianModel, HardStopsLieBeyondTheTravel) {
  for (int axis = 0; axis < 3; ++axis) {
    const JointLimit& limit = machine_->joint_limits()[axis];
    EXPECT_LT(1000.0 * model_->jnt_range[2 * joint_[axis]], limit.min) << limit.name;
    EXPECT_GT(1000.0 * model_->jnt_range[2 * joint_[axis] + 1], limit.max) << limit.name;
  }
}

// the servos, with the bed's weight fed forward, hold a commanded point: at rest the error is
// at most the guide friction over kp (0.3 N / 2e4 N/m = 0.015 mm on x)
TEST_F(CartesianModel, ServosHoldACommandedPointAgainstGravity) {
  const double target_mm[3] = {40.0, -25.0, 10.0};
  for (int step = 0; step < 2000; ++step) {
    mj_step1(model_.get(), data_.get());
    for (int axis = 0; axis < 3; ++axis) {
      const double kp = model_->actuator_gainprm[mjNGAIN * actuator_[axis]];
      const double bias = data_->qfrc_bias[model_->jnt_dofadr[joint_[axis]]];
      data_->ctrl[actuator_[axis]] = target_mm[axis] / 1000.0 + bias / kp;
    }
    mj_step2(model_.get(), data_.get());
  }
  const Vec3 tcp_mm = simulated_tcp_mm();
  for (int axis = 0; axis < 3; ++axis) EXPECT_NEAR(tcp_mm[axis], target_mm[axis], 0.016);
}

}  // namespace
}  // namespace depotwin
