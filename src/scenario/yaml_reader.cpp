#include "scenario/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/input_ranges.hpp"
#include "core/number_text.hpp"

namespace depotwin::scenario_detail {

namespace {

// yaml-cpp tags quoted scalars "!" and plain ones "?"
bool is_quoted(const YAML::Node& node) {
  return node.Tag() == "!";
}

bool is_empty(const YAML::Node& node) {
  return !node.IsDefined() || node.IsNull();
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// YAML's spellings of infinity and not-a-number (.inf, -.Inf, .NaN, ...)
bool is_yaml_special_float(const std::string& text) {
  const std::string lower = lowercase(text);
  return lower == ".nan" || lower == ".inf" || lower == "+.inf" || lower == "-.inf";
}

// counts documents as the parser reads them and keeps where the second one's content begins,
// and, in the first, where each anchored node that an alias repeats begins
class DocumentCounter : public YAML::EventHandler {
 public:
  int count = 0;
  int second_line = 0;
  std::vector<int> aliased_positions;

  void OnDocumentStart(const YAML::Mark&) override { ++count; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { node_at(mark, anchor); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    node_at(mark, 0);
    const auto anchored = anchor_positions_.find(anchor);
    if (count == 1 && anchored != anchor_positions_.end())
      aliased_positions.push_back(anchored->second);
  }
  std::string first_tag;
  int first_tag_line = 0;

  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                const std::string&) override {
    node_at(mark, anchor, tag);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    node_at(mark, anchor, tag);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    node_at(mark, anchor, tag);
  }
  void OnMapEnd() override {}

 private:
  std::map<YAML::anchor_t, int> anchor_positions_;

  void node_at(const YAML::Mark& mark, YAML::anchor_t anchor, const std::string& tag = "") {
    if (count == 2 && second_line == 0) second_line = mark.is_null() ? 0 : mark.line + 1;
    if (count == 1 && anchor != 0) anchor_positions_[anchor] = mark.pos;
    // yaml-cpp tags a plain node "?" (or nothing) and a quoted one "!"; anything else was
    // written (`!!str`, which it spells tag:yaml.org,2002:str, or `!custom`)
    if (count == 1 && first_tag_line == 0 && !tag.empty() && tag != "?" && tag != "!") {
      static const std::string kCoreTags = "tag:yaml.org,2002:";
      first_tag = tag.rfind(kCoreTags, 0) == 0 ? "!!" + tag.substr(kCoreTags.size()) : tag;
      first_tag_line = mark.is_null() ? 1 : mark.line + 1;
    }
  }
};

}  // namespace

YamlDocuments load_documents(const std::string& text) {
  // count the documents, stopping at the second (LoadAll's loop is what may not end)
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  DocumentCounter counter;
  while (counter.count < 2 && parser.HandleNextDocument(counter)) {
  }
  YamlDocuments documents;
  documents.count = counter.count;
  documents.second_line = counter.second_line;
  documents.aliased_positions = std::move(counter.aliased_positions);
  documents.first_tag = counter.first_tag;
  documents.first_tag_line = counter.first_tag_line;
  if (documents.count > 0) documents.first = YAML::Load(text);
  return documents;
}

int line_of(const YAML::Node& node) {
  if (!node.IsDefined()) return 0;
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

std::string describe(const YAML::Node& node) {
  if (is_empty(node)) return "nothing";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  if (is_quoted(node)) return "the text \"" + printable_text(node.Scalar()) + "\"";
  return "'" + printable_text(node.Scalar()) + "'";
}

void ProblemList::note_key_line(const std::string& key, int line) {
  // list entries (segments, polylines) are many and named by their index: not kept
  if (key.find('[') == std::string::npos) key_lines_.emplace(key, line);
}

void ProblemList::add(int line, const std::string& key, const std::string& message) {
  problems_.push_back(Problem{file_, line, key, message});
}

Field Field::child(const YAML::Node& value, const std::string& suffix) const {
  Field out;
  out.node = value;
  out.key = key.empty() ? suffix : key + "." + suffix;
  const int value_line = is_empty(value) ? 0 : line_of(value);
  out.line = value_line > 0 ? value_line : line;
  out.key_line = out.line;
  return out;
}

Field Field::item(std::size_t index) const {
  Field out;
  out.node = node[index];
  out.key = key + "[" + std::to_string(index) + "]";
  const int value_line = is_empty(out.node) ? 0 : line_of(out.node);
  out.line = value_line > 0 ? value_line : line;
  out.key_line = out.line;
  return out;
}

MapView::MapView(const Field& field, const std::vector<std::string>& allowed, ProblemList& problems)
    : field_(field) {
  if (!field.node.IsMap()) {
    problems.add(field.line, field.key, "expected a map, got " + describe(field.node));
    return;
  }
  is_map_ = true;
  for (const auto& key_value : field.node) {
    const YAML::Node key_node = key_value.first;
    const YAML::Node value_node = key_value.second;
    const int key_line = line_of(key_node) > 0 ? line_of(key_node) : field.line;
    if (!key_node.IsScalar()) {
      problems.add(key_line, field.key, "a key must be a name, got " + describe(key_node));
      continue;
    }
    const std::string name = key_node.Scalar();
    Field entry;
    entry.node = value_node;
    entry.key = field.key.empty() ? name : field.key + "." + name;
    // an empty value (`key:`) is marked at the next token; point at the key instead
    entry.line = is_empty(value_node) || line_of(value_node) == 0 ? key_line : line_of(value_node);
    entry.key_line = key_line;
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      std::string known;
      for (const std::string& a : allowed) known += (known.empty() ? "" : ", ") + a;
      const std::string shown = printable_text(name);
      problems.add(key_line, field.key.empty() ? shown : field.key + "." + shown,
                   "unknown key (expected one of: " + known + ")");
      continue;
    }
    if (find(name)) {
      problems.add(key_line, entry.key, "given twice (keep one)");
      continue;
    }
    problems.note_key_line(entry.key, key_line);
    entries_.emplace_back(name, std::move(entry));
  }
}

const Field* MapView::find(const std::string& key) const {
  for (const auto& [name, entry] : entries_)
    if (name == key) return &entry;
  return nullptr;
}

std::optional<double> read_number(const Field& field, ProblemList& problems, const Range& range) {
  const YAML::Node& node = field.node;
  if (!node.IsScalar()) {
    problems.add(field.line, field.key, "expected a number, got " + describe(node));
    return std::nullopt;
  }
  const std::string& text = node.Scalar();
  if (is_quoted(node)) {
    problems.add(field.line, field.key,
                 "expected a number, got " + describe(node) + " (write it without quotes)");
    return std::nullopt;
  }
  if (is_yaml_special_float(text)) {
    problems.add(field.line, field.key, "must be a finite number, got " + printable_text(text));
    return std::nullopt;
  }
  const std::optional<double> value = parse_double(text);
  if (!value) {
    problems.add(field.line, field.key, "expected a number, got " + describe(node));
    return std::nullopt;
  }
  if (!std::isfinite(*value)) {
    problems.add(field.line, field.key,
                 "must be a finite number, got " +
                     // digits beyond the doubles are not echoed (hundreds of them)
                     (text.find_first_of("0123456789") == std::string::npos
                          ? printable_text(text)
                          : std::string(*value < 0 ? "-" : "") + "a number beyond 1.8e+308"));
    return std::nullopt;
  }
  if (!range.contains(*value)) {
    // a number nearer 0 than the doubles hold (3e-400) reads as 0: shown as written, which
    // only a few digits can be once its mantissa is not 0
    const std::string mantissa = text.substr(0, text.find_first_of("eE"));
    const bool underflowed = std::abs(*value) < std::numeric_limits<double>::min() &&
                             mantissa.find_first_of("123456789") != std::string::npos;
    problems.add(field.line, field.key,
                 "must be " + range.text() + ", got " +
                     (underflowed ? printable_text(text) + " (nearer 0 than a double holds: 0)"
                                  : message_number_outside(*value, range.min, range.max)));
    return std::nullopt;
  }
  return value;
}

std::optional<long long> read_integer(const Field& field, ProblemList& problems,
                                      long long min_value, long long max_value) {
  const std::optional<double> value = read_number(field, problems);
  if (!value) return std::nullopt;
  const Range range{static_cast<double>(min_value), true, static_cast<double>(max_value), true};
  if (std::floor(*value) != *value || !range.contains(*value)) {
    problems.add(field.line, field.key,
                 "must be a whole number " + range.text() + ", got " +
                     message_number_outside(*value, range.min, range.max));
    return std::nullopt;
  }
  return static_cast<long long>(*value);
}

std::optional<std::uint64_t> read_seed(const Field& field, ProblemList& problems) {
  const YAML::Node& node = field.node;
  const std::string text = node.IsScalar() ? node.Scalar() : "";
  std::uint64_t value = 0;
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(text.data(), last, value);
  if (!node.IsScalar() || is_quoted(node) || text.empty() || error != std::errc() || end != last) {
    // a number is named by its value (never hundreds of digits), anything else as written
    const std::optional<double> number =
        node.IsScalar() && !is_quoted(node) ? parse_double(text) : std::nullopt;
    // a whole number written otherwise (1.0, 1e3) is that number, as read_integer reads it,
    // up to 2^53 (beyond it a double holds no longer every whole number)
    if (number && *number >= 0.0 && *number <= 9007199254740992.0 && std::floor(*number) == *number)
      return static_cast<std::uint64_t>(*number);
    const std::string got = !number                  ? describe(node)
                            : std::isfinite(*number) ? printable_text(text)
                                                     : "a number beyond 1.8e+308";
    problems.add(field.line, field.key, "expected a whole number >= 0 (a random seed), got " + got);
    return std::nullopt;
  }
  return value;
}

std::optional<bool> read_bool(const Field& field, ProblemList& problems) {
  bool value = false;
  if (!field.node.IsScalar() || is_quoted(field.node) ||
      !YAML::convert<bool>::decode(field.node, value)) {
    problems.add(field.line, field.key, "expected true or false, got " + describe(field.node));
    return std::nullopt;
  }
  return value;
}

std::optional<std::string> read_string(const Field& field, ProblemList& problems) {
  if (!field.node.IsScalar() || field.node.Scalar().empty()) {
    problems.add(field.line, field.key, "expected a name, got " + describe(field.node));
    return std::nullopt;
  }
  return field.node.Scalar();
}

bool expect_list(const Field& field, ProblemList& problems, const std::string& what) {
  if (field.node.IsSequence()) return true;
  problems.add(field.line, field.key, "expected " + what + ", got " + describe(field.node));
  return false;
}

std::optional<std::vector<double>> read_numbers(const Field& field, ProblemList& problems,
                                                std::size_t count, const Range& range) {
  if (!field.node.IsSequence() || field.node.size() != count) {
    const std::string got = field.node.IsSequence()
                                ? "a list of " + std::to_string(field.node.size())
                                : describe(field.node);
    problems.add(field.line, field.key,
                 "expected a list of " + std::to_string(count) + " numbers, got " + got);
    return std::nullopt;
  }
  std::vector<double> values;
  bool ok = true;
  for (std::size_t i = 0; i < count; ++i) {
    const std::optional<double> value = read_number(field.item(i), problems, range);
    ok = ok && value.has_value();
    values.push_back(value.value_or(0.0));
  }
  if (!ok) return std::nullopt;
  return values;
}

std::optional<Vec3> read_point(const Field& field, ProblemList& problems) {
  const YAML::Node& node = field.node;
  if (!node.IsSequence() || node.size() < 2 || node.size() > 3) {
    const std::string got = node.IsSequence() ? "a list of " + std::to_string(node.size()) +
                                                    " number" + (node.size() == 1 ? "" : "s")
                                              : describe(node);
    problems.add(field.line, field.key, "expected a point [x, y] or [x, y, z] in mm, got " + got);
    return std::nullopt;
  }
  Vec3 point = Vec3::Zero();
  bool ok = true;
  const Range coordinate =
      Range::closed(-input_ranges::kMaxCoordinate_mm, input_ranges::kMaxCoordinate_mm);
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::optional<double> value = read_number(field.item(i), problems, coordinate);
    ok = ok && value.has_value();
    if (value) point[static_cast<int>(i)] = *value;
  }
  if (!ok) return std::nullopt;
  return point;
}

}  // namespace depotwin::scenario_detail
