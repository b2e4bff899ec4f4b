#include "cli/verbs.hpp"

#include <iostream>

#include "core/error.hpp"
#include "pipeline/job.hpp"

namespace depotwin {

int plan_verb(const RunOptions& options) {
  const Scenario scenario = load_scenario(options.scenario);
  const PreparedJob job = prepare_job(scenario);
  const std::vector<PlannerSpec> planners = select_planners(scenario, options.planners);
  const std::string directory = output_directory(scenario, options.out);
  const std::vector<MetricsReport> reports = write_plans(job, planners, directory);
  std::cout << "scenario " << scenario.name << " (" << scenario.file << "), machine "
            << job.machine->name() << ", order " << scenario.order.label() << ", "
            << job.toolpath.paths.size() << " print paths\n\n"
            << summary_table(reports) << '\n';
  for (const MetricsReport& report : reports)
    for (const std::string& warning : report.warnings)
      std::cout << "warning (" << report.planner << "): " << warning << '\n';
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

int run_verb(const RunOptions&) { throw InternalError("run: not built yet"); }
int compare_verb(const CompareOptions&) { throw InternalError("compare: not built yet"); }

}  // namespace depotwin
