#include "report/summary_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace depotwin {

namespace {

SummaryCell text(std::string value) {
  SummaryCell cell;
  cell.is_text = true;
  cell.text = std::move(value);
  return cell;
}
SummaryCell number(std::optional<double> value) {
  SummaryCell cell;
  cell.number = value;
  return cell;
}
std::optional<double> percent(const std::optional<double>& fraction) {
  return fraction ? std::optional<double>(100.0 * *fraction) : std::nullopt;
}
// a simulated statistic, when there is one
template <typename Stats, typename Field>
std::optional<double> simulated(const std::optional<Stats>& stats, Field field) {
  return stats ? std::optional<double>((*stats).*field) : std::nullopt;
}

// a steady statistic, when any sample lies outside the ramps (none: n/a, not 0)
template <typename Field>
std::optional<double> steady(const VelocityErrorStats& stats, Field field) {
  return stats.counted_s > 0.0 ? std::optional<double>(stats.*field) : std::nullopt;
}
template <typename Field>
std::optional<double> steady(const std::optional<VelocityErrorStats>& stats, Field field) {
  return stats ? steady(*stats, field) : std::nullopt;
}

std::string fixed(double value, int digits) {
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}
std::string full(double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// a cell as the console and markdown show it
std::string shown(const SummaryCell& cell, int digits, const char* missing) {
  if (cell.is_text) return cell.text;
  return cell.number ? fixed(*cell.number, digits) : missing;
}

// a csv field: quoted when it holds a separator or a quote
std::string csv_field(const std::string& value) {
  if (value.find_first_of(",\"\n") == std::string::npos) return value;
  std::string quoted = "\"";
  for (char c : value) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

const std::vector<SummaryColumn>& summary_columns() {
  using R = MetricsReport;
  static const std::vector<SummaryColumn> list = {
      {"run", false, 0, [](const R& r) { return text(r.label.empty() ? r.planner : r.label); }},
      {"planner", false, 0, [](const R& r) { return text(r.planner); }},
      {"order", false, 0, [](const R& r) { return text(r.sequencer); }},
      {"time_s", false, 3, [](const R& r) { return number(r.time.total_s); }},
      {"print_s", false, 3, [](const R& r) { return number(r.time.print_s); }},
      {"transition_s", false, 3, [](const R& r) { return number(r.time.transition_s); }},
      // planned (the trajectory alone): whole printed length, then outside the ramps
      {"planned_vel_err_max_pct", false, 2,
       [](const R& r) { return number(100.0 * r.planned_velocity_error.max_rel); }},
      {"planned_vel_err_rms_pct", false, 2,
       [](const R& r) { return number(100.0 * r.planned_velocity_error.rms_rel); }},
      {"planned_vel_err_steady_max_pct", false, 2,
       [](const R& r) {
         return number(
             percent(steady(r.planned_velocity_error_steady, &VelocityErrorStats::max_rel)));
       }},
      {"planned_vel_err_steady_rms_pct", false, 2,
       [](const R& r) {
         return number(
             percent(steady(r.planned_velocity_error_steady, &VelocityErrorStats::rms_rel)));
       }},
      {"planned_path_err_max_mm", false, 4,
       [](const R& r) { return number(r.planned_path_error.max_mm); }},
      // simulated (the nozzle read back from MuJoCo)
      {"sim_vel_err_max_pct", true, 2,
       [](const R& r) {
         return number(percent(simulated(r.velocity_error, &VelocityErrorStats::max_rel)));
       }},
      {"sim_vel_err_rms_pct", true, 2,
       [](const R& r) {
         return number(percent(simulated(r.velocity_error, &VelocityErrorStats::rms_rel)));
       }},
      {"sim_vel_err_steady_max_pct", true, 2,
       [](const R& r) {
         return number(percent(steady(r.velocity_error_steady, &VelocityErrorStats::max_rel)));
       }},
      {"sim_vel_err_steady_rms_pct", true, 2,
       [](const R& r) {
         return number(percent(steady(r.velocity_error_steady, &VelocityErrorStats::rms_rel)));
       }},
      {"sim_path_err_max_mm", true, 4,
       [](const R& r) { return number(simulated(r.path_error, &PathErrorStats::max_mm)); }},
      // the deposit (simulated only)
      {"thickness_cv", true, 4,
       [](const R& r) { return number(simulated(r.thickness, &ThicknessSummary::cv)); }},
      {"line_cv", true, 4,
       [](const R& r) { return number(simulated(r.thickness, &ThicknessSummary::line_cv)); }},
      {"waste_pct", true, 2,
       [](const R& r) { return number(percent(simulated(r.waste, &WasteStats::fraction))); }},
      {"shutter_captured_pct", true, 2,
       [](const R& r) {
         return number(percent(simulated(r.waste, &WasteStats::shutter_captured)));
       }},
      {"overspray_pct", true, 2,
       [](const R& r) { return number(percent(simulated(r.waste, &WasteStats::overspray))); }},
      {"warnings", false, 0,
       [](const R& r) { return number(static_cast<double>(r.warnings.size())); }},
  };
  return list;
}

std::vector<SummaryColumn> summary_columns_for(const std::vector<MetricsReport>& reports) {
  const bool any_simulated = std::any_of(reports.begin(), reports.end(),
                                         [](const MetricsReport& r) { return r.sim.has_value(); });
  std::vector<SummaryColumn> shown;
  for (const SummaryColumn& c : summary_columns())
    if (any_simulated || !c.simulated) shown.push_back(c);
  return shown;
}

std::string summary_console(const std::vector<MetricsReport>& reports) {
  // cells[column][run], the name first
  const std::vector<SummaryColumn> columns = summary_columns_for(reports);
  std::vector<std::vector<std::string>> lines;
  for (const SummaryColumn& c : columns) {
    std::vector<std::string> line{c.name};
    for (const MetricsReport& r : reports) line.push_back(shown(c.cell(r), c.digits, "-"));
    lines.push_back(line);
  }
  // widths per output column, then the lines: names left, values right; a rule under `run`
  std::vector<size_t> width(reports.size() + 1, 0);
  for (const auto& line : lines)
    for (size_t i = 0; i < line.size(); ++i) width[i] = std::max(width[i], line[i].size());
  std::string out;
  for (size_t l = 0; l < lines.size(); ++l) {
    for (size_t i = 0; i < lines[l].size(); ++i) {
      const std::string& cell = lines[l][i];
      const std::string pad(width[i] - cell.size(), ' ');
      out += i == 0 ? cell + pad : "  " + pad + cell;
    }
    out += '\n';
    if (l == 0) {
      size_t total = 0;
      for (size_t i = 0; i < width.size(); ++i) total += width[i] + (i ? 2 : 0);
      out += std::string(total, '-') + '\n';
    }
  }
  return out;
}

std::string summary_csv(const std::vector<MetricsReport>& reports) {
  const std::vector<SummaryColumn> columns = summary_columns_for(reports);
  std::string out;
  for (size_t i = 0; i < columns.size(); ++i) out += (i ? "," : "") + std::string(columns[i].name);
  out += '\n';
  for (const MetricsReport& r : reports) {
    for (size_t i = 0; i < columns.size(); ++i) {
      const SummaryCell cell = columns[i].cell(r);
      out += i ? "," : "";
      out += cell.is_text ? csv_field(cell.text) : cell.number ? full(*cell.number) : "";
    }
    out += '\n';
  }
  return out;
}

std::string summary_markdown(const std::vector<MetricsReport>& reports) {
  const std::vector<SummaryColumn> columns = summary_columns_for(reports);
  std::string out = "|", rule = "|";
  for (const SummaryColumn& c : columns) {
    out += std::string(" ") + c.name + " |";
    rule += c.digits > 0 || c.name == std::string("warnings") ? "---:|" : "---|";
  }
  out += '\n' + rule + '\n';
  for (const MetricsReport& r : reports) {
    out += "|";
    for (const SummaryColumn& c : columns) out += " " + shown(c.cell(r), c.digits, "-") + " |";
    out += '\n';
  }
  return out;
}

nlohmann::ordered_json summary_json(const std::vector<MetricsReport>& reports) {
  using Json = nlohmann::ordered_json;
  const std::vector<SummaryColumn> columns = summary_columns_for(reports);
  Json names = Json::array();
  for (const SummaryColumn& c : columns) names.push_back(c.name);
  Json rows = Json::array();
  for (const MetricsReport& r : reports) {
    Json row = Json::object();
    for (const SummaryColumn& c : columns) {
      const SummaryCell cell = c.cell(r);
      // (a count, the columns of no decimals, as a whole number: 3, not 3.0)
      if (cell.is_text)
        row[c.name] = cell.text;
      else if (!cell.number)
        row[c.name] = Json();
      else if (c.digits == 0)
        row[c.name] = static_cast<long long>(std::llround(*cell.number));
      else
        row[c.name] = *cell.number;
    }
    rows.push_back(row);
  }
  return Json{{"columns", names}, {"rows", rows}};
}

}  // namespace depotwin
