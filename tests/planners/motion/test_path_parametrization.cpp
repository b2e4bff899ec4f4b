// The time-optimal path parametrisation (TOPP-RA, Pham & Pham 2018) against closed forms
// (the trapezoid on a line, the centripetal bound on a circle), a planar 2-link arm whose
// joint velocity limit binds near its reach, and a brute-force dynamic programme over the
// same discretised problem (time-optimality).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "planners/motion/path_parametrization.hpp"

namespace depotwin {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// a straight line from `from` along unit `dir`, grid step ds, speed bound `speed`
PathGrid line_grid(const Vec3& from, const Vec3& dir, double length, double ds, double speed) {
  PathGrid grid;
  grid.name = "test line";
  const int steps = static_cast<int>(std::ceil(length / ds));
  for (int i = 0; i <= steps; ++i) {
    PathPoint p;
    p.s_mm = length * i / steps;
    p.position_mm = from + p.s_mm * dir;
    p.d1_after = p.d1_before = dir;
    p.d2_after = p.d2_before = Vec3::Zero();
    p.speed_mm_s = speed;
    grid.points.push_back(p);
  }
  return grid;
}

// a circle of radius r in the xy-plane about the origin, from angle 0, `turns` times round
PathGrid circle_grid(double r, double turns, double ds, double speed) {
  PathGrid grid;
  grid.name = "test circle";
  const double length = 2 * kPi * r * turns;
  const int steps = static_cast<int>(std::ceil(length / ds));
  for (int i = 0; i <= steps; ++i) {
    PathPoint p;
    p.s_mm = length * i / steps;
    const double phi = p.s_mm / r;
    p.position_mm = Vec3(r * std::cos(phi), r * std::sin(phi), 0.0);
    p.d1_after = p.d1_before = Vec3(-std::sin(phi), std::cos(phi), 0.0);
    p.d2_after = p.d2_before = -Vec3(std::cos(phi), std::sin(phi), 0.0) / r;
    p.speed_mm_s = speed;
    grid.points.push_back(p);
  }
  return grid;
}

// A planar 2-link arm in the xy-plane (links 100 and 80 mm, elbow up): the joint angles of a
// TCP position, analytically; false out of reach.
constexpr double kL1 = 100.0, kL2 = 80.0;
bool arm_inverse(const Vec3& p, JointVector& q) {
  const double r2 = p.x() * p.x() + p.y() * p.y();
  const double c2 = (r2 - kL1 * kL1 - kL2 * kL2) / (2 * kL1 * kL2);
  if (c2 > 1.0 || c2 < -1.0) return false;
  const double q2 = std::acos(c2);
  const double q1 = std::atan2(p.y(), p.x()) - std::atan2(kL2 * std::sin(q2), kL1 + kL2 * c2);
  q = {q1, q2};
  return true;
}

JointMap arm_map(double v_max, double a_max) {
  JointMap map;
  map.limits = {JointLimit{"shoulder", -10, 10, v_max, a_max, 0},
                JointLimit{"elbow", -10, 10, v_max, a_max, 0}};
  map.solve = [](const std::vector<Pose>& poses, std::vector<JointVector>& joints,
                 std::string* why) {
    joints.resize(poses.size());
    for (size_t i = 0; i < poses.size(); ++i) {
      if (!arm_inverse(poses[i].position_mm, joints[i])) {
        if (why) *why = "pose " + std::to_string(i) + ": out of reach";
        return false;
      }
    }
    return true;
  };
  return map;
}

// dq/ds and d2q/ds2 of the arm along a straight line p(s) = from + s dir, by central
// differences of the analytic inverse with a small step (1e-9 accurate here)
void arm_rates(const Vec3& from, const Vec3& dir, double s, JointVector& d1, JointVector& d2) {
  const double h = 1e-3;
  JointVector a, b, c;
  arm_inverse(from + (s - h) * dir, a);
  arm_inverse(from + s * dir, b);
  arm_inverse(from + (s + h) * dir, c);
  d1 = {(c[0] - a[0]) / (2 * h), (c[1] - a[1]) / (2 * h)};
  d2 = {(c[0] - 2 * b[0] + a[0]) / (h * h), (c[1] - 2 * b[1] + a[1]) / (h * h)};
}

// every row of the discretised problem at every grid point, both sides of each interval
void expect_rows_hold(const PathGrid& grid, const TimeLaw& law,
                      const std::vector<MachineLimits>& limits, double tolerance) {
  for (size_t i = 0; i + 1 < grid.points.size(); ++i) {
    const double u = law.u[i];
    for (const size_t end : {i, i + 1}) {
      const PathPoint& p = grid.points[end];
      const Vec3& d1 = end == i ? p.d1_after : p.d1_before;
      const Vec3& d2 = end == i ? p.d2_after : p.d2_before;
      const double x = law.x[end];
      ASSERT_LE(std::sqrt(x) * d1.norm(), p.speed_mm_s * (1 + tolerance)) << "point " << end;
      for (int axis = 0; axis < 3; ++axis) {
        const AxisLimits& lim = limits[i].axes[axis];
        ASSERT_LE(std::abs(d1[axis]) * std::sqrt(x), lim.v_max_mm_s * (1 + tolerance))
            << "axis " << axis << " point " << end;
        ASSERT_LE(std::abs(d1[axis] * u + d2[axis] * x), lim.a_max_mm_s2 * (1 + tolerance))
            << "axis " << axis << " point " << end;
      }
      if (!grid.has_joints()) continue;
      for (size_t j = 0; j < grid.joint_limits.size(); ++j) {
        const double dq = end == i ? grid.dq_after[end][j] : grid.dq_before[end][j];
        const double ddq = end == i ? grid.ddq_after[end][j] : grid.ddq_before[end][j];
        ASSERT_LE(std::abs(dq) * std::sqrt(x), grid.joint_limits[j].v_max * (1 + tolerance))
            << "joint " << j << " point " << end;
        ASSERT_LE(std::abs(dq * u + ddq * x), grid.joint_limits[j].a_max * (1 + tolerance))
            << "joint " << j << " point " << end;
      }
    }
  }
}

// the sampled motion's cubic Hermite interpolation within the TCP limits at every sample
// period's ends (what a Trajectory interpolates; its acceleration is linear in between)
void expect_samples_within(const PathSamples& samples, const MachineLimits& limits) {
  const double h = samples.period_s;
  for (size_t k = 0; k + 1 < samples.size(); ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      const double c =
          6 * (samples.position_mm[k + 1][axis] - samples.position_mm[k][axis]) / (h * h);
      const double v0 = samples.velocity_mm_s[k][axis], v1 = samples.velocity_mm_s[k + 1][axis];
      const double a0 = c - (4 * v0 + 2 * v1) / h, a1 = -c + (2 * v0 + 4 * v1) / h;
      const AxisLimits& lim = limits.axes[axis];
      ASSERT_LE(std::abs(a0), lim.a_max_mm_s2 * (1 + 1e-6)) << "axis " << axis << " k " << k;
      ASSERT_LE(std::abs(a1), lim.a_max_mm_s2 * (1 + 1e-6)) << "axis " << axis << " k " << k;
      ASSERT_LE(std::abs(v0), lim.v_max_mm_s * (1 + 1e-9)) << "axis " << axis << " k " << k;
    }
  }
}

