// The curve math of Giberti et al. 2017 (papers/001): eqs. (4)-(5), (7)-(8), (11)-(24).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "planners/motion/bezier/bezier_curve.hpp"

namespace depotwin {
namespace {

// a corner turning by `turn_deg` in the xy-plane with fillet distance delta
BezierBlend corner_blend(double turn_deg, double delta_mm, double weight) {
  const double turn = deg_to_rad(turn_deg);
  return BezierBlend::at_corner(Vec3(10, 5, 1), Vec3(1, 0, 0),
                                Vec3(std::cos(turn), std::sin(turn), 0.0), delta_mm, weight);
}

TEST(BezierCurve, WeightOneIsThePolynomialParabola) {
  // eq. (8) and its derivatives by eq. (7)
  const BezierBlend blend = corner_blend(70.0, 0.8, 1.0);
  const Vec3 &e = blend.entry_mm, &c = blend.corner_mm, &x = blend.exit_mm;
  for (double u = 0.0; u <= 1.0; u += 0.05) {
    Vec3 p, d1, d2;
    blend.derivatives(u, p, d1, d2);
    const Vec3 parabola = (1 - u) * (1 - u) * e + 2 * u * (1 - u) * c + u * u * x;
    const Vec3 first = 2 * (1 - u) * (c - e) + 2 * u * (x - c);
    const Vec3 second = 2 * (e - 2 * c + x);
    EXPECT_LT((p - parabola).norm(), 1e-12);
    EXPECT_LT((d1 - first).norm(), 1e-12);
    EXPECT_LT((d2 - second).norm(), 1e-12);
  }
}

TEST(BezierCurve, DerivativesMatchFloatersFormsAndFiniteDifferences) {
  // eqs. (15)-(22) for the first derivative, eq. (23) (index typo fixed) for the second
  for (double w : {0.05, 0.4, 1.0, 2.7, 30.0}) {
    const BezierBlend blend = corner_blend(115.0, 1.3, w);
    for (double u = 0.02; u < 1.0; u += 0.06) {
      Vec3 p, d1, d2;
      blend.derivatives(u, p, d1, d2);
      EXPECT_LT((d1 - floater_first_derivative(blend, u)).norm(), 1e-10 * (1 + d1.norm())) << w;
      EXPECT_LT((d2 - floater_second_derivative(blend, u)).norm(), 1e-9 * (1 + d2.norm())) << w;
      const double h = 1e-5;
      Vec3 pa, pb, d1a, d1b, unused;
      blend.derivatives(u - h, pa, d1a, unused);
      blend.derivatives(u + h, pb, d1b, unused);
      EXPECT_LT(((pb - pa) / (2 * h) - d1).norm(), 1e-6 * (1 + d1.norm())) << w;
      EXPECT_LT(((d1b - d1a) / (2 * h) - d2).norm(), 1e-5 * (1 + d2.norm())) << w;
    }
  }
}

// distance from the corner to the nearest point of the blend, on a fine grid of u
double nearest_to_corner(const BezierBlend& blend) {
  double nearest = 1e300;
  for (int i = 0; i <= 20000; ++i)
    nearest = std::min(nearest, (blend.point(i / 20000.0) - blend.corner_mm).norm());
  return nearest;
}

TEST(BezierCurve, DistanceToCornerShrinksMonotonicallyAsWeightGrows) {
  // Sec. 5: a larger weight pulls the curve towards its corner. By symmetry the nearest point
  // is the apex R(1/2) = ((entry + exit)/2 + w corner) / (1 + w), at delta sin(turn/2) / (1 + w).
  const double delta = 0.9, turn_deg = 80.0;
  double previous = 1e300;
  for (double w : {0.01, 0.1, 0.5, 1.0, 1.5, 3.0, 10.0, 100.0}) {
    const double nearest = nearest_to_corner(corner_blend(turn_deg, delta, w));
    EXPECT_LT(nearest, previous) << "w = " << w;
    EXPECT_NEAR(nearest, delta * std::sin(deg_to_rad(turn_deg) / 2) / (1 + w), 1e-9) << w;
    previous = nearest;
  }
}

TEST(BezierCurve, StaysInsideTheSphereOfRadiusDelta) {
  // the control points lie within delta of the corner, so does their convex hull
  for (double w : {0.01, 1.0, 100.0}) {
    for (double turn : {5.0, 90.0, 170.0}) {
      const BezierBlend blend = corner_blend(turn, 0.5, w);
      for (double u = 0.0; u <= 1.0; u += 0.01)
        EXPECT_LE((blend.point(u) - blend.corner_mm).norm(), 0.5 + 1e-12);
    }
  }
}

TEST(BezierCurve, CurvatureOfTheParabolaMatchesItsClosedForm) {
  // w = 1, turn theta: kappa(1/2) = sin(theta/2) / (delta cos^2(theta/2)), kappa(0) = sin(theta) /
  // (2 delta)
  const double delta = 0.45;
  for (double turn_deg : {30.0, 90.0, 135.0}) {
    const BezierBlend blend = corner_blend(turn_deg, delta, 1.0);
    const double half = deg_to_rad(turn_deg) / 2;
    auto curvature = [&](double u) {
      Vec3 p, d1, d2;
      blend.derivatives(u, p, d1, d2);
      return d1.cross(d2).norm() / std::pow(d1.norm(), 3);
    };
    EXPECT_NEAR(curvature(0.5), std::sin(half) / (delta * std::cos(half) * std::cos(half)), 1e-9);
    EXPECT_NEAR(curvature(0.0), std::sin(2 * half) / (2 * delta), 1e-9);
  }
}

TEST(BezierCurve, ArcLengthOfTheDegenerateStraightBlend) {
  // no turn: the blend is the straight segment from entry to exit
  const BezierBlend blend = corner_blend(0.0, 0.7, 3.0);
  EXPECT_NEAR(blend.arc_length_mm(), 1.4, 1e-12);
}

TEST(BezierCurve, TaylorStepIsExactOnALine) {
  // eq. (5) on p(u) = p0 + u L dir: u advances by (v T + a T^2 / 2) / L
  const Vec3 dp_du(3.0, 4.0, 0.0);  // L = 5
  const double v = 12.0, a = 800.0, T = 0.001;
  EXPECT_DOUBLE_EQ(taylor_parameter_step(dp_du, Vec3::Zero(), v, a, T),
                   (v * T + 0.5 * a * T * T) / 5.0);
}

TEST(BezierCurve, TaylorStepOnABlendIsSecondOrder) {
  // eq. (4): one step at speed v covers v T of arc up to O(T^3); halving T cuts the
  // relative error about four times
  const BezierBlend blend = corner_blend(100.0, 0.5, 1.0);
  const double v = 20.0;
  auto relative_error = [&](double T) {
    Vec3 p, d1, d2;
    const double u0 = 0.3;
    blend.derivatives(u0, p, d1, d2);
    const double u1 = u0 + taylor_parameter_step(d1, d2, v, 0.0, T);
    return std::abs(blend.arc_length_mm(u0, u1) - v * T) / (v * T);
  };
  const double coarse = relative_error(0.0005), fine = relative_error(0.00025);
  EXPECT_GT(coarse, 0.0);
  EXPECT_NEAR(coarse / fine, 4.0, 0.5);
}

TEST(BezierCurve, JointCorrectionsInvertTheArcLength) {
  // eq. (11): the parameter at distance d from u = 0; eq. (12): the distance left from u_f
  // to u = 1. Both are 2nd-order: exact to O(d^3).
  const BezierBlend blend = corner_blend(120.0, 0.5, 1.0);
  Vec3 p, d1, d2;
  blend.derivatives(0.0, p, d1, d2);
  for (double d : {0.005, 0.01, 0.02}) {
    const double u = parameter_at_distance_from_start(d1, d2, d);
    EXPECT_NEAR(blend.arc_length_mm(0.0, u), d, 20 * d * d * d);
  }
  for (double u_f : {0.97, 0.99}) {
    Vec3 pf, d1f, d2f;
    blend.derivatives(u_f, pf, d1f, d2f);
    const double left = distance_to_end(d1f, d2f, u_f);
    const double exact = blend.arc_length_mm(u_f, 1.0);
    EXPECT_NEAR(left, exact, 20 * exact * exact * exact);
  }
}

}  // namespace
}  // namespace depotwin
