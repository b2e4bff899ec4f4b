#include "planners/sequencer.hpp"

#include "core/error.hpp"

namespace depotwin {

std::string OrderSpec::label() const { return refine.empty() ? method : method + "+" + refine; }

const std::vector<std::string>& sequencer_methods() {
  static const std::vector<std::string> names{"as_given", "random", "nearest_neighbor",
                                              "christofides"};
  return names;
}

const std::vector<std::string>& refine_methods() {
  static const std::vector<std::string> names{"two_opt", "three_opt", "or_opt"};
  return names;
}

const std::vector<std::string>& cost_models() {
  static const std::vector<std::string> names{"machine", "along_line"};
  return names;
}

OrderResult sequence(const Toolpath& toolpath, const MachineLimits&, const OrderSpec& spec) {
  // TODO(issue 6): the other sequencers; until then only the given order
  if (spec.method != "as_given" || !spec.refine.empty())
    throw InputError("order", "sequencer '" + spec.label() + "' is not available yet");
  OrderResult result;
  for (size_t i = 0; i < toolpath.paths.size(); ++i) {
    result.order.push_back(static_cast<int>(i));
    result.reversed.push_back(false);
  }
  return result;
}

Toolpath apply_order(const Toolpath& toolpath, const OrderResult& result) {
  Toolpath out;
  out.start_mm = toolpath.start_mm;
  out.end_mm = toolpath.end_mm;
  for (size_t k = 0; k < result.order.size(); ++k) {
    const PrintPath& path = toolpath.paths.at(result.order[k]);
    out.paths.push_back(result.reversed[k] ? path.reversed() : path);
  }
  return out;
}

}  // namespace depotwin
