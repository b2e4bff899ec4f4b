#include "motion/mtt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Displacement of the bang-coast-bang profile v0 -> v_c -> v1 over duration T with
// |a| = A: D(v_c) = v_c T - [(v_c - v0)|v_c - v0| + (v_c - v1)|v_c - v1|] / (2A).
// It is nondecreasing in v_c on the admissible range, which is what makes every
// duration between the extremes reachable (and the LSPB solution unique).
double displacement(double v_c, double T, double v0, double v1, double A) {
  const double e0 = v_c - v0, e1 = v_c - v1;
  return v_c * T - (e0 * std::abs(e0) + e1 * std::abs(e1)) / (2.0 * A);
}

// admissible cruise velocities for duration T: |v_c - v0| + |v_c - v1| <= A T, |v_c| <= V
double highest_cruise(double T, double v0, double v1, double V, double A) {
  return std::min(V, 0.5 * (v0 + v1 + A * T));
}
double lowest_cruise(double T, double v0, double v1, double V, double A) {
  return std::max(-V, 0.5 * (v0 + v1 - A * T));
}

// 2 sigma s - (v0 + v1) for the peak sigma s = ±sqrt(lambda), without the cancellation of
// two near-equal speeds: coasting at v0 = v1 with a tiny A d, the difference is 1e-5 of the
// speeds or less (s can even round to v0), and its rounding error moved the shortest duration by
// 1e-9 s, past what reachable() forgives, or to zero (found by fuzz_move). Since
// 4 lambda - (v0 + v1)^2 = 4 A d + (v0 - v1)^2, the difference is that over
// 2 sigma s + (v0 + v1) when the two terms share a sign.
double peak_excess(double sigma, double s, double d, double v0, double v1, double A) {
  const double sum = v0 + v1;
  if (sigma * sum <= 0.0) return 2.0 * sigma * s - sum;
  return (4.0 * A * d + (v0 - v1) * (v0 - v1)) / (2.0 * sigma * s + sum);
}

// The durations T >= |v1 - v0| / A in which even the fastest profile falls short of d,
// D_max(T) < d, as a half-open interval [lo, hi) (empty when lo >= hi). D_max is convex
// in T (its slope is the highest cruise velocity, which grows with T), so the set is
// one interval: the unclamped part solves 2 v_p^2 = 2 A d + v0^2 + v1^2 with
// v_p = (v0 + v1 + A T) / 2 (the peak of eq. 22), the clamped part V T - C < d.
std::pair<double, double> falls_short(double d, double v0, double v1, double V, double A) {
  double lo = kInf, hi = -kInf;
  const double lambda = A * d + 0.5 * (v0 * v0 + v1 * v1);
  if (lambda > 0.0) {
    // the peaks v_p in [max(-s, v0, v1), min(s, V)], as their excess 2 v_p - v0 - v1 = A T
    // (monotone in v_p; compared as excesses, since s itself can round to v0 = v1)
    const double s = std::sqrt(lambda);
    const double excess_lo = std::max(peak_excess(-1.0, s, d, v0, v1, A), std::abs(v0 - v1));
    const double excess_hi = std::min(peak_excess(+1.0, s, d, v0, v1, A), 2.0 * V - v0 - v1);
    if (excess_lo < excess_hi) {
      lo = excess_lo / A;
      hi = excess_hi / A;
    }
  }
  const double t_clamp = (2.0 * V - v0 - v1) / A;  // the highest cruise reaches V here
  const double c = ((V - v0) * (V - v0) + (V - v1) * (V - v1)) / (2.0 * A);
  const double t_reach = (d + c) / V;
  if (t_reach > t_clamp) {
    lo = std::min(lo, t_clamp);
    hi = std::max(hi, t_reach);
  }
  return {lo, hi};
}

bool reachable(const AxisBoundary& b, double T, double V, double A) {
  const double d = b.q1 - b.q0;
  const double scale = 1e-9 * (1.0 + std::abs(d) + (std::abs(b.v0) + std::abs(b.v1)) * T);
  if (T < std::abs(b.v1 - b.v0) / A - 1e-12) return false;
  const double d_max = displacement(highest_cruise(T, b.v0, b.v1, V, A), T, b.v0, b.v1, A);
  const double d_min = displacement(lowest_cruise(T, b.v0, b.v1, V, A), T, b.v0, b.v1, A);
  return d_min <= d + scale && d <= d_max + scale;
}

