// `depotwin compare`: several planners (or print orders) on the same toolpath, each run
// through the full pipeline; one row per run in comparison.{json,csv,md} and a side-by-side
// comparison.png.
#pragma once

#include <string>
#include <vector>

#include "pipeline/job_check.hpp"
#include "pipeline/run.hpp"

namespace depotwin {

struct ComparisonRow {
  std::string label;  // the run's folder under DIR (ComparisonCase::label)
  MetricsReport report;
};

// One run of a comparison: a planner under a print order, named by its label.
struct ComparisonCase {
  std::string label;    // its results folder and progress label
  PlannerSpec planner;  // labelled with `label`
  OrderSpec order;
};

// What `compare` runs: every planner on the scenario's order; with `orders`, every order under
// every planner (orders outermost). Labels: the planner's run label; with orders and one
// planner, the order's label ("christofides+three_opt"); with orders and several planners,
// "<order>+<planner>" ("nearest_neighbor+bezier", "christofides+three_opt+lspb_mtt").
// InputError when two runs would share a label.
std::vector<ComparisonCase> comparison_cases(const Scenario& scenario,
                                             const std::vector<PlannerSpec>& planners,
                                             const std::vector<OrderSpec>& orders);

// Run comparison_cases(...) and write DIR/<label>/... plus DIR/comparison.*. Returns the rows
// in order. Every case is prepared (its order, the arm's posture) and, with a budget, planned
// and sized against sim.max_steps and the budget (all runs together, as they are kept) before
// the first one simulates: every problem of every case in one InputError.
std::vector<ComparisonRow> compare_runs(const Scenario& scenario,
                                        const std::vector<PlannerSpec>& planners,
                                        const std::vector<OrderSpec>& orders,
                                        const std::string& directory, const RunSettings& settings,
                                        const JobBudget* budget = nullptr);

// "christofides+three_opt" -> {method christofides, refine three_opt}; InputError for unknown names
OrderSpec parse_order_label(const std::string& label, const OrderSpec& defaults);
// "as_given,nearest_neighbor+two_opt" -> one OrderSpec each; InputError for an unknown name
// or one named twice
std::vector<OrderSpec> parse_order_list(const std::string& list, const OrderSpec& defaults);

std::string comparison_csv(const std::vector<ComparisonRow>& rows);
std::string comparison_markdown(const std::string& scenario, const std::vector<ComparisonRow>& rows,
                                bool with_images);
std::string comparison_json(const std::string& scenario, const std::vector<ComparisonRow>& rows);

}  // namespace depotwin