// ---------------------------------------------------------------------------------------
// straight line: the closed-form trapezoid

TEST(PathParametrization, StraightLineIsTheClosedFormTrapezoid) {
  // along (3, 4, 0) / 5 with per-axis limits: y binds (0.8 of the path), so the path's
  // cruise speed is v / 0.8 and its acceleration a / 0.8
  const Vec3 dir = Vec3(3, 4, 0) / 5.0;
  const double length = 30.0, v = 8.0, a = 60.0;
  const MachineLimits limits = MachineLimits::uniform(v, a);
  const PathGrid grid = line_grid(Vec3(1, 2, 3), dir, length, 0.05, kInf);
  const std::vector<MachineLimits> per_interval(grid.points.size() - 1, limits);
  const TimeLaw law = parametrize_path(grid, per_interval);
  const double cruise = v / 0.8, accel = a / 0.8;
  const double expected = length / cruise + cruise / accel;
  EXPECT_NEAR(law.duration_s(), expected, 1e-3 * expected);
  // the cruise speed exactly, wherever the ramps are done
  const double ramp = cruise * cruise / (2 * accel);
  for (size_t i = 0; i < grid.points.size(); ++i) {
    const double s = grid.points[i].s_mm;
    if (s > ramp + 0.1 && s < length - ramp - 0.1) {
      EXPECT_EQ(law.sdot(i), cruise) << "s " << s;
    }
    if (s < ramp - 0.1) {
      EXPECT_NEAR(law.sdot(i), std::sqrt(2 * accel * s), 1e-9 * cruise) << "s " << s;
    }
  }
  expect_rows_hold(grid, law, per_interval, 1e-9);

  // at 1 ms: the cruise samples at the cruise velocity exactly, the interpolation within limits
  const TimedPath timed = time_path(grid, per_interval, 0.001);
  const PathSamples& samples = timed.samples;
  // the sampled law starts late by less than a period, to end on a whole period; it has 99 %
  // of the TCP's a_max (kSampledAccelMargin), and 85 % of that over its first 10 periods (here
  // the first grid interval, 0.05 mm): the closed-form trapezoid of those accelerations
  EXPECT_GE(samples.duration_s() - timed.law.duration_s(), 0.0);
  EXPECT_LT(samples.duration_s() - timed.law.duration_s(), 0.001);
  const double a2 = 0.99 * accel, a1 = 0.85 * a2, ds = 0.05;
  const double t1 = std::sqrt(2 * ds / a1), v1 = a1 * t1;
  const double ramps = t1 + (cruise - v1) / a2 + cruise / a2;
  const double ramp_length =
      ds + (cruise * cruise - v1 * v1) / (2 * a2) + cruise * cruise / (2 * a2);
  const double margined = ramps + (length - ramp_length) / cruise;
  EXPECT_NEAR(timed.law.duration_s(), margined, 1e-3 * margined);
  EXPECT_GT(timed.law.duration_s(), law.duration_s());
  EXPECT_EQ(samples.position_mm.front(), grid.points.front().position_mm);
  EXPECT_EQ(samples.position_mm.back(), grid.points.back().position_mm);
  EXPECT_EQ(samples.velocity_mm_s.back(), Vec3::Zero());
  int cruising = 0;
  for (size_t k = 0; k < samples.size(); ++k) {
    const double s = samples.s_mm[k];
    if (s < ramp + 0.1 || s > length - ramp - 0.1) continue;
    ++cruising;
    // to rounding (the quintic's derivative from positions of up to 24 mm)
    EXPECT_NEAR((samples.velocity_mm_s[k] - cruise * dir).norm(), 0.0, 1e-10) << "k " << k;
  }
  EXPECT_GT(cruising, 2000);
  // the ramps' ends, where the acceleration steps inside a period, needed velocity fits
  EXPECT_LE(samples.adjusted_samples, 12);
  EXPECT_EQ(timed.repair_rounds, 0);
  expect_samples_within(samples, limits);
}

