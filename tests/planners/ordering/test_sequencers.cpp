// The sequencers and refinements against exact optima, and their contracts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.hpp"
#include "planners/ordering/exact.hpp"
#include "planners/ordering/nearest_neighbor.hpp"
#include "planners/ordering/sequencer.hpp"

namespace depotwin {
namespace {

const MachineLimits kPaperLimits = MachineLimits::uniform(4.0, 30.0);

std::vector<OrderSpec> every_method(const std::string& cost_model, std::uint64_t seed = 1) {
  std::vector<OrderSpec> specs;
  for (const std::string& method : sequencer_methods()) {
    for (const std::string& refine : {std::string()})
      specs.push_back(testing::spec(method, refine, cost_model, seed));
    for (const std::string& refine : refine_methods())
      specs.push_back(testing::spec(method, refine, cost_model, seed));
  }
  return specs;
}

void expect_permutation(const OrderResult& result, int count) {
  ASSERT_EQ(static_cast<int>(result.order.size()), count);
  ASSERT_EQ(result.reversed.size(), result.order.size());
  std::vector<int> sorted = result.order;
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < count; ++i) EXPECT_EQ(sorted[i], i);
}

TEST(Sequencers, NoMethodBeatsTheBruteForceOptimumAndTheBoundStaysBelow) {
  for (const std::string model : {"machine", "along_line"}) {
    for (int count = 1; count <= 7; ++count) {
      for (std::uint64_t seed = 1; seed <= (count == 7 ? 2u : 4u); ++seed) {
        const Toolpath toolpath = testing::paper_instance(count, 100 * count + seed);
        const TransitionCost cost(toolpath, kPaperLimits, parse_cost_model(model));
        const double optimum_s = testing::brute_force_optimum(cost);
        for (const OrderSpec& spec : every_method(model, seed)) {
          const OrderResult result = sequence(toolpath, kPaperLimits, spec);
          expect_permutation(result, count);
          EXPECT_NEAR(result.cost_s, cost.order_cost(result), 1e-9);
          EXPECT_GE(result.cost_s, optimum_s - 1e-9) << spec.label() << " N=" << count;
          EXPECT_LE(result.lower_bound_s, optimum_s + 1e-9) << model << " N=" << count;
        }
      }
    }
  }
}

// a part in layers is printed layer on layer: every search keeps the layers in rising order
// (a multi-layer G-code file searched whole had upper layers printed before the ones under
// them); the given order, unrefined, stays the file's whatever its layers
TEST(Sequencers, SearchesKeepTheLayersInRisingOrder) {
  Toolpath toolpath = testing::paper_instance(12, 4242);
  for (std::size_t i = 0; i < toolpath.paths.size(); ++i) {
    PrintPath& path = toolpath.paths[i];
    path.layer = static_cast<int>((i * 7) % 3);  // layers 0, 1, 2 mixed through the file
    for (Vec3& p : path.points) p.z() = 0.2 * (path.layer + 1);
  }
  ASSERT_EQ(toolpath.layer_count(), 3);
  const TransitionCost cost(toolpath, kPaperLimits, CostModel::machine);
  for (const OrderSpec& spec : every_method("machine")) {
    const OrderResult result = sequence(toolpath, kPaperLimits, spec);
    expect_permutation(result, 12);
    EXPECT_NEAR(result.cost_s, cost.order_cost(result), 1e-9);
    if (spec.method == "as_given" && spec.refine.empty()) {
      for (int k = 0; k < 12; ++k) EXPECT_EQ(result.order[static_cast<std::size_t>(k)], k);
      continue;
    }
    for (std::size_t k = 1; k < result.order.size(); ++k)
      EXPECT_LE(toolpath.paths[static_cast<std::size_t>(result.order[k - 1])].layer,
                toolpath.paths[static_cast<std::size_t>(result.order[k])].layer)
          << spec.label() << " at " << k;
  }
}

TEST(Sequencers, ThreeOptReachesTheOptimumOnMostSeeds) {
  // N = 6 and 7, 15 seeds each, from nearest neighbour and from Christofides
  int runs = 0, optimal = 0;
  for (int count : {6, 7}) {
    for (std::uint64_t seed = 1; seed <= 15; ++seed) {
      const Toolpath toolpath = testing::paper_instance(count, 7000 + 100 * count + seed);
      const TransitionCost cost(toolpath, kPaperLimits, CostModel::machine);
      const double optimum_s = testing::brute_force_optimum(cost);
      for (const std::string method : {"nearest_neighbor", "christofides"}) {
        const OrderResult result =
            sequence(toolpath, kPaperLimits, testing::spec(method, "three_opt", "machine"));
        ++runs;
        optimal += result.cost_s <= optimum_s + 1e-9 ? 1 : 0;
      }
    }
  }
  EXPECT_GE(optimal, 0.8 * runs) << optimal << " of " << runs << " runs optimal";
}

TEST(Sequencers, RefinementsNeverIncreaseTheCost) {
  for (const std::string model : {"machine", "along_line"}) {
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      const Toolpath toolpath = testing::paper_instance(40, seed);
      for (const std::string& method : sequencer_methods()) {
        const double base_s =
            sequence(toolpath, kPaperLimits, testing::spec(method, "", model, seed)).cost_s;
        for (const std::string& refine : refine_methods()) {
          const double refined_s =
              sequence(toolpath, kPaperLimits, testing::spec(method, refine, model, seed)).cost_s;
          EXPECT_LE(refined_s, base_s + 1e-9) << method << "+" << refine << " " << model;
        }
      }
    }
  }
}

