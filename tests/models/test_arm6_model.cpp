// models/arm6.xml with raw MuJoCo against kinematics/arm6: the model loads without warnings,
// its joints, servos and masses are as specified, the `nozzle` site is where Arm6::forward
// says, the link frames and collision shapes are the MJCF's bodies and geoms, normal postures
// touch nothing (while a nozzle in the table and a folded arm do), and through the project's
// Simulation the TCP follows print lines and a tilted, turning circle within 0.05 mm.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "kinematics/arm6.hpp"
#include "models/mujoco_test_util.hpp"
#include "sim/mujoco_access.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

using testing_models::DataDeleter;
using testing_models::ModelDeleter;

std::string arm6_model_path() {
  return std::string(DEPOTWIN_MODELS_DIR) + "/arm6.xml";
}

Arm6Joints from_deg(double a, double b, double c, double d, double e, double f) {
  return {deg_to_rad(a), deg_to_rad(b), deg_to_rad(c), deg_to_rad(d), deg_to_rad(e), deg_to_rad(f)};
}

class Arm6Model : public ::testing::Test {
 protected:
  void SetUp() override {
    model_.reset(testing_models::load_test_model("arm6.xml"));
    ASSERT_TRUE(model_);
    data_.reset(mj_makeData(model_.get()));
    for (int j = 0; j < 6; ++j) {
      const std::string& name = arm_.joint_limits()[j].name;
      joint_[j] = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
      actuator_[j] = mj_name2id(model_.get(), mjOBJ_ACTUATOR, name.c_str());
      ASSERT_GE(joint_[j], 0) << name;
      ASSERT_GE(actuator_[j], 0) << name;
    }
    substrate_ = mj_name2id(model_.get(), mjOBJ_BODY, "substrate");
    nozzle_ = mj_name2id(model_.get(), mjOBJ_SITE, "nozzle");
    ASSERT_GE(substrate_, 0);
    ASSERT_GE(nozzle_, 0);
  }

  void TearDown() override { testing_models::expect_no_warnings(data_.get()); }

  void set_joints(const Arm6Joints& q) {
    for (int j = 0; j < 6; ++j) data_->qpos[model_->jnt_qposadr[joint_[j]]] = q[j];
    mj_forward(model_.get(), data_.get());
  }

  // a MuJoCo frame (position in m, row-major rotation) in the substrate frame, mm
  Eigen::Isometry3d in_substrate(const mjtNum* position, const mjtNum* rotation) const {
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> substrate_rotation(
        data_->xmat + 9 * substrate_);
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> frame_rotation(rotation);
    const Vec3 offset = Vec3(position[0], position[1], position[2]) -
                        Vec3(data_->xpos[3 * substrate_], data_->xpos[3 * substrate_ + 1],
                             data_->xpos[3 * substrate_ + 2]);
    Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
    frame.linear() = substrate_rotation.transpose() * frame_rotation;
    frame.translation() = m_to_mm(1.0) * (substrate_rotation.transpose() * offset);
    return frame;
  }

  // true when geoms a and b touch (in either order)
  bool touching(const std::string& a, const std::string& b) const {
    for (const std::string& pair : contact_pairs())
      if (pair == a + "/" + b || pair == b + "/" + a) return true;
    return false;
  }

  std::vector<std::string> contact_pairs() const {
    std::vector<std::string> pairs;
    for (int c = 0; c < data_->ncon; ++c)
      pairs.push_back(std::string(mj_id2name(model_.get(), mjOBJ_GEOM, data_->contact[c].geom1)) +
                      "/" + mj_id2name(model_.get(), mjOBJ_GEOM, data_->contact[c].geom2));
    return pairs;
  }

  Arm6 arm_;
  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  int joint_[6] = {-1, -1, -1, -1, -1, -1}, actuator_[6] = {-1, -1, -1, -1, -1, -1};
  int substrate_ = -1, nozzle_ = -1;
};