// A desired speed that steps down in the middle: the optimal law brakes exactly in time
// (closed form: accelerate, cruise, brake to the lower speed right at the step, cruise, stop).
TEST(PathParametrization, SpeedStepIsMetByBrakingJustInTime) {
  const double length = 40.0, v1 = 20.0, v2 = 5.0, a = 100.0;
  PathGrid grid = line_grid(Vec3::Zero(), Vec3::UnitX(), length, 0.02, v1);
  for (PathPoint& p : grid.points)
    if (p.s_mm >= 20.0) p.speed_mm_s = v2;
  const MachineLimits limits = MachineLimits::uniform(1000.0, a);
  const TimeLaw law = parametrize_path(grid, {grid.points.size() - 1, limits});
  const double brake = (v1 * v1 - v2 * v2) / (2 * a);
  const double expected = v1 / a + (20.0 - v1 * v1 / (2 * a) - brake) / v1 + (v1 - v2) / a +
                          (20.0 - v2 * v2 / (2 * a)) / v2 + v2 / a;
  EXPECT_NEAR(law.duration_s(), expected, 1e-3 * expected);
  // braking ends exactly at the step
  for (size_t i = 0; i < grid.points.size(); ++i) {
    const double s = grid.points[i].s_mm;
    if (s > 20.0 - brake + 0.05 && s < 20.0) {
      EXPECT_NEAR(law.sdot(i), std::sqrt(v2 * v2 + 2 * a * (20.0 - s)), 1e-9 * v1) << "s " << s;
    }
  }
}

