#include "sweep/results.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "sweep/task.hpp"

namespace depotwin {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

int ResultsTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < columns.size(); ++k)
    if (columns[k].name == name) return static_cast<int>(k);
  return -1;
}

const std::vector<std::string>& wall_time_columns() {
  static const std::vector<std::string> columns{"wall_s", "sim.wall_s", "sim.realtime_factor"};
  return columns;
}

namespace {

// one scalar of a task's metrics.json
struct MetricValue {
  std::string name;  // dotted path
  ResultCell value;
  std::string unit;
};

// what one task contributes to the table
struct TaskRow {
  std::string status, error, input_hash;
  // the folder its result is read from, relative to the results folder ("tasks/0007")
  std::string folder;
  double wall_s = NAN;
  std::vector<MetricValue> metrics;
};

// metrics.json's scalars by dotted path, read as a stream (no document built: a merge reads
// thousands); lists are left out but for `warnings`, counted; the `units` block is skipped
class MetricsReader : public nlohmann::json_sax<Json> {
 public:
  explicit MetricsReader(std::vector<MetricValue>& out) : out_(out) {}

  bool null() override { return scalar(std::monostate{}); }
  bool boolean(bool value) override { return scalar(static_cast<long long>(value ? 1 : 0)); }
  bool number_integer(number_integer_t value) override {
    return scalar(static_cast<long long>(value));
  }
  bool number_unsigned(number_unsigned_t value) override {
    return scalar(static_cast<long long>(value));
  }
  bool number_float(number_float_t value, const string_t&) override {
    return scalar(static_cast<double>(value));
  }
  bool string(string_t& value) override { return scalar(value); }
  bool binary(binary_t&) override { return scalar(std::monostate{}); }
  bool key(string_t& name) override {
    key_ = name;
    return true;
  }
  bool start_object(std::size_t) override {
    // the document itself, a section, or something inside a list or the units (skipped)
    if (stack_.empty()) {
      stack_.push_back(Frame{});
      return true;
    }
    const Frame& parent = stack_.back();
    Frame frame;
    frame.skip = parent.skip || parent.list || (stack_.size() == 1 && key_ == "units");
    frame.path = frame.skip ? "" : child_path();
    if (parent.list) ++stack_.back().count;
    stack_.push_back(frame);
    return true;
  }
  bool end_object() override {
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) override {
    const Frame& parent = stack_.back();
    Frame frame;
    frame.list = true;
    frame.skip = parent.skip || parent.list;
    frame.path = frame.skip ? "" : child_path();
    if (parent.list) ++stack_.back().count;
    stack_.push_back(frame);
    return true;
  }
  bool end_array() override {
    const Frame frame = stack_.back();
    stack_.pop_back();
    if (!frame.skip && frame.path == "warnings")
      out_.push_back(MetricValue{frame.path, static_cast<long long>(frame.count), "count"});
    return true;
  }
  bool parse_error(std::size_t position, const std::string&,
                   const nlohmann::detail::exception& error) override {
    throw std::runtime_error("at byte " + std::to_string(position) + ": " + error.what());
  }

 private:
  struct Frame {
    bool list = false;  // an array: its entries are counted, not read
    bool skip = false;  // inside a list or the units block
    std::string path;   // its dotted path
    std::size_t count = 0;
  };
  std::string child_path() const {
    const std::string& parent = stack_.back().path;
    return parent.empty() ? key_ : parent + "." + key_;
  }
  bool scalar(ResultCell value) {
    Frame& parent = stack_.back();
    if (parent.list) {
      ++parent.count;
      return true;
    }
    if (!parent.skip) out_.push_back(MetricValue{child_path(), std::move(value), ""});
    return true;
  }

