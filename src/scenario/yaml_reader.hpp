// Private to scenario/: typed reading of yaml-cpp nodes that records every problem
// ("file:line: key: message") instead of stopping at the first. Not installed for
// other modules; only scenario/*.cpp include it (and through it yaml-cpp).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/types.hpp"
#include "scenario/schema.hpp"

namespace depotwin::scenario_detail {

// 1-based line of a node, 0 when yaml-cpp has no mark for it
int line_of(const YAML::Node& node);

// The first document of a YAML text, how many there are (0, 1, or 2 for "more than one") and
// the 1-based line where the second one's content begins. Instead of YAML::LoadAll, which in
// yaml-cpp 0.7 never returns on some malformed text ("," or ",-/": it keeps adding null
// documents, jbeder/yaml-cpp#1040). Throws what yaml-cpp throws for malformed YAML.
struct YamlDocuments {
  YAML::Node first;
  int count = 0;
  int second_line = 0;
  // where (YAML::Mark::pos) each node of the first document that an alias repeats begins: the
  // tree holds it once, so an edit there changes every place that names it
  std::vector<int> aliased_positions;
  // the first explicit tag in the first document (`!!str 3`, `!foo`), as written, and its
  // line (0: none); a plain or quoted node has none
  std::string first_tag;
  int first_tag_line = 0;
};
YamlDocuments load_documents(const std::string& text);

// what a node holds, for messages: "a map", "a list", "nothing", "the text 'abc'"
std::string describe(const YAML::Node& node);

// every problem found in one input file, in the order found
class ProblemList {
 public:
  explicit ProblemList(std::string file) : file_(std::move(file)) {}

  void add(int line, const std::string& key, const std::string& message);
  // a problem in another file (e.g. an imported G-code file)
  void add_problem(Problem problem) { problems_.push_back(std::move(problem)); }

  const std::string& file() const { return file_; }
  std::size_t size() const { return problems_.size(); }
  // the line of every map key read outside lists (e.g. "sim.timestep_s"), for checks made
  // after loading that name a key
  void note_key_line(const std::string& key, int line);
  const std::map<std::string, int>& key_lines() const { return key_lines_; }
  bool empty() const { return problems_.empty(); }
  std::vector<Problem>& problems() { return problems_; }

 private:
  std::string file_;
  std::vector<Problem> problems_;
  std::map<std::string, int> key_lines_;
};

// a value in the document with the dotted key path and line used in messages
struct Field {
  YAML::Node node;
  std::string key;   // e.g. "toolpath.segments[2]"
  int line = 0;      // the value's line, or its key's line when the value is empty
  int key_line = 0;  // the line of its key (for a block map or list: the line above the value)

  Field child(const YAML::Node& value, const std::string& suffix) const;
  // the i-th element of a list
  Field item(std::size_t index) const;
};

// The entries of a YAML map. Reports a non-map, unknown keys (listing the allowed
// ones) and duplicate keys; `find` returns the entry for an allowed key or nothing.
class MapView {
 public:
  MapView(const Field& field, const std::vector<std::string>& allowed, ProblemList& problems);

  bool is_map() const { return is_map_; }
  const Field* find(const std::string& key) const;
  bool has(const std::string& key) const { return find(key) != nullptr; }
  const Field& field() const { return field_; }

 private:
  Field field_;
  bool is_map_ = false;
  std::vector<std::pair<std::string, Field>> entries_;
};

// an inclusive or exclusive numeric range (the schema tables' type)
using Range = ValueRange;

// Typed reads: each reports its problem (wrong type, not finite, out of range) and
// returns nothing, so the caller keeps its default and carries on.
std::optional<double> read_number(const Field& field, ProblemList& problems,
                                  const Range& range = Range{});
std::optional<long long> read_integer(const Field& field, ProblemList& problems,
                                      long long min_value, long long max_value);
std::optional<std::uint64_t> read_seed(const Field& field, ProblemList& problems);
std::optional<bool> read_bool(const Field& field, ProblemList& problems);
std::optional<std::string> read_string(const Field& field, ProblemList& problems);
// a list of exactly `count` numbers, each within `range`
std::optional<std::vector<double>> read_numbers(const Field& field, ProblemList& problems,
                                                std::size_t count, const Range& range);
// a point [x, y] (z = 0) or [x, y, z], every coordinate finite
std::optional<Vec3> read_point(const Field& field, ProblemList& problems);
// a list (reports anything else); true when the field holds a list
bool expect_list(const Field& field, ProblemList& problems, const std::string& what);

using depotwin::format_number;

}  // namespace depotwin::scenario_detail