TEST_F(Arm6Model, JointsServosAndMassesAreAsSpecified) {
  EXPECT_EQ(model_->nq, 6);
  EXPECT_EQ(model_->nv, 6);
  EXPECT_EQ(model_->nu, 6);
  EXPECT_EQ(model_->ntex, 0);  // software GL: no textures
  EXPECT_EQ(model_->opt.timestep, 0.001);
  EXPECT_EQ(model_->vis.global.offwidth, 1280);
  EXPECT_EQ(model_->vis.global.offheight, 960);
  EXPECT_GE(mj_name2id(model_.get(), mjOBJ_CAMERA, "render_cam"), 0);

  // ranges exactly the kinematics' (the datasheet's); position servos with gear 1
  const double force_range_nm[6] = {120, 160, 80, 20, 20, 10};
  for (int j = 0; j < 6; ++j) {
    const JointLimit& limit = arm_.joint_limits()[j];
    const int joint = joint_[j], actuator = actuator_[j];
    EXPECT_EQ(model_->jnt_type[joint], mjJNT_HINGE) << limit.name;
    EXPECT_TRUE(model_->jnt_limited[joint]) << limit.name;
    EXPECT_NEAR(model_->jnt_range[2 * joint], limit.min, 1e-12) << limit.name;
    EXPECT_NEAR(model_->jnt_range[2 * joint + 1], limit.max, 1e-12) << limit.name;
    EXPECT_EQ(model_->actuator_trnid[2 * actuator], joint);
    EXPECT_EQ(model_->actuator_gaintype[actuator], mjGAIN_FIXED);
    EXPECT_EQ(model_->actuator_biastype[actuator], mjBIAS_AFFINE);
    const double kp = model_->actuator_gainprm[mjNGAIN * actuator];
    EXPECT_GT(kp, 0.0);
    EXPECT_EQ(model_->actuator_biasprm[mjNBIAS * actuator], 0.0);
    EXPECT_EQ(model_->actuator_biasprm[mjNBIAS * actuator + 1], -kp);
    EXPECT_LT(model_->actuator_biasprm[mjNBIAS * actuator + 2], 0.0);
    EXPECT_EQ(model_->actuator_gear[6 * actuator], 1.0);
    EXPECT_TRUE(model_->actuator_forcelimited[actuator]);
    EXPECT_EQ(model_->actuator_forcerange[2 * actuator], -force_range_nm[j]);
    EXPECT_EQ(model_->actuator_forcerange[2 * actuator + 1], force_range_nm[j]);
  }

  // 25 kg as the IRB 120: base 7.5 (fixed), links 6, 5, 3.5, 1.5, 0.6, 0.1, head 0.8
  EXPECT_NEAR(mj_getTotalmass(model_.get()), 25.0, 1e-9);
  const char* bodies[] = {"base", "link1", "link2", "link3", "link4", "link5", "link6", "tool"};
  const double masses[] = {7.5, 6.0, 5.0, 3.5, 1.5, 0.6, 0.1, 0.8};
  for (int i = 0; i < 8; ++i) {
    const int body = mj_name2id(model_.get(), mjOBJ_BODY, bodies[i]);
    ASSERT_GE(body, 0) << bodies[i];
    EXPECT_NEAR(model_->body_mass[body], masses[i], 1e-12) << bodies[i];
  }

  // the work frame: the substrate 360 mm in front, on the table top 50 mm below the base
  mj_forward(model_.get(), data_.get());
  const Vec3 origin_mm =
      m_to_mm(1.0) * Vec3(data_->xpos[3 * substrate_], data_->xpos[3 * substrate_ + 1],
                          data_->xpos[3 * substrate_ + 2]);
  EXPECT_LT((origin_mm - arm_.geometry().work_origin_mm).norm(), 1e-12);
  const int table = mj_name2id(model_.get(), mjOBJ_GEOM, "table");
  ASSERT_GE(table, 0);
  EXPECT_NEAR(m_to_mm(data_->geom_xpos[3 * table + 2] + model_->geom_size[3 * table + 2]),
              origin_mm.z(), 1e-9);
}

