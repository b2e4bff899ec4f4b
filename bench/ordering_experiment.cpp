#include "bench/ordering_experiment.hpp"

#include <algorithm>

#include "planners/ordering/lower_bound.hpp"
#include "planners/ordering/transition_cost.hpp"

namespace depotwin {

std::vector<OrderSpec> ExperimentConfig::paper_methods() {
  std::vector<OrderSpec> methods;
  for (const char* method : {"random", "nearest_neighbor", "christofides"}) {
    for (const char* refine : {"", "two_opt", "three_opt"}) {
      OrderSpec spec;
      spec.method = method;
      spec.refine = refine;
      methods.push_back(spec);
    }
  }
  return methods;
}

std::vector<SizeAverages> run_ordering_experiment(const ExperimentConfig& config) {
  std::vector<SizeAverages> table;
  for (int size : config.sizes) {
    SizeAverages row;
    row.size = size;
    for (const OrderSpec& method : config.methods) row.methods.push_back({method});

    for (int i = 0; i < config.instances; ++i) {
      RandomSegmentsSpec instance_spec = config.instance;
      instance_spec.count = size;
      instance_spec.seed = 1000ull * size + i + 1;
      const Toolpath toolpath = make_random_segments(instance_spec);
      const TransitionCost cost(toolpath, config.limits, parse_cost_model(config.cost_model));
      const double bound_s = matching_lower_bound(cost);
      row.segment_length_mm += toolpath.print_length_mm() / std::max(size, 1);
      row.print_time_s += cost.print_time_s();
      row.lower_bound_s += bound_s;

      for (MethodAverages& averages : row.methods) {
        OrderSpec spec = averages.method;
        spec.cost_model = config.cost_model;
        spec.seed = instance_spec.seed;
        SequencerOptions options;
        options.lower_bound = false;  // computed once per instance above
        const OrderResult order = sequence(toolpath, config.limits, spec, options);
        const double gap = (order.cost_s - bound_s) / bound_s;
        averages.path_length_mm += cost.print_length_mm() + cost.transition_length_mm(order);
        averages.time_s += order.cost_s;
        averages.gap += gap;
        averages.max_gap = std::max(averages.max_gap, gap);
        averages.below_bound = std::max(averages.below_bound, bound_s - order.cost_s);
      }
    }
    // sums -> means
    const double n = std::max(config.instances, 1);
    row.segment_length_mm /= n, row.print_time_s /= n, row.lower_bound_s /= n;
    for (MethodAverages& averages : row.methods) {
      averages.path_length_mm /= n, averages.time_s /= n, averages.gap /= n;
    }
    table.push_back(row);
  }
  return table;
}

}  // namespace depotwin
