// Jerk-limited minimum-time moves: closed forms, an exhaustive discrete-time search that no
// jerk sequence beats the double-S family, a seeded random property test against an
// independent feasibility oracle, the limit j -> inf, fixed durations and synchronisation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/error.hpp"
#include "motion/jerk.hpp"
#include "motion/mtt.hpp"
#include "motion/sync.hpp"

namespace depotwin {
namespace {

constexpr double kV = 4.0, kA = 30.0, kJ = 500.0;

// boundary states, duration, and |v|, |a|, |jerk| at dense samples and inside phases
void expect_valid(const AxisProfile& p, const AxisBoundary& b, double duration_s, double v_max,
                  double a_max, double j_max) {
  EXPECT_NEAR(p.duration_s(), duration_s, 1e-9 * (1 + duration_s));
  const AxisState start = p.at(0.0), end = p.at(p.duration_s());
  EXPECT_NEAR(start.q, b.q0, 1e-9);
  EXPECT_NEAR(start.v, b.v0, 1e-9);
  EXPECT_NEAR(start.a, 0.0, 1e-9);
  EXPECT_NEAR(end.q, b.q1, 1e-9);
  EXPECT_NEAR(end.v, b.v1, 1e-9);
  EXPECT_NEAR(end.a, 0.0, 1e-9);
  EXPECT_LE(p.peak_speed(), v_max + 1e-9);
  EXPECT_LE(p.peak_acceleration(), a_max + 1e-9);
  EXPECT_LE(p.peak_jerk(), j_max * (1 + 1e-12));
  const int samples = 400;
  for (int k = 0; k <= samples; ++k) {
    const double t = p.duration_s() * k / samples;
    const AxisState s = p.at(t);
    ASSERT_LE(std::abs(s.v), v_max + 1e-9) << "t = " << t;
    ASSERT_LE(std::abs(s.a), a_max + 1e-9) << "t = " << t;
    ASSERT_LE(std::abs(p.jerk_at(t)), j_max * (1 + 1e-12)) << "t = " << t;
  }
}

std::vector<double> jerks_of(const AxisProfile& p) {
  std::vector<double> out;
  for (const Phase& phase : p.phases()) out.push_back(phase.jerk);
  return out;
}

// --- closed forms -----------------------------------------------------------------------

TEST(Jerk, ProfileEvaluatesCubicPhases) {
  AxisProfile p(1.0, 2.0);
  p.append_jerk(0.5, 8.0);   // a: 0 -> 4
  p.append_jerk(1.0, -8.0);  // a: 4 -> -4, v peaks where a = 0
  EXPECT_NEAR(p.at(0.5).q, 1 + 2 * 0.5 + 8 * 0.125 / 6, 1e-15);
  EXPECT_NEAR(p.at(0.5).v, 2 + 8 * 0.25 / 2, 1e-15);
  EXPECT_NEAR(p.at(0.5).a, 4.0, 1e-15);
  EXPECT_NEAR(p.v_end(), 3.0 + 4 * 1 - 8 * 0.5, 1e-15);
  EXPECT_NEAR(p.a_end(), -4.0, 1e-15);
  EXPECT_NEAR(p.peak_speed(), 3.0 + 4 * 0.5 - 8 * 0.125, 1e-15);  // v at t = 1
  EXPECT_NEAR(p.peak_acceleration(), 4.0, 1e-15);
  EXPECT_EQ(p.jerk_at(1.2), -8.0);
  EXPECT_NEAR(p.at(9.0).q, p.q_end(), 1e-15);  // clamped to the end
}

TEST(Jerk, SCurveDuration) {
  // knee a^2 / j = 1.8 mm/s: triangular below, trapezoidal above, continuous at the knee
  EXPECT_NEAR(s_curve_duration(1.0, kA, kJ), 2 * std::sqrt(1.0 / kJ), 1e-15);
  EXPECT_NEAR(s_curve_duration(-3.0, kA, kJ), 3.0 / kA + kA / kJ, 1e-15);
  EXPECT_NEAR(s_curve_duration(1.8, kA, kJ), 2 * kA / kJ, 1e-15);
}

TEST(Jerk, RestToRestReachingBothLimits) {
  // T = d / v + v / a + a / j, jerk pattern +j 0 -j 0 -j 0 +j
  const AxisBoundary b{1, 11, 0, 0};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, kJ);
  EXPECT_NEAR(p.duration_s(), 10 / kV + kV / kA + kA / kJ, 1e-12);
  expect_valid(p, b, p.duration_s(), kV, kA, kJ);
  EXPECT_EQ(jerks_of(p), (std::vector<double>{kJ, 0, -kJ, 0, -kJ, 0, kJ}));
  EXPECT_NEAR(p.phases()[0].duration_s, kA / kJ, 1e-12);
  EXPECT_NEAR(p.phases()[1].duration_s, kV / kA - kA / kJ, 1e-12);
  EXPECT_NEAR(p.phases()[3].duration_s, 10 / kV - kV / kA - kA / kJ, 1e-12);
  EXPECT_NEAR(p.peak_speed(), kV, 1e-12);
  EXPECT_NEAR(p.peak_acceleration(), kA, 1e-12);
  // the acceleration-limited move is exactly a / j shorter
  EXPECT_NEAR(p.duration_s() - min_time_move(b, kV, kA).duration_s(), kA / kJ, 1e-12);
}

TEST(Jerk, RestToRestReachingVmaxOnly) {
  // j = 100: the knee a^2 / j = 9 mm/s lies above v_max, so a_max is never reached:
  // T = d / v + 2 sqrt(v / j)
  const double j = 100.0;
  const AxisBoundary b{0, 10, 0, 0};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, j);
  EXPECT_NEAR(p.duration_s(), 10 / kV + 2 * std::sqrt(kV / j), 1e-12);
  EXPECT_NEAR(p.peak_acceleration(), std::sqrt(kV * j), 1e-9);
  EXPECT_EQ(jerks_of(p), (std::vector<double>{j, -j, 0, -j, j}));
  expect_valid(p, b, p.duration_s(), kV, kA, j);
}