// The nozzle site relative to the substrate body is Arm6::forward: position to 1e-9 mm, frame
// to 1e-12 against the link chain, and against tool_frame(axis, roll) wherever the roll is
// well conditioned (more than 5 deg from a nozzle pointing straight up, core/pose.hpp)
TEST_F(Arm6Model, ForwardKinematicsIsTheNozzleSite) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_mm = 0.0, worst_frame = 0.0, worst_tool_frame = 0.0;
  for (int i = 0; i < 300; ++i) {
    Arm6Joints q;
    for (int j = 0; j < 6; ++j) {
      const JointLimit& limit = arm_.joint_limits()[j];
      q[j] = limit.min + (limit.max - limit.min) * unit(rng);
    }
    set_joints(q);
    const Eigen::Isometry3d site =
        in_substrate(data_->site_xpos + 3 * nozzle_, data_->site_xmat + 9 * nozzle_);
    const Pose pose = arm_.forward(q);
    worst_mm = std::max(worst_mm, (site.translation() - pose.position_mm).norm());
    const Eigen::Isometry3d chain =
        arm_.link_frames(JointVector(q.begin(), q.end()))[7] * arm_.tool_transform();
    worst_frame = std::max(worst_frame, (site.linear() - chain.linear()).norm());
    if (axis_angle_rad(pose.tool_axis, -Vec3::UnitZ()) > deg_to_rad(5.0))
      worst_tool_frame = std::max(
          worst_tool_frame, (site.linear() - tool_frame(pose.tool_axis, pose.roll_rad)).norm());
  }
  std::printf("nozzle site vs Arm6::forward: %.2e mm, frame %.2e (tool_frame %.2e)\n", worst_mm,
              worst_frame, worst_tool_frame);
  EXPECT_LT(worst_mm, 1e-9);
  EXPECT_LT(worst_frame, 1e-12);
  EXPECT_LT(worst_tool_frame, 1e-12);
}

TEST_F(Arm6Model, LinkFramesAndCollisionShapesAreTheMjcfBodiesAndGeoms) {
  const char* bodies[] = {"base", "link1", "link2", "link3", "link4", "link5", "link6", "tool"};
  const std::vector<CollisionShape>& shapes = arm_.collision_shapes();
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_mm = 0.0, worst_rotation = 0.0;
  for (int i = 0; i < 100; ++i) {
    Arm6Joints q;
    for (int j = 0; j < 6; ++j) {
      const JointLimit& limit = arm_.joint_limits()[j];
      q[j] = limit.min + (limit.max - limit.min) * unit(rng);
    }
    set_joints(q);
    const std::vector<Eigen::Isometry3d> frames = arm_.link_frames(JointVector(q.begin(), q.end()));
    ASSERT_EQ(frames.size(), 8u);
    for (int link = 0; link < 8; ++link) {
      const int body = mj_name2id(model_.get(), mjOBJ_BODY, bodies[link]);
      const Eigen::Isometry3d frame = in_substrate(data_->xpos + 3 * body, data_->xmat + 9 * body);
      worst_mm = std::max(worst_mm, (frame.translation() - frames[link].translation()).norm());
      worst_rotation = std::max(worst_rotation, (frame.linear() - frames[link].linear()).norm());
    }
    for (const CollisionShape& shape : shapes) {
      const int geom = mj_name2id(model_.get(), mjOBJ_GEOM, shape.name.c_str());
      ASSERT_GE(geom, 0) << shape.name;
      const Eigen::Isometry3d frame =
          in_substrate(data_->geom_xpos + 3 * geom, data_->geom_xmat + 9 * geom);
      const Eigen::Isometry3d expected = frames[shape.link] * shape.in_link;
      worst_mm = std::max(worst_mm, (frame.translation() - expected.translation()).norm());
      worst_rotation = std::max(worst_rotation, (frame.linear() - expected.linear()).norm());
    }
  }
  EXPECT_LT(worst_mm, 1e-9);
  EXPECT_LT(worst_rotation, 1e-12);

  // each shape is its geom: body, type, size; every colliding geom of link2..link6 and the
  // tool is a shape, and nothing else is
  int colliding = 0;
  for (int geom = 0; geom < model_->ngeom; ++geom) {
    const int body = model_->geom_bodyid[geom];
    const std::string body_name = mj_id2name(model_.get(), mjOBJ_BODY, body);
    int link = -1;
    for (int i = 2; i < 8; ++i)
      if (body_name == bodies[i]) link = i;
    const bool collides = model_->geom_contype[geom] != 0 || model_->geom_conaffinity[geom] != 0;
    const std::string name = mj_id2name(model_.get(), mjOBJ_GEOM, geom);
    const auto shape = std::find_if(shapes.begin(), shapes.end(),
                                    [&](const CollisionShape& s) { return s.name == name; });
    if (link < 0 || !collides) {
      EXPECT_EQ(shape, shapes.end()) << name;
      continue;
    }
    ++colliding;
    ASSERT_NE(shape, shapes.end()) << name;
    EXPECT_EQ(shape->link, link) << name;
    const int type = model_->geom_type[geom];
    const int expected_type = shape->type == CollisionShape::Type::box        ? mjGEOM_BOX
                              : shape->type == CollisionShape::Type::cylinder ? mjGEOM_CYLINDER
                              : shape->type == CollisionShape::Type::capsule  ? mjGEOM_CAPSULE
                                                                              : mjGEOM_SPHERE;
    EXPECT_EQ(type, expected_type) << name;
    const int size_count = type == mjGEOM_BOX ? 3 : type == mjGEOM_SPHERE ? 1 : 2;
    for (int k = 0; k < size_count; ++k)
      EXPECT_NEAR(m_to_mm(model_->geom_size[3 * geom + k]), shape->size_mm[k], 1e-9) << name;
  }
  EXPECT_EQ(colliding, static_cast<int>(shapes.size()));
}

