// The one summary table of a set of runs, written alike to the console (`run`, `plan`,
// `compare`), comparison.csv, comparison.md and comparison.json: the same columns under the
// same names everywhere. Planned figures are named planned_*, simulated ones sim_*; every
// name ends in its unit (_s, _mm, _pct: percent). The sim_* and deposit columns are left
// out when no run was simulated (`plan`).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "metrics/metrics_report.hpp"

namespace depotwin {

// One cell: a text (names) or a number (nullopt: not available for this run).
struct SummaryCell {
  bool is_text = false;
  std::string text;
  std::optional<double> number;
};

struct SummaryColumn {
  const char* name;
  bool simulated;  // needs a simulation (left out of a plan's table)
  int digits;      // decimals on the console and in markdown (csv and json: full precision;
                   // 0: a count, a whole number in json)
  SummaryCell (*cell)(const MetricsReport&);
};

// every column, in table order (the first is `run`: the run's label)
const std::vector<SummaryColumn>& summary_columns();
// the columns shown for these reports: all when any was simulated, else the planned ones
std::vector<SummaryColumn> summary_columns_for(const std::vector<MetricsReport>& reports);

// console: one line per column, one column per run (the names are long, the runs few)
std::string summary_console(const std::vector<MetricsReport>& reports);
// comparison.csv: a header row of the column names, one row per run; "" where n/a
std::string summary_csv(const std::vector<MetricsReport>& reports);
// a markdown table: the column names as header, one row per run; "-" where n/a
std::string summary_markdown(const std::vector<MetricsReport>& reports);
// {"columns": [names], "rows": [{name: value}]}; null where n/a
nlohmann::ordered_json summary_json(const std::vector<MetricsReport>& reports);

}  // namespace depotwin