// ---------------------------------------------------------------------------------------
// circle: the centripetal bound

TEST(PathParametrization, CircleObeysTheCentripetalBoundPerAxis) {
  const double r = 10.0, a = 100.0;
  const MachineLimits limits = MachineLimits::uniform(1000.0, a);
  const PathGrid grid = circle_grid(r, 1.0, 0.01, 1000.0);
  const std::vector<MachineLimits> per_interval(grid.points.size() - 1, limits);
  const TimeLaw law = parametrize_path(grid, per_interval);
  expect_rows_hold(grid, law, per_interval, 1e-9);
  // where the centripetal acceleration is along one axis (phi = k pi / 2) and the tangent
  // along the other, that axis' row is v^2 / r <= a alone: the speed is sqrt(a r) at most,
  // and the time-optimal law reaches it at the interior ones
  const double bound = std::sqrt(a * r);
  for (const double phi : {kPi / 2, kPi, 3 * kPi / 2}) {
    const size_t i = static_cast<size_t>(
        std::lround(phi * r / 0.01 * (grid.points.size() - 1) / (2 * kPi * r / 0.01)));
    ASSERT_NEAR(grid.points[i].s_mm / r, phi, 1e-9);
    EXPECT_LE(law.sdot(i), bound * (1 + 1e-9)) << "phi " << phi;
    EXPECT_GE(law.sdot(i), bound * (1 - 1e-3)) << "phi " << phi;
  }
  // the sampled motion keeps the per-axis limits too
  const TimedPath timed = time_path(grid, per_interval, 0.001);
  expect_samples_within(timed.samples, limits);
}

// ---------------------------------------------------------------------------------------
// a planar 2-link arm: the joint velocity limit binds near the reach

