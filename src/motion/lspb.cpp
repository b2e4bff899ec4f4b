#include "motion/lspb.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace depotwin {

AxisProfile LspbSolution::profile(const AxisBoundary& b) const {
  AxisProfile p(b.q0, b.v0);
  p.append(t_b0, a0);
  p.append(t_b1 - t_b0, 0.0);
  p.append(duration_s - t_b1, a1);
  return p;
}

namespace {

// blend times of eqs. (5)-(6) for a candidate v_c and check eqs. (17)-(18);
// roundoff of a few ulps is clamped so that the extremal (minimum-time) profiles,
// where t_b0 == t_b1, are accepted
std::optional<LspbSolution> check_candidate(int index, double v_c, double a0, double a1,
                                            const AxisBoundary& b, double duration_s,
                                            double v_max) {
  if (!std::isfinite(v_c)) return std::nullopt;  // eq. (17): imaginary or undefined
  const double tol = 1e-10 * std::max(1.0, duration_s);
  if (std::abs(v_c) > v_max * (1.0 + 1e-12)) return std::nullopt;  // beyond the paper
  double t_b0 = (v_c - b.v0) / a0;                                 // eq. (5)
  double t_b1 = (v_c - b.v1) / a1 + duration_s;                    // eq. (6)
  // eq. (18): t0 <= t_b0 <= t_b1 <= t1
  if (t_b0 < -tol || t_b1 > duration_s + tol || t_b0 > t_b1 + tol) return std::nullopt;
  // a blend time a little outside [t0, t1] is roundoff only where its velocity change is: a
  // real change of the wrong sign is another case's profile (clamped to no blend, the cruise
  // would stay at v0 or end off v1: a 0.03 mm move in 200 s at 8000 mm/s^2 has blends of
  // 1.9e-8 s, inside `tol`, and was planned as no motion at all)
  const double roundoff_velocity =
      1e-9 * std::max({std::abs(b.v0), std::abs(b.v1), std::abs(v_c), 1e-300});
  if ((t_b0 < 0.0 && std::abs(v_c - b.v0) > roundoff_velocity) ||
      (t_b1 > duration_s && std::abs(v_c - b.v1) > roundoff_velocity))
    return std::nullopt;
  t_b0 = std::clamp(t_b0, 0.0, duration_s);
  t_b1 = std::clamp(t_b1, t_b0, duration_s);
  LspbSolution s;
  s.candidate = index;
  s.v_c = std::clamp(v_c, -v_max, v_max);
  s.a0 = a0;
  s.a1 = a1;
  s.t_b0 = t_b0;
  s.t_b1 = t_b1;
  s.duration_s = duration_s;
  return s;
}

// x + sqrt(gamma) and x - sqrt(gamma), where gamma = x^2 - product (NaN for gamma < 0): the
// one of the two that subtracts nearly equal numbers is taken as product / the other, their
// product (Vieta), so a long move's small cruise velocity keeps its digits (0.001 mm in
// 200 s at 8000 mm/s^2: x^2 / product = 6e13, and the difference kept 6e-6 of its value)
std::pair<double, double> roots_of_sum_and_difference(double x, double gamma, double product) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(gamma >= 0.0)) return {nan, nan};
  const double root = std::sqrt(gamma);
  if (x >= 0.0) {
    const double plus = x + root;
    return {plus, plus != 0.0 ? product / plus : x - root};
  }
  const double minus = x - root;
  return {minus != 0.0 ? product / minus : x + root, minus};
}

}  // namespace

std::optional<LspbSolution> solve_lspb(const AxisBoundary& b, double duration_s, double alpha,
                                       double v_max) {
  if (!(duration_s >= 0.0) || !(alpha > 0.0) || !(v_max > 0.0)) return std::nullopt;
  const double T = duration_s;
  const double d = b.q1 - b.q0;
  const double v0 = b.v0, v1 = b.v1;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::optional<LspbSolution> found;
  auto consider = [&](int index, double v_c, double a0, double a1) {
    if (!found) found = check_candidate(index, v_c, a0, a1, b, T, v_max);
  };

  // Case I, a0 = +alpha, a1 = -alpha, eqs. (11)-(12). The paper prints
  // gamma_1 with +(v0^2 + v1^2)/alpha; specialising eq. (8) gives the minus sign used here.
  const double x1 = (v0 + v1) / alpha + T;
  const double product1 = (2.0 / alpha) * ((v0 * v0 + v1 * v1) / alpha + 2.0 * d);
  const double gamma1 = x1 * x1 - product1;
  const auto [plus1, minus1] = roots_of_sum_and_difference(x1, gamma1, product1);
  consider(1, 0.5 * alpha * plus1, alpha, -alpha);
  consider(2, 0.5 * alpha * minus1, alpha, -alpha);

  // Case II, a0 = -alpha, a1 = +alpha, eqs. (13)-(14) as printed
  const double x2 = -(v0 + v1) / alpha + T;
  const double product2 = (2.0 / alpha) * ((v0 * v0 + v1 * v1) / alpha - 2.0 * d);
  const double gamma2 = x2 * x2 - product2;
  const auto [plus2, minus2] = roots_of_sum_and_difference(x2, gamma2, product2);
  consider(3, -0.5 * alpha * plus2, -alpha, alpha);
  consider(4, -0.5 * alpha * minus2, -alpha, alpha);

  // Case III, a0 = a1 = +alpha, eq. (15) (with t1 - t0 for the printed t1 + t0; t0 = 0)
  const double den5 = v0 - v1 + alpha * T;
  consider(5, den5 != 0.0 ? (alpha * d + 0.5 * (v0 * v0 - v1 * v1)) / den5 : nan, alpha, alpha);

  // Case IV, a0 = a1 = -alpha, eq. (16)
  const double den6 = v0 - v1 - alpha * T;
  consider(6, den6 != 0.0 ? (-alpha * d + 0.5 * (v0 * v0 - v1 * v1)) / den6 : nan, -alpha, -alpha);
  return found;
}

}  // namespace depotwin