TEST(Sequencers, SameSeedSameOrder) {
  const Toolpath toolpath = testing::paper_instance(60, 11);
  for (const OrderSpec& spec : every_method("machine", 5)) {
    const OrderResult a = sequence(toolpath, kPaperLimits, spec);
    const OrderResult b = sequence(toolpath, kPaperLimits, spec);
    EXPECT_EQ(a.order, b.order) << spec.label();
    EXPECT_EQ(a.reversed, b.reversed) << spec.label();
    EXPECT_EQ(a.cost_s, b.cost_s) << spec.label();
  }
  const OrderResult one =
      sequence(toolpath, kPaperLimits, testing::spec("random", "", "machine", 1));
  const OrderResult two =
      sequence(toolpath, kPaperLimits, testing::spec("random", "", "machine", 2));
  EXPECT_NE(one.order, two.order);
}

TEST(Sequencers, NearestNeighborTakesTheCheapestNextEntryEveryTime) {
  // the grid search must agree with a scan over every remaining entry
  for (CostModel model : {CostModel::machine, CostModel::along_line}) {
    const TransitionCost cost(testing::paper_instance(80, 21), kPaperLimits, model);
    const OrderResult result = nearest_neighbor_order(cost);
    expect_permutation(result, 80);
    std::vector<bool> done(80, false);
    int at = cost.start_node();
    for (size_t k = 0; k < result.order.size(); ++k) {
      double cheapest = INFINITY;
      for (int path = 0; path < 80; ++path)
        for (bool reversed : {false, true})
          if (!done[path])
            cheapest = std::min(cheapest, cost(at, TransitionCost::entry_node(path, reversed)));
      const int entry = TransitionCost::entry_node(result.order[k], result.reversed[k]);
      EXPECT_EQ(cost(at, entry), cheapest) << "step " << k;
      done[result.order[k]] = true;
      at = TransitionCost::exit_node(result.order[k], result.reversed[k]);
    }
  }
}

TEST(Sequencers, CollinearSegmentsArePrintedInLineOrder) {
  // start, three segments along x given shuffled and reversed, end: the only sensible
  // order is left to right, every segment forwards
  Toolpath toolpath;
  toolpath.start_mm = Vec3(-10, 0, 0);
  toolpath.end_mm = Vec3(60, 0, 0);
  for (auto [a, b] : {std::pair{40.0, 50.0}, {10.0, 0.0}, {30.0, 20.0}}) {
    PrintPath path;
    path.points = {Vec3(a, 0, 0), Vec3(b, 0, 0)};
    path.speed_mm_s = 3.0;
    toolpath.paths.push_back(path);
  }
  for (const OrderSpec& spec : every_method("machine")) {
    if (spec.method == "as_given" || (spec.method == "random" && spec.refine.empty())) continue;
    const OrderResult result = sequence(toolpath, kPaperLimits, spec);
    EXPECT_EQ(result.order, (std::vector<int>{1, 2, 0})) << spec.label();
    EXPECT_EQ(result.reversed, (std::vector<bool>{true, true, false})) << spec.label();
    // nothing to gain: all transitions are straight-through moves, the bound is tight
    EXPECT_NEAR(result.cost_s, result.lower_bound_s, 1e-5) << spec.label();
  }
}

