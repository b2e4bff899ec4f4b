// One contract test over every registered sequencer (planners/ordering/registry.cpp), alone and
// with each refinement, on seeded random instances: every path printed once, the reported cost
// is the order's cost and never below the lower bound, the same seed gives the same order, and
// per-move limits (a machine's TcpLimits) cost what the planners' transitions take.
#include <gtest/gtest.h>

#include <algorithm>

#include "planners/motion/transition.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {
namespace {

class SequencerContract : public ::testing::TestWithParam<std::string> {};

Toolpath instance(std::uint64_t seed, int count) {
  RandomSegmentsSpec spec;
  spec.count = count;
  spec.seed = seed;
  return make_random_segments(spec);
}

TEST_P(SequencerContract, EveryPathOnceAtTheReportedCost) {
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  std::vector<std::string> refinements{""};
  for (const std::string& refine : refine_methods()) refinements.push_back(refine);
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Toolpath toolpath = instance(seed, 12);
    for (const std::string& refine : refinements) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << " refine '" << refine << "'");
      OrderSpec spec;
      spec.method = GetParam();
      spec.refine = refine;
      spec.seed = seed;
      const OrderResult result = sequence(toolpath, limits, spec);
      // a permutation of the paths, a direction for each
      std::vector<int> sorted = result.order;
      std::sort(sorted.begin(), sorted.end());
      ASSERT_EQ(sorted.size(), toolpath.paths.size());
      for (size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], static_cast<int>(i));
      ASSERT_EQ(result.reversed.size(), result.order.size());
      // the cost is the order's, and the bound stays below it
      const TransitionCost cost(toolpath, limits, CostModel::machine);
      EXPECT_NEAR(result.cost_s, cost.order_cost(result), 1e-9);
      EXPECT_LE(result.lower_bound_s, result.cost_s + 1e-9);
      // the same seed, the same order
      const OrderResult again = sequence(toolpath, limits, spec);
      EXPECT_EQ(again.order, result.order);
      EXPECT_EQ(again.reversed, result.reversed);
    }
  }
}

// With limits that depend on the move, a transition costs what the planners' transition
// piece takes between the same ends (one limits rule for both)
TEST_P(SequencerContract, PerMoveLimitsCostWhatThePlannersTake) {
  const MachineLimits fast = MachineLimits::uniform(10.0, 100.0);
  const TcpLimits slow_on_the_right(fast, [fast](const Vec3&, const Vec3& hi) {
    MachineLimits limits = fast;
    if (hi.x() > 50.0)
      for (AxisLimits& axis : limits.axes) axis = AxisLimits{5.0, 20.0, 0.0};
    return limits;
  });
  const Toolpath toolpath = instance(3, 10);
  OrderSpec spec;
  spec.method = GetParam();
  const OrderResult result = sequence(toolpath, slow_on_the_right, spec);
  const TransitionCost cost(toolpath, slow_on_the_right, CostModel::machine);
  const std::vector<int> nodes = order_nodes(cost, result);
  for (size_t k = 0; k + 1 < nodes.size(); k += 2) {
    const int from = nodes[k], to = nodes[k + 1];
    // leave `from` along its path, enter `to` along its path (at rest at the job's ends)
    const double planned_s =
        transition_piece(0.0, cost.position(from), cost.exit_velocity(from), cost.position(to),
                         -cost.exit_velocity(to), slow_on_the_right)
            .t_end_s;
    EXPECT_NEAR(cost(from, to), planned_s, 1e-9) << "nodes " << from << " -> " << to;
  }
}

INSTANTIATE_TEST_SUITE_P(EverySequencer, SequencerContract,
                         ::testing::ValuesIn(sequencer_methods()),
                         [](const auto& info) { return info.param; });

TEST(SequencerRegistry, NamesAreUniqueAndFindable) {
  for (const SequencerInfo& info : sequencer_registry()) {
    EXPECT_EQ(find_sequencer(info.name), &info);
    EXPECT_FALSE(info.description.empty());
  }
  EXPECT_EQ(find_sequencer("simulated_annealing"), nullptr);
}

}  // namespace
}  // namespace depotwin
