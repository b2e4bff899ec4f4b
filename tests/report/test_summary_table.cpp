// The summary table is the same in every format: the console, comparison.csv, .md and .json
// have the same columns under the same names, in the same order.
#include <gtest/gtest.h>

#include <cmath>
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
  r.planned_velocity_error_steady = {0.0038, 0.001, 0.002, 0.0, 7.6};
  r.planned_path_error.max_mm = 0.0409;
  if (simulated) {
    r.velocity_error = VelocityErrorStats{0.6182, 0.05, 0.1, 0.02};
    r.velocity_error_steady = VelocityErrorStats{0.004, 0.001, 0.002, 0.0, 7.6};
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
  // a count is a whole number in json (0, not 0.0), a figure a float
  EXPECT_TRUE(json["rows"][0]["warnings"].is_number_integer());
  EXPECT_EQ(json["rows"][0]["warnings"].dump(), "0");
  EXPECT_TRUE(json["rows"][0]["time_s"].is_number_float());
  EXPECT_NE(summary_csv(run).find(",61.83,"), std::string::npos);
  EXPECT_NE(summary_console(run).find("planned_vel_err_steady_max_pct      0.38\n"),
            std::string::npos)
      << summary_console(run);
  // a run that is all ramps: its steady columns are n/a (a dash, null), not 0.00
  std::vector<MetricsReport> all_ramps{report("lspb_mtt", true)};
  all_ramps[0].velocity_error_steady = VelocityErrorStats{};
  all_ramps[0].planned_velocity_error_steady = VelocityErrorStats{};
  const nlohmann::ordered_json ramps_json = summary_json(all_ramps);
  for (const char* column : {"planned_vel_err_steady_max_pct", "planned_vel_err_steady_rms_pct",
                             "sim_vel_err_steady_max_pct", "sim_vel_err_steady_rms_pct"})
    EXPECT_TRUE(ramps_json["rows"][0][column].is_null()) << column;
  EXPECT_NE(summary_console(all_ramps).find("sim_vel_err_steady_max_pct             -\n"),
            std::string::npos)
      << summary_console(all_ramps);
}

// ... and the same values: every cell of every row reads the same in comparison.csv (full
// precision), comparison.json and, rounded to the column's digits, on the console and in
// markdown; a figure a run lacks is empty in csv, null in json and a dash on the console and
// in markdown. The percent columns are the report's fractions times 100.
TEST(SummaryTable, SameValuesInEveryFormat) {
  std::vector<MetricsReport> reports{report("lspb_mtt", true), report("stop_and_go", true)};
  reports[1].planner = "stop_and_go";
  reports[1].time.total_s = 20.25;
  reports[1].velocity_error->max_rel = 1.0;
  reports[1].thickness.reset();  // no deposit figures for this run
  const std::string csv = summary_csv(reports);
  const nlohmann::ordered_json json = summary_json(reports);
  const std::vector<std::string> names = csv_names(csv);
  const std::vector<SummaryColumn> columns = summary_columns_for(reports);
  ASSERT_EQ(columns.size(), names.size());

  // csv rows and markdown rows (after the header and the rule)
  std::vector<std::vector<std::string>> csv_rows, md_rows;
  {
    std::stringstream in(csv);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) csv_rows.push_back(split(line, ','));
    std::stringstream md(summary_markdown(reports));
    std::getline(md, line);
    std::getline(md, line);
    while (std::getline(md, line)) {
      std::vector<std::string> cells;
      for (const std::string& cell : split(line, '|'))
        if (!trim(cell).empty() || !cells.empty()) cells.push_back(trim(cell));
      if (!cells.empty() && cells.back().empty()) cells.pop_back();
      md_rows.push_back(cells);
    }
  }
  // console: one line per column: name, then one value per run
  std::vector<std::vector<std::string>> console_lines;
  {
    std::stringstream in(summary_console(reports));
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '-') continue;
      std::stringstream words(line);
      std::vector<std::string> cells;
      std::string word;
      while (words >> word) cells.push_back(word);
      console_lines.push_back(cells);
    }
  }
  ASSERT_EQ(csv_rows.size(), 2u);
  ASSERT_EQ(md_rows.size(), 2u);
  ASSERT_EQ(console_lines.size(), names.size());
  for (size_t run = 0; run < 2; ++run) {
    for (size_t c = 0; c < names.size(); ++c) {
      SCOPED_TRACE(names[c] + " of run " + std::to_string(run));
      const SummaryCell cell = columns[c].cell(reports[run]);
      const nlohmann::ordered_json& value = json["rows"][run][names[c]];
      const std::string& in_csv = csv_rows[run].at(c);
      const std::string& in_md = md_rows[run].at(c);
      const std::string& on_console = console_lines[c].at(run + 1);
      if (cell.is_text) {
        EXPECT_EQ(value, cell.text);
        EXPECT_EQ(in_csv, cell.text);
        EXPECT_EQ(in_md, cell.text);
        EXPECT_EQ(on_console, cell.text);
      } else if (!cell.number) {
        EXPECT_TRUE(value.is_null());
        EXPECT_EQ(in_csv, "");
        EXPECT_EQ(in_md, "-");
        EXPECT_EQ(on_console, "-");
      } else {
        const double v = *cell.number;
        EXPECT_NEAR(value.get<double>(), v, 1e-12 * std::abs(v));
        EXPECT_NEAR(std::stod(in_csv), v, 1e-5 * std::abs(v));
        const double step = std::pow(10.0, -columns[c].digits);
        EXPECT_NEAR(std::stod(in_md), v, 0.5 * step + 1e-12);
        EXPECT_NEAR(std::stod(on_console), v, 0.5 * step + 1e-12);
      }
    }
  }
  // the percent columns are the fractions x 100, the times the report's seconds
  EXPECT_DOUBLE_EQ(json["rows"][1]["sim_vel_err_max_pct"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(json["rows"][1]["time_s"].get<double>(), 20.25);
  EXPECT_DOUBLE_EQ(json["rows"][0]["waste_pct"].get<double>(), 45.7);
  EXPECT_TRUE(json["rows"][1]["thickness_cv"].is_null());
}

}  // namespace
}  // namespace depotwin