// no motion to make: what a zero duration can do (a zero-length feasible interval at T = 0
// stays only for such a move, the one fixed_time_move accepts at T = 0; a move a rounding error
// long gets its own tiny duration instead)
bool null_move(const AxisBoundary& b) {
  return std::abs(b.q1 - b.q0) <= 1e-12 && std::abs(b.v1 - b.v0) <= 1e-12;
}

void check_inputs(const AxisBoundary& b, double v_max, double a_max) {
  if (!(v_max > 0.0) || !(a_max > 0.0) || !std::isfinite(v_max) || !std::isfinite(a_max))
    throw InternalError("move: v_max and a_max must be positive and finite");
  if (!std::isfinite(b.q0) || !std::isfinite(b.q1) || !std::isfinite(b.v0) || !std::isfinite(b.v1))
    throw InternalError("move: boundary values must be finite");
  if (std::abs(b.v0) > v_max * (1 + 1e-12) || std::abs(b.v1) > v_max * (1 + 1e-12))
    throw InternalError("move: |v0| and |v1| must not exceed v_max");
}

}  // namespace

bool FeasibleDurations::contains(double t, double tolerance) const {
  for (const auto& [lo, hi] : intervals)
    if (t >= lo - tolerance && t <= hi + tolerance) return true;
  return false;
}

double FeasibleDurations::earliest_at_least(double t) const {
  for (const auto& [lo, hi] : intervals)
    if (hi >= t) return std::max(lo, t);
  return kInf;  // unreachable: the last interval ends at +inf
}

FeasibleDurations feasible_durations(const AxisBoundary& b, double v_max, double a_max) {
  check_inputs(b, v_max, a_max);
  const double d = b.q1 - b.q0;
  const double t_velocity = std::abs(b.v1 - b.v0) / a_max;  // time to change the velocity at all
  // durations where the fastest profile falls short, and (mirrored: q, v -> -q, -v) where
  // the slowest one overshoots
  const auto short_of = falls_short(d, b.v0, b.v1, v_max, a_max);
  const auto over = falls_short(-d, -b.v0, -b.v1, v_max, a_max);

  // [t_velocity, inf) minus both blocked intervals
  std::vector<std::pair<double, double>> feasible{{t_velocity, kInf}};
  for (const auto& [lo, hi] : {short_of, over}) {
    if (!(lo < hi)) continue;
    std::vector<std::pair<double, double>> kept;
    for (const auto& [a, z] : feasible) {
      if (hi <= a || lo >= z) {
        kept.push_back({a, z});
        continue;
      }
      if (lo >= a) kept.push_back({a, lo});
      if (hi < z) kept.push_back({hi, z});
    }
    feasible.swap(kept);
  }
  // a single point survives only where the move really is possible (e.g. T = 0 for a null move)
  FeasibleDurations out;
  for (const auto& interval : feasible) {
    const bool possible =
        interval.first > 0.0 ? reachable(b, interval.first, v_max, a_max) : null_move(b);
    // (a sliver a rounding error of T wide is no interval: one ulp of 1e5 s is 1.5e-11 s)
    const double sliver_s = 1e-12 * (1.0 + interval.first);
    if (interval.second - interval.first > sliver_s || possible) out.intervals.push_back(interval);
  }
  if (out.intervals.empty() || std::isfinite(out.intervals.back().second))
    throw InternalError("move: no feasible duration found (bug)");
  return out;
}

namespace {

// At the minimum duration the displacement is flat in v_c, so a solve pins v_c only to
// ~sqrt(eps) and can leave a spurious nanosecond cruise. Replace such a profile by the
// exact bang-bang one: v_p - v0 = a0 t_b and v1 - v_p = -a0 (T - t_b).
LspbSolution snap_to_bang_bang(LspbSolution s, const AxisBoundary& b, double v_max) {
  const double T = s.duration_s;
  if (s.t_b1 - s.t_b0 >= 1e-6 * std::max(1.0, T) || s.t_b1 == s.t_b0 || s.a1 != -s.a0) return s;
  const double v_peak = 0.5 * (b.v0 + b.v1 + s.a0 * T);
  const double t_peak = (v_peak - b.v0) / s.a0;
  if (std::abs(v_peak) > v_max * (1.0 + 1e-12) || t_peak < 0.0 || t_peak > T) return s;
  s.v_c = v_peak;
  s.t_b0 = s.t_b1 = t_peak;
  return s;
}

}  // namespace

