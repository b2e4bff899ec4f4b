#include "cli/verbs.hpp"

#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/job.hpp"
#include "pipeline/run.hpp"
#include "render/scene.hpp"
#include "report/output_dir.hpp"

namespace depotwin {

namespace {

// select_planners, each run once: its label names its results folder
std::vector<PlannerSpec> selected_planners(const Scenario& scenario, const std::string& names,
                                           const std::string& option = "--planner") {
  const std::vector<PlannerSpec> planners = select_planners(scenario, names);
  for (size_t i = 0; i < planners.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (planners[k].run_label() == planners[i].run_label())
        throw InputError(option, "'" + planners[i].run_label() + "' is named twice");
  return planners;
}

}  // namespace

int plan_verb(const RunOptions& options) {
  const Scenario scenario = load_scenario(options.scenario);
  const std::vector<PlannerSpec> planners = selected_planners(scenario, options.planners);
  // the output folder is checked before any planning, and replaced whole at the end
  OutputFolder out(output_directory(scenario, options.out), "plan", scenario.file,
                   !options.no_wait);
  const std::string& directory = out.final_path();
  const PreparedJob job = prepare_job(scenario);
  const std::vector<MetricsReport> reports = write_plans(job, planners, out.path());
  out.commit();
  std::cout << "scenario " << scenario.name << " (" << scenario.file << "), machine "
            << job.machine->name() << ", order " << scenario.order.label() << ", "
            << job.toolpath.paths.size() << " print paths\n\n"
            << summary_table(reports) << '\n';
  for (const MetricsReport& report : reports)
    for (const std::string& warning : report.warnings)
      std::cout << "warning (" << (report.label.empty() ? report.planner : report.label)
                << "): " << warning << '\n';
  std::cout << "plans written to " << directory << "/<planner>/{metrics.json,trajectory.csv}\n";
  return kExitOk;
}

int validate_verb(const std::string& path) {
  const Scenario scenario = load_scenario(path);
  const PreparedJob job = prepare_job(scenario);
  std::cout << path << ": ok — scenario " << scenario.name << ", machine " << job.machine->name()
            << ", " << scenario.toolpath.paths.size() << " print paths, "
            << scenario.planners.size() << " planner(s)\n";
  return kExitOk;
}

namespace {

void print_warnings(const std::vector<MetricsReport>& reports) {
  for (const MetricsReport& report : reports)
    for (const std::string& warning : report.warnings)
      std::cout << "warning (" << report.planner << "): " << warning << '\n';
}

RunSettings run_settings(const Scenario& scenario, const RunOptions& options) {
  RunSettings settings;
  settings.render = scenario.outputs.render && !options.no_render;
  settings.progress = !options.quiet;
  settings.video = options.video;                    // moving pictures
  settings.video_length_s = options.video_length_s;  // moving pictures
  if (settings.render) settings.scene_renderer = std::make_shared<SceneRenderer>();
  return settings;
}

}  // namespace

int run_verb(const RunOptions& options) {
  const Scenario scenario = load_scenario(options.scenario);
  const std::vector<PlannerSpec> planners = selected_planners(scenario, options.planners);
  // the output folder is checked before any planning, and replaced whole at the end; it
  // outlives the writer below, which writes into it
  OutputFolder out(output_directory(scenario, options.out), "run", scenario.file, !options.no_wait);
  const std::string& directory = out.final_path();
  const PreparedJob job = prepare_job(scenario);
  const RunSettings settings = run_settings(scenario, options);
  if (settings.scene_renderer)
    settings.scene_renderer->prepare(job.model_path, scene_render_options(scenario),
                                     job.model_text);
  // each planner simulates while the previous one's results are written
  std::vector<MetricsReport> reports;
  std::vector<SimulatedRun> runs;
  runs.reserve(planners.size());  // the writer holds references: no reallocation
  BackgroundRunWriter writer;
  for (const PlannerSpec& spec : planners) {
    runs.push_back(simulate_job(job, spec, settings));
    writer.submit(job, runs.back(), (std::filesystem::path(out.path()) / spec.run_label()).string(),
                  settings);
    reports.push_back(runs.back().report);
  }
  writer.wait();
  out.commit();
  std::cout << "scenario " << scenario.name << " (" << scenario.file << "), machine "
            << job.machine->name() << ", process " << scenario.process.type << ", order "
            << scenario.order.label() << "\n\n"
            << summary_table(reports) << '\n';
  print_warnings(reports);
  std::cout << "results written to " << directory << "/<planner>/ (metrics.json, trajectory.csv, "
            << "thickness.csv" << (settings.render ? ", images" : "") << ")\n";
  return kExitOk;
}

int compare_verb(const CompareOptions& options) {
  const Scenario scenario = load_scenario(options.run.scenario);
  const std::vector<PlannerSpec> planners =
      selected_planners(scenario, options.run.planners, "--planners");
  const std::vector<OrderSpec> orders = parse_order_list(options.orders, scenario.order);
  comparison_cases(scenario, planners, orders);  // refuses runs sharing a label, before any work
  // the output folder is checked before any planning, and replaced whole at the end
  OutputFolder out(output_directory(scenario, options.run.out), "compare", scenario.file,
                   !options.run.no_wait);
  const std::string& directory = out.final_path();
  const RunSettings settings = run_settings(scenario, options.run);
  const std::vector<ComparisonRow> rows =
      compare_runs(scenario, planners, orders, out.path(), settings);
  out.commit();
  std::vector<MetricsReport> reports;
  for (const ComparisonRow& row : rows) reports.push_back(row.report);
  std::cout << "scenario " << scenario.name << " (" << scenario.file
            << "): " << (orders.empty() ? "planners" : "print orders") << " compared\n\n"
            << summary_table(reports) << '\n';
  print_warnings(reports);
  std::cout << "comparison written to " << directory << "/comparison.{json,csv,md"
            << (settings.render ? ",png" : "") << "}, one folder per run\n";
  return kExitOk;
}

}  // namespace depotwin
