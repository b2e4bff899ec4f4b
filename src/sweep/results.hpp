// `depotwin sweep FILE --merge`: every task's record and metrics gathered into one table,
// written as DIR/results.sqlite (table `results`, with `columns` naming each column's kind
// and unit, and `sweep` holding the sweep's own facts) and DIR/results.csv.
//
// One row per task, in task order. Columns: `task`; one per parameter, named by its key
// (`planner`, `toolpath.speed`); `status` (ok | failed | missing), `error`, `wall_s` (the
// task's wall time), `input_hash`, `folder` (relative to DIR); then one per scalar of
// metrics.json, named by its dotted path (`time_s.total`, `thickness.line_cv`,
// `waste.fraction`), numbers as numbers, words as text, `warnings` as a count; lists (per
// joint, per layer) and the `units` block are left out (the units go to `columns`). A
// `missing` task has no record for its current inputs: not run yet, still running, its
// folder holding an older result, or its process died on a route that could not record it
// (its log's last line is then its error).
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "sweep/sweep.hpp"

namespace depotwin {

// nothing (NULL), a whole number, a real number or text
using ResultCell = std::variant<std::monostate, long long, double, std::string>;

struct ResultColumn {
  std::string name;
  std::string kind;  // task | parameter | status | metric
  std::string type;  // INTEGER | REAL | TEXT (SQLite)
  std::string unit;  // from metrics.json's units block; "" when it has none
};

struct ResultsTable {
  std::vector<ResultColumn> columns;
  std::vector<std::vector<ResultCell>> rows;  // one per task, a cell per column
  std::uint64_t ok = 0, failed = 0, missing = 0;

  // the column's position, -1 when there is none
  int column(const std::string& name) const;
};

// the columns that hold wall-clock times, which differ from run to run and route to route
const std::vector<std::string>& wall_time_columns();

// Reads every task's task.json and metrics.json. `threads` share the reading.
ResultsTable collect_results(const Sweep& sweep, int threads);

// results.sqlite, written beside its place and renamed over it (never half-written)
void write_results_sqlite(const ResultsTable& table, const Sweep& sweep, const std::string& path);

// results.csv: a header of column names, a line per task; numbers in their shortest exact form
std::string results_csv(const ResultsTable& table);

}  // namespace depotwin
