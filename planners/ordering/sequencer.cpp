#include "planners/ordering/sequencer.hpp"

#include <algorithm>
#include <limits>

#include "core/error.hpp"
#include "planners/ordering/local_search.hpp"
#include "planners/ordering/lower_bound.hpp"
#include "planners/ordering/neighbor_lists.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

namespace {

bool known(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string joined(const std::vector<std::string>& names, const char* separator = ", ") {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : separator) + name;
  return out;
}

void check_spec(const OrderSpec& spec) {
  std::vector<Problem> problems;
  if (!known(sequencer_methods(), spec.method))
    problems.push_back(
        {"", 0, "order.method",
         "unknown sequencer '" + spec.method + "' (expected " + joined(sequencer_methods()) + ")"});
  if (!spec.refine.empty() && !known(refine_methods(), spec.refine))
    problems.push_back(
        {"", 0, "order.refine",
         "unknown refinement '" + spec.refine + "' (expected " + joined(refine_methods()) + ")"});
  if (!known(cost_models(), spec.cost_model))
    problems.push_back(
        {"", 0, "order.cost_model",
         "unknown cost model '" + spec.cost_model + "' (expected " + joined(cost_models()) + ")"});
  if (!problems.empty()) throw InputError(std::move(problems));
}

}  // namespace

std::string OrderSpec::label() const {
  return refine.empty() ? method : method + "+" + refine;
}

const std::vector<std::string>& sequencer_methods() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> list;
    for (const SequencerInfo& info : sequencer_registry()) list.push_back(info.name);
    return list;
  }();
  return names;
}

const std::vector<std::string>& refine_methods() {
  static const std::vector<std::string> names{"two_opt", "three_opt", "or_opt"};
  return names;
}

std::string parse_order_name(const std::string& name, OrderSpec& order) {
  const std::size_t plus = name.find('+');
  const std::string first = name.substr(0, plus);
  const std::string second = plus == std::string::npos ? "" : name.substr(plus + 1);
  const bool ok = plus == std::string::npos
                      ? known(sequencer_methods(), first) || known(refine_methods(), first)
                      : known(sequencer_methods(), first) && known(refine_methods(), second);
  if (!ok)
    return "unknown sequencer '" + name + "' (expected " + joined(sequencer_methods()) +
           ", optionally +" + joined(refine_methods(), "|") + ", or " + joined(refine_methods()) +
           " alone for nearest_neighbor+it)";
  // a refinement alone is shorthand for nearest_neighbor plus that refinement
  if (known(refine_methods(), first)) {
    order.method = "nearest_neighbor";
    order.refine = first;
  } else {
    order.method = first;
    order.refine = second;
  }
  return "";
}

const std::vector<std::string>& cost_models() {
  static const std::vector<std::string> names{"machine", "along_line"};
  return names;
}

namespace {

// construct, then refine over neighbour lists
OrderResult search_order(const TransitionCost& cost, const OrderSpec& spec,
                         const SequencerOptions& options) {
  OrderResult result = find_sequencer(spec.method)->construct(cost, spec);
  if (!spec.refine.empty()) {
    const NeighborLists neighbors(cost, options.neighbors);
    refine_order(result, cost, neighbors, parse_refinement(spec.refine));
  }
  return result;
}

// A part in layers (a slicer's G-code, a hatch's layers) is printed layer on layer: the
// order is searched within each layer, the layers taken in rising order (across them a
// sequencer printed a layer before the one under it, which no machine can). Each layer's
// search starts where the last one ended and ends where the next layer's first path as given
// begins (a slicer starts each layer near where it ended the last); the last layer ends at the
// toolpath's end.
OrderResult search_layer_by_layer(const Toolpath& toolpath, const TcpLimits& limits,
                                  const OrderSpec& spec, const SequencerOptions& options) {
  std::vector<std::vector<int>> layers(static_cast<std::size_t>(toolpath.layer_count()));
  for (std::size_t i = 0; i < toolpath.paths.size(); ++i)
    layers[static_cast<std::size_t>(toolpath.paths[i].layer)].push_back(static_cast<int>(i));
  layers.erase(std::remove_if(layers.begin(), layers.end(),
                              [](const std::vector<int>& paths) { return paths.empty(); }),
               layers.end());
  OrderResult result;
  Vec3 at = toolpath.start_mm;
  for (std::size_t l = 0; l < layers.size(); ++l) {
    Toolpath layer;
    layer.start_mm = at;
    layer.end_mm =
        l + 1 == layers.size()
            ? toolpath.end_mm
            : toolpath.paths[static_cast<std::size_t>(layers[l + 1].front())].points.front();
    for (const int i : layers[l])
      layer.paths.push_back(toolpath.paths[static_cast<std::size_t>(i)]);
    const TransitionCost cost(layer, limits, parse_cost_model(spec.cost_model));
    const OrderResult within = search_order(cost, spec, options);
    for (std::size_t k = 0; k < within.order.size(); ++k) {
      result.order.push_back(layers[l][static_cast<std::size_t>(within.order[k])]);
      result.reversed.push_back(within.reversed[k]);
    }
    const PrintPath& last = layer.paths[static_cast<std::size_t>(within.order.back())];
    at = within.reversed.back() ? last.points.front() : last.points.back();
  }
  return result;
}

}  // namespace

OrderResult sequence(const Toolpath& toolpath, const TcpLimits& limits, const OrderSpec& spec,
                     const SequencerOptions& options) {
  check_spec(spec);
  const TransitionCost cost(toolpath, limits, parse_cost_model(spec.cost_model));
  // (the given order, unrefined, is the file's, whatever its layers)
  const bool searched = spec.method != "as_given" || !spec.refine.empty();
  OrderResult result = toolpath.layer_count() > 1 && searched
                           ? search_layer_by_layer(toolpath, limits, spec, options)
                           : search_order(cost, spec, options);

  result.cost_s = cost.order_cost(result);
  result.print_time_s = cost.print_time_s();
  // the matching lower bound only when asked for and within its size limit (it grows faster
  // than the sequencers: seconds at 10^4 paths)
  const bool bound = options.lower_bound &&
                     static_cast<long>(toolpath.paths.size()) <= options.lower_bound_max_paths;
  result.lower_bound_s =
      bound ? matching_lower_bound(cost) : std::numeric_limits<double>::quiet_NaN();
  return result;
}

Toolpath apply_order(const Toolpath& toolpath, const OrderResult& result) {
  Toolpath out;
  out.start_mm = toolpath.start_mm;
  out.end_mm = toolpath.end_mm;
  out.start_roll_rad = toolpath.start_roll_rad;
  out.end_roll_rad = toolpath.end_roll_rad;
  out.chord_tolerance_mm = toolpath.chord_tolerance_mm;
  for (size_t k = 0; k < result.order.size(); ++k) {
    const PrintPath& path = toolpath.paths.at(result.order[k]);
    out.paths.push_back(result.reversed[k] ? path.reversed() : path);
  }
  return out;
}

}  // namespace depotwin