TEST(PathParametrization, ArmJointVelocityLimitBindsAndEveryLimitHolds) {
  // a line at x = 170 from y = -60 to 60: r goes 180.3 .. 170 .. 180.3, near the full reach
  // 180 mm: the elbow swings fast there
  const Vec3 from(170.0, -50.0, 0.0), dir = Vec3::UnitY();
  const double length = 100.0, v_joint = 0.5, a_joint = 200.0;
  PathGrid grid = line_grid(from, dir, length, 0.05, 200.0);
  const JointMap map = arm_map(v_joint, a_joint);
  attach_joints(grid, map);
  const MachineLimits tcp = MachineLimits::uniform(500.0, 10000.0);
  const std::vector<MachineLimits> per_interval(grid.points.size() - 1, tcp);
  const TimeLaw law = parametrize_path(grid, per_interval);
  expect_rows_hold(grid, law, per_interval, 1e-9);

  // a joint's velocity limit binds over most of the path: each point's speed is v_j over the
  // largest rate |q_j'| over its two intervals (to a grid step's change of the rate)
  int binding = 0;
  for (size_t i = 1; i + 1 < grid.points.size(); ++i) {
    double ratio = 0.0;
    for (size_t j = 0; j < 2; ++j) {
      const double rate = std::max(std::abs(grid.dq_after[i][j]), std::abs(grid.dq_before[i][j]));
      ratio = std::max(ratio, law.sdot(i) * rate / v_joint);
    }
    if (ratio >= 1 - 2e-3) ++binding;
    EXPECT_LE(ratio, 1 + 1e-9);
    EXPECT_LT(law.sdot(i), 200.0);
  }
  EXPECT_GT(binding, 1000);
  // the finite differences match the analytic joint rates (second order in the grid step)
  for (size_t i = 0; i < grid.points.size(); i += 37) {
    JointVector d1, d2;
    arm_rates(from, dir, grid.points[i].s_mm, d1, d2);
    for (size_t j = 0; j < 2; ++j) {
      EXPECT_NEAR(grid.dq_after[i][j], d1[j], 1e-5 * (std::abs(d1[j]) + 1e-3)) << i;
      EXPECT_NEAR(grid.ddq_after[i][j], d2[j], 2e-3 * (std::abs(d2[j]) + 1e-3)) << i;
    }
  }
  // between grid points, at 1 ms: the joint rates from the law's s, sdot, sddot and the
  // analytic arm stay within the limits to 1e-3 (x is linear in s on an interval while q' and
  // q'' vary: a second-order error in the grid step)
  double worst_v = 0.0, worst_a = 0.0;
  size_t hint = 0;
  for (double t = 0.0; t <= law.duration_s(); t += 0.001) {
    double s = 0, sdot = 0, sddot = 0;
    law.state(t, s, sdot, sddot, &hint);
    JointVector d1, d2;
    arm_rates(from, dir, s, d1, d2);
    for (size_t j = 0; j < 2; ++j) {
      worst_v = std::max(worst_v, std::abs(d1[j] * sdot) / v_joint);
      worst_a = std::max(worst_a, std::abs(d1[j] * sddot + d2[j] * sdot * sdot) / a_joint);
    }
  }
  EXPECT_LE(worst_v, 1 + 1e-3);
  EXPECT_LE(worst_a, 1 + 1e-3);
  EXPECT_GT(worst_v, 1 - 2e-3);  // it does bind
  // and the sampled TCP motion within its limits
  const TimedPath timed = time_path(grid, per_interval, 0.001);
  expect_samples_within(timed.samples, tcp);
}

// A made-up joint q = -(L / pi) cos(pi s / L) along a line (q' = sin(pi s / L), largest in the
// middle) whose velocity limit is below the path's speed: the law passes the middle at
// exactly v_j / |q'| = v_j, and nowhere faster than the joint allows.
TEST(PathParametrization, MadeUpJointBindsAtItsPeak) {
  const double length = 20.0, v_joint = 0.5;
  PathGrid grid = line_grid(Vec3::Zero(), Vec3::UnitX(), length, 0.05, 10.0);
  grid.joint_limits = {JointLimit{"wave", -100, 100, v_joint, 100.0, 0}};
  for (const PathPoint& p : grid.points)
    grid.q.push_back({-(length / kPi) * std::cos(kPi * p.s_mm / length)});
  joint_derivatives_by_differences(grid);
  const MachineLimits tcp = MachineLimits::uniform(100.0, 1000.0);
  const std::vector<MachineLimits> per_interval(grid.points.size() - 1, tcp);
  const TimeLaw law = parametrize_path(grid, per_interval);
  expect_rows_hold(grid, law, per_interval, 1e-9);
  const size_t middle = (grid.points.size() - 1) / 2;
  ASSERT_DOUBLE_EQ(grid.points[middle].s_mm, length / 2);
  // the 3-point difference's error, h^2 q''' / 6 = 1.03e-5
  EXPECT_NEAR(grid.dq_after[middle][0], 1.0, 1.1e-5);
  EXPECT_NEAR(law.sdot(middle), v_joint / std::abs(grid.dq_after[middle][0]), 1e-9);
  // the joint rate q' sdot at 1 ms, with the analytic q'
  size_t hint = 0;
  double worst = 0.0;
  for (double t = 0.0; t <= law.duration_s(); t += 0.001) {
    double s = 0, sdot = 0, sddot = 0;
    law.state(t, s, sdot, sddot, &hint);
    worst = std::max(worst, std::sin(kPi * s / length) * sdot / v_joint);
  }
  EXPECT_LE(worst, 1 + 1.1e-5);
  EXPECT_GT(worst, 1 - 1e-6);
}

