// Print ordering (Ganganath et al., papers/004): reorder and possibly reverse the print
// paths to cut transition time. Start and end points stay fixed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "core/toolpath.hpp"

namespace depotwin {

// `order:` in a scenario
struct OrderSpec {
  std::string method = "as_given";     // as_given | random | nearest_neighbor | christofides
  std::string refine;                  // "" | two_opt | three_opt | or_opt
  std::string cost_model = "machine";  // machine (synchronised per-axis MTT) | along_line
  std::uint64_t seed = 1;

  std::string label() const;  // e.g. "christofides+three_opt"
};

struct OrderResult {
  std::vector<int> order;      // indices into the input toolpath's paths, in print order
  std::vector<bool> reversed;  // per entry of `order`: print that path backwards
  double cost_s = 0.0;         // print time + transitions under the cost model
  double lower_bound_s = 0.0;  // print time + min-weight perfect matching of all ends
                               // (exact at any N, see lower_bound.hpp)
  double print_time_s = 0.0;   // sum of length / speed (the part no order changes)
};

// knobs for benchmarks and tests; the defaults are what scenarios get
struct SequencerOptions {
  int neighbors = 12;  // candidate list length per path end (local search)
  // the lower bound is exact at any N but its cost grows faster than the sequencers': on
  // dense random instances (0.5-4 mm segments in 90 x 90 mm, nearest_neighbor) about 6 s at
  // 2000 paths, 11 s at 5000, 90 s at 10^4 and 330 s at 2 x 10^4 (2 loaded cores). Above
  // lower_bound_max_paths paths (or when false) lower_bound_s is NaN (null in metrics.json)
  bool lower_bound = true;
  int lower_bound_max_paths = 5000;
};

class TransitionCost;

// One registered sequencer: its name (`order.method`), a line of description, and how it
// builds an order from the transition costs (before any refinement).
struct SequencerInfo {
  std::string name;
  std::string description;
  OrderResult (*construct)(const TransitionCost& cost, const OrderSpec& spec);
};

// every registered sequencer, in a stable order (planners/ordering/registry.cpp): the only
// list of sequencer names
const std::vector<SequencerInfo>& sequencer_registry();
const SequencerInfo* find_sequencer(const std::string& name);

// names accepted by OrderSpec::method (the registry's) / refine / cost_model
const std::vector<std::string>& sequencer_methods();
const std::vector<std::string>& refine_methods();
const std::vector<std::string>& cost_models();

// An order written as a name (`order: NAME`, `compare --orders NAME,...`): a method, method+refine,
// or a refinement alone for nearest_neighbor+it. Sets `order`'s method and refine and returns
// ""; or returns what is wrong, naming the accepted forms, and leaves `order` as it was.
std::string parse_order_name(const std::string& name, OrderSpec& order);

// Throws InputError for unknown names (key order.method / order.refine / order.cost_model)
// and for paths the limits cannot print at their speed.
// (the transition costs take each move's own limits, as the planners do)
OrderResult sequence(const Toolpath& toolpath, const TcpLimits& limits, const OrderSpec& spec,
                     const SequencerOptions& options = {});
// the toolpath in the given order and directions (source_index kept)
Toolpath apply_order(const Toolpath& toolpath, const OrderResult& result);

}  // namespace depotwin
