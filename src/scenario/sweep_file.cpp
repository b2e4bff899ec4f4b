// Sweep files: YAML -> SweepSpec, every problem collected (scenario/sweep_file.hpp).
#include "scenario/sweep_file.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/file_io.hpp"
#include "core/number_text.hpp"
#include "scenario/override_tree.hpp"

namespace depotwin {

namespace {

using namespace scenario_detail;
namespace fs = std::filesystem;

// the most values one parameter may take
constexpr std::uint64_t kMaxValuesPerParameter = 1000000;

// a number as a value's text: whole numbers without a point, others with 12 significant digits
// (so a range's 0.1 + 2 x 0.1 is written 0.3)
std::string value_text(double value) {
  char buffer[64];
  if (std::abs(value) < 1e15 && value == std::round(value))
    std::snprintf(buffer, sizeof buffer, "%lld", static_cast<long long>(std::llround(value)));
  else
    std::snprintf(buffer, sizeof buffer, "%.12g", value);
  return buffer;
}

SweepValue value_of(const YAML::Node& node) {
  SweepValue value;
  value.yaml = flow_text(node);
  value.text = value.yaml;
  // a plain scalar that reads as a finite number (quoted text stays text)
  if (node.IsScalar() && node.Tag() != "!") {
    const std::optional<double> number = parse_double(node.Scalar());
    if (number && std::isfinite(*number)) value.number = *number;
  }
  return value;
}

SweepValue number_value(double number) {
  SweepValue value;
  value.yaml = value_text(number);
  value.text = value.yaml;
  value.number = number;
  return value;
}

// the range's values, or a problem where two of them read alike as written (each task's value
// is its text: `{from: 1, to: 1.000000000001, count: 3}` made three tasks of speed 1)
std::optional<std::vector<SweepValue>> distinct_range_values(std::vector<SweepValue> values,
                                                             const Field& field,
                                                             ProblemList& problems) {
  for (std::size_t k = 1; k < values.size(); ++k)
    if (values[k].text == values[k - 1].text) {
      problems.add(field.line, field.key,
                   "values " + std::to_string(k - 1) + " and " + std::to_string(k) +
                       " of the range both read " + values[k].text +
                       ": its values are closer than the digits a value is written with (widen "
                       "the range or take fewer values)");
      return std::nullopt;
    }
  return values;
}

// `{from: a, to: b}` (step 1), `{from, to, step}` or `{from, to, count}` (evenly spaced, ends
// included)
std::optional<std::vector<SweepValue>> read_range(const Field& field, ProblemList& problems) {
  const MapView view(field, {"from", "to", "step", "count"}, problems);
  if (!view.is_map()) return std::nullopt;
  const std::size_t before = problems.size();
  const Field* from_field = view.find("from");
  const Field* to_field = view.find("to");
  if (from_field == nullptr || to_field == nullptr)
    problems.add(field.key_line, field.key,
                 "a range needs from: and to: ({from: 1, to: 200}, {from: 0.1, to: 1, step: 0.1} "
                 "or {from: 10, to: 100, count: 4})");
  if (view.has("step") && view.has("count"))
    problems.add(field.key_line, field.key, "give step: or count:, not both");
  std::optional<double> from, to, step;
  std::optional<long long> count;
  if (from_field) from = read_number(*from_field, problems);
  if (to_field) to = read_number(*to_field, problems);
  if (const Field* f = view.find("step")) step = read_number(*f, problems, ValueRange::positive());
  if (const Field* f = view.find("count"))
    count = read_integer(*f, problems, 1, static_cast<long long>(kMaxValuesPerParameter));
  if (problems.size() != before || !from || !to) return std::nullopt;

  std::vector<SweepValue> values;
  if (count) {
    // evenly spaced, both ends included
    if (*count == 1 && *from != *to) {
      problems.add(field.line, field.key, "count: 1 takes from: alone; give from: == to:");
      return std::nullopt;
    }
    for (long long k = 0; k < *count; ++k)
      values.push_back(number_value(*count == 1 ? *from
                                                : *from + (*to - *from) * static_cast<double>(k) /
                                                              static_cast<double>(*count - 1)));
    return distinct_range_values(std::move(values), field, problems);
  }
  // from, from + step, ... up to `to` (included within a millionth of a step)
  const double step_size = step.value_or(1.0);
  const double span = (*to - *from) / step_size;
  if (span < -1e-6) {
    problems.add(field.line, field.key,
                 "to: " + value_text(*to) + " is below from: " + value_text(*from) +
                     " (a range counts up by its step)");
    return std::nullopt;
  }
  const double steps = std::floor(span + 1e-6);
  if (steps + 1 > static_cast<double>(kMaxValuesPerParameter)) {
    problems.add(field.line, field.key,
                 "gives " + value_text(steps + 1) + " values; at most " +
                     std::to_string(kMaxValuesPerParameter) + " per parameter");
    return std::nullopt;
  }
  for (long long k = 0; k <= static_cast<long long>(steps); ++k)
    values.push_back(number_value(*from + step_size * static_cast<double>(k)));
  return distinct_range_values(std::move(values), field, problems);
}

// the values of one swept key: a list, or a range
std::optional<std::vector<SweepValue>> read_values(const Field& field, ProblemList& problems) {
  if (field.node.IsMap()) return read_range(field, problems);
  if (!field.node.IsSequence()) {
    problems.add(field.line, field.key,
                 "expected a list of values or a range {from, to, step | count}, got " +
                     describe(field.node) + " (a value every task gets goes under set:)");
    return std::nullopt;
  }
  if (field.node.size() == 0) {
    problems.add(field.line, field.key, "is an empty list: a parameter needs at least one value");
    return std::nullopt;
  }
  std::vector<SweepValue> values;
  for (std::size_t i = 0; i < field.node.size(); ++i) {
    const YAML::Node item = field.node[i];
    if (!item.IsDefined() || item.IsNull()) {
      problems.add(field.item(i).line, field.key + "[" + std::to_string(i) + "]", "an empty value");
      continue;
    }
    values.push_back(value_of(item));
  }
  // a value twice would run the same task twice; numbers are one value whatever their text
  // (2, 2.0, 2e0 and +2 are one speed)
  std::map<std::string, std::string> seen;  // the value's identity -> its text as first given
  for (const SweepValue& value : values) {
    std::string identity = value.number ? "number " : value.yaml;
    if (value.number) append_number(identity, *value.number, 17);
    const auto [first, added] = seen.emplace(identity, value.text);
    if (added) continue;
    problems.add(field.line, field.key,
                 "lists " + value.text + " twice" +
                     (first->second == value.text
                          ? std::string()
                          : " (" + first->second + " and " + value.text + " are one value)"));
  }
  return values;
}

class SweepReader {
 public:
  explicit SweepReader(const std::string& path) : problems_(path) {
    spec_.file = path;
    std::error_code error;
    const fs::path absolute = fs::absolute(fs::path(path), error);
    spec_.directory = (error ? fs::path(path) : absolute).parent_path().lexically_normal().string();
    spec_.name = fs::path(path).stem().string();
  }