TEST(Jerk, RestToRestReachingAmaxOnly) {
  // peak v_p between the knee (1.8) and v_max: d = v_p (v_p / a + a / j), T = 2 (v_p / a + a / j)
  const double d = 0.5, knee = kA * kA / kJ;
  const double v_p = 0.5 * (-knee + std::sqrt(knee * knee + 4 * kA * d));
  ASSERT_GT(v_p, knee);
  ASSERT_LT(v_p, kV);
  const AxisBoundary b{0, d, 0, 0};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, kJ);
  EXPECT_NEAR(p.duration_s(), 2 * (v_p / kA + kA / kJ), 1e-12);
  EXPECT_NEAR(p.peak_speed(), v_p, 1e-9);
  EXPECT_NEAR(p.peak_acceleration(), kA, 1e-12);
  EXPECT_EQ(jerks_of(p), (std::vector<double>{kJ, 0, -kJ, -kJ, 0, kJ}));
  expect_valid(p, b, p.duration_s(), kV, kA, kJ);
}

TEST(Jerk, RestToRestReachingNeither) {
  // d = 2 v_p sqrt(v_p / j) with v_p under the knee: T = 4 sqrt(v_p / j) = (32 d / j)^(1/3)
  const AxisBoundary b{0, -0.01, 0, 0};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, kJ);
  EXPECT_NEAR(p.duration_s(), std::cbrt(32 * 0.01 / kJ), 1e-12);
  EXPECT_EQ(jerks_of(p), (std::vector<double>{-kJ, kJ, kJ, -kJ}));
  expect_valid(p, b, p.duration_s(), kV, kA, kJ);
}

TEST(Jerk, AMoveOfARoundingErrorTakesItsOwnTime) {
  // 1e-10 mm is within the feasibility tolerance of standing still, yet no move of zero
  // duration makes it: T = (32 d / j)^(1/3), alone and synchronised (zero once, an internal
  // error)
  const AxisBoundary b{0, 1e-10, 0, 0};
  const double expected_s = std::cbrt(32 * 1e-10 / kJ);
  EXPECT_NEAR(jerk_min_time_move(b, kV, kA, kJ).duration_s(), expected_s, 1e-9 * expected_s);
  const SynchronizedMove move = synchronized_move({AxisMove{b, kV, kA, kJ}});
  EXPECT_NEAR(move.duration_s, expected_s, 1e-9 * expected_s);
  expect_valid(move.axes[0], b, expected_s, kV, kA, kJ);
}

