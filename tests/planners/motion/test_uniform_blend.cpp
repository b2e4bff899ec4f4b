// `uniform`'s corner geometry: the clothoid pair blend against independent oracles (numeric
// quadrature of its integrals, finite differences of its positions, the distance to the
// polyline), its tolerance band, its curvature continuity and its constant-speed limits.
#include <gtest/gtest.h>

#include <cmath>

#include "planners/motion/uniform/clothoid_blend.hpp"

namespace depotwin {
namespace {

// the distance from p to the corner's two edges (each long enough to hold the blend)
double distance_to_corner_polyline(const Vec3& p, const Vec3& corner, const Vec3& d_in,
                                   const Vec3& d_out, double edge_mm) {
  const auto to_segment = [&](const Vec3& a, const Vec3& b) {
    const Vec3 d = b - a;
    const double f = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (a + f * d - p).norm();
  };
  return std::min(to_segment(corner - edge_mm * d_in, corner),
                  to_segment(corner, corner + edge_mm * d_out));
}

Vec3 heading(double degrees) {
  return Vec3(std::cos(deg_to_rad(degrees)), std::sin(deg_to_rad(degrees)), 0.0);
}

TEST(ClothoidIntegrals, MatchSimpsonQuadrature) {
  // X(u) = int_0^u cos(phi w^2) dw, Y(u) = int_0^u sin(phi w^2) dw by composite Simpson
  for (const double phi : {0.01, 0.4, 1.0, 1.5}) {
    for (const double u : {0.3, 1.0}) {
      const int n = 2000;
      double sx = 0.0, sy = 0.0;
      for (int k = 0; k <= n; ++k) {
        const double w = u * k / n;
        const double weight = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        sx += weight * std::cos(phi * w * w);
        sy += weight * std::sin(phi * w * w);
      }
      sx *= u / (3.0 * n);
      sy *= u / (3.0 * n);
      double x = 0.0, y = 0.0;
      clothoid_integrals(phi, u, x, y);
      EXPECT_NEAR(x, sx, 1e-12) << "phi " << phi << " u " << u;
      EXPECT_NEAR(y, sy, 1e-12) << "phi " << phi << " u " << u;
    }
  }
}

// Ends on the lines, tangent to them with zero curvature; arc-length parametrised; its
// derivatives agree with finite differences of its positions; the curvature linear in arc
// length on each half and continuous (no jump anywhere, apex included).
TEST(ClothoidBlend, EndsTangentWithZeroCurvatureAndContinuousCurvature) {
  const Vec3 corner(2.0, -1.0, 0.5);
  for (const double turn_deg : {10.0, 63.43, 90.0, 135.0, 170.0}) {
    SCOPED_TRACE(testing::Message() << "turn " << turn_deg);
    const Vec3 d_in = heading(20.0), d_out = heading(20.0 + turn_deg);
    const ClothoidBlend blend(corner, d_in, d_out, 0.3);
    EXPECT_NEAR(blend.turn_rad(), deg_to_rad(turn_deg), 1e-12);
    // the ends: on the lines, T from the corner
    const double T = blend.tangent_length_mm();
    EXPECT_LT((blend.start_mm() - (corner - T * d_in)).norm(), 1e-12);
    EXPECT_LT((blend.end_mm() - (corner + T * d_out)).norm(), 1e-12);
    Vec3 p, d1, d2, d3;
    blend.at(0.0, p, d1, d2, d3);
    EXPECT_LT((d1 - d_in).norm(), 1e-12);
    EXPECT_LT(d2.norm(), 1e-12);
    blend.at(blend.length_mm(), p, d1, d2, d3);
    EXPECT_LT((p - blend.end_mm()).norm(), 1e-12);
    EXPECT_LT((d1 - d_out).norm(), 1e-12);
    EXPECT_LT(d2.norm(), 1e-12);
    // the second half's closed form meets the first at the apex
    const double L = blend.half_length_mm();
    EXPECT_LT(
        (blend.position(std::nextafter(L, 0.0)) - blend.position(std::nextafter(L, 1.0))).norm(),
        1e-12);
    // derivatives against central differences of the positions; |p'| = 1
    const double h = 1e-5;
    double previous_curvature = 0.0, largest_jump = 0.0;
    const int samples = 400;
    for (int k = 1; k < samples; ++k) {
      const double s = blend.length_mm() * k / samples;
      blend.at(s, p, d1, d2, d3);
      EXPECT_NEAR(d1.norm(), 1.0, 1e-12);
      const Vec3 fd1 = (blend.position(s + h) - blend.position(s - h)) / (2 * h);
      const Vec3 fd2 = (blend.position(s + h) - 2 * p + blend.position(s - h)) / (h * h);
      EXPECT_LT((fd1 - d1).norm(), 1e-8);
      EXPECT_LT((fd2 - d2).norm(), 2e-4 * (1 + d2.norm()));
      // the curvature is 2 phi r / L^2, r the distance to the nearer end
      const double r = std::min(s, blend.length_mm() - s);
      EXPECT_NEAR(d2.norm(), 2.0 * 0.5 * blend.turn_rad() * r / (L * L), 1e-9);
      if (k > 1) largest_jump = std::max(largest_jump, std::abs(d2.norm() - previous_curvature));
      previous_curvature = d2.norm();
    }
    // continuous: neighbouring samples differ by the curvature rate times the step, no more
    const double rate = blend.turn_rad() / (L * L);
    EXPECT_LE(largest_jump, rate * blend.length_mm() / samples * (1 + 1e-9));
  }
}

// The deviation is the largest distance from the polyline, reached at the apex, and scales
// with the size; a blend sized for a tolerance never leaves the band.
TEST(ClothoidBlend, NeverLeavesTheToleranceBand) {
  const Vec3 corner(0.0, 0.0, 0.0);
  for (const double interior_deg : {170.0, 150.0, 116.57, 90.0, 45.0, 10.0}) {
    SCOPED_TRACE(testing::Message() << "joint " << interior_deg);
    const double turn = deg_to_rad(180.0 - interior_deg);
    const Vec3 d_in = heading(-30.0), d_out = heading(-30.0 + rad_to_deg(turn));
    const double tolerance = 0.05;
    const double half = tolerance / ClothoidBlend::deviation_per_length(turn);
    const ClothoidBlend blend(corner, d_in, d_out, half);
    EXPECT_NEAR(blend.deviation_mm(), tolerance, 1e-12);
    double worst = 0.0;
    for (int k = 0; k <= 2000; ++k) {
      const double s = blend.length_mm() * k / 2000.0;
      worst = std::max(worst, distance_to_corner_polyline(blend.position(s), corner, d_in, d_out,
                                                          10.0 * blend.tangent_length_mm()));
    }
    EXPECT_LE(worst, tolerance * (1 + 1e-9));
    EXPECT_NEAR(worst, tolerance, 1e-9);  // reached at the apex
  }
}

// At the constant speed the limits allow, no axis exceeds its acceleration v^2 |p''_k| or
// jerk v^3 |p'''_k| anywhere, and one of them is reached (within the sampling slack); the least
// size for a speed inverts the bound.
TEST(ClothoidBlend, ConstantSpeedBoundKeepsEveryAxisWithinLimits) {
  MachineLimits limits = MachineLimits::uniform(100.0, 30.0, 600.0);
  limits.axes[1].a_max_mm_s2 = 20.0;
  for (const double turn_deg : {20.0, 90.0, 150.0}) {
    SCOPED_TRACE(testing::Message() << "turn " << turn_deg);
    const Vec3 d_in = heading(10.0), d_out = heading(10.0 + turn_deg);
    const BlendShape shape = ClothoidBlend::unit_shape(d_in, d_out);
    for (const double half : {0.05, 0.4}) {
      const double v = blend_speed_bound(shape, half, limits);
      const ClothoidBlend blend(Vec3::Zero(), d_in, d_out, half);
      double tightest = 0.0;
      for (int k = 0; k <= 4000; ++k) {
        const double s = blend.length_mm() * k / 4000.0;
        Vec3 p, d1, d2, d3;
        blend.at(s, p, d1, d2, d3);
        for (int axis = 0; axis < 3; ++axis) {
          const double a = v * v * std::abs(d2[axis]) / limits.axes[axis].a_max_mm_s2;
          const double j = v * v * v * std::abs(d3[axis]) / limits.axes[axis].j_max_mm_s3;
          EXPECT_LE(a, 1.0);
          EXPECT_LE(j, 1.0);
          tightest = std::max({tightest, a, j});
        }
      }
      EXPECT_GT(tightest, 0.995);
      EXPECT_NEAR(blend_half_length_for_speed(shape, v, limits), half, 1e-9 * half);
    }
  }
  // a tangent that swings past an axis faster than its speed limit allows: no size helps
  MachineLimits slow_x = MachineLimits::uniform(2.0, 30.0, 600.0);
  slow_x.axes[1].v_max_mm_s = 10.0;  // the lines themselves are within both axes' limits
  const BlendShape swing = ClothoidBlend::unit_shape(heading(-80.0), heading(80.0));
  EXPECT_TRUE(std::isinf(blend_half_length_for_speed(swing, 3.0, slow_x)));
}

}  // namespace
}  // namespace depotwin