  std::vector<MetricValue>& out_;
  std::vector<Frame> stack_;
  std::string key_;
};

// the unit of every scalar: metrics.json's units block (the same shape as the report)
void collect_units(const Json& units, const std::string& path,
                   std::map<std::string, std::string>& out) {
  if (units.is_object()) {
    for (const auto& [key, child] : units.items())
      collect_units(child, path.empty() ? key : path + "." + key, out);
  } else if (units.is_string()) {
    out[path] = units.get<std::string>();
  }
}

// a whole file in one read (a merge reads two per task)
std::string read_file(const std::string& path, bool& found) {
  std::string text;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  found = fd >= 0;
  if (!found) return text;
  char buffer[16384];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;)
    text.append(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  return text;
}

TaskRow read_task_row(const Sweep& sweep, std::uint64_t index) {
  TaskRow row;
  row.status = "missing";
  row.folder = sweep.task_folder_name(index);
  const SweepTask task = sweep.task(index);
  try {
    row.input_hash = sweep.input_hash(task);
  } catch (const InputError& error) {
    row.error = std::string("its overrides do not fit the scenario: ") + error.what();
    return row;
  }
  const std::string folder = sweep.found_task_folder(index);
  row.folder = "tasks/" + fs::path(folder).filename().string();
  const std::optional<TaskRecord> record = read_task_record(folder);
  std::error_code ignored;
  const std::string log = sweep.task_log(index);
  if (!record) {
    row.error = "no result: not run yet";
    // a process that died without a record may have left a log
    bool found = false;
    const std::string text = read_file(log, found);
    if (found) {
      std::string last = text;
      while (!last.empty() && (last.back() == '\n' || last.back() == ' ')) last.pop_back();
      last = last.substr(
          last.find_last_of('\n') == std::string::npos ? 0 : last.find_last_of('\n') + 1);
      row.error = "no result recorded (still running, or its process died); its log " + log +
                  (last.empty() ? " is empty" : " ends: " + last);
    }
    return row;
  }
  if (record->input_hash != row.input_hash) {
    row.error =
        "its folder holds the result of other inputs (the sweep, its scenario or depotwin "
        "changed since): run the task again";
    return row;
  }
  row.status = record->status;
  row.error = record->error;
  row.wall_s = record->wall_s;
  if (record->status != "ok") return row;
  bool found = false;
  const std::string text = read_file(folder + "/" + record->run + "/metrics.json", found);
  try {
    if (!found) throw std::runtime_error("no metrics.json");
    MetricsReader reader(row.metrics);
    Json::sax_parse(text, &reader);
  } catch (const std::exception& error) {
    // none of a half-read file's values: the row's numbers would pass for the task's
    row.metrics.clear();
    row.status = "missing";
    std::string why = error.what();
    const size_t id = why.find("[json.exception.");  // nlohmann's error id: no help to a reader
    if (id != std::string::npos && why.find("] ", id) != std::string::npos)
      why.erase(id, why.find("] ", id) + 2 - id);
    row.error = "its metrics.json cannot be read (" + why + "): run it again";
  }
  return row;
}

// the SQLite type that holds every value of a column
std::string type_of(const std::vector<const ResultCell*>& cells) {
  bool any_real = false, any_text = false;
  for (const ResultCell* cell : cells) {
    if (std::holds_alternative<double>(*cell)) any_real = true;
    if (std::holds_alternative<std::string>(*cell)) any_text = true;
  }
  return any_text ? "TEXT" : any_real ? "REAL" : "INTEGER";
}

// a parameter's value as a cell: its number (whole numbers as integers) or its text
ResultCell parameter_cell(const SweepValue& value) {
  if (!value.number) return value.text;
  const double number = *value.number;
  if (std::abs(number) < 9e15 && number == std::round(number))
    return static_cast<long long>(std::llround(number));
  return number;
}

}  // namespace

