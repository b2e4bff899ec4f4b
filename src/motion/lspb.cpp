#include "motion/lspb.hpp"

#include <algorithm>
#include <array>
#include <cmath>

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
  const double gamma1 = x1 * x1 + (2.0 / alpha) * (-(v0 * v0 + v1 * v1) / alpha - 2.0 * d);
  const double root1 = gamma1 >= 0.0 ? std::sqrt(gamma1) : nan;
  consider(1, 0.5 * alpha * (x1 + root1), alpha, -alpha);
  consider(2, 0.5 * alpha * (x1 - root1), alpha, -alpha);

  // Case II, a0 = -alpha, a1 = +alpha, eqs. (13)-(14) as printed
  const double x2 = -(v0 + v1) / alpha + T;
  const double gamma2 = x2 * x2 - (2.0 / alpha) * ((v0 * v0 + v1 * v1) / alpha - 2.0 * d);
  const double root2 = gamma2 >= 0.0 ? std::sqrt(gamma2) : nan;
  consider(3, -0.5 * alpha * (x2 + root2), -alpha, alpha);
  consider(4, -0.5 * alpha * (x2 - root2), -alpha, alpha);

  // Case III, a0 = a1 = +alpha, eq. (15) (with t1 - t0 for the printed t1 + t0; t0 = 0)
  const double den5 = v0 - v1 + alpha * T;
  consider(5, den5 != 0.0 ? (alpha * d + 0.5 * (v0 * v0 - v1 * v1)) / den5 : nan, alpha, alpha);

  // Case IV, a0 = a1 = -alpha, eq. (16)
  const double den6 = v0 - v1 - alpha * T;
  consider(6, den6 != 0.0 ? (-alpha * d + 0.5 * (v0 * v0 - v1 * v1)) / den6 : nan, -alpha, -alpha);
  return found;
}

}  // namespace depotwin