// No contact at normal postures (vertical and tilted nozzle over the part's area, the zero
// pose); a nozzle pushed into the table and an arm folded onto itself are reported
TEST_F(Arm6Model, NormalPosturesTouchNothing) {
  set_joints(Arm6Joints{});
  EXPECT_EQ(data_->ncon, 0);
  int postures = 0;
  for (double x : {-75.0, 0.0, 75.0})
    for (double y : {-65.0, 0.0, 65.0})
      for (double z : {0.0, 40.0})
        for (int tilt = 0; tilt <= 4; ++tilt) {
          // vertical at roll 0, or tilted 45 deg towards +-x, +-y at the best of 12 rolls
          Vec3 axis = Vec3::UnitZ();
          if (tilt > 0) {
            const double direction = 0.5 * kPi * (tilt - 1);
            axis = Vec3(std::cos(direction), std::sin(direction), 1.0).normalized();
          }
          JointVector best;
          double best_margin = -1.0;
          for (int r = 0; r < (tilt == 0 ? 1 : 12); ++r) {
            JointVector q;
            if (!arm_.inverse(Pose(Vec3(x, y, z), axis, 2 * kPi * r / 12), q)) continue;
            const double margin = std::min(arm_.joint_margin_rad(q), arm_.wrist_alignment(q));
            if (margin > best_margin) {
              best_margin = margin;
              best = q;
            }
          }
          ASSERT_FALSE(best.empty()) << x << " " << y << " " << z << " tilt " << tilt;
          set_joints({best[0], best[1], best[2], best[3], best[4], best[5]});
          const std::vector<std::string> pairs = contact_pairs();
          EXPECT_TRUE(pairs.empty())
              << x << " " << y << " " << z << " tilt " << tilt << ": " << pairs.front();
          ++postures;
        }
  EXPECT_EQ(postures, 90);

  // the nozzle 10 mm into the table: its thin end touches the table
  JointVector q;
  ASSERT_TRUE(arm_.inverse(Pose(Vec3(0, 0, -10)), q));
  set_joints({q[0], q[1], q[2], q[3], q[4], q[5]});
  EXPECT_TRUE(touching("table", "tool_nozzle_tip")) << ::testing::PrintToString(contact_pairs());
  // the forearm folded back over the shoulder: the head hits link 1
  set_joints(from_deg(0, -110, 70, 0, 90, 0));
  EXPECT_TRUE(touching("link1_shoulder", "tool_body")) << ::testing::PrintToString(contact_pairs());
}

// ---------------------------------------------------------------------------------------------
// tracking through the project's Simulation

// A path with its pose per arc length s (mm) and its tangent dp/ds.
struct PathShape {
  std::function<Pose(double s)> pose;
  std::function<Vec3(double s)> tangent;
  double length_mm = 0.0;
};

