// `depotwin compare`: several planners (or print orders) on the same toolpath, each run
// through the full pipeline; one row per run in comparison.{json,csv,md} and a side-by-side
// comparison.png.
#pragma once

#include <string>
#include <vector>

#include "pipeline/run.hpp"

namespace depotwin {

struct ComparisonRow {
  std::string label;  // the run's folder under DIR: the planner, or the order for --orders
  MetricsReport report;
};

// Run every planner named (or, with `orders` non-empty, the first planner under each of the
// orders) and write DIR/<label>/... plus DIR/comparison.*. Returns the rows in order.
std::vector<ComparisonRow> compare_runs(const Scenario& scenario,
                                        const std::vector<PlannerSpec>& planners,
                                        const std::vector<OrderSpec>& orders,
                                        const std::string& directory, const RunSettings& settings);

// "christofides+three_opt" -> {method christofides, refine three_opt}; InputError for unknown names
OrderSpec parse_order_label(const std::string& label, const OrderSpec& defaults);

std::string comparison_csv(const std::vector<ComparisonRow>& rows);
std::string comparison_markdown(const std::string& scenario, const std::vector<ComparisonRow>& rows,
                                bool with_images);
std::string comparison_json(const std::string& scenario, const std::vector<ComparisonRow>& rows);

}  // namespace depotwin
