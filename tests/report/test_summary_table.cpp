// The summary table is the same in every format: the console, comparison.csv, .md and .json
// have the same columns under the same names, in the same order.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "report/summary_table.hpp"

namespace depotwin {
namespace {

MetricsReport report(const std::string& label, bool simulated) {
  MetricsReport r;
  r.planner = "lspb_mtt";
  r.label = label;
  r.sequencer = "as_given";
  r.time = {19.355, 11.011, 8.344};
  r.planned_velocity_error.max_rel = 0.6183;
  r.planned_velocity_error_steady.max_rel = 0.0038;
  r.planned_path_error.max_mm = 0.0409;
  if (simulated) {
    r.velocity_error = VelocityErrorStats{0.6182, 0.05, 0.1, 0.02};
    r.velocity_error_steady = VelocityErrorStats{0.004, 0.001, 0.002, 0.0};
    r.path_error = PathErrorStats{0.05, 0.01};
    r.thickness = ThicknessSummary{1.2, 0.5098, 0.0771, 0.1, 1.9};
    r.waste = WasteStats{0.457, 0.4, 0.057, 8.0};
    r.sim = SimStats{};
  }
  return r;
}

std::vector<std::string> split(const std::string& line, char separator) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, separator)) cells.push_back(cell);
  return cells;
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// the names as each format gives them
std::vector<std::string> csv_names(const std::string& csv) {
  return split(csv.substr(0, csv.find('\n')), ',');
}
std::vector<std::string> markdown_names(const std::string& md) {
  std::vector<std::string> names;
  for (const std::string& cell : split(md.substr(0, md.find('\n')), '|'))
    if (!trim(cell).empty()) names.push_back(trim(cell));
  return names;
}
std::vector<std::string> console_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '-') names.push_back(line.substr(0, line.find(' ')));
  return names;
}

TEST(SummaryTable, SameColumnsInEveryFormat) {
  for (bool simulated : {false, true}) {
    const std::vector<MetricsReport> reports{report("lspb_mtt", simulated),
                                             report("stop_and_go", simulated)};
    const std::vector<std::string> names = csv_names(summary_csv(reports));
    EXPECT_EQ(markdown_names(summary_markdown(reports)), names);
    EXPECT_EQ(console_names(summary_console(reports)), names);
    const nlohmann::ordered_json json = summary_json(reports);
    EXPECT_EQ(json["columns"].get<std::vector<std::string>>(), names);
    for (const auto& row : json["rows"]) {
      std::vector<std::string> keys;
      for (const auto& [key, value] : row.items()) keys.push_back(key);
      EXPECT_EQ(keys, names);
    }
    EXPECT_EQ(names.front(), "run");
  }
}

TEST(SummaryTable, PlannedAndSimulatedColumnsAreNamedApart) {
  const std::vector<MetricsReport> run{report("lspb_mtt", true)};
  EXPECT_EQ(summary_csv(run).substr(0, summary_csv(run).find('\n')),
            "run,planner,order,time_s,print_s,transition_s,planned_vel_err_max_pct,"
            "planned_vel_err_rms_pct,planned_vel_err_steady_max_pct,"
            "planned_vel_err_steady_rms_pct,planned_path_err_max_mm,sim_vel_err_max_pct,"
            "sim_vel_err_rms_pct,sim_vel_err_steady_max_pct,sim_vel_err_steady_rms_pct,"
            "sim_path_err_max_mm,thickness_cv,line_cv,waste_pct,shutter_captured_pct,"
            "overspray_pct,warnings");
  // a plan has no simulated columns
  const std::vector<MetricsReport> plan{report("lspb_mtt", false)};
  for (const std::string& name : csv_names(summary_csv(plan))) {
    EXPECT_NE(name.rfind("sim_", 0), 0u) << name;
    EXPECT_NE(name, "thickness_cv");
  }
  // values: percent under _pct, full precision in csv, fixed digits on the console
  const nlohmann::ordered_json json = summary_json(run);
  EXPECT_DOUBLE_EQ(json["rows"][0]["planned_vel_err_max_pct"].get<double>(), 61.83);
  EXPECT_DOUBLE_EQ(json["rows"][0]["sim_vel_err_steady_max_pct"].get<double>(), 0.4);
  EXPECT_NE(summary_csv(run).find(",61.83,"), std::string::npos);
  EXPECT_NE(summary_console(run).find("planned_vel_err_steady_max_pct      0.38\n"),
            std::string::npos)
      << summary_console(run);
}

}  // namespace
}  // namespace depotwin