ResultsTable collect_results(const Sweep& sweep, int threads) {
  const std::uint64_t count = sweep.size();
  // every task's record and metrics, read on `threads` threads
  std::vector<TaskRow> rows(static_cast<std::size_t>(count));
  std::atomic<std::uint64_t> next{0};
  const auto read = [&] {
    for (std::uint64_t i = next++; i < count && interrupt_signal() == 0; i = next++)
      rows[static_cast<std::size_t>(i)] = read_task_row(sweep, i);
  };
  std::vector<std::thread> helpers;
  for (int k = 1; k < threads && static_cast<std::uint64_t>(k) < count; ++k)
    helpers.emplace_back(read);
  read();
  for (std::thread& helper : helpers) helper.join();
  throw_if_interrupted();  // a signal asked to stop: nothing is written (core/interrupt.hpp)

  // the metrics' units, from the first task that ran
  std::map<std::string, std::string> units;
  for (std::uint64_t i = 0; i < count && units.empty(); ++i) {
    if (rows[static_cast<std::size_t>(i)].status != "ok") continue;
    const std::string folder = sweep.found_task_folder(i);
    const std::optional<TaskRecord> record = read_task_record(folder);
    bool found = false;
    const std::string text =
        read_file(folder + "/" + (record ? record->run : "") + "/metrics.json", found);
    try {
      const Json metrics = Json::parse(text);
      if (metrics.contains("units")) collect_units(metrics["units"], "", units);
    } catch (const std::exception&) {
      // no units: the columns say none
    }
  }

  // the columns: task, parameters, status, then every metric in order of first appearance
  ResultsTable table;
  table.columns.push_back(ResultColumn{"task", "task", "INTEGER", "index"});
  const std::vector<std::string>& keys = sweep.parameter_keys();
  for (const std::string& key : keys)
    table.columns.push_back(ResultColumn{key, "parameter", "", ""});
  table.columns.push_back(ResultColumn{"status", "status", "TEXT", ""});
  table.columns.push_back(ResultColumn{"error", "status", "TEXT", ""});
  table.columns.push_back(ResultColumn{"wall_s", "status", "REAL", "s"});
  table.columns.push_back(ResultColumn{"input_hash", "status", "TEXT", ""});
  table.columns.push_back(ResultColumn{"folder", "status", "TEXT", ""});
  std::map<std::string, std::size_t> metric_column;
  for (const std::string& key : keys) metric_column[key] = 0;  // a parameter's name is taken
  for (const char* name : {"task", "status", "error", "wall_s", "input_hash", "folder"})
    metric_column[name] = 0;
  for (const TaskRow& row : rows)
    for (const MetricValue& metric : row.metrics)
      if (metric_column.emplace(metric.name, table.columns.size()).second)
        table.columns.push_back(ResultColumn{
            metric.name, "metric", "", metric.unit.empty() ? units[metric.name] : metric.unit});

  // the rows
  const std::size_t width = table.columns.size();
  table.rows.reserve(rows.size());
  for (std::uint64_t i = 0; i < count; ++i) {
    const TaskRow& source = rows[static_cast<std::size_t>(i)];
    std::vector<ResultCell> cells(width);
    cells[0] = static_cast<long long>(i);
    const SweepTask task = sweep.task(i);
    for (std::size_t k = 0; k < task.parameters.size(); ++k)
      cells[1 + k] = parameter_cell(task.parameters[k].second);
    const std::size_t status_at = 1 + keys.size();
    cells[status_at] = source.status;
    if (!source.error.empty()) cells[status_at + 1] = source.error;
    if (std::isfinite(source.wall_s)) cells[status_at + 2] = source.wall_s;
    cells[status_at + 3] = source.input_hash;
    cells[status_at + 4] = source.folder;
    for (const MetricValue& metric : source.metrics) {
      const std::size_t at = metric_column[metric.name];
      if (at != 0) cells[at] = metric.value;
    }
    if (source.status == "ok")
      ++table.ok;
    else if (source.status == "failed")
      ++table.failed;
    else
      ++table.missing;
    table.rows.push_back(std::move(cells));
  }
  // each column's type from its values
  for (std::size_t k = 0; k < width; ++k) {
    if (!table.columns[k].type.empty()) continue;
    std::vector<const ResultCell*> cells;
    for (const std::vector<ResultCell>& row : table.rows) cells.push_back(&row[k]);
    table.columns[k].type = type_of(cells);
  }
  return table;
}

namespace {

std::string quoted_identifier(const std::string& name) {
  std::string text = "\"";
  for (const char c : name) text += c == '"' ? std::string("\"\"") : std::string(1, c);
  return text + "\"";
}

class Database {
 public:
  explicit Database(const std::string& path) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
        SQLITE_OK)
      fail("cannot create");
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(const std::string& sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) fail(sql);
  }
  // INSERT rows of cells through one prepared statement
  void insert(const std::string& table, std::size_t width,
              const std::vector<std::vector<ResultCell>>& rows) {
    std::string sql = "INSERT INTO " + quoted_identifier(table) + " VALUES (";
    for (std::size_t k = 0; k < width; ++k) sql += k == 0 ? "?" : ", ?";
    sql += ")";
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) fail(sql);
    for (const std::vector<ResultCell>& row : rows) {
      for (std::size_t k = 0; k < width; ++k) {
        const int at = static_cast<int>(k) + 1;
        const ResultCell& cell = row[k];
        if (const auto* integer = std::get_if<long long>(&cell))
          sqlite3_bind_int64(statement, at, *integer);
        else if (const auto* real = std::get_if<double>(&cell))
          sqlite3_bind_double(statement, at, *real);
        else if (const auto* text = std::get_if<std::string>(&cell))
          sqlite3_bind_text(statement, at, text->c_str(), static_cast<int>(text->size()),
                            SQLITE_TRANSIENT);
        else
          sqlite3_bind_null(statement, at);
      }
      if (sqlite3_step(statement) != SQLITE_DONE) {
        sqlite3_finalize(statement);
        fail("insert into " + table);
      }
      sqlite3_reset(statement);
    }
    sqlite3_finalize(statement);
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    const std::string message = "SQLite, " + path_ + ": " + what + ": " + sqlite3_errmsg(db_);
    // a full disk, a read-only or unreachable file: the machine's refusal, not a bug
    switch (sqlite3_errcode(db_) & 0xff) {
      case SQLITE_FULL:
      case SQLITE_IOERR:
      case SQLITE_CANTOPEN:
      case SQLITE_READONLY:
      case SQLITE_PERM:
        throw EnvironmentError(message);
      default:
        throw InternalError(message);
    }
  }
  std::string path_;
  sqlite3* db_ = nullptr;
};

}  // namespace

