// Linear delta kinematics: inverse/forward identities, the workspace check, the
// Jacobian and its derivative, the Cartesian-limit mapping and the load feed-forward.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kinematics/linear_delta.hpp"

namespace depotwin {
namespace {

constexpr double kWorkspaceRadiusMm = 125.0;  // documented: every point this close to the axis
constexpr double kWorkspaceTopMm = 150.0;     // and 0 <= z <= this is reachable

Vec3 random_workspace_point(std::mt19937_64& rng, double radius_mm = kWorkspaceRadiusMm) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double r_mm = radius_mm * std::sqrt(unit(rng));
  const double angle_rad = 2.0 * kPi * unit(rng);
  return Vec3(r_mm * std::cos(angle_rad), r_mm * std::sin(angle_rad), kWorkspaceTopMm * unit(rng));
}

// inverse kinematics that must succeed
JointVector solve(const LinearDelta& delta, const Vec3& tcp_mm) {
  JointVector joints;
  std::string why;
  EXPECT_TRUE(delta.inverse(tcp_mm, joints, &why)) << why;
  return joints;
}

TEST(LinearDelta, HomeMatchesClosedForm) {
  const LinearDelta delta;
  const LinearDeltaGeometry& g = delta.geometry();
  // tcp (0,0,0): platform joints 9 mm below the nozzle, every rod 160 mm from its column;
  // the carriage joints 9 + sqrt(350^2 - 160^2) mm below the nozzle: every joint at 0
  EXPECT_NEAR(g.home_carriage_height_mm(), -9.0 - std::sqrt(350.0 * 350.0 - 160.0 * 160.0), 1e-12);
  const JointVector joints = solve(delta, Vec3::Zero());
  ASSERT_EQ(joints.size(), 3u);
  for (double joint_mm : joints) EXPECT_NEAR(joint_mm, 0.0, 1e-12);
  EXPECT_TRUE(delta.forward({0.0, 0.0, 0.0}).position_mm.isZero(1e-12));

  // tcp +40 mm in y: the platform moves 40 mm away from column 1 (at 90 deg), its rods
  // now 200 mm out, so carriage 1 rises; columns 2 and 3 stay mirror images
  const JointVector moved = solve(delta, Vec3(0, 40, 0));
  EXPECT_NEAR(moved[0],
              std::sqrt(350.0 * 350.0 - 160.0 * 160.0) - std::sqrt(350.0 * 350.0 - 200.0 * 200.0),
              1e-12);
  EXPECT_GT(moved[0], 0.0);
  EXPECT_NEAR(moved[1], moved[2], 1e-12);
  // moving the TCP up by 10 mm lowers the platform, hence every carriage, by 10 mm
  const JointVector lower = solve(delta, Vec3(0, 0, 10));
  for (int arm = 0; arm < 3; ++arm) EXPECT_NEAR(lower[arm], joints[arm] - 10.0, 1e-12);

  const std::vector<JointLimit>& limits = delta.joint_limits();
  ASSERT_EQ(limits.size(), 3u);
  EXPECT_EQ(limits[0].name, "carriage1");
  EXPECT_EQ(limits[2].name, "carriage3");
  EXPECT_EQ(limits[1].v_max, 200.0);
  EXPECT_EQ(limits[1].a_max, 3000.0);
  EXPECT_EQ(delta.model_file(), "linear_delta.xml");
}

TEST(LinearDelta, InverseThenForwardIsIdentity) {
  const LinearDelta delta;
  std::mt19937_64 rng(5);
  double worst_mm = 0.0;
  for (int sample = 0; sample < 2000; ++sample) {
    const Vec3 tcp_mm = random_workspace_point(rng);
    const JointVector joints = solve(delta, tcp_mm);
    worst_mm = std::max(worst_mm, (delta.forward(joints).position_mm - tcp_mm).norm());
  }
  EXPECT_LT(worst_mm, 1e-9);
}

TEST(LinearDelta, ForwardThenInverseIsIdentity) {
  const LinearDelta delta;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> shift_mm(-30.0, 30.0);
  int checked = 0;
  for (int sample = 0; sample < 2000; ++sample) {
    // arbitrary carriage heights near a reachable pose
    JointVector joints = solve(delta, random_workspace_point(rng));
    for (double& joint_mm : joints) joint_mm += shift_mm(rng);
    const Vec3 tcp_mm = delta.forward(joints).position_mm;
    ASSERT_TRUE(tcp_mm.allFinite());
    JointVector again;
    if (!delta.inverse(tcp_mm, again)) continue;  // shifted out of the workspace
    ++checked;
    for (int arm = 0; arm < 3; ++arm) EXPECT_NEAR(again[arm], joints[arm], 1e-9);
  }
  EXPECT_GT(checked, 1000);
}

TEST(LinearDelta, ForwardOfImpossibleCarriagesIsNaN) {
  const LinearDelta delta;
  // carriages 800 mm apart in height cannot hold 350 mm rods to one point
  EXPECT_FALSE(delta.forward({0.0, 800.0, 0.0}).position_mm.allFinite());
  EXPECT_FALSE(delta.forward({300.0, 300.0}).position_mm.allFinite());
}

TEST(LinearDelta, UnreachablePointsAreRejectedWithAReason) {
  const LinearDelta delta;
  JointVector joints;
  std::string why;

  // 200 mm off-axis away from column 1 (at 90 deg): its rods lean past 55 deg
  EXPECT_FALSE(delta.inverse(Vec3(0, 200, 10), joints, &why));
  EXPECT_NE(why.find("carriage1"), std::string::npos) << why;
  EXPECT_NE(why.find("deg"), std::string::npos) << why;
  EXPECT_NE(why.find("55"), std::string::npos) << why;

  // 300 mm above the substrate the platform drops so far that the carriages leave their travel
  why.clear();
  EXPECT_FALSE(delta.inverse(Vec3(0, 0, 300), joints, &why));
  EXPECT_NE(why.find("outside its travel [-200, 125] mm"), std::string::npos) << why;

  // the nozzle cannot dig into the substrate
  why.clear();
  EXPECT_FALSE(delta.inverse(Vec3(0, 0, -5), joints, &why));
  EXPECT_NE(why.find("into the substrate"), std::string::npos) << why;

  why.clear();
  EXPECT_FALSE(delta.inverse(Vec3(NAN, 0, 0), joints, &why));
  EXPECT_FALSE(why.empty());

  // the reachable-region boundary: within reach at 125 mm in every direction
  for (int k = 0; k < 360; ++k) {
    const double angle_rad = deg_to_rad(k);
    EXPECT_TRUE(
        delta.inverse(Vec3(125 * std::cos(angle_rad), 125 * std::sin(angle_rad), 0), joints));
  }
}

// q along tcp(t) = tcp0 + v t + a t^2 / 2, by the inverse kinematics
JointVector joints_at(const LinearDelta& delta, const Vec3& tcp_mm, const Vec3& v, const Vec3& a,
                      double t_s) {
  return solve(delta, tcp_mm + v * t_s + 0.5 * a * t_s * t_s);
}

TEST(LinearDelta, JacobianAndItsDerivativeMatchFiniteDifferences) {
  const LinearDelta delta;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> velocity(-100.0, 100.0), acceleration(-2000.0, 2000.0);
  const double step_s = 1e-3;
  for (int sample = 0; sample < 300; ++sample) {
    const Vec3 tcp_mm = random_workspace_point(rng, 115.0) + Vec3(0, 0, 5);
    const Vec3 v(velocity(rng), velocity(rng), velocity(rng));
    const Vec3 a(acceleration(rng), acceleration(rng), acceleration(rng));
    const JointVector before = joints_at(delta, tcp_mm, v, a, -step_s);
    const JointVector now = joints_at(delta, tcp_mm, v, a, 0.0);
    const JointVector after = joints_at(delta, tcp_mm, v, a, step_s);
    const JointVector q_dot = delta.joint_velocity(now, v);
    const JointVector q_ddot = delta.joint_acceleration(now, v, a);
    for (int arm = 0; arm < 3; ++arm) {
      // the central difference's own error is h^2/6 q''' (up to ~1e-3 mm/s at 200 mm/s here),
      // plus the rounding of q / h: 1e-3 + 1e-5 of the rate
      EXPECT_NEAR(q_dot[arm], (after[arm] - before[arm]) / (2 * step_s),
                  1e-3 + 1e-5 * std::abs(q_dot[arm]));
      EXPECT_NEAR(q_ddot[arm], (after[arm] - 2 * now[arm] + before[arm]) / (step_s * step_s), 0.05);
    }
  }
}

struct LimitCase {
  MachineLimits requested;
  Vec3 lo, hi;
  double carriage_v_max_mm_s, carriage_a_max_mm_s2;
};

// Random points of the box, random per-axis v and a within the returned limits: the
// carriages (q' = J v, q'' = J a + J' v, both checked against finite differences of the
// inverse kinematics) stay within their limits.
TEST(LinearDelta, CartesianLimitsKeepEveryCarriageWithinItsLimits) {
  const std::vector<LimitCase> cases = {
      // loose enough: passes unchanged
      {MachineLimits::uniform(20, 500), Vec3(-50, -50, 0), Vec3(50, 50, 20), 150, 2000},
      // velocity and acceleration cut
      {MachineLimits::uniform(500, 20000), Vec3(-100, -100, 0), Vec3(100, 100, 50), 150, 2000},
      // the box corners lie outside the workspace (a 120 mm circle's box)
      {MachineLimits::uniform(1000, 200), Vec3(-120, -120, 0), Vec3(120, 120, 10), 150, 2000},
      // off-centre box
      {MachineLimits::uniform(300, 5000), Vec3(20, -80, 5), Vec3(110, 10, 6), 150, 2000},
      // weak carriages: the centripetal term needs half of their acceleration
      {MachineLimits::uniform(1000, 1000), Vec3(-100, -100, 0), Vec3(100, 100, 20), 150, 40},
  };
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0), sign(-1.0, 1.0);
  const double step_s = 1e-4;

