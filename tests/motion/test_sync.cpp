// Multi-axis synchronisation, eq. (39) of Thompson & Yoon, with blocked durations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "motion/mtt.hpp"
#include "motion/sync.hpp"

namespace depotwin {
namespace {

TEST(Sync, SlowestAxisDecides) {
  // x: 10 mm from rest to rest (2.6333 s); y: 1 mm, re-planned over the same time
  const std::vector<AxisMove> axes{{{0, 10, 0, 0}, 4, 30}, {{0, 1, 0, 0}, 4, 30}};
  const SynchronizedMove move = synchronized_move(axes);
  EXPECT_NEAR(move.duration_s, 10.0 / 4 + 4.0 / 30, 1e-12);
  for (size_t i = 0; i < axes.size(); ++i) {
    EXPECT_NEAR(move.axes[i].duration_s(), move.duration_s, 1e-12);
    EXPECT_NEAR(move.axes[i].q_end(), axes[i].boundary.q1, 1e-9);
    EXPECT_NEAR(move.axes[i].v_end(), axes[i].boundary.v1, 1e-9);
  }
}

TEST(Sync, BlockedDurationIsSkipped) {
  // y alone needs 0.2 s (a 0.3 mm triangle), but x (d = 0, v0 = v1 = 3) is blocked on
  // (0, 0.4): the common duration is 0.4 s, not max(t_x, t_y) = 0.2 s
  const std::vector<AxisMove> axes{{{0, 0, 3, 3}, 4, 30}, {{0, 0.3, 0, 0}, 4, 30}};
  const double t_y = min_time_move(axes[1].boundary, 4, 30).duration_s();
  EXPECT_NEAR(t_y, 0.2, 1e-12);
  const SynchronizedMove move = synchronized_move(axes);
  EXPECT_NEAR(move.duration_s, 0.4, 1e-12);
  EXPECT_GT(move.duration_s, std::max(0.0, t_y) + 0.1);
  EXPECT_NEAR(move.axes[0].q_end(), 0.0, 1e-9);
  EXPECT_NEAR(move.axes[0].v_end(), 3.0, 1e-9);
  EXPECT_NEAR(move.axes[1].q_end(), 0.3, 1e-9);
}

// the `move` verb's case: a 200 mm axis at 1 mm/s sets 200.01 s, and a fast axis moving
// 0.03 mm backwards in that time still gets there (it was planned as no motion at all)
TEST(Sync, ATinyAxisBackwardsUnderALongOneStillMoves) {
  const std::vector<AxisMove> axes{{{0, 200, 0, 0}, 1, 100}, {{0, -0.03, 0, 0}, 400, 8000}};
  const SynchronizedMove move = synchronized_move(axes);
  EXPECT_NEAR(move.duration_s, 200.0 + 1.0 / 100.0, 1e-9);
  EXPECT_NEAR(move.axes[1].q_end(), -0.03, 1e-14);
  EXPECT_NEAR(move.axes[1].duration_s(), move.duration_s, 1e-12);
  EXPECT_LT(move.axes[1].at(0.5 * move.duration_s).q, -0.0149);
}

TEST(Sync, RandomMovesMeetBoundariesAndLimits) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> pos(-10, 10), vel(-3.9, 3.9);
  for (int i = 0; i < 2000; ++i) {
    std::vector<AxisMove> axes;
    for (int k = 0; k < 3; ++k) axes.push_back({{pos(rng), pos(rng), vel(rng), vel(rng)}, 4, 30});
    const SynchronizedMove move = synchronized_move(axes);
    double slowest = 0.0;
    for (size_t k = 0; k < axes.size(); ++k) {
      const AxisProfile& p = move.axes[k];
      slowest = std::max(slowest, min_time_move(axes[k].boundary, 4, 30).duration_s());
      EXPECT_NEAR(p.duration_s(), move.duration_s, 1e-9);
      EXPECT_NEAR(p.q_end(), axes[k].boundary.q1, 1e-9);
      EXPECT_NEAR(p.v_end(), axes[k].boundary.v1, 1e-9);
      EXPECT_LE(p.peak_speed(), 4 + 1e-9);
      EXPECT_LE(p.peak_acceleration(), 30 + 1e-9);
      EXPECT_TRUE(feasible_durations(axes[k].boundary, 4, 30).contains(move.duration_s, 1e-9));
    }
    EXPECT_GE(move.duration_s, slowest - 1e-12);
  }
}

}  // namespace
}  // namespace depotwin
