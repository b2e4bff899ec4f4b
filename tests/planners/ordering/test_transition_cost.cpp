// Transition costs: the paper's along-line model (closed forms of Sec. II) and the
// machine's synchronised per-axis minimum-time move.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "motion/mtt.hpp"
#include "planners/ordering/exact.hpp"
#include "planners/ordering/lower_bound.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {
namespace {

PrintPath segment(Vec3 a, Vec3 b, double speed_mm_s = 3.0) {
  PrintPath path;
  path.points = {a, b};
  path.speed_mm_s = speed_mm_s;
  return path;
}

// two collinear segments on the x axis: [0, 10] and [10 + gap, 20 + gap]
Toolpath two_on_a_line(double gap_mm) {
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-20, 0, 0);
  toolpath.end_mm = Vec3(40 + gap_mm, 0, 0);
  toolpath.paths = {segment(Vec3(0, 0, 0), Vec3(10, 0, 0)),
                    segment(Vec3(10 + gap_mm, 0, 0), Vec3(20 + gap_mm, 0, 0))};
  return toolpath;
}

const MachineLimits kPaperLimits = MachineLimits::uniform(4.0, 30.0);

TEST(TransitionCost, AlongLineLongTransitionClosedForm) {
  // v_p = 3, v_max = 4, a = 30: d / v_max + (v_max - v_p)^2 / (a v_max) = d/4 + 1/120
  for (double d : {0.5, 1.0, 5.0, 37.5, 100.0}) {
    const TransitionCost cost(two_on_a_line(d), kPaperLimits, CostModel::along_line);
    const int exit0 = TransitionCost::exit_node(0, false),
              entry1 = TransitionCost::entry_node(1, false);
    EXPECT_NEAR(cost(exit0, entry1), d / 4.0 + 1.0 / 120.0, 1e-12) << "d = " << d;
  }
}

TEST(TransitionCost, AlongLineShortTransitionIsTriangular) {
  // eq. (2) with a1 = -a2 = a: v_peak = sqrt(a d + v^2) <= v_max; eq. (1): 2 (v_peak - v) / a
  for (double d : {1e-3, 0.05, 0.1, 0.2}) {
    const TransitionCost cost(two_on_a_line(d), kPaperLimits, CostModel::along_line);
    const double v_peak = std::sqrt(30.0 * d + 9.0);
    ASSERT_LE(v_peak, 4.0);
    EXPECT_NEAR(cost(1, 2), 2.0 * (v_peak - 3.0) / 30.0, 1e-12) << "d = " << d;
  }
}

TEST(TransitionCost, AlongLineFromRestMatchesOneAxisMinimumTime) {
  // start (at rest) 20 mm before the first segment's front, entering at 3 mm/s; and a
  // start 0.1 mm away, too short to reach 3 mm/s without overshooting
  for (double gap : {20.0, 0.1}) {
    Toolpath toolpath = two_on_a_line(5.0);
    toolpath.start_mm = Vec3(-gap, 0, 0);
    const TransitionCost cost(toolpath, kPaperLimits, CostModel::along_line);
    const double expected = feasible_durations({0.0, gap, 0.0, 3.0}, 4.0, 30.0).t_min();
    EXPECT_NEAR(cost(cost.start_node(), TransitionCost::entry_node(0, false)), expected, 1e-12);
  }
}

TEST(TransitionCost, MachineCostFollowsPrintDirections) {
  const double gap = 50.0;
  const TransitionCost cost(two_on_a_line(gap), kPaperLimits, CostModel::machine);
  // leave [0, 10] at +3 mm/s, enter [60, 70] at +3 mm/s: only x moves, d/4 + 1/120
  EXPECT_NEAR(cost(TransitionCost::exit_node(0, false), TransitionCost::entry_node(1, false)),
              gap / 4.0 + 1.0 / 120.0, 1e-9);
  // enter the second segment reversed (at x = 70, moving -x): overshoot and come back
  const double reversed =
      cost(TransitionCost::exit_node(0, false), TransitionCost::entry_node(1, true));
  EXPECT_NEAR(reversed, feasible_durations({10.0, 70.0, 3.0, -3.0}, 4.0, 30.0).t_min(), 1e-9);
  EXPECT_GT(reversed, (70.0 - 10.0) / 4.0);
  // the along-line model ignores direction: the reversed entry costs its distance only
  const TransitionCost line(two_on_a_line(gap), kPaperLimits, CostModel::along_line);
  EXPECT_NEAR(line(TransitionCost::exit_node(0, false), TransitionCost::entry_node(1, true)),
              60.0 / 4.0 + 1.0 / 120.0, 1e-12);
}

TEST(TransitionCost, SymmetricUnderTimeReversalAndAboveTheBounds) {
  const Toolpath toolpath = testing::paper_instance(15, 3);
  for (CostModel model : {CostModel::machine, CostModel::along_line}) {
    const TransitionCost cost(toolpath, kPaperLimits, model);
    for (int a = 0; a < cost.node_count(); ++a) {
      for (int b = 0; b < cost.node_count(); ++b) {
        if (a == b) continue;
        const double time_s = cost(a, b);
        EXPECT_NEAR(time_s, cost(b, a), 1e-9);
        EXPECT_LE(cost.bound(a, b), time_s + 1e-12);
        const Vec3 offset = cost.position(b) - cost.position(a);
        const double chebyshev_xy = std::max(std::abs(offset.x()), std::abs(offset.y()));
        EXPECT_LE(cost.bound_for_distance(chebyshev_xy), time_s + 1e-12);
      }
    }
  }
}

