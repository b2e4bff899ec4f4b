// The matching lower bound: exact (equal to an independent enumeration / a dense
// matching) and below every order.
#include <gtest/gtest.h>

#include <lemon/matching.h>
#include <lemon/smart_graph.h>
#include <cmath>

#include "planners/ordering/exact.hpp"
#include "planners/ordering/lower_bound.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {
namespace {

const MachineLimits kPaperLimits = MachineLimits::uniform(4.0, 30.0);

// the same matching on the complete graph, straight from LEMON (double weights)
double dense_matching_bound(const TransitionCost& cost) {
  using Graph = lemon::SmartGraph;
  Graph graph;
  const int n = cost.node_count();
  for (int v = 0; v < n; ++v) graph.addNode();
  Graph::EdgeMap<double> weight(graph);
  for (int u = 0; u < n; ++u)
    for (int v = u + 1; v < n; ++v)
      if (v != TransitionCost::partner(u))
        weight[graph.addEdge(graph.nodeFromId(u), graph.nodeFromId(v))] = -cost(u, v);
  lemon::MaxWeightedPerfectMatching<Graph, Graph::EdgeMap<double>> matching(graph, weight);
  EXPECT_TRUE(matching.run());
  double total = 0.0;
  for (int v = 0; v < n; ++v) {
    const int mate = graph.id(matching.mate(graph.nodeFromId(v)));
    if (v < mate) total += cost(v, mate);
  }
  return cost.print_time_s() + total;
}

TEST(LowerBound, EqualsTheEnumeratedMinimumMatching) {
  for (CostModel model : {CostModel::machine, CostModel::along_line}) {
    for (int count : {1, 2, 5, 9}) {
      const TransitionCost cost(testing::paper_instance(count, 31 + count), kPaperLimits, model);
      // integer microseconds, rounded down: at most 1 us per transition below
      const double exact = testing::brute_force_matching_bound(cost);
      const double bound = matching_lower_bound(cost);
      EXPECT_LE(bound, exact + 1e-12);
      EXPECT_GE(bound, exact - 1e-6 * (count + 1)) << "N = " << count;
    }
  }
}

TEST(LowerBound, PricingFindsTheCompleteGraphOptimum) {
  // instances large enough that the neighbour-list graph misses optimal pairs: the
  // dual check must add them and end at the complete graph's optimum
  long added = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (CostModel model : {CostModel::machine, CostModel::along_line}) {
      RandomSegmentsSpec spec;
      spec.count = 150;
      spec.bed_x_mm = spec.bed_y_mm = 130.0;
      spec.seed = seed;
      const TransitionCost cost(make_random_segments(spec), kPaperLimits, model);
      MatchingBoundStats stats;
      const double bound = matching_lower_bound(cost, &stats);
      added += stats.added_pairs;
      const double dense = dense_matching_bound(cost);
      EXPECT_LE(bound, dense + 1e-9);
      EXPECT_GE(bound, dense - 1e-6 * (spec.count + 1));
    }
  }
  EXPECT_GT(added, 0) << "the test did not exercise pricing";
}

TEST(LowerBound, StartFarFromTheBedStillExact) {
  // one end far away gives a very low dual value: the outlier path of the check
  Toolpath toolpath = testing::paper_instance(40, 77);
  toolpath.start_mm = Vec3(-400, 900, 0);
  const TransitionCost cost(toolpath, kPaperLimits, CostModel::machine);
  EXPECT_NEAR(matching_lower_bound(cost), dense_matching_bound(cost), 1e-6 * 41);
}

}  // namespace
}  // namespace depotwin

namespace depotwin {
namespace {

// the sequencer computes the bound only when asked and only up to lower_bound_max_paths
// paths (SequencerOptions): the same bound as matching_lower_bound below it, NaN above
TEST(LowerBound, SequencerComputesItOnlyUpToTheMaximumPaths) {
  const Toolpath toolpath = testing::paper_instance(12, 5);
  const TcpLimits limits(kPaperLimits);
  const OrderSpec nearest{"nearest_neighbor", "", "machine", 1};
  SequencerOptions options;
  options.lower_bound_max_paths = 12;
  const OrderResult bounded = sequence(toolpath, limits, nearest, options);
  const TransitionCost cost(toolpath, limits, CostModel::machine);
  EXPECT_EQ(bounded.lower_bound_s, matching_lower_bound(cost));
  EXPECT_LE(bounded.lower_bound_s, bounded.cost_s);
  options.lower_bound_max_paths = 11;
  EXPECT_TRUE(std::isnan(sequence(toolpath, limits, nearest, options).lower_bound_s));
  options.lower_bound_max_paths = 12;
  options.lower_bound = false;
  EXPECT_TRUE(std::isnan(sequence(toolpath, limits, nearest, options).lower_bound_s));
  // the default
  EXPECT_EQ(SequencerOptions{}.lower_bound_max_paths, 5000);
}

}  // namespace
}  // namespace depotwin
