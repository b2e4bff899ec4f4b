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
  std::vector<int> order;        // indices into the input toolpath's paths, in print order
  std::vector<bool> reversed;    // per entry of `order`: print that path backwards
  double cost_s = 0.0;           // print time + transitions under the cost model
  double lower_bound_s = 0.0;    // print time + min-weight perfect matching of all ends
};

// names accepted by OrderSpec::method / refine / cost_model
const std::vector<std::string>& sequencer_methods();
const std::vector<std::string>& refine_methods();
const std::vector<std::string>& cost_models();

OrderResult sequence(const Toolpath& toolpath, const MachineLimits& limits, const OrderSpec& spec);
// the toolpath in the given order and directions (source_index kept)
Toolpath apply_order(const Toolpath& toolpath, const OrderResult& result);

}  // namespace depotwin
