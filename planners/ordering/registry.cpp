// The sequencer registry: the only list of sequencer names. A new sequencer is one file pair
// in this folder and one entry here.
#include "planners/ordering/christofides.hpp"
#include "planners/ordering/nearest_neighbor.hpp"
#include "planners/ordering/random_order.hpp"
#include "planners/ordering/sequencer.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

namespace {

OrderResult as_given_order(const TransitionCost& cost, const OrderSpec&) {
  OrderResult given;
  for (int i = 0; i < cost.path_count(); ++i) {
    given.order.push_back(i);
    given.reversed.push_back(false);
  }
  return given;
}

}  // namespace

const std::vector<SequencerInfo>& sequencer_registry() {
  static const std::vector<SequencerInfo> registry{
      {"as_given", "the scenario's order and directions", &as_given_order},
      {"random", "a seeded random order and directions (order.seed)",
       [](const TransitionCost& cost, const OrderSpec& spec) {
         return random_order(cost.path_count(), spec.seed);
       }},
      {"nearest_neighbor", "greedy: always the nearest free path end in transition time",
       [](const TransitionCost& cost, const OrderSpec&) { return nearest_neighbor_order(cost); }},
      {"christofides", "Christofides' tree and matching heuristic on the transition times",
       [](const TransitionCost& cost, const OrderSpec&) { return christofides_order(cost); }},
  };
  return registry;
}

const SequencerInfo* find_sequencer(const std::string& name) {
  for (const SequencerInfo& info : sequencer_registry())
    if (info.name == name) return &info;
  return nullptr;
}

}  // namespace depotwin