  for (const LimitCase& c : cases) {
    LinearDelta delta;
    delta.set_carriage_limits(c.carriage_v_max_mm_s, c.carriage_a_max_mm_s2);
    const double carriage_v = c.carriage_v_max_mm_s * delta.geometry().limit_margin;
    const double carriage_a = c.carriage_a_max_mm_s2 * delta.geometry().limit_margin;
    const MachineLimits limits = delta.cartesian_limits(c.requested, c.lo, c.hi);
    ASSERT_EQ(limits.validate(), "");
    double worst_v = 0.0, worst_a = 0.0;
    int checked = 0;
    for (int sample = 0; sample < 4000; ++sample) {
      Vec3 tcp_mm, v, a;
      for (int axis = 0; axis < 3; ++axis) {
        // never looser than requested
        EXPECT_LE(limits.axes[axis].v_max_mm_s, c.requested.axes[axis].v_max_mm_s);
        EXPECT_LE(limits.axes[axis].a_max_mm_s2, c.requested.axes[axis].a_max_mm_s2);
        tcp_mm[axis] = c.lo[axis] + (c.hi[axis] - c.lo[axis]) * unit(rng);
        // half the samples on the corners of the velocity/acceleration box
        const bool extreme = sample % 2 == 0;
        v[axis] = limits.axes[axis].v_max_mm_s * (extreme ? (sign(rng) < 0 ? -1 : 1) : sign(rng));
        a[axis] = limits.axes[axis].a_max_mm_s2 * (extreme ? (sign(rng) < 0 ? -1 : 1) : sign(rng));
      }
      JointVector now;
      if (!delta.inverse(tcp_mm, now)) continue;  // box corners may lie outside the workspace
      JointVector before, after;
      if (!delta.inverse(Vec3(tcp_mm - v * step_s + 0.5 * a * step_s * step_s), before) ||
          !delta.inverse(Vec3(tcp_mm + v * step_s + 0.5 * a * step_s * step_s), after))
        continue;
      ++checked;
      const JointVector q_dot = delta.joint_velocity(now, v);
      const JointVector q_ddot = delta.joint_acceleration(now, v, a);
      for (int arm = 0; arm < 3; ++arm) {
        const double fd_velocity = (after[arm] - before[arm]) / (2 * step_s);
        const double fd_acceleration =
            (after[arm] - 2 * now[arm] + before[arm]) / (step_s * step_s);
        EXPECT_NEAR(q_dot[arm], fd_velocity, 1e-4 * carriage_v);
        EXPECT_NEAR(q_ddot[arm], fd_acceleration, 2e-3 * carriage_a);
        worst_v = std::max(worst_v, std::abs(q_dot[arm]));
        worst_a = std::max(worst_a, std::abs(q_ddot[arm]));
      }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_LE(worst_v, carriage_v);
    EXPECT_LE(worst_a, carriage_a);
    // and the bound is tight: when the request had to be cut, some carriage comes within
    // 15 % of one of its limits
    const bool cut = limits.axes[0].v_max_mm_s < c.requested.axes[0].v_max_mm_s;
    if (cut) {
      EXPECT_GT(std::max(worst_v / carriage_v, worst_a / carriage_a), 0.85);
    }
    std::printf(
        "box [%g %g %g]-[%g %g %g]: v_max %.2f mm/s, a_max %.1f mm/s^2 -> worst carriage "
        "%.2f mm/s (limit %.1f), %.1f mm/s^2 (limit %.1f)\n",
        c.lo.x(), c.lo.y(), c.lo.z(), c.hi.x(), c.hi.y(), c.hi.z(), limits.axes[0].v_max_mm_s,
        limits.axes[0].a_max_mm_s2, worst_v, carriage_v, worst_a, carriage_a);
  }
}

TEST(LinearDelta, CartesianLimitsFollowCarriageLimits) {
  LinearDelta delta;
  const MachineLimits requested = MachineLimits::uniform(1000, 1e5);
  const Vec3 lo(-60, -60, 0), hi(60, 60, 10);
  const MachineLimits fast = delta.cartesian_limits(requested, lo, hi);
  delta.set_carriage_limits(100.0, 3000.0);
  const MachineLimits slow = delta.cartesian_limits(requested, lo, hi);
  EXPECT_EQ(delta.joint_limits()[0].v_max, 100.0);
  // the velocity bound is linear in the limits: half the carriage speed, half the TCP speed
  EXPECT_NEAR(slow.axes[0].v_max_mm_s, 0.5 * fast.axes[0].v_max_mm_s, 1e-9);
  // a request well inside the carriage limits passes unchanged
  const MachineLimits gentle = MachineLimits::uniform(5, 50, 1000);
  const MachineLimits kept = delta.cartesian_limits(gentle, lo, hi);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(kept.axes[axis].v_max_mm_s, 5.0);
    EXPECT_EQ(kept.axes[axis].a_max_mm_s2, 50.0);
    EXPECT_EQ(kept.axes[axis].j_max_mm_s3, 1000.0);
  }
}

