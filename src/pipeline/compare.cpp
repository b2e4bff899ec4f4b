#include "pipeline/compare.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "core/error.hpp"
#include "pipeline/step_heartbeat.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"
#include "report/summary_table.hpp"

namespace depotwin {

namespace fs = std::filesystem;

OrderSpec parse_order_label(const std::string& label, const OrderSpec& defaults) {
  // the names a scenario's `order:` takes, a refinement alone included
  OrderSpec spec = defaults;
  if (const std::string problem = parse_order_name(label, spec); !problem.empty())
    throw InputError("--orders", problem);
  return spec;
}

std::vector<OrderSpec> parse_order_list(const std::string& list, const OrderSpec& defaults) {
  std::vector<OrderSpec> orders;
  std::stringstream stream(list);
  std::string label;
  while (std::getline(stream, label, ',')) {
    if (label.empty()) continue;
    orders.push_back(parse_order_label(label, defaults));
    // each order once: its label names its results folder
    for (size_t i = 0; i + 1 < orders.size(); ++i)
      if (orders[i].label() == orders.back().label())
        throw InputError("--orders", "'" + label + "' is named twice");
  }
  return orders;
}

std::vector<ComparisonCase> comparison_cases(const Scenario& scenario,
                                             const std::vector<PlannerSpec>& planners,
                                             const std::vector<OrderSpec>& orders) {
  // every order (or the scenario's) under every planner, orders outermost
  std::vector<ComparisonCase> cases;
  if (orders.empty()) {
    for (const PlannerSpec& p : planners) cases.push_back({p.run_label(), p, scenario.order});
  } else {
    for (const OrderSpec& o : orders)
      for (const PlannerSpec& p : planners) {
        // one planner: the order names the run; several: "<order>+<planner>"
        const std::string label =
            planners.size() == 1 ? o.label() : o.label() + "+" + p.run_label();
        cases.push_back({label, p, o});
      }
  }
  // the label names the results folder and the progress line: unique, or refused
  for (size_t i = 0; i < cases.size(); ++i) {
    cases[i].planner.label = cases[i].label;
    for (size_t k = 0; k < i; ++k)
      if (cases[k].label == cases[i].label)
        throw InputError(orders.empty() ? "--planners" : "--orders",
                         "two runs would both be named '" + cases[i].label +
                             "' (name each planner and order once)");
  }
  return cases;
}

namespace {

// the comparison sheet's column for one run
plots::ComparisonColumn sheet_column(const std::string& label, const SimulatedRun& run,
                                     const HeightMap* map) {
  plots::ComparisonColumn column;
  column.planner = label;
  column.thickness = map;
  plots::set_speed_error(column, run.simulated);
  column.transitions = plots::transition_intervals(run.plan.trajectory);
  // the print order and its travels (an orders comparison shows these instead of the maps)
  column.order = run.report.sequencer;
  plots::set_travels(column, run.plan.planned);
  const MetricsReport& r = run.report;
  if (r.velocity_error) {
    column.max_speed_error_rel = r.velocity_error->max_rel;
    column.rms_speed_error_rel = r.velocity_error->rms_rel;
  }
  if (r.velocity_error_steady && r.velocity_error_steady->counted_s > 0.0)  // else n/a: all ramps
    column.steady_speed_error_rel = r.velocity_error_steady->max_rel;
  if (r.thickness) column.thickness_cv = r.thickness->cv;
  if (r.waste) column.waste_fraction = r.waste->fraction;
  column.total_time_s = r.time.total_s;
  return column;
}

}  // namespace

std::vector<ComparisonRow> compare_runs(const Scenario& scenario,
                                        const std::vector<PlannerSpec>& planners,
                                        const std::vector<OrderSpec>& orders,
                                        const std::string& directory, const RunSettings& settings,
                                        const JobBudget* budget) {
  const std::vector<ComparisonCase> cases = comparison_cases(scenario, planners, orders);
  std::vector<ComparisonRow> rows;
  std::vector<SimulatedRun> runs;
  std::vector<HeightMap> maps;
  std::vector<PreparedJob> jobs;
  // each case simulates while the previous one's results are written; the writer holds
  // references into runs and jobs, so neither may reallocate
  runs.reserve(cases.size());
  jobs.reserve(cases.size());
  // every case prepared (and with a budget planned and sized) before the first simulates
  std::vector<Problem> problems;
  std::vector<RunEstimate> estimates;
  for (const ComparisonCase& c : cases) {
    Scenario variant = scenario;
    variant.order = c.order;
    try {
      jobs.push_back(prepare_job(variant));
    } catch (const InputError& e) {
      const std::vector<Problem> found = scenario.located(e.problems());
      problems.insert(problems.end(), found.begin(), found.end());
      continue;
    }
    if (!budget) continue;
    const std::vector<RunEstimate> sized = check_runs(jobs.back(), {c.planner}, true, problems);
    estimates.insert(estimates.end(), sized.begin(), sized.end());
  }
  if (budget && problems.empty()) problems = size_problems(scenario, estimates, *budget);
  if (!problems.empty()) {
    sort_problems(problems, scenario.file);
    throw InputError(std::move(problems));
  }
  BackgroundRunWriter writer;
  for (size_t i = 0; i < cases.size(); ++i) {
    const ComparisonCase& c = cases[i];
    const PreparedJob& job = jobs[i];
    if (settings.scene_renderer)
      settings.scene_renderer->prepare(job.model_path, scene_render_options(job.scenario),
                                       job.model_text);
    runs.push_back(simulate_job(job, c.planner, settings));
    SimulatedRun& run = runs.back();
    run.report.planner = c.planner.name;
    run.report.label = c.label;
    writer.submit(job, run, (fs::path(directory) / c.label).string(), settings);
    rows.push_back({c.label, run.report});
  }
  const WorkingStep step("writing the results");
  writer.wait();

  // the tables, then the side-by-side sheet on a shared colour scale
  fs::create_directories(directory);
  write_file_atomically((fs::path(directory) / "comparison.json").string(),
                        comparison_json(scenario.name, rows));
  write_file_atomically((fs::path(directory) / "comparison.csv").string(), comparison_csv(rows));
  write_file_atomically((fs::path(directory) / "comparison.md").string(),
                        comparison_markdown(scenario.name, rows, settings.render));
  if (settings.render) {
    for (const SimulatedRun& run : runs)
      maps.push_back(field_heightmap(run.deposit->normal_field()));
    plots::ComparisonInput input;
    input.title = scenario.name;
    input.toolpath = &jobs.front().toolpath;
    for (size_t i = 0; i < runs.size(); ++i)
      input.columns.push_back(sheet_column(rows[i].label, runs[i], &maps[i]));
    plots::render_comparison(input, (fs::path(directory) / "comparison.png").string());
  }
  return rows;
}

std::string comparison_json(const std::string& scenario, const std::vector<ComparisonRow>& rows) {
  // the summary table (the columns of comparison.csv and .md), then every run's metrics
  nlohmann::ordered_json j;
  j["scenario"] = scenario;
  std::vector<MetricsReport> reports;
  for (const ComparisonRow& row : rows) reports.push_back(row.report);
  const nlohmann::ordered_json table = summary_json(reports);
  j["columns"] = table["columns"];
  j["rows"] = table["rows"];
  nlohmann::ordered_json runs = nlohmann::ordered_json::array();
  for (const ComparisonRow& row : rows) {
    nlohmann::ordered_json entry;
    entry["run"] = row.label;
    entry["metrics"] = to_json(row.report);
    runs.push_back(entry);
  }
  j["runs"] = runs;
  return j.dump(2) + "\n";
}

namespace {

// the reports of the rows, each under its row's label (the `run` column)
std::vector<MetricsReport> labelled_reports(const std::vector<ComparisonRow>& rows) {
  std::vector<MetricsReport> reports;
  for (const ComparisonRow& row : rows) {
    reports.push_back(row.report);
    reports.back().label = row.label;
  }
  return reports;
}

}  // namespace

std::string comparison_csv(const std::vector<ComparisonRow>& rows) {
  return summary_csv(labelled_reports(rows));
}

std::string comparison_markdown(const std::string& scenario, const std::vector<ComparisonRow>& rows,
                                bool with_images) {
  std::string out = "# " + scenario + ": comparison\n\n";
  if (with_images) out += "![comparison sheet](comparison.png)\n\n";
  out += summary_markdown(labelled_reports(rows));
  out +=
      "\nDefinitions: README.md, \"Metrics\". planned_* come from the plan alone, sim_* from the "
      "simulated nozzle; _pct are percent; vel_err_steady leaves out each printed stretch's "
      "start and end ramps (metrics.json speed_ramps).\n";
  if (with_images) {
    out += "\n## Images per run\n\n";
    for (const ComparisonRow& row : rows) {
      const std::string& d = row.label;
      out += "- **" + d + "**: [scene](" + d + "/scene.png), [thickness map](" + d +
             "/thickness.png), [path](" + d + "/path.png), [axes](" + d + "/axes.png), [errors](" +
             d + "/errors.png), [thickness profile](" + d + "/thickness_profile.png), [metrics](" +
             d + "/metrics.json)\n";
    }
  }
  return out;
}

}  // namespace depotwin