TEST(Jerk, ATinyMoveAtSpeedIsTimedByItsLength) {
  // 1e-7 mm cruising at 770 mm/s (fuzz_move's regression-tiny-move-at-speed): T = d / v to
  // 1e-9, the peak a mere ~1e-19 mm/s above v0. The velocity brackets must resolve that
  // (1e-24 of v_max = 8e-21 alone left T 4 % short, and the move "not feasible")
  const AxisBoundary b{0, 1e-7, 770, 770};
  const double v_max = 7770, a_max = 1, j_max = 77, expected_s = 1e-7 / 770;
  EXPECT_NEAR(jerk_min_time_move(b, v_max, a_max, j_max).duration_s(), expected_s,
              1e-9 * expected_s);
  const SynchronizedMove move = synchronized_move({AxisMove{b, v_max, a_max, j_max}});
  EXPECT_NEAR(move.duration_s, expected_s, 1e-9 * expected_s);
  expect_valid(move.axes[0], b, move.duration_s, v_max, a_max, j_max);
}

TEST(Jerk, AnAxisAtRestInPlaceStaysAtRestForAnyDuration) {
  // the z of a move in the plane: any duration is feasible, and the axis holds still for
  // exactly that long (the general solution had femtosecond phases at both ends, ~1e-25 mm/s)
  const AxisBoundary b{1.5, 1.5, 0, 0};
  const FeasibleDurations feasible = jerk_feasible_durations(b, 100, 3000, 60000);
  ASSERT_EQ(feasible.intervals.size(), 1u);
  EXPECT_EQ(feasible.t_min(), 0.0);
  EXPECT_EQ(feasible.intervals.front().second, std::numeric_limits<double>::infinity());
  for (const double T : {0.0, 1e-9, 0.37, 1e4}) {
    const AxisProfile profile = jerk_fixed_time_move(b, T, 100, 3000, 60000);
    EXPECT_EQ(profile.duration_s(), T);
    for (const double t : {0.0, 0.5 * T, T}) {
      const AxisState state = profile.at(t);
      EXPECT_EQ(state.q, 1.5);
      EXPECT_EQ(state.v, 0.0);
      EXPECT_EQ(state.a, 0.0);
    }
  }
  // synchronised with a moving axis, it takes the moving one's time
  const SynchronizedMove move = synchronized_move(
      {AxisMove{AxisBoundary{0, 2, 0, 0}, 100, 3000, 60000}, AxisMove{b, 100, 3000, 60000}});
  EXPECT_EQ(move.axes[1].duration_s(), move.duration_s);
  EXPECT_EQ(move.axes[1].at(0.5 * move.duration_s).q, 1.5);
}

TEST(Jerk, ALongMoveHasNoFeasibleSliverOfOneRoundingError) {
  // Mtt.ALongMoveHasNoFeasibleSliverOfOneRoundingError with a jerk limit: the move must still
  // pass the ramp to rest (at least 77777 s plus the jerk ramps) and come back, exactly
  const AxisBoundary b{0, 0, 77777, 1e-9};
  const double v_max = 7777710, a_max = 1, j_max = 100;
  const SynchronizedMove move = synchronized_move({AxisMove{b, v_max, a_max, j_max}});
  EXPECT_GT(move.duration_s, 77777 + a_max / j_max);
  EXPECT_NEAR(move.duration_s, jerk_min_time_move(b, v_max, a_max, j_max).duration_s(),
              1e-9 * move.duration_s);
  // at the end, within 1e-12 of the 3e9 mm excursion and of v0 (doubles hold 16 digits)
  const double excursion_mm = b.v0 * b.v0 / (2 * a_max);
  EXPECT_NEAR(move.axes[0].q_end(), b.q1, 1e-12 * excursion_mm);
  EXPECT_NEAR(move.axes[0].v_end(), b.v1, 1e-12 * b.v0);
}

TEST(Jerk, ReversalInPlace) {
  // +3 -> -3 mm/s with d = 0: one S-curve, tau(6) = 6 / a + a / j, and it moves (3 - 3) / 2 tau = 0
  const AxisBoundary b{0, 0, 3, -3};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, kJ);
  EXPECT_NEAR(p.duration_s(), 6 / kA + kA / kJ, 1e-12);
  expect_valid(p, b, p.duration_s(), kV, kA, kJ);
}

TEST(Jerk, OvershootAndComeBack) {
  // v0 = 4 towards a target 0.1 mm ahead: it must reverse to v_p = -u (both S-curves
  // trapezoidal): u^2 + (a^2 / j) u - (v0^2 / 2 + v0 a^2 / (2 j) - a d) = 0,
  // T = (v0 + 2 u) / a + 2 a / j = 0.397838 s
  const double v0 = 4, d = 0.1, knee = kA * kA / kJ;
  const double c = v0 * v0 / 2 + v0 * knee / 2 - kA * d;
  const double u = 0.5 * (-knee + std::sqrt(knee * knee + 4 * c));
  const AxisBoundary b{0, d, v0, 0};
  const AxisProfile p = jerk_min_time_move(b, kV, kA, kJ);
  EXPECT_NEAR(p.duration_s(), (v0 + 2 * u) / kA + 2 * kA / kJ, 1e-12);
  EXPECT_NEAR(p.duration_s(), 0.397838, 5e-7);
  EXPECT_NEAR(p.at(p.phases()[2].t_begin_s + p.phases()[2].duration_s).v, -u, 1e-9);
  expect_valid(p, b, p.duration_s(), kV, kA, kJ);
}