  SweepSpec read() {
    YAML::Node root;
    if (!read_document(root)) throw InputError(problems_.problems());
    const MapView top(Field{root, "", 1, 1}, {"name", "base", "keep", "set", "grid", "zip"},
                      problems_);
    if (top.is_map()) {
      if (const Field* f = top.find("name")) read_name(*f);
      read_base(top.find("base"));
      if (const Field* f = top.find("keep")) read_keep(*f);
      if (const Field* f = top.find("set")) read_set(*f);
      if (const Field* f = top.find("grid")) read_parameters(*f, spec_.grid);
      if (const Field* f = top.find("zip")) read_zip(*f);
      if (!top.has("grid") && !top.has("zip"))
        problems_.add(1, "grid", "no parameters: a sweep needs grid: or zip: (or both)");
    }
    count_tasks();
    if (!problems_.empty()) throw InputError(problems_.problems());
    return spec_;
  }

 private:
  bool read_document(YAML::Node& root) {
    const std::string& path = problems_.file();
    std::string problem = missing_file_problem("sweep", "", path);
    if (problem.empty()) problem = settings_file_size_problem("sweep", path);
    if (!problem.empty()) {
      problems_.add(0, "", problem);
      return false;
    }
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) {
      problems_.add(0, "", "cannot read the sweep file");
      return false;
    }
    // the scenario's rules: UTF-8 text, one document, a tab or CR line ends named
    std::optional<YAML::Node> document = parse_scenario_text(text.str(), problems_, "sweep");
    if (!document) return false;
    root = *document;
    return true;
  }

  void read_name(const Field& field) {
    const std::optional<std::string> name = read_string(field, problems_);
    if (!name) return;
    if (name->empty() || name->find_first_of("/\\") != std::string::npos || *name == "." ||
        *name == "..") {
      problems_.add(field.line, field.key,
                    "'" + *name + "' cannot name a results folder (no '/', '\\', '.' or '..')");
      return;
    }
    spec_.name = *name;
  }