// The path at `speed`: a smooth ramp from rest (speed (1 - cos(pi t / T)) / 2) over `ramp_s`,
// the constant-speed print, a mirrored ramp to rest; sampled every millisecond as three pieces
// (transition, print, transition). Returns the print piece's time interval.
Trajectory sampled_print(const PathShape& path, double speed_mm_s, double ramp_s,
                         double& print_begin_s, double& print_end_s) {
  const double period_s = 0.001;
  const double ramp_mm = 0.5 * speed_mm_s * ramp_s;  // distance covered by a ramp
  const double print_s = path.length_mm / speed_mm_s;
  // arc length and speed at time t over the whole motion, s = -ramp_mm at t = 0
  const auto state = [&](double t, double& s, double& v) {
    if (t < ramp_s) {
      v = 0.5 * speed_mm_s * (1.0 - std::cos(kPi * t / ramp_s));
      s = -ramp_mm + 0.5 * speed_mm_s * (t - ramp_s / kPi * std::sin(kPi * t / ramp_s));
    } else if (t < ramp_s + print_s) {
      v = speed_mm_s;
      s = speed_mm_s * (t - ramp_s);
    } else {
      const double u = std::min(t - ramp_s - print_s, ramp_s);
      v = 0.5 * speed_mm_s * (1.0 + std::cos(kPi * u / ramp_s));
      s = path.length_mm + 0.5 * speed_mm_s * (u + ramp_s / kPi * std::sin(kPi * u / ramp_s));
    }
  };
  // piece boundaries on the millisecond grid; every sample at its own time on it
  const auto on_grid = [period_s](double t) { return std::round(t / period_s) * period_s; };
  const double times[4] = {0.0, on_grid(ramp_s), on_grid(ramp_s + print_s),
                           on_grid(2 * ramp_s + print_s)};
  std::vector<TrajectoryPiece> pieces;
  for (int p = 0; p < 3; ++p) {
    TrajectoryPiece piece;
    piece.t_begin_s = times[p];
    piece.t_end_s = times[p + 1];
    piece.path_index = p == 1 ? 0 : -1;
    piece.depositing = p == 1;
    piece.desired_speed_mm_s = p == 1 ? speed_mm_s : 0.0;
    SampledMotion motion;
    motion.period_s = period_s;
    const long count = std::lround((times[p + 1] - times[p]) / period_s);
    for (long k = 0; k <= count; ++k) {
      double s = 0.0, v = 0.0;
      state(times[p] + static_cast<double>(k) * period_s, s, v);
      const Pose pose = path.pose(s);
      motion.position_mm.push_back(pose.position_mm);
      motion.velocity_mm_s.push_back(v * path.tangent(s));
      motion.tool_axis.push_back(pose.tool_axis);
      motion.roll_rad.push_back(pose.roll_rad);
    }
    piece.motion = motion;
    pieces.push_back(piece);
  }
  print_begin_s = pieces[1].t_begin_s;
  print_end_s = pieces[1].t_end_s;
  return Trajectory("arm6 test", std::move(pieces));
}

struct Tracking {
  double max_moving_mm = 0.0;  // while the reference moves
  double max_print_mm = 0.0;   // during the constant-speed print
  double max_whole_mm = 0.0;   // anywhere, including the settle at the end
  double peak_torque_fraction = 0.0;
};

Tracking track(const Arm6& arm, const Trajectory& trajectory, double print_begin_s,
               double print_end_s) {
  SimSettings settings;
  settings.settle_s = 0.2;
  Simulation simulation(arm6_model_path(), arm, settings);
  const RecordedRun run = simulation.run(trajectory);
  Tracking result;
  for (size_t k = 0; k < run.size(); ++k) {
    const double t = run.t_s[k];
    const TrajectorySample planned = trajectory.at(t);
    const double error_mm = (run.nozzle_mm[k] - planned.position_mm).norm();
    result.max_whole_mm = std::max(result.max_whole_mm, error_mm);
    if (t <= trajectory.duration_s() && planned.velocity_mm_s.norm() > 1e-9)
      result.max_moving_mm = std::max(result.max_moving_mm, error_mm);
    if (t >= print_begin_s && t <= print_end_s)
      result.max_print_mm = std::max(result.max_print_mm, error_mm);
  }
  const std::vector<double> limits = simulation.actuator_force_limits();
  for (size_t k = 0; k < run.size(); ++k)
    for (int j = 0; j < run.joint_count; ++j)
      result.peak_torque_fraction = std::max(
          result.peak_torque_fraction, std::abs(run.joint(run.actuator_force, k, j)) / limits[j]);
  EXPECT_EQ(run.contacts.self_events + run.contacts.other_events, 0) << run.contacts.first;
  const mjData& data = SimulationAccess::data(simulation);
  for (int kind = 0; kind < mjNWARNING; ++kind)
    EXPECT_EQ(data.warning[kind].number, 0) << "MuJoCo warning kind " << kind;
  return result;
}