TEST(Jerk, BlockedDurations) {
  // d = 0, v0 = v1 = 3: T = 0, or the round trip 3 -> -3 -> 3 of 2 tau(6) = 0.52 s and longer
  const AxisBoundary b{0, 0, 3, 3};
  const FeasibleDurations set = jerk_feasible_durations(b, kV, kA, kJ);
  ASSERT_EQ(set.intervals.size(), 2u);
  EXPECT_EQ(set.intervals[0].first, 0.0);
  EXPECT_EQ(set.intervals[0].second, 0.0);
  EXPECT_NEAR(set.intervals[1].first, 2 * (6 / kA + kA / kJ), 1e-12);
  EXPECT_FALSE(set.contains(0.3));
  for (double T : {0.52, 0.6, 1.0, 5.0})
    expect_valid(jerk_fixed_time_move(b, T, kV, kA, kJ), b, T, kV, kA, kJ);
  EXPECT_THROW(jerk_fixed_time_move(b, 0.3, kV, kA, kJ), InternalError);
}

TEST(Jerk, RejectsBadLimits) {
  EXPECT_THROW(jerk_feasible_durations({0, 1, 0, 0}, kV, kA, 0.0), InternalError);
  EXPECT_THROW(jerk_feasible_durations({0, 1, 0, 0}, kV, -1.0, kJ), InternalError);
  EXPECT_THROW(jerk_feasible_durations({0, 1, 5, 0}, kV, kA, kJ), InternalError);
}

// --- every fixed duration of the feasible set has a profile -----------------------------

TEST(Jerk, FixedDurationsFillTheReachableInterval) {
  // v0 = 0 -> v1 = 2 in T = 3 s with j = 1: the S-curves alone take tau(2) = 2.83 s, so peaks
  // half-way between 0 and 2 are not admissible and the double-S displacements leave a gap
  // around d = 3 (one gentler S-curve); there the blend of the two bounding members is used.
  const double v_max = 10, a_max = 100, j_max = 1, T = 3;
  int blended = 0;
  for (int k = 0; k <= 200; ++k) {
    const double d = 2.5 + 1.0 * k / 200;
    const AxisBoundary b{0, d, 0, 2};
    if (!jerk_feasible_durations(b, v_max, a_max, j_max).contains(T)) continue;
    const AxisProfile p = jerk_fixed_time_move(b, T, v_max, a_max, j_max);
    expect_valid(p, b, T, v_max, a_max, j_max);
    // a blended profile has phases with a jerk strictly between 0 and j_max
    for (const Phase& phase : p.phases())
      if (std::abs(phase.jerk) > 1e-9 && std::abs(phase.jerk) < j_max * (1 - 1e-9)) {
        ++blended;
        break;
      }
  }
  EXPECT_GT(blended, 10);
  // d = 3 itself: T = 3 is feasible and in the gap
  EXPECT_TRUE(jerk_feasible_durations({0, 3, 0, 2}, v_max, a_max, j_max).contains(T));
}

// --- exhaustive discrete-time search ----------------------------------------------------
// Every profile whose jerk is -j, 0 or +j on each step of h = 1/N (j = 1) lands on an exact
// integer lattice: a = i h, v = k h^2 / 2, q = m h^3 / 6, with one step
//   i' = i + s,  k' = k + 2 i + s,  m' = m + 3 k + 3 i + s,   s in {-1, 0, 1}.
// The acceleration never changes sign strictly inside a step, so the velocity is monotone
// there and the limits need checking only at the steps. A breadth-first sweep over all
// (i, k) with a bitset over m finds every state reachable in exactly n steps; for each
// rest-acceleration target it reaches, the analytic minimum must not be longer than the
// first n h, and every n h at which it is reached must be in the analytic feasible set.
struct LatticeSearch {
  int i_max = 0, k_max = 0, steps = 0;
  long m_offset = 0;
  size_t words = 0;
  std::vector<std::vector<uint64_t>> at_rest;  // per step: bits over (k, m) with a = 0

