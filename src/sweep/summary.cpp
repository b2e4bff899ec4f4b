#include "sweep/summary.hpp"

#include <cmath>
#include <map>

namespace depotwin {

namespace {

// the metrics summary.png draws, in row order, with their labels and display scales
struct HeadlineMetric {
  const char* column;
  const char* label;
  double scale;
};
constexpr HeadlineMetric kHeadlineMetrics[] = {
    {"time_s.total", "time (s)", 1.0},
    {"thickness.line_cv", "line CV", 1.0},
    {"velocity_error_steady.max_rel", "steady speed error, max (%)", 100.0},
    {"path_error_mm.max", "path error, max (mm)", 1.0},
    {"waste.fraction", "waste (%)", 100.0},
    {"thickness.cv", "thickness CV", 1.0},
};

double number_in(const ResultCell& cell) {
  if (const auto* integer = std::get_if<long long>(&cell)) return static_cast<double>(*integer);
  if (const auto* real = std::get_if<double>(&cell)) return *real;
  return NAN;
}

std::string text_in(const ResultCell& cell) {
  if (const auto* text = std::get_if<std::string>(&cell)) return *text;
  if (const auto* integer = std::get_if<long long>(&cell)) return std::to_string(*integer);
  return "";
}

}  // namespace

plots::SweepPlotInput summary_plot_input(const ResultsTable& table, const Sweep& sweep) {
  plots::SweepPlotInput input;
  const int status = table.column("status");
  std::vector<std::size_t> ok_rows;
  for (std::size_t r = 0; r < table.rows.size(); ++r)
    if (text_in(table.rows[r][static_cast<std::size_t>(status)]) == "ok") ok_rows.push_back(r);
  input.title = sweep.spec().name + ": " + std::to_string(sweep.size()) + " tasks (" +
                std::to_string(table.ok) + " ok" +
                (table.failed > 0 ? ", " + std::to_string(table.failed) + " failed" : "") +
                (table.missing > 0 ? ", " + std::to_string(table.missing) + " missing" : "") +
                "); lines: means over the other parameters, dots: tasks";

  // one curve per planner when `planner` is swept; the other parameters are the x axes (the
  // planner itself when it is the only one)
  const std::vector<std::string>& keys = sweep.parameter_keys();
  const bool planner_curves =
      std::find(keys.begin(), keys.end(), "planner") != keys.end() && keys.size() > 1;
  std::map<std::string, std::size_t> curve_of;
  if (planner_curves) {
    const int planner = table.column("planner");
    for (const std::size_t r : ok_rows) {
      const std::string name = text_in(table.rows[r][static_cast<std::size_t>(planner)]);
      if (curve_of.emplace(name, input.curves.size()).second) input.curves.push_back(name);
    }
  }
  for (const std::size_t r : ok_rows)
    input.curve.push_back(
        planner_curves
            ? curve_of[text_in(table.rows[r][static_cast<std::size_t>(table.column("planner"))])]
            : 0);

  for (const std::string& key : keys) {
    if (planner_curves && key == "planner") continue;
    const int column = table.column(key);
    plots::SweepPlotInput::Parameter parameter{key, {}};
    std::vector<double> x;
    const bool words = table.columns[static_cast<std::size_t>(column)].type == "TEXT";
    std::map<std::string, std::size_t> position;
    if (words)  // the values in the sweep file's order
      for (std::uint64_t i = 0; i < sweep.size() && position.size() < 1000; ++i) {
        const std::string value = text_in(table.rows[i][static_cast<std::size_t>(column)]);
        if (position.emplace(value, parameter.categories.size()).second)
          parameter.categories.push_back(value);
      }
    for (const std::size_t r : ok_rows) {
      const ResultCell& cell = table.rows[r][static_cast<std::size_t>(column)];
      x.push_back(words ? static_cast<double>(position[text_in(cell)]) : number_in(cell));
    }
    input.parameters.push_back(parameter);
    input.x.push_back(std::move(x));
  }

  // the headline metrics the tasks have
  for (const HeadlineMetric& metric : kHeadlineMetrics) {
    const int column = table.column(metric.column);
    if (column < 0) continue;
    std::vector<double> y;
    bool any = false;
    for (const std::size_t r : ok_rows) {
      y.push_back(number_in(table.rows[r][static_cast<std::size_t>(column)]));
      any = any || std::isfinite(y.back());
    }
    if (!any) continue;
    if (std::string(metric.column) == "time_s.total")
      input.pareto_x = static_cast<int>(input.metrics.size());
    if (std::string(metric.column) == "thickness.line_cv")
      input.pareto_y = static_cast<int>(input.metrics.size());
    input.metrics.push_back(plots::SweepPlotInput::Metric{metric.label, metric.scale});
    input.y.push_back(std::move(y));
  }
  if (input.pareto_x < 0 || input.pareto_y < 0) input.pareto_x = input.pareto_y = -1;
  return input;
}

bool write_summary_plot(const ResultsTable& table, const Sweep& sweep,
                        const std::string& png_path) {
  const plots::SweepPlotInput input = summary_plot_input(table, sweep);
  if (input.curve.empty() || input.metrics.empty()) return false;
  plots::render_sweep_summary(input, png_path);
  return true;
}

}  // namespace depotwin
