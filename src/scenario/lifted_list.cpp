#include "scenario/lifted_list.hpp"

#include <cmath>

#include "core/input_ranges.hpp"
#include "core/number_text.hpp"

namespace depotwin::scenario_detail {

namespace {

// one line of the text, without its newline
struct Line {
  std::size_t begin = 0, end = 0;
};

std::vector<Line> split_lines(const std::string& text) {
  std::vector<Line> lines;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t newline = text.find('\n', begin);
    const std::size_t end = newline == std::string::npos ? text.size() : newline;
    lines.push_back({begin, end});
    if (newline == std::string::npos) break;
    begin = newline + 1;
  }
  return lines;
}

// a small cursor over one line
class Cursor {
 public:
  Cursor(const std::string& text, Line line) : text_(text), at_(line.begin), end_(line.end) {}

  void skip_spaces() {
    while (at_ < end_ && (text_[at_] == ' ' || text_[at_] == '\r')) ++at_;
  }
  bool take(char c) {
    skip_spaces();
    if (at_ < end_ && text_[at_] == c) {
      ++at_;
      return true;
    }
    return false;
  }
  bool at_end() {
    skip_spaces();
    return at_ == end_;
  }
  // a plain number up to ',' or ']': finite and within the coordinates' range
  bool number(double& value) {
    skip_spaces();
    const std::size_t start = at_;
    while (at_ < end_ && text_[at_] != ',' && text_[at_] != ']' && text_[at_] != ' ') ++at_;
    const std::optional<double> parsed = parse_double(text_.substr(start, at_ - start));
    if (!parsed || !std::isfinite(*parsed) || std::abs(*parsed) > input_ranges::kMaxCoordinate_mm)
      return false;
    value = *parsed;
    return true;
  }
  // [x, y] or [x, y, z]
  bool point(Vec3& p) {
    p = Vec3::Zero();
    if (!take('[')) return false;
    for (int axis = 0; axis < 3; ++axis) {
      if (!number(p[axis])) return false;
      if (take(']')) return axis >= 1;
      if (!take(',')) return false;
    }
    return false;
  }

 private:
  const std::string& text_;
  std::size_t at_, end_;
};

std::size_t indent_of(const std::string& text, Line line) {
  std::size_t at = line.begin;
  while (at < line.end && text[at] == ' ') ++at;
  return at - line.begin;
}

bool blank_or_comment(const std::string& text, Line line) {
  const std::size_t indent = indent_of(text, line);
  return line.begin + indent == line.end || text[line.begin + indent] == '#' ||
         text[line.begin + indent] == '\r';
}

// the line is `KEY:` alone (spaces and a comment allowed after it), at any indent
bool is_key_line(const std::string& text, Line line, const std::string& key) {
  const std::size_t start = line.begin + indent_of(text, line);
  if (text.compare(start, key.size() + 1, key + ":") != 0) return false;
  Cursor rest(text, {start + key.size() + 1, line.end});
  return rest.at_end() || rest.take('#');
}

}  // namespace

std::optional<LiftedSegments> lift_segments(std::string& text, std::size_t min_items) {
  const std::vector<Line> lines = split_lines(text);
  // the top-level `toolpath:` block, and its `segments:` key alone on its line
  std::size_t key = lines.size();
  bool in_toolpath = false;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (blank_or_comment(text, lines[i])) continue;
    if (indent_of(text, lines[i]) == 0) {
      if (text.compare(lines[i].begin, 3, "---") == 0) return std::nullopt;  // documents
      in_toolpath = is_key_line(text, lines[i], "toolpath");
      continue;
    }
    if (in_toolpath && is_key_line(text, lines[i], "segments")) {
      if (key != lines.size()) return std::nullopt;  // given twice: yaml-cpp's to report
      key = i;
    }
  }
  if (key == lines.size()) return std::nullopt;

  // every line after it, up to the next key at its indent or less: `- [[x, y], [x, y]]`
  LiftedSegments lifted;
  lifted.key_line = static_cast<int>(key) + 1;
  const std::size_t key_indent = indent_of(text, lines[key]);
  std::size_t last = key;
  std::size_t item_indent = 0;
  for (std::size_t i = key + 1; i < lines.size(); ++i) {
    if (blank_or_comment(text, lines[i])) {
      // a comment inside the list stays yaml-cpp's business
      if (indent_of(text, lines[i]) + lines[i].begin < lines[i].end) return std::nullopt;
      continue;
    }
    const std::size_t indent = indent_of(text, lines[i]);
    Cursor item(text, {lines[i].begin + indent, lines[i].end});
    const bool is_item = item.take('-');
    if (indent < key_indent || (indent == key_indent && !is_item)) break;
    // every entry at the first one's indent (another indent nests or breaks the list)
    if (!lifted.segments.empty() && indent != item_indent) return std::nullopt;
    item_indent = indent;
    std::array<Vec3, 2> segment;
    if (!is_item || !item.take('[') || !item.point(segment[0]) || !item.take(',') ||
        !item.point(segment[1]) || !item.take(']') || !item.at_end())
      return std::nullopt;
    lifted.segments.push_back(segment);
    lifted.lines.push_back(static_cast<int>(i) + 1);
    last = i;
  }
  if (lifted.segments.size() < min_items) return std::nullopt;

  // the list's lines blanked (their newlines kept), then the key given an empty list (the
  // key's line comes first, so the blanked positions stay valid)
  for (std::size_t i = key + 1; i <= last; ++i)
    for (std::size_t at = lines[i].begin; at < lines[i].end; ++at) text[at] = ' ';
  const std::size_t colon = text.find(':', lines[key].begin);
  text.replace(colon + 1, lines[key].end - colon - 1, " []");
  return lifted;
}

}  // namespace depotwin::scenario_detail
