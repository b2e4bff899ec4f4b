#include "pipeline/compare.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "plots/plots.hpp"
#include "render/scene.hpp"
#include "report/metrics_json.hpp"
#include "report/output_dir.hpp"

namespace depotwin {

namespace fs = std::filesystem;

OrderSpec parse_order_label(const std::string& label, const OrderSpec& defaults) {
  OrderSpec spec = defaults;
  const size_t plus = label.find('+');
  spec.method = label.substr(0, plus);
  spec.refine = plus == std::string::npos ? "" : label.substr(plus + 1);
  const auto& methods = sequencer_methods();
  const auto& refines = refine_methods();
  if (std::find(methods.begin(), methods.end(), spec.method) == methods.end())
    throw InputError("--orders", "unknown order method '" + spec.method + "'");
  if (!spec.refine.empty() &&
      std::find(refines.begin(), refines.end(), spec.refine) == refines.end())
    throw InputError("--orders", "unknown refinement '" + spec.refine + "'");
  return spec;
}

namespace {

std::string number(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// the comparison sheet's column for one run
plots::ComparisonColumn sheet_column(const std::string& label, const SimulatedRun& run,
                                     const HeightMap* map) {
  plots::ComparisonColumn column;
  column.planner = label;
  column.thickness = map;
  plots::set_speed_error(column, run.simulated);
  column.transitions = plots::transition_intervals(run.plan.trajectory);
  const MetricsReport& r = run.report;
  if (r.velocity_error) {
    column.max_speed_error_rel = r.velocity_error->max_rel;
    column.rms_speed_error_rel = r.velocity_error->rms_rel;
  }
  if (r.thickness) column.thickness_cv = r.thickness->cv;
  if (r.waste) column.waste_fraction = r.waste->fraction;
  column.total_time_s = r.time.total_s;
  return column;
}

}  // namespace

std::vector<ComparisonRow> compare_runs(const Scenario& scenario,
                                        const std::vector<PlannerSpec>& planners,
                                        const std::vector<OrderSpec>& orders,
                                        const std::string& directory, const RunSettings& settings) {
  // what to run: planners on the scenario's order, or the first planner on each order
  struct Case {
    std::string label;
    PlannerSpec planner;
    OrderSpec order;
  };
  std::vector<Case> cases;
  if (orders.empty()) {
    for (const PlannerSpec& p : planners) cases.push_back({p.run_label(), p, scenario.order});
  } else {
    for (const OrderSpec& o : orders) cases.push_back({o.label(), planners.front(), o});
  }

  std::vector<ComparisonRow> rows;
  std::vector<SimulatedRun> runs;
  std::vector<HeightMap> maps;
  std::vector<PreparedJob> jobs;
  // each case simulates while the previous one's results are written; the writer holds
  // references into runs and jobs, so neither may reallocate
  runs.reserve(cases.size());
  jobs.reserve(cases.size());
  BackgroundRunWriter writer;
  for (const Case& c : cases) {
    Scenario variant = scenario;
    variant.order = c.order;
    jobs.push_back(prepare_job(variant));
    if (settings.scene_renderer)
      settings.scene_renderer->prepare(jobs.back().model_path, scene_render_options(variant),
                                       jobs.back().model_text);
    runs.push_back(simulate_job(jobs.back(), c.planner, settings));
    SimulatedRun& run = runs.back();
    run.report.planner = c.planner.name;
    run.report.label = c.label;
    writer.submit(jobs.back(), run, (fs::path(directory) / c.label).string(), settings);
    rows.push_back({c.label, run.report});
  }
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
  nlohmann::ordered_json j;
  j["scenario"] = scenario;
  nlohmann::ordered_json runs = nlohmann::ordered_json::array();
  for (const ComparisonRow& row : rows) {
    nlohmann::ordered_json entry;
    entry["label"] = row.label;
    entry["metrics"] = to_json(row.report);
    runs.push_back(entry);
  }
  j["runs"] = runs;
  return j.dump(2) + "\n";
}

namespace {

// the comparison columns: (header, value of a report)
struct Column {
  const char* header;
  std::string (*value)(const MetricsReport&);
};

const std::vector<Column>& columns() {
  static const std::vector<Column> list = {
      {"planner", [](const MetricsReport& r) { return r.planner; }},
      {"order", [](const MetricsReport& r) { return r.sequencer; }},
      {"time_s", [](const MetricsReport& r) { return number(r.time.total_s); }},
      {"print_s", [](const MetricsReport& r) { return number(r.time.print_s); }},
      {"transition_s", [](const MetricsReport& r) { return number(r.time.transition_s); }},
      {"vel_err_max",
       [](const MetricsReport& r) {
         return r.velocity_error ? number(r.velocity_error->max_rel) : std::string("");
       }},
      {"vel_err_rms",
       [](const MetricsReport& r) {
         return r.velocity_error ? number(r.velocity_error->rms_rel) : std::string("");
       }},
      {"vel_err_frac_over_1pct",
       [](const MetricsReport& r) {
         return r.velocity_error ? number(r.velocity_error->frac_len_over_1pct) : std::string("");
       }},
      {"planned_vel_err_max",
       [](const MetricsReport& r) { return number(r.planned_velocity_error.max_rel); }},
      {"path_err_max_mm", [](const MetricsReport& r) { return number(r.path_error.max_mm); }},
      {"thickness_cv",
       [](const MetricsReport& r) {
         return r.thickness ? number(r.thickness->cv) : std::string("");
       }},
      {"line_cv",
       [](const MetricsReport& r) {
         return r.thickness ? number(r.thickness->line_cv) : std::string("");
       }},
      {"waste_fraction",
       [](const MetricsReport& r) {
         return r.waste ? number(r.waste->fraction) : std::string("");
       }},
      {"shutter_captured",
       [](const MetricsReport& r) {
         return r.waste ? number(r.waste->shutter_captured) : std::string("");
       }},
      {"overspray",
       [](const MetricsReport& r) {
         return r.waste ? number(r.waste->overspray) : std::string("");
       }},
      {"warnings", [](const MetricsReport& r) { return std::to_string(r.warnings.size()); }},
  };
  return list;
}

}  // namespace

std::string comparison_csv(const std::vector<ComparisonRow>& rows) {
  std::string out = "label";
  for (const Column& c : columns()) out += std::string(",") + c.header;
  out += '\n';
  for (const ComparisonRow& row : rows) {
    out += row.label;
    for (const Column& c : columns()) out += "," + c.value(row.report);
    out += '\n';
  }
  return out;
}

std::string comparison_markdown(const std::string& scenario, const std::vector<ComparisonRow>& rows,
                                bool with_images) {
  std::string out = "# " + scenario + ": comparison\n\n";
  if (with_images) out += "![comparison sheet](comparison.png)\n\n";
  out += "| run |";
  for (const Column& c : columns()) out += std::string(" ") + c.header + " |";
  out += "\n|---|";
  for (size_t i = 0; i < columns().size(); ++i) out += "---|";
  out += '\n';
  for (const ComparisonRow& row : rows) {
    out += "| " + row.label + " |";
    for (const Column& c : columns()) out += " " + c.value(row.report) + " |";
    out += '\n';
  }
  out +=
      "\nDefinitions: README.md, \"Metrics\". Speed errors and waste are fractions (0.01 = 1 %).\n";
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