  void read_base(const Field* field) {
    if (field == nullptr) {
      problems_.add(1, "base", "missing: the scenario every task starts from (base: FILE.yaml)");
      return;
    }
    spec_.base_line = field->line;
    const std::optional<std::string> base = read_string(*field, problems_);
    if (!base) return;
    const fs::path resolved = (fs::path(spec_.file).parent_path() / *base).lexically_normal();
    if (const std::string problem = missing_file_problem("scenario", *base, resolved.string());
        !problem.empty()) {
      problems_.add(field->line, field->key, problem);
      return;
    }
    spec_.base = resolved.string();
  }

  void read_keep(const Field& field) {
    const std::optional<std::string> keep = read_string(field, problems_);
    if (!keep) return;
    if (*keep != "metrics" && *keep != "all") {
      problems_.add(field.line, field.key,
                    "expected metrics (each task keeps metrics.json) or all (everything `run "
                    "--no-render` writes), got '" +
                        *keep + "'");
      return;
    }
    spec_.keep = *keep;
  }

  // a key of set:, grid: or zip:, checked once over all three
  bool claim_key(const std::string& key, int line, const std::string& section) {
    const std::string why = override_key_problem(key);
    if (!why.empty()) {
      problems_.add(line, section + "." + key, why);
      return false;
    }
    if (!claimed_.insert(key).second) {
      problems_.add(line, section + "." + key,
                    "given twice (a key is set, swept in grid: or zipped, once)");
      return false;
    }
    // a key inside another (`limits` and `limits.a_max`): one would silently win
    const auto inside = [](const std::string& inner, const std::string& outer) {
      return inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
             (inner[outer.size()] == '.' || inner[outer.size()] == '[');
    };
    for (const std::string& other : claimed_)
      if (inside(key, other) || inside(other, key)) {
        problems_.add(line, section + "." + key,
                      "overlaps " + other + " (one holds the other, so one value would " +
                          "silently replace the other): set, sweep or zip one of them");
        return false;
      }
    return true;
  }

  // the keys of a map, whatever they are (the override keys are checked by claim_key)
  static std::vector<std::string> keys_in(const Field& field) {
    std::vector<std::string> keys;
    if (field.node.IsMap())
      for (const auto& entry : field.node)
        if (entry.first.IsScalar()) keys.push_back(entry.first.Scalar());
    return keys;
  }

  void read_set(const Field& field) {
    const MapView view(field, keys_in(field), problems_);
    if (!view.is_map()) return;
    for (const std::string& key : keys_in(field)) {
      const Field* entry = view.find(key);
      if (entry == nullptr || !claim_key(key, entry->key_line, "set")) continue;
      // ~ (null) removes the key from the base scenario
      const std::string value = entry->node.IsNull() ? "~" : flow_text(entry->node);
      spec_.fixed.push_back(ScenarioOverride{key, value, spec_.file, entry->key_line});
    }
  }

  void read_parameters(const Field& field, std::vector<SweepParameter>& parameters) {
    const MapView view(field, keys_in(field), problems_);
    if (!view.is_map()) return;
    if (field.node.size() == 0) {
      problems_.add(field.line, field.key, "is empty: name at least one key and its values");
      return;
    }
    const std::string section = field.key;
    for (const std::string& key : keys_in(field)) {
      const Field* entry = view.find(key);
      if (entry == nullptr || !claim_key(key, entry->key_line, section)) continue;
      std::optional<std::vector<SweepValue>> values = read_values(*entry, problems_);
      if (!values) continue;
      parameters.push_back(SweepParameter{key, entry->key_line, std::move(*values)});
    }
  }

  void read_zip(const Field& field) {
    read_parameters(field, spec_.zip);
    // one length for all
    for (const SweepParameter& parameter : spec_.zip)
      if (parameter.values.size() != spec_.zip.front().values.size())
        problems_.add(parameter.line, "zip." + parameter.key,
                      "has " + std::to_string(parameter.values.size()) + " values, zip." +
                          spec_.zip.front().key + " " +
                          std::to_string(spec_.zip.front().values.size()) +
                          ": zipped lists advance together, so they need one length");
  }

  void count_tasks() {
    std::uint64_t count = 1;
    bool too_many = false;
    const auto multiply = [&](std::uint64_t factor) {
      if (factor != 0 && count > kMaxSweepTasks / factor) too_many = true;
      count *= factor;
    };
    for (const SweepParameter& parameter : spec_.grid) multiply(parameter.values.size());
    if (!spec_.zip.empty()) multiply(spec_.zip.front().values.size());
    if (too_many)
      problems_.add(1, "grid",
                    "more than " + std::to_string(kMaxSweepTasks) +
                        " tasks: split the sweep into several files");
    spec_.task_count = too_many ? 0 : count;
  }

  ProblemList problems_;
  SweepSpec spec_;
  std::set<std::string> claimed_;
};

}  // namespace

SweepSpec read_sweep_file(const std::string& path) {
  return SweepReader(path).read();
}

}  // namespace depotwin
