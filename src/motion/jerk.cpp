#include "motion/jerk.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "core/error.hpp"

namespace depotwin {

// --- planning ---------------------------------------------------------------------------

double s_curve_duration(double dv, double a_max, double j_max) {
  dv = std::abs(dv);
  // triangular acceleration up to the knee a^2 / j, trapezoidal beyond
  return dv <= a_max * a_max / j_max ? 2.0 * std::sqrt(dv / j_max) : dv / a_max + a_max / j_max;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// velocity brackets resolve to this share of v_max at the coarsest (AxisProblem::resolution),
// and finer where a tiny S-curve would move the position by more than kDistanceResolution_mm
constexpr double kVelocityResolution = 1e-24;
constexpr double kDistanceResolution_mm = 1e-12;

// a double's place in the order of all doubles (-0 and +0 alike), and back: adjacent doubles
// have adjacent keys
int64_t order_key(double x) {
  int64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  return bits >= 0 ? bits : -(bits & std::numeric_limits<int64_t>::max());
}
double from_order_key(int64_t key) {
  const int64_t bits = key >= 0 ? key : (-key) | std::numeric_limits<int64_t>::min();
  double x = 0.0;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

// The point where a predicate that holds left of it and fails right of it flips, to full
// double precision (the two adjacent doubles it flips between), or to within `resolution`
// (absolute), whichever is coarser; returns the side where it holds (so a profile built from it
// never needs a negative cruise). Bisects the doubles themselves, in their order: at most 64
// probes however small the flip point (halving the value takes over a thousand to reach a flip
// near 0). The resolution ends a bracket around 0, whose probes would otherwise go down
// through every binade to the subnormals (whose arithmetic is many times slower).
template <class Predicate>
double bisect(double lo, double hi, double resolution, Predicate holds) {
  if (!(lo < hi) || hi - lo <= resolution) return lo;
  int64_t lo_key = order_key(lo), hi_key = order_key(hi);
  // the doubles strictly between hi and lo, plus one (unsigned: no overflow for any bracket)
  const auto gap = [&] { return static_cast<uint64_t>(hi_key) - static_cast<uint64_t>(lo_key); };
  // a flip at either end of the bracket (common: a limit reached exactly) in one probe each
  if (gap() > 2) {
    if (!holds(from_order_key(lo_key + 1))) return lo;
    if (holds(from_order_key(hi_key - 1))) return from_order_key(hi_key - 1);
  }
  while (gap() > 1 && from_order_key(hi_key) - from_order_key(lo_key) > resolution) {
    const int64_t mid_key = lo_key + static_cast<int64_t>(gap() / 2);
    (holds(from_order_key(mid_key)) ? lo_key : hi_key) = mid_key;
  }
  return from_order_key(lo_key);
}

// The same point as bisect(lo, hi, resolution, holds) with holds(x) = residual(x) <= 0 (or < 0 when
// strict), found in far fewer probes: Illinois steps on the residual (a midpoint where it is
// not finite or two steps have not halved the bracket) narrow the bracket, each probe decided
// by the predicate, so it always holds at lo and fails at hi; bisect finishes to adjacent
// doubles. For a predicate that flips once, the result is bisect's to the last bit.
template <class Residual>
double bisect_residual(double lo, double hi, double resolution, Residual residual, bool strict) {
  const auto holds = [strict](double r) { return strict ? r < 0.0 : r <= 0.0; };
  double r_lo = residual(lo), r_hi = residual(hi);
  if (holds(r_lo) && !holds(r_hi)) {
    int side = 0;  // which end the last probe moved (Illinois: halve the other's residual)
    double width_before = 2.0 * (hi - lo);
    for (int i = 0; i < 16; ++i) {
      const double width = hi - lo;
      if (!(width > 1e-13 * std::max(std::abs(lo), std::abs(hi))) || width <= resolution) break;
      double x = 0.5 * (lo + hi);
      if (std::isfinite(r_lo) && std::isfinite(r_hi)) {
        // the interpolated probe, a little away from the ends
        x = std::clamp(lo + width * (r_lo / (r_lo - r_hi)), lo + 1e-3 * width, hi - 1e-3 * width);
      }
      if (i % 2 == 1) {
        if (width > 0.5 * width_before) x = 0.5 * (lo + hi);
        width_before = width;
      }
      if (!(x > lo && x < hi)) break;
      const double r = residual(x);
      if (holds(r)) {
        lo = x, r_lo = r;
        if (side == -1) r_hi *= 0.5;
        side = -1;
      } else {
        hi = x, r_hi = r;
        if (side == 1) r_lo *= 0.5;
        side = 1;
      }
    }
  }
  return bisect(lo, hi, resolution, [&](double x) { return holds(residual(x)); });
}

// A peak (or trough) velocity v_p of the family, held as the two velocity changes into and
// out of it, dv0 = v_p - v0 and dv1 = v_p - v1: a tiny S-curve next to v0 or v1 keeps its full
// relative precision (its duration 2 sqrt(dv / j) is steep in dv), and the profile is built
// from exactly the numbers that gave its time and displacement.
struct Peak {
  double dv0 = 0.0, dv1 = 0.0;
};

// one planning problem: boundary velocities and limits
struct AxisProblem {
  double v0 = 0.0, v1 = 0.0;
  double v_max = 0.0, a_max = 0.0, j_max = 0.0;

  double knee() const { return a_max * a_max / j_max; }
  // the velocity brackets' resolution (bisect: it ends the brackets around 0 before the
  // subnormals). A velocity change this small changes no profile measurably: 1e-24 of v_max,
  // and at most dx with 4 sqrt(dx / j) v_max <= kDistanceResolution_mm, since both S-curves'
  // time 4 sqrt(x / j) at a tiny x moves by up to 4 sqrt(dx / j) (a 1e-7 mm move at 770 mm/s
  // turns on x ~ 1e-19, which 1e-24 of v_max = 8e-21 alone left 4 % short in time)
  double resolution() const {
    const double time_s = kDistanceResolution_mm / (4.0 * v_max);
    return std::min(kVelocityResolution * v_max, j_max * time_s * time_s);
  }
  double tau(double dv) const { return s_curve_duration(dv, a_max, j_max); }
  // d tau / d|dv|
  double tau_slope(double dv) const {
    dv = std::abs(dv);
    return dv <= knee() ? 1.0 / std::sqrt(dv * j_max) : 1.0 / a_max;
  }

  // v_p = max(v0, v1) + x
  Peak above(double x) const { return v0 >= v1 ? Peak{x, x + (v0 - v1)} : Peak{x + (v1 - v0), x}; }
  // v_p = min(v0, v1) + x and v_p = max(v0, v1) - x, for 0 <= x <= |v1 - v0|
  Peak up_from_low(double x) const {
    const double gap = std::abs(v1 - v0);
    return v0 <= v1 ? Peak{x, x - gap} : Peak{x - gap, x};
  }
  Peak down_from_high(double x) const {
    const double gap = std::abs(v1 - v0);
    return v0 >= v1 ? Peak{-x, gap - x} : Peak{gap - x, -x};
  }
  Peak at(double v_p) const { return Peak{v_p - v0, v_p - v1}; }

  // g: time of both S-curves
  double time(const Peak& p) const { return tau(p.dv0) + tau(p.dv1); }
  // F: displacement of both S-curves, (va + vb) / 2 tau each
  double travel(const Peak& p) const {
    return 0.5 * (2.0 * v0 + p.dv0) * tau(p.dv0) + 0.5 * (2.0 * v1 + p.dv1) * tau(p.dv1);
  }
  // D(v_p, T) = F + v_p (T - g): the member with this peak filling T by a cruise
  double displacement(const Peak& p, double T) const {
    return travel(p) + (v0 + p.dv0) * std::max(0.0, T - time(p));
  }
  // dF/dv_p where v_p >= max(v0, v1): sum of tau_i / 2 + (v_i + v_p) / 2 tau'(dv_i)
  double travel_slope(const Peak& p) const {
    return 0.5 * (tau(p.dv0) + (2.0 * v0 + p.dv0) * tau_slope(p.dv0)) +
           0.5 * (tau(p.dv1) + (2.0 * v1 + p.dv1) * tau_slope(p.dv1));
  }

  // the same problem mirrored, q, v -> -q, -v
  AxisProblem mirrored() const { return AxisProblem{-v0, -v1, v_max, a_max, j_max}; }
};

Peak negated(const Peak& p) {
  return Peak{-p.dv0, -p.dv1};
}

// g(above(x)) = T in closed form (NaN where none is found): each S-curve's time is
// 2 sqrt(dv / j) up to the knee and dv / a + a / j beyond, so on each side of the knees the
// equation is linear in x or quadratic in a root of it (u = sqrt(x + c), c the velocity change
// at x = 0); the root whose pieces agree with the knees is the one
double peak_time_root(const AxisProblem& pr, double T) {
  const Peak base = pr.above(0.0);
  const double c0 = base.dv0, c1 = base.dv1;
  const double a = pr.a_max, j = pr.j_max, knee = pr.knee(), root_j = std::sqrt(j);
  // (the pieces' conditions with a little slack: the bracket is checked on g itself)
  const auto below = [&](double dv) { return dv <= knee * (1.0 + 1e-9); };
  const auto above = [&](double dv) { return dv >= knee * (1.0 - 1e-9); };
  // both S-curves trapezoidal: (x + c0) / a + (x + c1) / a + 2 a / j = T
  const double linear = 0.5 * (a * (T - 2.0 * a / j) - c0 - c1);
  if (above(linear + c0) && above(linear + c1)) return linear;
  // both triangular: u + w = T sqrt(j) / 2 with u^2 - w^2 = c0 - c1
  const double sum = 0.5 * T * root_j;
  const double u = 0.5 * (sum + (c0 - c1) / sum);
  const double both_roots = u * u - c0;
  if (u >= 0.0 && sum - u >= 0.0 && below(both_roots + c0) && below(both_roots + c1))
    return both_roots;
  // one triangular (its change c_s), the other trapezoidal (c_l): u^2 / a + 2 u / sqrt(j) +
  // (c_l - c_s) / a + a / j - T = 0
  for (const auto& [c_s, c_l] : {std::pair{c0, c1}, std::pair{c1, c0}}) {
    const double constant = (c_l - c_s) / a + a / j - T;
    const double discriminant = 1.0 / j - constant / a;
    if (!(discriminant >= 0.0)) continue;
    const double root = a * (std::sqrt(discriminant) - 1.0 / root_j);
    const double x = root * root - c_s;
    if (root >= 0.0 && below(x + c_s) && above(x + c_l)) return x;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// the highest admissible peak for T >= tau(|v1 - v0|): g <= T, v_p <= v_max (g rises on
// v_p >= max(v0, v1))
Peak highest_peak(const AxisProblem& pr, double T) {
  const Peak top = pr.at(pr.v_max);
  if (pr.time(top) <= T) return top;
  if (pr.time(pr.above(0.0)) >= T) return pr.above(0.0);
  const double x_top = pr.v_max - std::max(pr.v0, pr.v1);
  const auto residual = [&](double x) { return pr.time(pr.above(x)) - T; };
  // the closed form's root brackets the flip point within a few doubles, each end checked on g
  // (the flip point, and so the bisection's result, is the same whatever the bracket where the
  // resolution is finer than the doubles there: bisect_residual's to the last bit)
  const double guess = peak_time_root(pr, T);
  const double margin = 8.0 * std::numeric_limits<double>::epsilon() * std::abs(guess);
  if (guess - margin > 0.0 && guess + margin < x_top && pr.resolution() < 0.01 * margin &&
      residual(guess - margin) <= 0.0 && residual(guess + margin) > 0.0)
    return pr.above(bisect(guess - margin, guess + margin, pr.resolution(),
                           [&](double x) { return residual(x) <= 0.0; }));
  return pr.above(bisect_residual(0.0, x_top, pr.resolution(), residual, false));
}
Peak lowest_peak(const AxisProblem& pr, double T) {
  return negated(highest_peak(pr.mirrored(), T));
}

// The durations T >= tau(|v1 - v0|) in which even the farthest-reaching profile falls short
// of d, D_max(T) < d, as an interval (lo, hi) ([lo, hi) when it starts at the first
// duration; empty when lo >= hi). On T <= g(v_max) the highest peak climbs from max(v0, v1)
// to v_max with D_max = F(peak); beyond, D_max = F(v_max) + v_max (T - g(v_max)). F is
// convex on [max(v0, v1), 0] and increasing on [0, v_max], so D_max falls, then rises.
std::pair<double, double> falls_short(const AxisProblem& pr, double d) {
  const double m = std::max(pr.v0, pr.v1), x_top = pr.v_max - m;
  auto F = [&](double x) { return pr.travel(pr.above(x)); };
  auto g = [&](double x) { return pr.time(pr.above(x)); };
  // lowest point of F: where its slope crosses zero on v_p in [m, 0], else at m
  const double x_low = m < 0.0 ? bisect_residual(
                                     0.0, -m, pr.resolution(),
                                     [&](double x) { return pr.travel_slope(pr.above(x)); }, true)
                               : 0.0;
  if (F(x_low) >= d) return {kInf, -kInf};
  // falling side: from the first duration, or from where F comes down to d
  const double lo =
      F(0.0) < d ? g(0.0)
                 : g(bisect_residual(
                       0.0, x_low, pr.resolution(), [&](double x) { return d - F(x); }, false));
  // rising side: where F climbs back to d, or on the cruise at v_max
  const Peak top = pr.at(pr.v_max);
  const double F_top = pr.travel(top);
  const double hi =
      F_top >= d ? g(bisect_residual(
                       x_low, x_top, pr.resolution(), [&](double x) { return F(x) - d; }, true))
                 : pr.time(top) + (d - F_top) / pr.v_max;
  return {lo, hi};
}

AxisProblem checked_problem(const AxisBoundary& b, double v_max, double a_max, double j_max) {
  for (const double limit : {v_max, a_max, j_max})
    if (!(limit > 0.0) || !std::isfinite(limit))
      throw InternalError("jerk-limited move: v_max, a_max and j_max must be positive and finite");
  if (!std::isfinite(b.q0) || !std::isfinite(b.q1) || !std::isfinite(b.v0) || !std::isfinite(b.v1))
    throw InternalError("jerk-limited move: boundary values must be finite");
  if (std::abs(b.v0) > v_max * (1 + 1e-12) || std::abs(b.v1) > v_max * (1 + 1e-12))
    throw InternalError("jerk-limited move: |v0| and |v1| must not exceed v_max");
  // a boundary velocity a rounding error above v_max becomes the limit
  return AxisProblem{b.v0, b.v1, std::max({v_max, std::abs(b.v0), std::abs(b.v1)}), a_max, j_max};
}

// no motion to make: what a zero duration can do (a zero-length feasible interval at T = 0
// stays only for such a move, the one jerk_fixed_time_move accepts at T = 0; a move a rounding
// error long gets its own tiny duration instead)
bool null_move(const AxisBoundary& b) {
  return std::abs(b.q1 - b.q0) <= 1e-12 && std::abs(b.v1 - b.v0) <= 1e-12;
}

// an axis the move leaves where it is, at rest at both ends (the z of a move in the plane): it
// may take any time, and stays at rest throughout
bool at_rest_in_place(const AxisBoundary& b) {
  return b.q0 == b.q1 && b.v0 == 0.0 && b.v1 == 0.0;
}

double tolerance(const AxisBoundary& b, double T, const AxisProblem& pr) {
  return 1e-9 * (1.0 + std::abs(b.q1 - b.q0) + pr.v_max * T);
}

bool reachable(const AxisBoundary& b, double T, const AxisProblem& pr) {
  if (T < pr.tau(b.v1 - b.v0) - 1e-12) return false;
  const double d = b.q1 - b.q0, tol = tolerance(b, T, pr);
  return pr.displacement(lowest_peak(pr, T), T) <= d + tol &&
         d <= pr.displacement(highest_peak(pr, T), T) + tol;
}

// the S-curve changing the velocity by dv, appended to p
void append_s_curve(AxisProfile& p, double dv, const AxisProblem& pr) {
  const double x = std::abs(dv), sign = dv >= 0.0 ? 1.0 : -1.0;
  if (x <= pr.knee()) {
    // triangular acceleration, peak sqrt(x j) <= a_max
    const double t_ramp = std::sqrt(x / pr.j_max);
    p.append_jerk(t_ramp, sign * pr.j_max);
    p.append_jerk(t_ramp, -sign * pr.j_max);
  } else {
    // trapezoidal acceleration: ramp to a_max, hold, ramp down
    const double t_ramp = pr.a_max / pr.j_max;
    p.append_jerk(t_ramp, sign * pr.j_max);
    p.append_jerk(x / pr.a_max - t_ramp, 0.0);
    p.append_jerk(t_ramp, -sign * pr.j_max);
  }
}

// the family member: S-curve v0 -> v_p, cruise for the rest of T, S-curve v_p -> v1
AxisProfile double_s(const AxisBoundary& b, const Peak& peak, double T, const AxisProblem& pr) {
  AxisProfile p(b.q0, b.v0);
  append_s_curve(p, peak.dv0, pr);
  // a cruise of a rounding error (the time-optimal member has none) is left out
  const double cruise_s = T - pr.time(peak);
  if (cruise_s > 1e-13 * (1.0 + T)) p.append_jerk(cruise_s, 0.0);
  append_s_curve(p, -peak.dv1, pr);
  return p;
}

// (1 - w) first + w second, phase by phase over [0, T]: the jerk of each piece between the
// union of both profiles' switching times is the same blend, so every state is too
AxisProfile blend(const AxisProfile& first, const AxisProfile& second, double w, double T) {
  AxisProfile out(first.q_start(), first.v_start(), first.a_start());
  const auto& p1 = first.phases();
  const auto& p2 = second.phases();
  size_t i = 0, k = 0;
  double t = 0.0;
  auto end_of = [](const Phase& p) { return p.t_begin_s + p.duration_s; };
  while (t < T) {
    while (i < p1.size() && end_of(p1[i]) <= t) ++i;
    while (k < p2.size() && end_of(p2[k]) <= t) ++k;
    const double end1 = i < p1.size() ? end_of(p1[i]) : kInf;
    const double end2 = k < p2.size() ? end_of(p2[k]) : kInf;
    const double next = std::min({end1, end2, T});
    const double j1 = i < p1.size() ? p1[i].jerk : 0.0;
    const double j2 = k < p2.size() ? p2[k].jerk : 0.0;
    out.append_jerk(next - t, (1.0 - w) * j1 + w * j2);
    t = next;
  }
  return out;
}

}  // namespace

FeasibleDurations jerk_feasible_durations(const AxisBoundary& b, double v_max, double a_max,
                                          double j_max) {
  const AxisProblem pr = checked_problem(b, v_max, a_max, j_max);
  if (at_rest_in_place(b)) return FeasibleDurations{{{0.0, kInf}}};
  const double d = b.q1 - b.q0;
  const double t_velocity = pr.tau(b.v1 - b.v0);
  // durations where the farthest profile falls short, and (mirrored: q, v -> -q, -v) where
  // the nearest one overshoots
  const auto short_of = falls_short(pr, d);
  const auto over = falls_short(pr.mirrored(), -d);

  // [t_velocity, inf) minus both blocked intervals (their ends stay: D reaches d there)
  std::vector<std::pair<double, double>> feasible{{t_velocity, kInf}};
  for (const auto& [lo, hi] : {short_of, over}) {
    if (!(lo < hi)) continue;
    std::vector<std::pair<double, double>> kept;
    for (const auto& [first, last] : feasible) {
      if (hi <= first || lo >= last) {
        kept.push_back({first, last});
        continue;
      }
      if (lo >= first) kept.push_back({first, lo});
      if (hi < last) kept.push_back({hi, last});
    }
    feasible.swap(kept);
  }
  // a single point survives only where the move really is possible (e.g. T = 0 for a null move)
  FeasibleDurations out;
  for (const auto& interval : feasible) {
    const bool possible = interval.first > 0.0 ? reachable(b, interval.first, pr) : null_move(b);
    // (a sliver a rounding error of T wide is no interval: one ulp of 1e5 s is 1.5e-11 s)
    const double sliver_s = 1e-12 * (1.0 + interval.first);
    if (interval.second - interval.first > sliver_s || possible) out.intervals.push_back(interval);
  }
  if (out.intervals.empty() || std::isfinite(out.intervals.back().second))
    throw InternalError("jerk-limited move: no feasible duration found (bug)");
  return out;
}

AxisProfile jerk_fixed_time_move(const AxisBoundary& b, double duration_s, double v_max,
                                 double a_max, double j_max) {
  const AxisProblem pr = checked_problem(b, v_max, a_max, j_max);
  const double T = duration_s, d = b.q1 - b.q0;
  if (T <= 0.0) {
    if (null_move(b)) return AxisProfile(b.q0, b.v0);
    throw InternalError("jerk-limited move: zero duration for a non-null move");
  }
  if (at_rest_in_place(b)) {
    AxisProfile rest(b.q0, 0.0);
    rest.append(T, 0.0);
    return rest;
  }
  if (!reachable(b, T, pr))
    throw InternalError("jerk-limited move: duration " + std::to_string(T) + " s is not feasible");

  // the extreme family members; roundoff beyond them takes the extreme itself
  Peak lo = lowest_peak(pr, T), hi = highest_peak(pr, T);
  if (d >= pr.displacement(hi, T)) return double_s(b, hi, T, pr);
  if (d <= pr.displacement(lo, T)) return double_s(b, lo, T, pr);

  // peaks between v0 and v1 are admissible only near them when g there exceeds T; g is
  // symmetric about the middle and rises towards it, so the blocked peaks are (c1, c2) with
  // c1 = min(v0, v1) + x and c2 = max(v0, v1) - x
  const double gap = std::abs(b.v1 - b.v0);
  if (gap > 0.0 && pr.time(pr.up_from_low(0.5 * gap)) > T) {
    const double x = bisect_residual(
        0.0, 0.5 * gap, pr.resolution(), [&](double y) { return pr.time(pr.up_from_low(y)) - T; },
        false);
    const Peak c1 = pr.up_from_low(x), c2 = pr.down_from_high(x);
    const double d1 = pr.displacement(c1, T), d2 = pr.displacement(c2, T);
    // d in the gap: blend the two members bounding it (both fill T exactly)
    if (d > d1 && d < d2)
      return blend(double_s(b, c1, T, pr), double_s(b, c2, T, pr), (d - d1) / (d2 - d1), T);
    if (d <= d1)
      hi = c1;
    else
      lo = c2;
  }
  // D(v_p, T) rises with v_p: bisect over dv0 = v_p - v0 for the peak that lands on q1
  // (an end of the bracket is used as it is, so that its exact velocity changes are kept)
  const double x_lo = lo.dv0, x_hi = hi.dv0;
  auto member = [&](double dv0) { return Peak{dv0, dv0 + (b.v0 - b.v1)}; };
  const double x = bisect_residual(
      x_lo, x_hi, pr.resolution(), [&](double y) { return pr.displacement(member(y), T) - d; },
      true);
  return double_s(b, x == x_lo ? lo : member(x), T, pr);
}

AxisProfile jerk_min_time_move(const AxisBoundary& b, double v_max, double a_max, double j_max) {
  return jerk_fixed_time_move(b, jerk_feasible_durations(b, v_max, a_max, j_max).t_min(), v_max,
                              a_max, j_max);
}

}  // namespace depotwin