  bool reached(int step, int k, long m) const {
    const long bit = m + m_offset;
    if (bit < 0 || bit >= static_cast<long>(words * 64)) return false;
    const uint64_t word = at_rest[step][static_cast<size_t>(k + k_max) * words + bit / 64];
    return (word >> (bit % 64)) & 1u;
  }
};

// dst |= src shifted by `shift` bits (towards higher bits when positive)
void shift_or(uint64_t* dst, const uint64_t* src, size_t words, long shift) {
  const size_t ws = static_cast<size_t>(std::abs(shift)) / 64, bs = std::abs(shift) % 64;
  if (shift >= 0) {
    for (size_t w = words; w-- > ws;) {
      uint64_t v = src[w - ws] << bs;
      if (bs && w > ws) v |= src[w - ws - 1] >> (64 - bs);
      dst[w] |= v;
    }
  } else {
    for (size_t w = 0; w + ws < words; ++w) {
      uint64_t v = src[w + ws] >> bs;
      if (bs && w + ws + 1 < words) v |= src[w + ws + 1] << (64 - bs);
      dst[w] |= v;
    }
  }
}

LatticeSearch lattice_search(int i_max, int k_max, int k_start, int steps) {
  LatticeSearch s;
  s.i_max = i_max;
  s.k_max = k_max;
  s.steps = steps;
  // |m| grows by at most 3 k_max + 3 i_max + 1 per step
  s.m_offset = static_cast<long>(steps) * (3 * k_max + 3 * i_max + 1);
  s.words = static_cast<size_t>(2 * s.m_offset + 1 + 63) / 64;
  const int ni = 2 * i_max + 1, nk = 2 * k_max + 1;
  std::vector<uint64_t> now(static_cast<size_t>(ni) * nk * s.words, 0), next(now.size(), 0);
  auto cell = [&](std::vector<uint64_t>& v, int i, int k) {
    return v.data() + (static_cast<size_t>(i + i_max) * nk + (k + k_max)) * s.words;
  };
  auto keep_rest = [&]() {
    const uint64_t* row = cell(now, 0, -k_max);
    s.at_rest.emplace_back(row, row + nk * s.words);
  };
  cell(now, 0, k_start)[s.m_offset / 64] |= uint64_t{1} << (s.m_offset % 64);
  keep_rest();
  for (int n = 1; n <= steps; ++n) {
    std::fill(next.begin(), next.end(), 0);
    for (int i = -i_max; i <= i_max; ++i)
      for (int k = -k_max; k <= k_max; ++k)
        for (int sign = -1; sign <= 1; ++sign) {
          const int i2 = i + sign, k2 = k + 2 * i + sign;
          if (std::abs(i2) > i_max || std::abs(k2) > k_max) continue;
          shift_or(cell(next, i2, k2), cell(now, i, k), s.words, 3L * k + 3L * i + sign);
        }
    now.swap(next);
    keep_rest();
  }
  return s;
}

TEST(Jerk, NoJerkSequenceBeatsTheDoubleSFamily) {
  const int N = 4, steps = 28;  // h = 0.25 s, 7 s horizon, j = 1
  std::mt19937_64 rng(17);
  int targets = 0, with_gap = 0, exact = 0;
  for (int config = 0; config < 16; ++config) {
    const int i_max = std::uniform_int_distribution<int>(2, 6)(rng);   // a_max = i_max / N
    const int k_max = std::uniform_int_distribution<int>(8, 40)(rng);  // v_max = k_max / 2N^2
    const int k_start = std::uniform_int_distribution<int>(-k_max, k_max)(rng);
    const LatticeSearch search = lattice_search(i_max, k_max, k_start, steps);
    const double a_max = static_cast<double>(i_max) / N, v_max = k_max / (2.0 * N * N);
    std::uniform_int_distribution<int> pick_k(-k_max, k_max);
    std::uniform_int_distribution<long> pick_m(-search.m_offset, search.m_offset);
    // sample rest-acceleration targets that some jerk sequence reaches
    int found = 0;
    for (int tries = 0; tries < 400000 && found < 250; ++tries) {
      const int k_end = pick_k(rng);
      const long m_end = pick_m(rng);
      std::vector<int> hits;
      for (int n = 0; n <= steps; ++n)
        if (search.reached(n, k_end, m_end)) hits.push_back(n);
      if (hits.empty()) continue;
      ++found;
      const AxisBoundary b{0.0, m_end / (6.0 * N * N * N), k_start / (2.0 * N * N),
                           k_end / (2.0 * N * N)};
      SCOPED_TRACE(testing::Message() << "a_max=" << a_max << " v_max=" << v_max << " v0=" << b.v0
                                      << " v1=" << b.v1 << " d=" << b.q1);
      const FeasibleDurations set = jerk_feasible_durations(b, v_max, a_max, 1.0);
      EXPECT_LE(set.t_min(), static_cast<double>(hits.front()) / N + 1e-9);
      for (int n : hits) EXPECT_TRUE(set.contains(static_cast<double>(n) / N, 1e-9)) << n;
      if (std::abs(set.t_min() - static_cast<double>(hits.front()) / N) < 1e-9) ++exact;
      if (set.intervals.size() > 1) ++with_gap;
    }
    targets += found;
  }
  EXPECT_EQ(targets, 16 * 250);
  EXPECT_GT(exact, 5);      // the bound is attained where the optimum switches on the grid
  EXPECT_GT(with_gap, 20);  // and the sample covers blocked durations
}

