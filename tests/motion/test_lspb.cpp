// LSPB of Thompson & Yoon (papers/000) eqs. (1)-(18): one hand-computed case per v_c candidate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "motion/lspb.hpp"
#include "motion/mtt.hpp"

namespace depotwin {
namespace {

// the profile meets eqs. (1)-(4) and has |a| = alpha in both blends
void expect_valid(const LspbSolution& s, const AxisBoundary& b, double alpha) {
  const AxisProfile p = s.profile(b);
  EXPECT_NEAR(p.duration_s(), s.duration_s, 1e-12);
  EXPECT_NEAR(p.at(0.0).q, b.q0, 1e-9);
  EXPECT_NEAR(p.at(0.0).v, b.v0, 1e-9);
  EXPECT_NEAR(p.q_end(), b.q1, 1e-9);
  EXPECT_NEAR(p.v_end(), b.v1, 1e-9);
  EXPECT_DOUBLE_EQ(std::abs(s.a0), alpha);
  EXPECT_DOUBLE_EQ(std::abs(s.a1), alpha);
  for (const Phase& phase : p.phases())
    EXPECT_TRUE(phase.a0 == 0.0 || std::abs(phase.a0) == alpha) << phase.a0;
}

struct SixCase {
  int candidate;
  AxisBoundary b;
  double duration_s, alpha, v_c;
};

TEST(Lspb, EachOfTheSixCandidates) {
  const double c2 =
      (15.0 - std::sqrt(105.0)) / 2.0;  // (alpha T - sqrt(alpha^2 T^2 - 4 alpha d)) / 2
  const SixCase cases[] = {
      // v_c1: the larger root of case I is valid only on the triangle (gamma_1 = 0)
      {1, {0, 2, 0, 0}, 2.0, 2.0, 2.0},
      // v_c2: rest to rest with a cruise
      {2, {0, 1, 0, 0}, 0.5, 30.0, c2},
      // v_c3 / v_c4: the same, mirrored
      {3, {0, -2, 0, 0}, 2.0, 2.0, -2.0},
      {4, {0, -1, 0, 0}, 0.5, 30.0, -c2},
      // v_c5: accelerate, cruise, accelerate: (30*1 + (1-9)/2) / (1-3+15) = 2
      {5, {0, 1, 1, 3}, 0.5, 30.0, 2.0},
      // v_c6: decelerate, cruise, decelerate: (-30 + (9-1)/2) / (3-1-15) = 2
      {6, {0, 1, 3, 1}, 0.5, 30.0, 2.0},
  };
  for (const SixCase& c : cases) {
    SCOPED_TRACE(c.candidate);
    const auto s = solve_lspb(c.b, c.duration_s, c.alpha);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->candidate, c.candidate);
    EXPECT_NEAR(s->v_c, c.v_c, 1e-12);
    expect_valid(*s, c.b, c.alpha);
  }
}

TEST(Lspb, BlendTimesFollowEquations5And6) {
  // case v_c5: t_b0 = (2-1)/30, t_b1 = (2-3)/30 + 0.5
  const auto s = solve_lspb({0, 1, 1, 3}, 0.5, 30.0);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->t_b0, 1.0 / 30.0, 1e-12);
  EXPECT_NEAR(s->t_b1, 0.5 - 1.0 / 30.0, 1e-12);
}

TEST(Lspb, NoSolutionWhenTooShort) {
  // 1 mm in 0.1 s from rest needs 4 d / T^2 = 400 mm/s^2 > 30
  EXPECT_FALSE(solve_lspb({0, 1, 0, 0}, 0.1, 30.0).has_value());
  // the cruise velocity would exceed v_max
  EXPECT_FALSE(solve_lspb({0, 10, 0, 0}, 2.0, 30.0, 4.0).has_value());
  EXPECT_TRUE(solve_lspb({0, 10, 0, 0}, 2.0, 30.0, 6.0).has_value());
}

TEST(Lspb, RandomFeasibleDurationsAlwaysSolve) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-20, 20), vel(-4, 4), extra(0.0, 2.0);
  int solved = 0;
  for (int i = 0; i < 5000; ++i) {
    const AxisBoundary b{pos(rng), pos(rng), vel(rng), vel(rng)};
    const FeasibleDurations set = feasible_durations(b, 4.0, 30.0);
    const double t = set.earliest_at_least(set.t_min() + extra(rng));
    const auto s = solve_lspb(b, t, 30.0, 4.0);
    ASSERT_TRUE(s.has_value()) << "case " << i << " T=" << t;
    expect_valid(*s, b, 30.0);
    EXPECT_LE(std::abs(s->v_c), 4.0 + 1e-9);
    ++solved;
  }
  EXPECT_EQ(solved, 5000);
}

// A short move stretched over a long time (the slow axis of a synchronised move): blends of
// 1.9e-8 s at 8000 mm/s^2, within the roundoff window of eq. (18). The cruise velocity solves
// v T - v^2 / alpha = |d|: v = 2 |d| / (T + sqrt(T^2 - 4 |d| / alpha)) (no cancellation).
// Backwards, case I's candidate 2 (a0 = +alpha, v_c < 0) once passed that window and was
// clamped to no blend: a profile that never moved; and the root by x - sqrt(gamma) kept only
// a few digits of the cruise velocity (6e-6 off at 0.001 mm).
TEST(Lspb, TinyMoveStretchedOverALongTimeInEitherDirection) {
  const double T = 200.01, alpha = 8000.0;
  for (const double d : {0.03, -0.03, 0.001, -0.001, 1e-6, -1e-6}) {
    SCOPED_TRACE(d);
    const AxisBoundary b{0.0, d, 0.0, 0.0};
    const auto s = solve_lspb(b, T, alpha, 400.0);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->candidate, d > 0 ? 2 : 4);
    const double v = 2.0 * std::abs(d) / (T + std::sqrt(T * T - 4.0 * std::abs(d) / alpha));
    EXPECT_NEAR(s->v_c, std::copysign(v, d), 1e-12 * v);
    const AxisProfile p = s->profile(b);
    EXPECT_NEAR(p.q_end(), d, 1e-12 * std::abs(d));
    // (the last blend's time is T - t_b1, short against T: alpha times a few ulps of T)
    EXPECT_NEAR(p.v_end(), 0.0, alpha * 8.0 * std::numeric_limits<double>::epsilon() * T);
  }
}

}  // namespace
}  // namespace depotwin
