#include "planners/motion/bezier/bezier_curve.hpp"

#include <array>
#include <cmath>

#include <Eigen/Core>

namespace depotwin {

BezierBlend BezierBlend::at_corner(const Vec3& corner_mm, const Vec3& in_dir, const Vec3& out_dir,
                                   double delta_mm, double weight) {
  // Fig. 1: the entry point lies delta before the corner on the incoming line, the exit
  // point delta after it on the outgoing line. (The text calls the entry p_j^i, eq. (8)
  // calls it p_j^e; both are the same point.)
  BezierBlend blend;
  blend.entry_mm = corner_mm - delta_mm * in_dir;
  blend.corner_mm = corner_mm;
  blend.exit_mm = corner_mm + delta_mm * out_dir;
  blend.weight = weight;
  return blend;
}

BezierBlend BezierBlend::curvature_continuous_at_corner(const Vec3& corner_mm, const Vec3& in_dir,
                                                        const Vec3& out_dir, double delta_mm,
                                                        double weight) {
  BezierBlend blend = at_corner(corner_mm, in_dir, out_dir, delta_mm, weight);
  blend.degree = 4;
  return blend;
}

namespace {

// A rational Bezier's derivatives with respect to u up to the third, from its homogeneous
// control points (w_i P_i, w_i): the k-th derivative of a degree-n Bernstein sum is
// n! / (n - k)! times the sum of the k-th forward differences over degree n - k (de Casteljau),
// then the quotient rule for R = N / W.
void rational_derivatives(const Vec3* points, const double* weights, int degree, double u, Vec3& p,
                          Vec3& d1, Vec3& d2, Vec3& d3) {
  using Vec4 = Eigen::Vector4d;
  std::array<Vec4, 5> q;
  for (int i = 0; i <= degree; ++i) q[i] << weights[i] * points[i], weights[i];
  std::array<Vec4, 4> value;  // N^(k), W^(k) for k = 0..3
  double falling = 1.0;       // n! / (n - k)!
  for (int k = 0; k <= 3; ++k) {
    const int m = degree - k;  // the degree of the k-th differences
    if (m < 0) {
      value[k].setZero();
      continue;
    }
    // de Casteljau on the k-th differences
    std::array<Vec4, 5> b;
    for (int i = 0; i <= m; ++i) b[i] = q[i];
    for (int level = 1; level <= m; ++level)
      for (int i = 0; i <= m - level; ++i) b[i] = (1.0 - u) * b[i] + u * b[i + 1];
    value[k] = falling * b[0];
    falling *= m;
    // the next differences
    for (int i = 0; i < m; ++i) q[i] = q[i + 1] - q[i];
  }
  const double w = value[0][3], w1 = value[1][3], w2 = value[2][3], w3 = value[3][3];
  p = value[0].head<3>() / w;
  d1 = (value[1].head<3>() - p * w1) / w;
  d2 = (value[2].head<3>() - 2.0 * d1 * w1 - p * w2) / w;
  d3 = (value[3].head<3>() - 3.0 * d2 * w1 - 3.0 * d1 * w2 - p * w3) / w;
}

}  // namespace

void BezierBlend::derivatives(double u, Vec3& p, Vec3& dp_du, Vec3& d2p_du2, Vec3& d3p_du3) const {
  if (degree == 2) {
    const Vec3 points[3] = {entry_mm, corner_mm, exit_mm};
    const double weights[3] = {1.0, weight, 1.0};
    rational_derivatives(points, weights, 2, u, p, dp_du, d2p_du2, d3p_du3);
    return;
  }
  const Vec3 points[5] = {entry_mm, 0.5 * (entry_mm + corner_mm), corner_mm,
                          0.5 * (corner_mm + exit_mm), exit_mm};
  const double weights[5] = {1.0, 1.0, weight, 1.0, 1.0};
  rational_derivatives(points, weights, 4, u, p, dp_du, d2p_du2, d3p_du3);
}

Vec3 BezierBlend::third_arc_derivative(double u) const {
  // with s' = |p'|, T = p' / s', the curvature vector k = p''/s'^2 - g p'/s'^4 (g = p'.p''),
  // and d3p/ds3 = (dk/du) / s'
  Vec3 p, d1, d2, d3;
  derivatives(u, p, d1, d2, d3);
  const double s2 = d1.squaredNorm(), g = d1.dot(d2), g1 = d2.squaredNorm() + d1.dot(d3);
  const Vec3 dk =
      d3 / s2 - 3.0 * g * d2 / (s2 * s2) - g1 * d1 / (s2 * s2) + 4.0 * g * g * d1 / (s2 * s2 * s2);
  return dk / std::sqrt(s2);
}

Vec3 BezierBlend::point(double u) const {
  Vec3 p, d1, d2;
  derivatives(u, p, d1, d2);
  return p;
}

void BezierBlend::derivatives(double u, Vec3& p, Vec3& dp_du, Vec3& d2p_du2) const {
  if (degree != 2) {
    Vec3 d3p_du3;
    derivatives(u, p, dp_du, d2p_du2, d3p_du3);
    return;
  }
  // eq. (18) as numerator N(u) over denominator D(u) (eq. (21) with w0 = w2 = 1)
  const double v = 1.0 - u;
  const double w = weight;
  const Vec3 n = v * v * entry_mm + 2.0 * w * u * v * corner_mm + u * u * exit_mm;
  const Vec3 n1 = -2.0 * v * entry_mm + 2.0 * w * (1.0 - 2.0 * u) * corner_mm + 2.0 * u * exit_mm;
  const Vec3 n2 = 2.0 * entry_mm - 4.0 * w * corner_mm + 2.0 * exit_mm;
  const double d = v * v + 2.0 * w * u * v + u * u;
  const double d1 = -2.0 * v + 2.0 * w * (1.0 - 2.0 * u) + 2.0 * u;
  const double d2 = 4.0 - 4.0 * w;
  // quotient rule: R = N/D, R' = (N' - R D')/D, R'' = (N'' - 2 R' D' - R D'')/D
  p = n / d;
  dp_du = (n1 - p * d1) / d;
  d2p_du2 = (n2 - 2.0 * dp_du * d1 - p * d2) / d;
}

double BezierBlend::arc_length_mm(double u0, double u1) const {
  // 8-point Gauss-Legendre on 8 sub-intervals: |dp/du| is smooth, its minimum sharp only
  // for near-reversal corners
  static constexpr std::array<double, 4> kNode = {0.1834346424956498, 0.5255324099163290,
                                                  0.7966664774136267, 0.9602898564975363};
  static constexpr std::array<double, 4> kWeight = {0.3626837833783620, 0.3137066458778873,
                                                    0.2223810344533745, 0.1012285362903763};
  constexpr int kIntervals = 8;
  const double h = (u1 - u0) / kIntervals;
  double length = 0.0;
  Vec3 p, d1, d2;
  for (int i = 0; i < kIntervals; ++i) {
    const double mid = u0 + (i + 0.5) * h;
    for (size_t k = 0; k < kNode.size(); ++k) {
      for (double sign : {-1.0, 1.0}) {
        derivatives(mid + sign * 0.5 * h * kNode[k], p, d1, d2);
        length += kWeight[k] * 0.5 * h * d1.norm();
      }
    }
  }
  return length;
}

Vec3 floater_first_derivative(const BezierBlend& blend, double u) {
  // eq. (21) with w0 = w2 = 1, w1 = w
  const double v = 1.0 - u, w = blend.weight;
  const double w02 = v * v + 2.0 * w * u * v + u * u;
  // eqs. (19), (20), simplified by the common factor (1 - u) u. Eq. (16) prints the product
  // B_{j,m} B_{k,m} inside a sum over i; its expansions (19)-(20) show B_{i,m} B_{k,m} is
  // meant. Eq. (20) then writes w0 w2 in its second term where the sum gives w1 w2; the sum
  // is used here.
  const double lambda0 = 2.0 * v * (v * w + u) / (w02 * w02);
  const double lambda1 = 2.0 * u * (v + u * w) / (w02 * w02);
  // eq. (22) with the control points of eq. (18) (the paper numbers them p1..p3 there and
  // p0..p2 in eq. (22))
  return lambda0 * (blend.corner_mm - blend.entry_mm) + lambda1 * (blend.exit_mm - blend.corner_mm);
}

Vec3 floater_second_derivative(const BezierBlend& blend, double u) {
  // eq. (23) for m = 2 with the intermediate weights of eq. (17) and points of eq. (24)
  // (for m - 2 = 0 the points P_{i,0} are the control points themselves). As printed, the
  // second term uses w_{2,m-1}, which needs a weight w_3 a quadratic does not have; the
  // mirror image of the first term, w_{2,m-2}, is what matches the quotient rule.
  constexpr double m = 2.0;
  const double v = 1.0 - u, w = blend.weight;
  const double w0m = v * v + 2.0 * w * u * v + u * u;  // w_{0,2}
  const double w01 = v * 1.0 + u * w;                  // w_{0,1}
  const double w11 = v * w + u * 1.0;                  // w_{1,1}
  const double w00 = 1.0, w20 = 1.0;                   // w_{0,0}, w_{2,0}
  const double cube = w0m * w0m * w0m;
  const double first =
      m * w20 / cube * (2.0 * m * w01 * w01 - (m - 1.0) * w00 * w0m - 2.0 * w01 * w0m);
  const double second =
      m * w00 / cube * (2.0 * m * w11 * w11 - (m - 1.0) * w20 * w0m - 2.0 * w11 * w0m);
  return first * (blend.exit_mm - blend.corner_mm) - second * (blend.corner_mm - blend.entry_mm);
}

double taylor_bracket(const Vec3& dp_du, const Vec3& d2p_du2) {
  const double speed2 = dp_du.squaredNorm();
  return dp_du.dot(d2p_du2) / (speed2 * speed2);
}

double taylor_parameter_step(const Vec3& dp_du, const Vec3& d2p_du2, double speed_mm_s,
                             double accel_mm_s2, double period_s) {
  // eq. (5): u_{k+1} - u_k = v T / |p'| + T^2 / 2 (a / |p'| - v^2 [p'.p'' / |p'|^4])
  const double norm = dp_du.norm();
  return speed_mm_s * period_s / norm +
         0.5 * period_s * period_s *
             (accel_mm_s2 / norm - speed_mm_s * speed_mm_s * taylor_bracket(dp_du, d2p_du2));
}

double parameter_at_distance_from_start(const Vec3& dp_du0, const Vec3& d2p_du20,
                                        double distance_mm) {
  // eq. (11): u_i = dp / |b'(0)| - dp^2 / 2 [b'.b'' / |b'|^4]_{u=0}
  return distance_mm / dp_du0.norm() -
         0.5 * distance_mm * distance_mm * taylor_bracket(dp_du0, d2p_du20);
}

double distance_to_end(const Vec3& dp_du, const Vec3& d2p_du2, double u_f) {
  // eq. (12): c/2 dp^2 - dp / |b'| + (1 - u_f) = 0 with c = [b'.b''/|b'|^4]_{u_f}, i.e. eq.
  // (4) with u_{k+1} = 1, u_k = u_f, v_c T_s = dp (the text says "for the evaluation of
  // Delta b", it is Delta p that eq. (4) gives); the root
  // near |b'| (1 - u_f), written in the form that stays accurate as c -> 0
  const double c = taylor_bracket(dp_du, d2p_du2);
  const double inv_norm = 1.0 / dp_du.norm();
  const double remaining_u = 1.0 - u_f;
  const double discriminant = inv_norm * inv_norm - 2.0 * c * remaining_u;
  if (discriminant <= 0.0) return remaining_u / inv_norm;  // beyond the Taylor model's reach
  return 2.0 * remaining_u / (inv_norm + std::sqrt(discriminant));
}

}  // namespace depotwin