TEST(TransitionCost, OrderCostAddsPrintTimeAndTransitions) {
  const double gap = 30.0;
  const TransitionCost cost(two_on_a_line(gap), kPaperLimits, CostModel::along_line);
  EXPECT_DOUBLE_EQ(cost.print_time_s(), 20.0 / 3.0);
  OrderResult order;
  order.order = {0, 1};
  order.reversed = {false, false};
  // start at rest 20 mm before, 30 mm between, 20 mm to the end at rest
  const double from_rest = feasible_durations({0.0, 20.0, 0.0, 3.0}, 4.0, 30.0).t_min();
  EXPECT_NEAR(cost.order_cost(order), 20.0 / 3.0 + 2.0 * from_rest + gap / 4.0 + 1.0 / 120.0,
              1e-12);
  EXPECT_NEAR(cost.transition_length_mm(order), 20.0 + gap + 20.0, 1e-12);
}

// two paths that meet at a corner are printed through it (the planners join them): the joint
// costs nothing under either model, the order costs the print time plus the start's and the
// end's moves, and the matching bound is that cost (before, a zero-length move at the two
// paths' speeds was charged: (3 + 3 sqrt 2) / 30 s here, above every plan)
TEST(TransitionCost, PathsMeetingAtAPointAreJoinedAtNoCost) {
  Toolpath corner;
  corner.start_mm = Vec3(0, 0, 0);
  corner.end_mm = Vec3(3, 3, 0);
  corner.paths = {segment(Vec3(0, 0, 0), Vec3(3, 0, 0)), segment(Vec3(3, 0, 0), Vec3(3, 3, 0))};
  for (CostModel model : {CostModel::machine, CostModel::along_line}) {
    const TransitionCost cost(corner, kPaperLimits, model);
    const int exit0 = TransitionCost::exit_node(0, false);
    const int entry1 = TransitionCost::entry_node(1, false);
    EXPECT_EQ(cost(exit0, entry1), 0.0);
    EXPECT_EQ(cost(entry1, exit0), 0.0);
    OrderResult order;
    order.order = {0, 1};
    order.reversed = {false, false};
    // from rest at the first path's start to 3 mm/s, and from 3 mm/s to rest at the end:
    // (3 + 3 sqrt 2) / 30 s each, zero-displacement moves of one axis
    const double at_rest_end = (3.0 + 3.0 * std::sqrt(2.0)) / 30.0;
    if (model == CostModel::machine) {
      EXPECT_NEAR(cost(cost.start_node(), TransitionCost::entry_node(0, false)), at_rest_end,
                  1e-12);
      EXPECT_NEAR(cost.order_cost(order), 2.0 + 2.0 * at_rest_end, 1e-12);
      // (the matching works in whole microseconds)
      EXPECT_LE(matching_lower_bound(cost), cost.order_cost(order));
      EXPECT_NEAR(matching_lower_bound(cost), cost.order_cost(order), 1e-5);
    }
  }
}

// paths too fast where the machine's joints slow the TCP (limits that fall with x, as an arm's
// near its base): the first ten named with the joints' limit, the rest counted with the lowest
TEST(TransitionCost, PathsTooFastForTheJointsAreNamedThenCounted) {
  const TcpLimits falling(kPaperLimits, [](const Vec3&, const Vec3& hi) {
    return MachineLimits::uniform(4.0 - 0.1 * hi.x(), 30.0);
  });
  Toolpath toolpath;
  toolpath.start_mm = toolpath.end_mm = Vec3(0, -10, 0);
  for (int i = 0; i < 12; ++i)  // path i from x = i to i + 1 (v_max 3.9 - 0.1 i) at 3.85 mm/s
    toolpath.paths.push_back(segment(Vec3(i, 3.0 * i, 0), Vec3(i + 1, 3.0 * i, 0), 3.85));
  for (int i = 0; i < 12; ++i) toolpath.paths[i].source_index = i;
  std::vector<Problem> problems;
  try {
    TransitionCost cost(toolpath, falling, CostModel::machine);
  } catch (const InputError& e) {
    problems = e.problems();
  }
  // path 0 (v_max 3.9) is fine; paths 1 to 11 are too fast: 1 to 10 named, 11 counted
  ASSERT_EQ(problems.size(), 11u);
  EXPECT_EQ(problems[0].key, "toolpath.paths[1].speed");
  EXPECT_EQ(problems[0].message,
            "print speed 3.85 mm/s exceeds v_max = 3.8 mm/s of axis x at its ends (the machine's "
            "joint limits mapped over this path; limits v_max is 4)");
  EXPECT_EQ(problems[9].key, "toolpath.paths[10].speed");
  EXPECT_EQ(problems[10].key, "toolpath");
  EXPECT_EQ(problems[10].message,
            "... and 1 more print paths too fast at their ends (11 in all): print them at 2.8 "
            "mm/s or less");
}

TEST(TransitionCost, UnprintablePathsAreInputErrors) {
  Toolpath toolpath = two_on_a_line(5.0);
  toolpath.paths[1].speed_mm_s = 5.0;  // above v_max on x
  EXPECT_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::machine), InputError);
  EXPECT_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::along_line), InputError);
  // 5 mm/s diagonally is 3.54 mm/s per axis: fine for the machine, not along the line
  toolpath.paths[1] = segment(Vec3(30, 30, 0), Vec3(40, 40, 0), 5.0);
  EXPECT_NO_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::machine));
  EXPECT_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::along_line), InputError);
  toolpath.paths[1] = segment(Vec3(30, 30, 0), Vec3(30, 30, 0));  // no length
  EXPECT_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::machine), InputError);
  toolpath = two_on_a_line(5.0);
  toolpath.paths[0].speed_mm_s = 0.0;
  EXPECT_THROW(TransitionCost(toolpath, kPaperLimits, CostModel::machine), InputError);
  EXPECT_THROW(parse_cost_model("euclidean"), InputError);
}

}  // namespace
}  // namespace depotwin