TEST(Sequencers, EmptyAndSingleSegmentJobs) {
  Toolpath empty;
  empty.start_mm = Vec3(0, 0, 0);
  empty.end_mm = Vec3(30, 40, 0);
  for (const OrderSpec& spec : every_method("machine")) {
    const OrderResult result = sequence(empty, kPaperLimits, spec);
    EXPECT_TRUE(result.order.empty());
    const TransitionCost cost(empty, kPaperLimits, CostModel::machine);
    EXPECT_DOUBLE_EQ(result.cost_s, cost(cost.start_node(), cost.end_node()));
    EXPECT_DOUBLE_EQ(result.lower_bound_s, result.cost_s);
  }
  // one segment: the bound's matching is one of the two directions, so it is exact
  const Toolpath single = testing::paper_instance(1, 5);
  for (const OrderSpec& spec : every_method("machine")) {
    if (spec.refine.empty()) continue;  // constructions alone may pick the worse direction
    const OrderResult result = sequence(single, kPaperLimits, spec);
    EXPECT_NEAR(result.cost_s, result.lower_bound_s, 2e-6) << spec.label();
  }
}

TEST(Sequencers, LargeInstancesStayValid) {
  // beyond Christofides' dense limit (sparse tree and matching) and the neighbour lists
  RandomSegmentsSpec spec;
  spec.count = 1500;
  spec.bed_x_mm = spec.bed_y_mm = 400.0;
  spec.seed = 9;
  const Toolpath toolpath = make_random_segments(spec);
  SequencerOptions options;
  double nearest_s = 0.0;
  for (const std::string method : {"nearest_neighbor", "christofides"}) {
    for (const std::string refine : {"", "two_opt", "or_opt", "three_opt"}) {
      const OrderResult result =
          sequence(toolpath, kPaperLimits, testing::spec(method, refine, "machine"), options);
      expect_permutation(result, 1500);
      EXPECT_GE(result.cost_s, result.lower_bound_s) << method << "+" << refine;
      if (method == std::string("nearest_neighbor") && refine.empty()) nearest_s = result.cost_s;
      if (!refine.empty()) {
        EXPECT_LT(result.cost_s, nearest_s) << method << "+" << refine;
      }
    }
  }
  options.lower_bound = false;
  EXPECT_TRUE(std::isnan(
      sequence(toolpath, kPaperLimits, testing::spec("nearest_neighbor"), options).lower_bound_s));
}

TEST(Sequencers, UnknownNamesAreInputErrors) {
  const Toolpath toolpath = testing::paper_instance(5, 1);
  EXPECT_THROW(sequence(toolpath, kPaperLimits, testing::spec("greedy")), InputError);
  EXPECT_THROW(sequence(toolpath, kPaperLimits, testing::spec("random", "four_opt")), InputError);
  EXPECT_THROW(sequence(toolpath, kPaperLimits, testing::spec("random", "", "manhattan")),
               InputError);
  EXPECT_EQ(testing::spec("christofides", "three_opt").label(), "christofides+three_opt");
  EXPECT_EQ(OrderSpec{}.label(), "as_given");
}

// `order: NAME` and `compare --orders NAME` read one grammar: a refinement alone is
// nearest_neighbor plus it; anything else unknown is named with the accepted forms
TEST(Sequencers, OrderNamesReadAsTheScenarioReadsThem) {
  OrderSpec order;
  EXPECT_EQ(parse_order_name("three_opt", order), "");
  EXPECT_EQ(order.label(), "nearest_neighbor+three_opt");
  EXPECT_EQ(parse_order_name("christofides+or_opt", order), "");
  EXPECT_EQ(order.label(), "christofides+or_opt");
  EXPECT_EQ(parse_order_name("random", order), "");
  EXPECT_EQ(order.label(), "random");
  for (const char* bad : {"greedy", "as_given+", "+two_opt", "two_opt+three_opt", ""}) {
    OrderSpec kept = testing::spec("christofides", "two_opt");
    const std::string problem = parse_order_name(bad, kept);
    EXPECT_EQ(problem.rfind("unknown sequencer '" + std::string(bad) + "'", 0), 0u) << problem;
    EXPECT_NE(problem.find("alone for nearest_neighbor+it"), std::string::npos) << problem;
    EXPECT_EQ(kept.label(), "christofides+two_opt") << bad;
  }
}

TEST(Sequencers, ApplyOrderReordersAndReverses) {
  const Toolpath toolpath = testing::paper_instance(3, 8);
  OrderResult result;
  result.order = {2, 0, 1};
  result.reversed = {true, false, false};
  const Toolpath ordered = apply_order(toolpath, result);
  ASSERT_EQ(ordered.paths.size(), 3u);
  EXPECT_EQ(ordered.paths[0].front(), toolpath.paths[2].back());
  EXPECT_EQ(ordered.paths[0].source_index, 2);
  EXPECT_EQ(ordered.paths[1].front(), toolpath.paths[0].front());
  EXPECT_EQ(ordered.start_mm, toolpath.start_mm);
  EXPECT_EQ(ordered.end_mm, toolpath.end_mm);
}

}  // namespace
}  // namespace depotwin
