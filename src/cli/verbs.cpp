#include "cli/verbs.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>

#include "core/error.hpp"
#include "core/number_text.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/job.hpp"
#include "pipeline/job_check.hpp"
#include "pipeline/run.hpp"
#include "pipeline/step_heartbeat.hpp"
#include "render/scene.hpp"
#include "report/output_dir.hpp"

namespace depotwin {

namespace {

// select_planners, each run once: its label names its results folder
std::vector<PlannerSpec> selected_planners(const Scenario& scenario, const std::string& names,
                                           const std::string& option = "--planner") {
  std::vector<PlannerSpec> planners;
  try {
    planners = select_planners(scenario, names);
  } catch (const InputError& e) {
    // (named by the verb's own option: compare's is --planners)
    std::vector<Problem> problems = e.problems();
    for (Problem& problem : problems)
      if (problem.key == "--planner") problem.key = option;
    throw InputError(std::move(problems));
  }
  for (size_t i = 0; i < planners.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (planners[k].run_label() == planners[i].run_label())
        throw InputError(option, "'" + planners[i].run_label() + "' is named twice");
  return planners;
}

// --max-memory, or the default budget
JobBudget job_budget(const std::string& max_memory) {
  JobBudget budget;
  if (!max_memory.empty()) budget.max_memory_bytes = parse_memory_size(max_memory);
  return budget;
}

// at most this many warnings of one kind (the same text but for its numbers) are printed for
// a run: a slicer's file can give lspb_mtt one per segment, hundreds; the rest are counted
constexpr int kWarningsPrintedPerKind = 3;

// a warning's kind: its text with each number (a run of digits and points) as '#' ("path #
// segment #: no LSPB in L/v = # s; ...")
std::string warning_kind(const std::string& warning) {
  const auto in_number = [&](size_t k) {
    return k < warning.size() && ((warning[k] >= '0' && warning[k] <= '9') || warning[k] == '.');
  };
  std::string kind;
  for (size_t i = 0; i < warning.size();) {
    if (in_number(i) && warning[i] != '.') {
      while (in_number(i)) ++i;
      kind += '#';
    } else {
      kind += warning[i++];
    }
  }
  return kind;
}

// a run's warnings, named by its run label (two runs of one planner with other settings are
// told apart), in order: of each kind the first kWarningsPrintedPerKind, then how many more
// of the kinds that had more, and where all of them are
void print_run_warnings(const std::string& run, const std::vector<std::string>& warnings,
                        const std::string& where_all_are) {
  // each kind in the order of its first warning: that warning, and how many of the kind
  struct Kind {
    const std::string* first;
    int count;
  };
  std::vector<Kind> kinds;
  std::map<std::string, size_t> kind_index;
  for (const std::string& warning : warnings) {
    const auto [at, is_new] = kind_index.try_emplace(warning_kind(warning), kinds.size());
    if (is_new) kinds.push_back({&warning, 0});
    if (++kinds[at->second].count <= kWarningsPrintedPerKind)
      std::cout << "warning (" << terminal_text(run) << "): " << terminal_text(warning) << '\n';
  }
  for (const Kind& kind : kinds)
    if (kind.count > kWarningsPrintedPerKind)
      std::cout << "warning (" << terminal_text(run) << "): ... and "
                << kind.count - kWarningsPrintedPerKind << " more like \""
                << printable_text(*kind.first, 40) << "\", " << where_all_are << '\n';
}

// each run's warnings, as print_run_warnings prints them; every one of them is in the run's
// folder under `directory`, in metrics.json
void print_warnings(const std::vector<MetricsReport>& reports, const std::string& directory) {
  for (const MetricsReport& report : reports) {
    const std::string& run = report.label.empty() ? report.planner : report.label;
    print_run_warnings(run, report.warnings,
                       "every one in " + terminal_text(directory + "/" + run + "/metrics.json") +
                           " (\"warnings\")");
  }
}

// the run folders a verb wrote, for its last line: DIR/a/, or DIR/{a,b}/ for several
std::string run_folders_text(const std::string& directory, const std::vector<PlannerSpec>& runs) {
  std::string labels;
  for (const PlannerSpec& spec : runs) labels += (labels.empty() ? "" : ",") + spec.run_label();
  if (runs.size() > 1) labels = "{" + labels + "}";
  return terminal_text(directory + "/" + labels + "/");
}

}  // namespace

int plan_verb(const RunOptions& options) {
  const StepHeartbeat heartbeat = job_heartbeat(options.scenario, options.quiet);
  // every check before any work (pipeline/job_check.hpp), the same as validate's
  const JobBudget budget = job_budget(options.max_memory);
  const Scenario scenario = check_scenario(options.scenario, budget, 0, false);
  const std::vector<PlannerSpec> planners = selected_planners(scenario, options.planners);
  // the output folder is checked before any planning, and replaced whole at the end
  OutputFolder out(output_directory(scenario, options.out), "plan", scenario.file, !options.no_wait,
                   scenario_input_files(scenario));
  const std::string& directory = out.final_path();
  // (every pose of each plan solved, as validate does: a plan the machine cannot follow is
  // refused, not written)
  const PreparedJob job =
      prepare_checked_job(scenario, planners, budget, false, true, nullptr, true);
  const std::vector<MetricsReport> reports = write_plans(job, planners, out.path());
  out.commit();
  std::cout << "scenario " << scenario.name << " (" << terminal_text(scenario.file) << "), machine "
            << job.machine->name() << ", order " << scenario.order.label() << ", "
            << job.toolpath.paths.size() << " print paths\n\n"
            << summary_table(reports) << '\n';
  print_warnings(reports, directory);
  std::cout << "plans written to " << run_folders_text(directory, planners)
            << " (metrics.json, trajectory.csv)\n";
  return kExitOk;
}

int validate_verb(const std::string& path, const std::string& max_memory, bool quiet) {
  const StepHeartbeat heartbeat = job_heartbeat(path, quiet);
  // every check `run` makes before it simulates, made the same way (pipeline/job_check.hpp),
  // and the plans' poses, which `run` checks as it simulates; no lower bound of the print order
  // (a report shows it, validate does not)
  const JobBudget budget = job_budget(max_memory);
  const Scenario scenario = check_scenario(path, budget);
  std::vector<RunEstimate> runs;
  const PreparedJob job =
      prepare_checked_job(scenario, scenario.planners, budget, true, false, &runs, true);
  // what `run` would take: the longest run, and the memory of all of them
  const auto longest = std::max_element(
      runs.begin(), runs.end(),
      [](const RunEstimate& a, const RunEstimate& b) { return a.steps < b.steps; });
  // the runs' data, and all the memory --max-memory is compared with
  double data_bytes = 0.0;
  for (const RunEstimate& run : runs) data_bytes += run.memory_bytes;
  const double memory_bytes = job_memory_bytes(scenario, runs);
  std::cout << terminal_text(path) << ": ok — scenario " << scenario.name << ", machine "
            << job.machine->name() << ", " << scenario.toolpath.paths.size() << " print paths, "
            << scenario.planners.size() << " planner(s)\n";
  if (longest != runs.end())
    std::cout << "  `run` would take: the longest plan " << longest->label << " "
              << message_number(longest->duration_s) << " s, " << message_number(longest->steps)
              << " physics steps (sim.max_steps "
              << message_number(static_cast<double>(scenario.sim.max_steps)) << "); about "
              << format_bytes(memory_bytes) << " of memory, the runs' data "
              << format_bytes(data_bytes) << " of it (--max-memory "
              << format_bytes(budget.max_memory_bytes) << ")\n";
  // what loading found and every run will repeat (a surface turned over, a G-code rule chosen)
  for (const std::string& note : scenario.notes)
    std::cout << "warning: " << terminal_text(note) << '\n';
  // and what each planner said of its plan, as `plan` and `run` print it
  for (const PlannerSpec& spec : scenario.planners)
    if (const Trajectory* plan = job.checked_plan(spec))
      print_run_warnings(spec.run_label(), plan_warnings(job, *plan),
                         "`depotwin plan` writes every one to the run's metrics.json");
  return kExitOk;
}

namespace {

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
  const StepHeartbeat heartbeat = job_heartbeat(options.scenario, options.quiet);
  // every check before any work (pipeline/job_check.hpp), the same as validate's
  const JobBudget budget = job_budget(options.max_memory);
  const Scenario scenario = check_scenario(options.scenario, budget);
  const std::vector<PlannerSpec> planners = selected_planners(scenario, options.planners);
  // the output folder is checked before any planning, and replaced whole at the end; it
  // outlives the writer below, which writes into it
  OutputFolder out(output_directory(scenario, options.out), "run", scenario.file, !options.no_wait,
                   scenario_input_files(scenario));
  const std::string& directory = out.final_path();
  const PreparedJob job = prepare_checked_job(scenario, planners, budget, true, true);
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
  {
    const WorkingStep step("writing the results");
    writer.wait();
  }
  out.commit();
  std::cout << "scenario " << scenario.name << " (" << terminal_text(scenario.file) << "), machine "
            << job.machine->name() << ", process " << scenario.process.type << ", order "
            << scenario.order.label() << "\n\n"
            << summary_table(reports) << '\n';
  print_warnings(reports, directory);
  std::cout << "results written to " << run_folders_text(directory, planners)
            << " (metrics.json, trajectory.csv, "
            << "thickness.csv" << (settings.render ? ", images" : "") << ")\n";
  return kExitOk;
}

int compare_verb(const CompareOptions& options) {
  const StepHeartbeat heartbeat = job_heartbeat(options.run.scenario, options.run.quiet);
  // every check before any work (pipeline/job_check.hpp), the same as validate's; each case
  // is prepared and planned in compare_runs before the first simulates
  const JobBudget budget = job_budget(options.run.max_memory);
  const Scenario scenario = check_scenario(options.run.scenario, budget);
  const std::vector<PlannerSpec> planners =
      selected_planners(scenario, options.run.planners, "--planners");
  const std::vector<OrderSpec> orders = parse_order_list(options.orders, scenario.order);
  comparison_cases(scenario, planners, orders);  // refuses runs sharing a label, before any work
  // the output folder is checked before any planning, and replaced whole at the end
  OutputFolder out(output_directory(scenario, options.run.out), "compare", scenario.file,
                   !options.run.no_wait, scenario_input_files(scenario));
  const std::string& directory = out.final_path();
  const RunSettings settings = run_settings(scenario, options.run);
  const std::vector<ComparisonRow> rows =
      compare_runs(scenario, planners, orders, out.path(), settings, &budget);
  out.commit();
  std::vector<MetricsReport> reports;
  for (const ComparisonRow& row : rows) reports.push_back(row.report);
  std::cout << "scenario " << scenario.name << " (" << terminal_text(scenario.file)
            << "): " << (orders.empty() ? "planners" : "print orders") << " compared\n\n"
            << summary_table(reports) << '\n';
  print_warnings(reports, directory);
  std::cout << "comparison written to " << terminal_text(directory) << "/comparison.{json,csv,md"
            << (settings.render ? ",png" : "") << "}, one folder per run\n";
  return kExitOk;
}

}  // namespace depotwin