// --- independent oracle -----------------------------------------------------------------
// For duration T the reachable displacements are [D_min, D_max], the extremes over the
// double-S family. The oracle scans the peak velocity (a grid, the boundary velocities and
// the exact ends of the admissible peaks, found by bisection on the elementary monotone
// pieces of the S-curve time) and integrates each member's jerk phases step by step. It
// assumes nothing about how the displacement depends on the peak or on T.
struct Oracle {
  double v_max, a_max, j_max;

  // the phases (duration, jerk) of the fastest S-curve changing the velocity by dv
  void s_curve_phases(double dv, std::vector<std::pair<double, double>>& phases) const {
    const double x = std::abs(dv), sign = dv >= 0 ? 1.0 : -1.0;
    if (x == 0.0) return;
    const double ramp = std::min(std::sqrt(x / j_max), a_max / j_max);
    const double hold = x / (j_max * ramp) - ramp;  // velocity left after both ramps, at a = j ramp
    phases.push_back({ramp, sign * j_max});
    if (hold > 0) phases.push_back({hold, 0.0});
    phases.push_back({ramp, -sign * j_max});
  }
  double phases_time(const std::vector<std::pair<double, double>>& phases) const {
    double t = 0;
    for (const auto& [duration, jerk] : phases) t += duration;
    return t;
  }
  double transfer_time(double v_p, double v0, double v1) const {
    std::vector<std::pair<double, double>> phases;
    s_curve_phases(v_p - v0, phases);
    s_curve_phases(v1 - v_p, phases);
    return phases_time(phases);
  }
  // displacement of the member with peak v_p filling T (nan when it does not fit)
  double member_displacement(double v_p, double v0, double v1, double T) const {
    std::vector<std::pair<double, double>> first, second;
    s_curve_phases(v_p - v0, first);
    s_curve_phases(v1 - v_p, second);
    const double cruise = T - phases_time(first) - phases_time(second);
    if (cruise < -1e-12 * (1 + T)) return std::nan("");
    first.push_back({std::max(0.0, cruise), 0.0});
    first.insert(first.end(), second.begin(), second.end());
    double q = 0, v = v0, a = 0;
    for (const auto& [t, j] : first) {
      q += t * (v + t * (a / 2 + t * j / 6));
      v += t * (a + t * j / 2);
      a += t * j;
    }
    return q;
  }
  // > 0: infeasible by that margin (mm, or mm/s for the velocity change); <= 0: feasible
  double infeasibility(const AxisBoundary& b, double T) const {
    const double v0 = b.v0, v1 = b.v1, d = b.q1 - b.q0;
    const double t_velocity = transfer_time(v0, v0, v1);
    if (T < t_velocity) return 1e-3 * (t_velocity - T) + 1e-300;
    std::vector<double> peaks{-v_max, v_max, v0, v1};
    for (int k = 0; k <= 64; ++k) peaks.push_back(-v_max + 2 * v_max * k / 64);
    // where the transfer time crosses T on each piece where it is monotone
    const double lo = std::min(v0, v1), hi = std::max(v0, v1), mid = 0.5 * (lo + hi);
    const std::pair<double, double> pieces[4] = {{-v_max, lo}, {lo, mid}, {mid, hi}, {hi, v_max}};
    for (const auto& [x0, x1] : pieces) {
      const double g0 = transfer_time(x0, v0, v1) - T, g1 = transfer_time(x1, v0, v1) - T;
      if (g0 * g1 > 0 || x0 >= x1) continue;
      double a = x0, c = x1;
      for (int it = 0; it < 100; ++it) {
        const double m = 0.5 * (a + c);
        ((transfer_time(m, v0, v1) - T) * g0 > 0 ? a : c) = m;
      }
      peaks.push_back(g0 <= 0 ? a : c);  // the admissible side
    }
    double d_min = INFINITY, d_max = -INFINITY;
    for (double v_p : peaks) {
      const double D = member_displacement(v_p, v0, v1, T);
      if (std::isnan(D)) continue;
      d_min = std::min(d_min, D);
      d_max = std::max(d_max, D);
    }
    return std::max(d - d_max, d_min - d);
  }
};