void write_results_sqlite(const ResultsTable& table, const Sweep& sweep, const std::string& path) {
  // built under a temporary name beside its place, then renamed over it
  const std::string temporary = path + ".partial-" + std::to_string(::getpid());
  std::error_code ignored;
  fs::remove(temporary, ignored);
  try {
    Database db(temporary);
    db.exec("PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF; BEGIN");
    std::string create = "CREATE TABLE results (";
    for (std::size_t k = 0; k < table.columns.size(); ++k)
      create += (k == 0 ? "" : ", ") + quoted_identifier(table.columns[k].name) + " " +
                table.columns[k].type + (k == 0 ? " PRIMARY KEY" : "");
    db.exec(create + ")");
    db.insert("results", table.columns.size(), table.rows);
    // what each column is
    db.exec("CREATE TABLE columns (name TEXT PRIMARY KEY, kind TEXT, type TEXT, unit TEXT)");
    std::vector<std::vector<ResultCell>> columns;
    for (const ResultColumn& column : table.columns)
      columns.push_back({column.name, column.kind, column.type,
                         column.unit.empty() ? ResultCell{} : ResultCell{column.unit}});
    db.insert("columns", 4, columns);
    // the sweep itself
    db.exec("CREATE TABLE sweep (key TEXT PRIMARY KEY, value TEXT)");
    const SweepSpec& spec = sweep.spec();
    db.insert("sweep", 2,
              {{std::string("name"), spec.name},
               {std::string("sweep_file"), spec.file},
               {std::string("base"), spec.base},
               {std::string("keep"), spec.keep},
               {std::string("tasks"), std::to_string(sweep.size())},
               {std::string("ok"), std::to_string(table.ok)},
               {std::string("failed"), std::to_string(table.failed)},
               {std::string("missing"), std::to_string(table.missing)},
               {std::string("depotwin"), std::string(sweep_depotwin_version())}});
    db.exec("COMMIT");
  } catch (...) {
    fs::remove(temporary, ignored);
    throw;
  }
  fs::rename(temporary, path, ignored);
  if (ignored) {
    const std::string why = ignored.message();
    fs::remove(temporary, ignored);
    throw EnvironmentError("cannot move " + temporary + " to " + path + ": " + why);
  }
}

namespace {

// a CSV field: quoted when it holds a comma, a quote or a line break
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string cell_text(const ResultCell& cell) {
  if (const auto* integer = std::get_if<long long>(&cell)) return std::to_string(*integer);
  if (const auto* real = std::get_if<double>(&cell)) {
    // the shortest text that reads back as the same double
    char buffer[64];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, *real).ptr;
    return std::string(buffer, end);
  }
  if (const auto* text = std::get_if<std::string>(&cell)) return csv_field(*text);
  return "";
}

}  // namespace

std::string results_csv(const ResultsTable& table) {
  std::string csv;
  csv.reserve(table.rows.size() * table.columns.size() * 12 + 4096);
  for (std::size_t k = 0; k < table.columns.size(); ++k)
    csv += (k == 0 ? "" : ",") + csv_field(table.columns[k].name);
  csv += '\n';
  for (const std::vector<ResultCell>& row : table.rows) {
    for (std::size_t k = 0; k < row.size(); ++k) {
      if (k > 0) csv += ',';
      csv += cell_text(row[k]);
    }
    csv += '\n';
  }
  return csv;
}

}  // namespace depotwin