// 50 mm lines with a vertical nozzle at 30 and 50 mm/s: the TCP within 0.05 mm of the plan
TEST(Arm6Tracking, FollowsPrintLines) {
  const Arm6 arm;
  for (double speed_mm_s : {30.0, 50.0}) {
    const Vec3 start(-30, -25, 5), direction = Vec3(1.0, 0.8, 0.2).normalized();
    PathShape line;
    line.length_mm = 50.0;
    line.pose = [&](double s) { return Pose(start + s * direction); };
    line.tangent = [&](double) { return direction; };
    double begin_s = 0.0, end_s = 0.0;
    const Trajectory trajectory = sampled_print(line, speed_mm_s, 0.3, begin_s, end_s);
    const Tracking tracking = track(arm, trajectory, begin_s, end_s);
    std::printf(
        "line 50 mm at %.0f mm/s: max TCP error %.2e mm while moving (%.2e mm printing, %.2e mm "
        "overall); peak torque %.0f %% of the forcerange\n",
        speed_mm_s, tracking.max_moving_mm, tracking.max_print_mm, tracking.max_whole_mm,
        100 * tracking.peak_torque_fraction);
    EXPECT_LT(tracking.max_moving_mm, 0.05);
    EXPECT_LT(tracking.max_whole_mm, 0.05);
    EXPECT_LT(tracking.peak_torque_fraction, 0.8);
  }
}

// A 20 mm radius circle at 20 mm/s with the nozzle tilted 30 deg towards the centre, turning
// with it (the roll follows the angle, joint 6 takes the whole turn)
TEST(Arm6Tracking, FollowsATiltedTurningCircle) {
  const Arm6 arm;
  const Vec3 centre(60, 0, 20);
  const double radius_mm = 20.0, tilt = deg_to_rad(30.0);
  PathShape circle;
  circle.length_mm = 2 * kPi * radius_mm;
  circle.pose = [&](double s) {
    const double angle = s / radius_mm;
    const Vec3 radial(std::cos(angle), std::sin(angle), 0);
    return Pose(centre + radius_mm * radial,
                std::cos(tilt) * Vec3::UnitZ() - std::sin(tilt) * radial, angle);
  };
  circle.tangent = [&](double s) {
    const double angle = s / radius_mm;
    return Vec3(-std::sin(angle), std::cos(angle), 0);
  };
  double begin_s = 0.0, end_s = 0.0;
  const Trajectory trajectory = sampled_print(circle, 20.0, 0.3, begin_s, end_s);
  const Tracking tracking = track(arm, trajectory, begin_s, end_s);
  std::printf(
      "tilted turning circle r 20 mm at 20 mm/s: max TCP error %.2e mm while moving (%.2e mm "
      "printing, %.2e mm overall); peak torque %.0f %% of the forcerange\n",
      tracking.max_moving_mm, tracking.max_print_mm, tracking.max_whole_mm,
      100 * tracking.peak_torque_fraction);
  EXPECT_LT(tracking.max_moving_mm, 0.05);
  EXPECT_LT(tracking.max_whole_mm, 0.05);
  EXPECT_LT(tracking.peak_torque_fraction, 0.8);
}

// The nozzle driven down 20 mm from 10 mm above the table: the simulation records a contact
// event with the table (none of the arm with itself), names it first, when the tip has gone
// 3 mm into the table (the nozzle's last 3 mm are visual only), and only one: it stays
TEST(Arm6Tracking, ANozzleDrivenIntoTheTableIsRecordedAsOneContactWithTheTable) {
  const Arm6 arm;
  const Vec3 start(0, 0, 10), down(0, 0, -1);
  PathShape line;
  line.length_mm = 20.0;
  line.pose = [&](double s) { return Pose(start + s * down); };
  line.tangent = [&](double) { return down; };
  double begin_s = 0.0, end_s = 0.0;
  const double speed_mm_s = 20.0, ramp_s = 0.1;
  const Trajectory trajectory = sampled_print(line, speed_mm_s, ramp_s, begin_s, end_s);
  SimSettings settings;
  settings.settle_s = 0.2;
  Simulation simulation(arm6_model_path(), arm, settings);
  const RecordedRun run = simulation.run(trajectory);
  EXPECT_EQ(run.contacts.other_events, 1) << run.contacts.first;
  EXPECT_EQ(run.contacts.self_events, 0);
  EXPECT_NE(run.contacts.first.find("table"), std::string::npos) << run.contacts.first;
  EXPECT_NE(run.contacts.first.find("tool_nozzle_tip"), std::string::npos) << run.contacts.first;
  // z = -3 mm at s = 13 mm, reached at the constant speed (s = v (t - ramp_s))
  double first_s = -1.0;
  ASSERT_EQ(std::sscanf(run.contacts.first.c_str(), "t = %lf s", &first_s), 1);
  EXPECT_NEAR(first_s, ramp_s + 13.0 / speed_mm_s, 0.01) << run.contacts.first;
}

}  // namespace
}  // namespace depotwin