TEST(Jerk, RandomCasesAreFeasibleAndNothingShorterIs) {
  std::mt19937_64 rng(2025);
  std::uniform_real_distribution<double> pos(-10, 10), vel(-kV, kV), unit(0, 1);
  const double jerks[3] = {100.0, 500.0, 5000.0};  // knee 9, 1.8, 0.18 mm/s
  int overshoots = 0, blocked = 0;
  for (int i = 0; i < 6000; ++i) {
    const double j_max = jerks[i % 3];
    const Oracle oracle{kV, kA, j_max};
    AxisBoundary b{pos(rng), pos(rng), vel(rng), vel(rng)};
    if (i % 10 == 0) b.q1 = b.q0 + 0.01 * pos(rng);  // short moves: overshoot territory
    if (i % 10 == 1) b.q1 = b.q0 + 0.1 * pos(rng);
    if (i % 50 == 0) b.v1 = (i % 100 == 0) ? kV : -kV;  // velocity at the limit
    SCOPED_TRACE(testing::Message() << "case " << i << " j=" << j_max << " q0=" << b.q0
                                    << " q1=" << b.q1 << " v0=" << b.v0 << " v1=" << b.v1);
    const FeasibleDurations set = jerk_feasible_durations(b, kV, kA, j_max);
    const AxisProfile p = jerk_min_time_move(b, kV, kA, j_max);
    const double t_min = set.t_min();
    expect_valid(p, b, t_min, kV, kA, j_max);
    EXPECT_LE(oracle.infeasibility(b, t_min), 1e-9);
    // no shorter duration is feasible: scan [0, t_min) and bisect towards t_min
    for (int k = 0; k < 16; ++k) {
      const double t = t_min * unit(rng) * (1 - 1e-6);
      ASSERT_GT(oracle.infeasibility(b, t), 0.0) << "shorter feasible duration " << t;
    }
    double lo = 0.0, hi = t_min;
    for (int k = 0; k < 30; ++k) {
      const double mid = 0.5 * (lo + hi);
      (oracle.infeasibility(b, mid) > 0.0 ? lo : hi) = mid;
    }
    EXPECT_NEAR(hi, t_min, 1e-6 * (1 + t_min));
    // the rest of the set agrees with the oracle, and its durations have profiles
    const double horizon = 1.5 * set.intervals.back().first + 0.2;
    for (int k = 0; k < 4; ++k) {
      const double t = horizon * unit(rng);
      const double margin = oracle.infeasibility(b, t);
      if (margin > 1e-7) {
        EXPECT_FALSE(set.contains(t)) << "t = " << t;
      }
      if (margin < -1e-7) {
        ASSERT_TRUE(set.contains(t)) << "t = " << t;
        expect_valid(jerk_fixed_time_move(b, t, kV, kA, j_max), b, t, kV, kA, j_max);
      }
    }
    // moves that run against the displacement somewhere
    for (const Phase& phase : p.phases())
      if (phase.v0 * (b.q1 - b.q0) < -1e-9) {
        ++overshoots;
        break;
      }
    if (set.intervals.size() > 1) ++blocked;
  }
  EXPECT_GT(overshoots, 1000);  // the sample covers velocities against the displacement
  EXPECT_GT(blocked, 30);       // and durations with a blocked range
}

// --- j -> inf: the acceleration-limited minimum-time move -------------------------------