// ---------------------------------------------------------------------------------------
// time-optimality: a brute-force dynamic programme over sdot^2 levels on the same grid and
// the same rows (both ends of every interval) never beats TOPP-RA, and approaches it

double brute_force_time(const PathGrid& grid, const std::vector<MachineLimits>& limits,
                        int levels) {
  const size_t n = grid.points.size();
  std::vector<double> x_cap(n, kInf);
  for (size_t i = 0; i < n; ++i) {
    const PathPoint& p = grid.points[i];
    x_cap[i] = p.speed_mm_s * p.speed_mm_s / p.d1_after.squaredNorm();
    for (size_t j = 0; j < grid.joint_limits.size(); ++j) {
      const double dq = std::max(std::abs(grid.dq_after[i][j]), std::abs(grid.dq_before[i][j]));
      if (dq > 0) x_cap[i] = std::min(x_cap[i], std::pow(grid.joint_limits[j].v_max / dq, 2));
    }
    for (int axis = 0; axis < 3; ++axis) {
      const double d = std::abs(p.d1_after[axis]);
      const double v = limits[std::min(i, n - 2)].axes[axis].v_max_mm_s;
      if (d > 0) x_cap[i] = std::min(x_cap[i], v * v / (d * d));
    }
  }
  double x_top = 0.0;
  for (double c : x_cap) x_top = std::max(x_top, std::min(c, 1e12));
  // levels: a uniform ladder plus each point's own cap
  const auto level = [&](size_t i, int k) {
    return k == levels ? x_cap[i] : std::min(x_cap[i], x_top * k / levels);
  };
  std::vector<double> best(levels + 1, kInf), next(levels + 1);
  best[0] = 0.0;
  for (size_t i = 0; i + 1 < n; ++i) {
    const double ds = grid.points[i + 1].s_mm - grid.points[i].s_mm;
    std::fill(next.begin(), next.end(), kInf);
    for (int a = 0; a <= levels; ++a) {
      if (!std::isfinite(best[a])) continue;
      const double xa = level(i, a);
      for (int b = 0; b <= levels; ++b) {
        const double xb = (i + 2 == n) ? (b == 0 ? 0.0 : -1.0) : level(i + 1, b);
        if (xb < 0.0 || xa + xb <= 0.0) continue;
        const double u = (xb - xa) / (2 * ds);
        bool ok = true;
        for (int end = 0; end < 2 && ok; ++end) {
          const PathPoint& p = grid.points[i + end];
          const Vec3& d1 = end == 0 ? p.d1_after : p.d1_before;
          const Vec3& d2 = end == 0 ? p.d2_after : p.d2_before;
          const double x = end == 0 ? xa : xb;
          for (int axis = 0; axis < 3 && ok; ++axis)
            ok = std::abs(d1[axis] * u + d2[axis] * x) <= limits[i].axes[axis].a_max_mm_s2;
          for (size_t j = 0; j < grid.joint_limits.size() && ok; ++j) {
            const double dq = end == 0 ? grid.dq_after[i][j] : grid.dq_before[i + 1][j];
            const double ddq = end == 0 ? grid.ddq_after[i][j] : grid.ddq_before[i + 1][j];
            ok = std::abs(dq * u + ddq * x) <= grid.joint_limits[j].a_max;
          }
        }
        if (!ok) continue;
        const double t = best[a] + 2 * ds / (std::sqrt(xa) + std::sqrt(xb));
        next[b] = std::min(next[b], t);
      }
    }
    best.swap(next);
  }
  return best[0];
}