AxisProfile fixed_time_move(const AxisBoundary& b, double duration_s, double v_max, double a_max) {
  check_inputs(b, v_max, a_max);
  if (duration_s <= 0.0) {
    if (null_move(b)) return AxisProfile(b.q0, b.v0);
    throw InternalError("move: zero duration for a non-null move");
  }
  // the paper's six LSPB candidates, eqs. (11)-(18)
  if (auto solution = solve_lspb(b, duration_s, a_max, v_max))
    return snap_to_bang_bang(*solution, b, v_max).profile(b);

  // roundoff at an extreme duration can reject all six: find v_c by bisection on the
  // monotone displacement and rebuild the same LSPB shape
  const double T = duration_s, d = b.q1 - b.q0;
  if (!reachable(b, T, v_max, a_max))
    throw InternalError("move: duration " + std::to_string(T) + " s is not feasible");
  double lo = lowest_cruise(T, b.v0, b.v1, v_max, a_max);
  double hi = highest_cruise(T, b.v0, b.v1, v_max, a_max);
  for (int i = 0; i < 200 && hi - lo > 1e-15 * (1.0 + std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (displacement(mid, T, b.v0, b.v1, a_max) < d ? lo : hi) = mid;
  }
  const double v_c = 0.5 * (lo + hi);
  LspbSolution s;
  s.v_c = v_c;
  s.a0 = v_c >= b.v0 ? a_max : -a_max;
  s.a1 = v_c >= b.v1 ? -a_max : a_max;
  s.t_b0 = std::min(std::abs(v_c - b.v0) / a_max, T);
  s.t_b1 = std::clamp(T - std::abs(v_c - b.v1) / a_max, s.t_b0, T);
  s.duration_s = T;
  return snap_to_bang_bang(s, b, v_max).profile(b);
}

AxisProfile min_time_move(const AxisBoundary& b, double v_max, double a_max) {
  return fixed_time_move(b, feasible_durations(b, v_max, a_max).t_min(), v_max, a_max);
}

double mtt_paper_duration(const AxisBoundary& b, double v_max, double a_max) {
  const double d = b.q1 - b.q0, v0 = b.v0, v1 = b.v1, alpha = a_max;
  // eqs. (23)-(26): triangular candidates. The printed eq. (24) has (v1^2 - v0^2)/2;
  // substituting (19)-(20) into (21) gives (v0^2 + v1^2)/2, used here (and in eq. 26).
  const double lambda1 = alpha * d + 0.5 * (v0 * v0 + v1 * v1);
  const double lambda2 = -alpha * d + 0.5 * (v0 * v0 + v1 * v1);
  struct Candidate {
    double v_p, a0, a1, lambda;
  };
  const Candidate candidates[4] = {{+1, alpha, -alpha, lambda1},
                                   {-1, alpha, -alpha, lambda1},
                                   {+1, -alpha, alpha, lambda2},
                                   {-1, -alpha, alpha, lambda2}};
  for (const Candidate& c : candidates) {
    if (c.lambda < 0.0) continue;  // eq. (27)
    const double v_p = c.v_p * std::sqrt(c.lambda);
    const double t_b = (v_p - v0) / c.a0;             // eq. (19)
    const double t_1 = (v1 - v_p) / c.a1 + t_b;       // eq. (20)
    if (t_b < -1e-12 || t_b > t_1 + 1e-12) continue;  // eq. (28)
    if (std::abs(v_p) <= v_max) return t_1;
    // eq. (29): the peak exceeds v_max -> LSPB with v_c = v_max and the signs of
    // eqs. (33)-(35) substituted into eq. (30). (The printed eq. (37) also multiplies the
    // v_max/a_max term by sgn(q1 - q0), which is wrong for q1 < q0.)
    const double s = d > 0.0 ? 1.0 : (d < 0.0 ? -1.0 : 0.0);
    if (s == 0.0) return -1.0;
    return std::abs(d) / v_max + v_max / alpha - s * (v0 + v1) / alpha +
           (v0 * v0 + v1 * v1) / (2.0 * alpha * v_max);
  }
  return -1.0;
}

}  // namespace depotwin