TEST(Jerk, InfiniteJerkLimitIsTheAccelerationLimitedMove) {
  // a jerk limit only removes profiles, and the minimum converges to the acceleration-limited
  // one like a / j (observed excess <= 4.6 a / j on 20,000 cases for j >= 1e4 a). Where the
  // acceleration-limited set opens with a window narrower than a few a / j, the jerk limit
  // closes it and the minimum moves to the next interval (e.g. d = 0.011 mm, v0 = 3.562,
  // v1 = 3.652 mm/s: window [3.0534, 3.0547] ms, gone at j = 3e5, back at j = 3e6).
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> pos(-10, 10), vel(-kV, kV);
  int narrow = 0;
  for (int i = 0; i < 2000; ++i) {
    AxisBoundary b{pos(rng), pos(rng), vel(rng), vel(rng)};
    if (i % 10 == 0) b.q1 = b.q0 + 0.01 * pos(rng);
    const FeasibleDurations acc = feasible_durations(b, kV, kA);
    for (double j_max : {3e5, 3e7, 3e9}) {
      SCOPED_TRACE(testing::Message() << "case " << i << " j " << j_max);
      const double t_jerk = jerk_feasible_durations(b, kV, kA, j_max).t_min();
      const double excess_bound = 10 * kA / j_max;
      EXPECT_GE(t_jerk, acc.t_min() - 1e-12);
      const auto& [first_start, first_end] = acc.intervals.front();
      if (first_end - first_start > 2 * excess_bound) {
        EXPECT_LE(t_jerk - first_start, excess_bound);
      } else {
        ++narrow;
        EXPECT_LE(t_jerk - acc.intervals[1].first, excess_bound);
      }
    }
  }
  EXPECT_GT(narrow, 0);
}

// --- synchronisation --------------------------------------------------------------------

TEST(JerkSync, SlowestAxisDecides) {
  // x: 10 mm rest to rest (10/4 + 4/30 + 30/500 s); y: 1 mm and z: -0.2 mm over the same time
  const std::vector<AxisMove> axes{
      {{0, 10, 0, 0}, kV, kA, kJ}, {{0, 1, 0, 0}, kV, kA, kJ}, {{5, 4.8, 0, 0}, kV, kA, 2 * kJ}};
  const SynchronizedMove move = synchronized_move(axes);
  EXPECT_NEAR(move.duration_s, 10 / kV + kV / kA + kA / kJ, 1e-12);
  for (size_t i = 0; i < axes.size(); ++i)
    expect_valid(move.axes[i], axes[i].boundary, move.duration_s, kV, kA, axes[i].j_max);
}

TEST(JerkSync, BlockedDurationIsSkipped) {
  // y alone needs (32 * 0.05 / j)^(1/3) = 0.147 s, but x (d = 0, v0 = v1 = 3) is blocked
  // on (0, 0.52): the common duration is 0.52 s
  const std::vector<AxisMove> axes{{{0, 0, 3, 3}, kV, kA, kJ}, {{0, 0.05, 0, 0}, kV, kA, kJ}};
  EXPECT_NEAR(jerk_min_time_move(axes[1].boundary, kV, kA, kJ).duration_s(),
              std::cbrt(32 * 0.05 / kJ), 1e-12);
  const SynchronizedMove move = synchronized_move(axes);
  EXPECT_NEAR(move.duration_s, 2 * (6 / kA + kA / kJ), 1e-12);
  for (size_t i = 0; i < axes.size(); ++i)
    expect_valid(move.axes[i], axes[i].boundary, move.duration_s, kV, kA, kJ);
}

TEST(JerkSync, RandomMovesShareTheEarliestCommonDuration) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> pos(-10, 10), vel(-3.9, 3.9), unit(0, 1);
  for (int i = 0; i < 1500; ++i) {
    std::vector<AxisMove> axes;
    const int count = 2 + i % 2;
    for (int k = 0; k < count; ++k) {
      AxisBoundary b{pos(rng), pos(rng), vel(rng), vel(rng)};
      if (unit(rng) < 0.3) b.q1 = b.q0 + 0.02 * pos(rng);
      axes.push_back({b, kV, kA, k == 0 ? kJ : 100 + 4900 * unit(rng)});
    }
    const SynchronizedMove move = synchronized_move(axes);
    std::vector<FeasibleDurations> sets;
    for (size_t k = 0; k < axes.size(); ++k) {
      const AxisMove& m = axes[k];
      sets.push_back(jerk_feasible_durations(m.boundary, m.v_max, m.a_max, m.j_max));
      EXPECT_TRUE(sets.back().contains(move.duration_s, 1e-9));
      expect_valid(move.axes[k], m.boundary, move.duration_s, m.v_max, m.a_max, m.j_max);
    }
    // the earliest common duration starts one of the intervals; no earlier start is common
    for (const FeasibleDurations& set : sets)
      for (const auto& [start, end] : set.intervals) {
        if (start >= move.duration_s - 1e-12) continue;
        bool common = true;
        for (const FeasibleDurations& other : sets) common = common && other.contains(start, 0.0);
        EXPECT_FALSE(common) << "earlier common duration " << start;
      }
  }
}

}  // namespace
}  // namespace depotwin