TEST(LinearDelta, FeedForwardHoldsTheWeightAndBalancesPower) {
  const LinearDeltaGeometry g;
  // at rest on the axis every carriage carries a third of the platform plus itself
  const std::array<double, 3> rest =
      linear_delta_feedforward_forces_n(g, Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
  for (double force_n : rest)
    EXPECT_NEAR(force_n, (g.platform_mass_kg / 3.0 + g.carriage_mass_kg) * g.gravity_m_s2, 1e-12);

  // moving: the carriage power equals the power into the platform and the carriages,
  // sum F_i q'_i = m_p (p'' + g e_z) . p' + sum m_c (q''_i + g) q'_i   (SI units)
  const LinearDelta delta(g);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> velocity(-80.0, 80.0), acceleration(-1500.0, 1500.0);
  for (int sample = 0; sample < 200; ++sample) {
    const Vec3 tcp_mm = random_workspace_point(rng);
    const Vec3 v(velocity(rng), velocity(rng), velocity(rng));
    const Vec3 a(acceleration(rng), acceleration(rng), acceleration(rng));
    const std::array<double, 3> forces = linear_delta_feedforward_forces_n(g, tcp_mm, v, a);
    const JointVector joints = solve(delta, tcp_mm);
    const JointVector q_dot = delta.joint_velocity(joints, v);
    const JointVector q_ddot = delta.joint_acceleration(joints, v, a);
    double carriage_power_w = 0.0, expected_power_w = 0.0;
    for (int arm = 0; arm < 3; ++arm) {
      carriage_power_w += forces[arm] * mm_to_m(q_dot[arm]);
      expected_power_w +=
          g.carriage_mass_kg * (mm_to_m(q_ddot[arm]) + g.gravity_m_s2) * mm_to_m(q_dot[arm]);
    }
    const Vec3 platform_velocity_m_s = -v / kMmPerM;
    const Vec3 platform_force_n = g.platform_mass_kg * (-a / kMmPerM + Vec3(0, 0, g.gravity_m_s2));
    expected_power_w += platform_force_n.dot(platform_velocity_m_s);
    EXPECT_NEAR(carriage_power_w, expected_power_w, 1e-9);
  }
}

TEST(LinearDelta, RegistryMakesIt) {
  const std::unique_ptr<Machine> machine = make_machine("linear_delta");
  ASSERT_TRUE(machine);
  EXPECT_EQ(machine->name(), "linear_delta");
  EXPECT_EQ(machine->joint_count(), 3);
  EXPECT_NE(dynamic_cast<const LinearDelta*>(machine.get()), nullptr);
}

TEST(LinearDelta, GeometryValidation) {
  EXPECT_EQ(LinearDeltaGeometry{}.validate(), "");
  LinearDeltaGeometry bad;
  bad.platform_radius_mm = 300.0;
  EXPECT_NE(bad.validate(), "");
  bad = LinearDeltaGeometry{};
  bad.carriage_a_max_mm_s2 = 0.0;
  EXPECT_NE(bad.validate().find("a_max"), std::string::npos);
}

}  // namespace
}  // namespace depotwin