TEST(PathParametrization, NoBruteForceLawIsFaster) {
  // the arm near its reach: velocity, acceleration and joint limits all bind somewhere
  const Vec3 from(170.0, -30.0, 0.0), dir = Vec3::UnitY();
  PathGrid grid = line_grid(from, dir, 60.0, 0.5, 40.0);
  attach_joints(grid, arm_map(0.5, 2.0));
  const MachineLimits tcp = MachineLimits::uniform(30.0, 100.0);
  const std::vector<MachineLimits> per_interval(grid.points.size() - 1, tcp);
  const TimeLaw law = parametrize_path(grid, per_interval);
  const double coarse = brute_force_time(grid, per_interval, 100);
  const double fine = brute_force_time(grid, per_interval, 800);
  EXPECT_GE(coarse, law.duration_s() * (1 - 1e-9));
  EXPECT_GE(fine, law.duration_s() * (1 - 1e-9));
  EXPECT_LE(fine, coarse);
  EXPECT_LE(fine, law.duration_s() * 1.01);
}

// ---------------------------------------------------------------------------------------
// boundary speeds and infeasible paths

TEST(PathParametrization, GivenBoundarySpeeds) {
  const MachineLimits limits = MachineLimits::uniform(100.0, 50.0);
  const PathGrid grid = line_grid(Vec3::Zero(), Vec3::UnitX(), 10.0, 0.05, 10.0);
  TimeLawOptions options;
  options.sdot_begin = 10.0;  // already cruising, braking to rest
  const TimeLaw law = parametrize_path(grid, {grid.points.size() - 1, limits}, options);
  EXPECT_EQ(law.sdot(0), 10.0);
  EXPECT_NEAR(law.duration_s(), (10.0 - 1.0) / 10.0 + 10.0 / 50.0, 1e-3);
  options.sdot_end = 200.0;  // beyond the axis' v_max
  try {
    parametrize_path(grid, {grid.points.size() - 1, limits}, options);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test line"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot end"), std::string::npos) << e.what();
  }
}

TEST(PathParametrization, NoWayThroughIsAnInputErrorSayingWhere) {
  const MachineLimits limits = MachineLimits::uniform(100.0, 50.0);
  // two neighbouring points where a joint would have to turn 1e200 rad per mm (its velocity
  // limit allows no speed there): the path cannot go on (no acceleration limit on that joint)
  PathGrid grid = line_grid(Vec3::Zero(), Vec3::UnitX(), 10.0, 0.5, 10.0);
  grid.joint_limits = {JointLimit{"stuck", -1, 1, 1.0, 0.0, 0}};
  grid.q.assign(grid.points.size(), JointVector{0.0});
  joint_derivatives_by_differences(grid);
  for (size_t i = 0; i < grid.points.size(); ++i)
    grid.dq_after[i][0] = grid.dq_before[i][0] = (i == 8 || i == 9) ? 1e200 : 0.0;
  try {
    parametrize_path(grid, {grid.points.size() - 1, limits});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("test line"), std::string::npos) << what;
    // the velocity bound takes the largest rate over both intervals at a point, so the points
    // next to them have no speed either: the first stopped interval starts at point 7
    EXPECT_NE(what.find("s = 3.5000 mm"), std::string::npos) << what;
    EXPECT_NE(what.find("joint 'stuck' velocity limit"), std::string::npos) << what;
  }
  // a single point that allows no speed (a stop) is passed through at rest
  PathGrid stop = line_grid(Vec3::Zero(), Vec3::UnitX(), 10.0, 0.5, 10.0);
  stop.points[8].speed_mm_s = 0.0;
  const TimeLaw law = parametrize_path(stop, {stop.points.size() - 1, limits});
  EXPECT_EQ(law.x[8], 0.0);
  EXPECT_GT(law.x[7], 0.0);
  EXPECT_GT(law.x[9], 0.0);

  // a pose the arm cannot reach: named with where it is on the path
  PathGrid far = line_grid(Vec3(150, 0, 0), Vec3::UnitX(), 50.0, 0.5, 10.0);
  far.name = "print path 7";
  try {
    attach_joints(far, arm_map(1.0, 1.0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("print path 7"), std::string::npos) << what;
    EXPECT_NE(what.find("s = 30.5000 mm"), std::string::npos) << what;
    EXPECT_NE(what.find("out of reach"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace depotwin
