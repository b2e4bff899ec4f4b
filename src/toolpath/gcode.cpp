#include "toolpath/gcode.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

#include "core/error.hpp"
#include "core/number_text.hpp"

namespace depotwin {

namespace {

constexpr const char* kKey = "toolpath.gcode";
constexpr double kMmPerInch = 25.4;
constexpr double kSecondsPerMinute = 60.0;
// report this many malformed lines, then only count the rest
constexpr std::size_t kMaxListedProblems = 20;

// one address word of a G-code line, e.g. X12.5
struct Word {
  char letter = 0;
  double value = 0.0;
  std::string text;  // the number as written
};

// the whole text as a finite double, or nothing
std::optional<double> parse_number(const std::string& text) {
  const std::optional<double> value = parse_double(text);
  if (!value || !std::isfinite(*value)) return std::nullopt;
  return value;
}

// the line without comments (`;...` and `(...)`) and checksum (`*...`)
std::string strip_comments(const std::string& raw) {
  std::string text;
  bool in_paren = false;
  for (char c : raw) {
    if (in_paren) {
      in_paren = c != ')';
      continue;
    }
    if (c == ';' || c == '*') break;
    if (c == '(') {
      in_paren = true;
      continue;
    }
    if (c != '\r') text += c;
  }
  return text;
}

bool is_number_char(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+';
}

// Split a line into words. Returns "" or what is malformed.
std::string split_words(const std::string& text, std::vector<Word>& words) {
  words.clear();
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (!std::isalpha(static_cast<unsigned char>(c)))
      return std::string("unexpected '") + c + "' (expected a letter followed by a number)";
    Word word;
    word.letter = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    ++i;
    while (i < text.size() && is_number_char(text[i])) word.text += text[i++];
    const bool ends_cleanly =
        i == text.size() || std::isspace(static_cast<unsigned char>(text[i])) ||
        (!word.text.empty() && std::isalpha(static_cast<unsigned char>(text[i])));
    const std::optional<double> value = parse_number(word.text);
    if (!ends_cleanly || !value) {
      std::size_t end = i;
      while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
      const std::size_t start = i - word.text.size() - 1;
      return "malformed word '" + text.substr(start, end - start) + "' (expected " +
             std::string(1, word.letter) + " followed by a number)";
    }
    word.value = *value;
    words.push_back(word);
  }
  return "";
}

// the parser's state: modal settings and the position reached so far
class GcodeParser {
 public:
  GcodeParser(std::string file_label, double default_speed_mm_s)
      : file_(std::move(file_label)), default_speed_mm_s_(default_speed_mm_s) {}

  void line(const std::string& raw, int line_number);
  GcodeImport finish();

 private:
  void problem(int line_number, const std::string& message);
  void move(const std::vector<Word>& words, int line_number);
  void set_position(const std::vector<Word>& words);
  void home(const std::vector<Word>& words);
  void end_path();

  std::string file_;
  double default_speed_mm_s_;
  std::vector<Problem> problems_;
  std::size_t problem_count_ = 0;

  // modal state
  Vec3 position_mm_ = Vec3::Zero();  // machine frame
  Vec3 offset_mm_ = Vec3::Zero();    // machine = programmed + offset (G92)
  double extruder_ = 0.0;            // programmed E
  bool axes_relative_ = false;       // G91
  bool extruder_relative_ = false;   // M83
  double unit_mm_ = 1.0;             // G20: 25.4
  double feed_mm_s_ = 0.0;           // 0: no F given yet
  bool reported_missing_feed_ = false;

  // output
  GcodeImport result_;
  PrintPath path_;
  std::vector<int> path_lines_;
};

void GcodeParser::problem(int line_number, const std::string& message) {
  ++problem_count_;
  if (problems_.size() < kMaxListedProblems)
    problems_.push_back(Problem{file_, line_number, kKey, message});
}

void GcodeParser::line(const std::string& raw, int line_number) {
  const std::string text = strip_comments(raw);
  // the command word (after an optional line number N...)
  std::size_t pos = text.find_first_not_of(" \t");
  if (pos == std::string::npos || text.substr(pos, 1) == "%") return;  // blank, or a CNC % marker
  std::vector<Word> words;
  std::string command;
  while (pos != std::string::npos) {
    std::size_t end = pos;
    while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
    const std::string token = text.substr(pos, end - pos);
    pos = text.find_first_not_of(" \t", end);
    const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(token[0])));
    if (letter == 'N' && token.size() > 1 && std::isdigit(static_cast<unsigned char>(token[1])))
      continue;
    command = token;
    break;
  }
  if (command.empty()) return;
  // command letter and number, e.g. G1, g01, M83 (sub-codes like G29.1 are other commands)
  const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(command[0])));
  std::size_t digits_end = 1;
  while (digits_end < command.size() &&
         std::isdigit(static_cast<unsigned char>(command[digits_end])))
    ++digits_end;
  if (!std::isalpha(static_cast<unsigned char>(command[0])) || digits_end == 1) {
    problem(line_number, "'" + command + "' is not a G-code command (expected e.g. G1 X10 Y5)");
    return;
  }
  // words glued to the command (G1X10Y5) are part of the rest
  const std::string rest =
      command.substr(digits_end) + (pos == std::string::npos ? "" : " " + text.substr(pos));
  int number = -1;
  const char* digits_last = command.data() + digits_end;
  const auto [digits_stop, digits_error] = std::from_chars(command.data() + 1, digits_last, number);
  const bool plain_number =
      digits_error == std::errc() && digits_stop == digits_last && (rest.empty() || rest[0] != '.');
  const bool handled =
      plain_number &&
      ((letter == 'G' && (number <= 3 || number == 20 || number == 21 || number == 28 ||
                          number == 90 || number == 91 || number == 92)) ||
       (letter == 'M' && (number == 82 || number == 83)));
  if (!handled) return;  // every other command (M104, T0, M117 text, ...) is ignored
  const std::string error = split_words(rest, words);
  if (!error.empty()) {
    problem(line_number, error);
    return;
  }
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i].letter == 'G' || words[i].letter == 'M') {
      problem(line_number, "one command per line expected, found " + std::string(1, letter) +
                               std::to_string(number) + " and " + words[i].letter + words[i].text);
      return;
    }
    for (std::size_t j = 0; j < i; ++j)
      if (words[j].letter == words[i].letter) {
        problem(line_number, std::string(1, words[i].letter) + " given twice on one line");
        return;
      }
  }

  if (letter == 'M') {
    extruder_relative_ = number == 83;
  } else if (number == 0 || number == 1) {
    move(words, line_number);
  } else if (number == 2 || number == 3) {
    problem(line_number,
            "arc moves (G2/G3) are not supported: export line segments (turn off arc fitting)");
  } else if (number == 20 || number == 21) {
    unit_mm_ = number == 20 ? kMmPerInch : 1.0;
  } else if (number == 28) {
    home(words);
  } else if (number == 90 || number == 91) {
    axes_relative_ = number == 91;
  } else if (number == 92) {
    set_position(words);
  }
}

void GcodeParser::move(const std::vector<Word>& words, int line_number) {
  // target position and extrusion of this move
  Vec3 target_mm = position_mm_;
  double extruded = 0.0;
  for (const Word& word : words) {
    const double value = word.value * unit_mm_;
    if (word.letter >= 'X' && word.letter <= 'Z') {
      const int axis = word.letter - 'X';
      target_mm[axis] = axes_relative_ ? target_mm[axis] + value : value + offset_mm_[axis];
    } else if (word.letter == 'E') {
      const bool relative = axes_relative_ || extruder_relative_;
      extruded = relative ? value : value - extruder_;
      extruder_ = relative ? extruder_ + value : value;
    } else if (word.letter == 'F') {
      if (word.value <= 0.0) {
        problem(line_number, "feed rate F" + word.text + " must be > 0 (mm/min)");
        return;
      }
      feed_mm_s_ = value / kSecondsPerMinute;
      reported_missing_feed_ = false;
    }
  }
  const double displacement_mm = (target_mm - position_mm_).norm();
  // no displacement (retract, prime, feed change): the path carries on
  if (displacement_mm <= kJoinTolerance_mm) {
    position_mm_ = target_mm;
    return;
  }
  // travel: ends the current path
  if (extruded <= 0.0) {
    end_path();
    position_mm_ = target_mm;
    return;
  }
  // print move: extend the path, or start a new one (after a travel or at a new speed)
  const double speed_mm_s = feed_mm_s_ > 0.0 ? feed_mm_s_ : default_speed_mm_s_;
  if (speed_mm_s <= 0.0) {
    if (!reported_missing_feed_)
      problem(line_number,
              "print move before any feed rate: give F (mm/min) or toolpath.speed in the scenario");
    reported_missing_feed_ = true;
    end_path();
    position_mm_ = target_mm;
    return;
  }
  if (!path_.points.empty() && path_.speed_mm_s != speed_mm_s) end_path();
  if (path_.points.empty()) {
    path_.points.push_back(position_mm_);
    path_.speed_mm_s = speed_mm_s;
    path_lines_.push_back(line_number);
  }
  path_.points.push_back(target_mm);
  path_lines_.push_back(line_number);
  position_mm_ = target_mm;
}

void GcodeParser::set_position(const std::vector<Word>& words) {
  // G92 without words: every axis and E become 0 here
  if (words.empty()) {
    offset_mm_ = position_mm_;
    extruder_ = 0.0;
    return;
  }
  for (const Word& word : words) {
    const double value = word.value * unit_mm_;
    if (word.letter >= 'X' && word.letter <= 'Z') {
      const int axis = word.letter - 'X';
      offset_mm_[axis] = position_mm_[axis] - value;
    } else if (word.letter == 'E') {
      extruder_ = value;
    }
  }
}

void GcodeParser::home(const std::vector<Word>& words) {
  // homing is a travel to 0 on the named axes (all when none is named)
  end_path();
  bool any_axis = false;
  for (const Word& word : words) any_axis = any_axis || (word.letter >= 'X' && word.letter <= 'Z');
  for (int axis = 0; axis < 3; ++axis) {
    bool named = !any_axis;
    for (const Word& word : words) named = named || word.letter == 'X' + axis;
    if (!named) continue;
    position_mm_[axis] = 0.0;
    offset_mm_[axis] = 0.0;
  }
}

void GcodeParser::end_path() {
  if (path_.points.size() >= 2) {
    path_.source_index = static_cast<int>(result_.toolpath.paths.size());
    result_.toolpath.paths.push_back(path_);
    result_.point_lines.push_back(path_lines_);
  }
  path_ = PrintPath{};
  path_lines_.clear();
}

GcodeImport GcodeParser::finish() {
  end_path();
  if (problem_count_ > problems_.size())
    problems_.push_back(
        Problem{file_, 0, kKey,
                std::to_string(problem_count_ - problems_.size()) + " more problems not listed"});
  if (!problems_.empty()) throw InputError(problems_);
  return std::move(result_);
}

}  // namespace

GcodeImport parse_gcode(std::istream& in, const std::string& file_label,
                        double default_speed_mm_s) {
  GcodeParser parser(file_label, default_speed_mm_s);
  std::string raw;
  int line_number = 0;
  while (std::getline(in, raw)) {
    // a UTF-8 byte order mark is not part of the first command
    if (line_number == 0 && raw.rfind("\xEF\xBB\xBF", 0) == 0) raw.erase(0, 3);
    parser.line(raw, ++line_number);
  }
  return parser.finish();
}

GcodeImport read_gcode(const std::string& path, double default_speed_mm_s) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(path, 0, kKey, "G-code file not found");
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, kKey, "cannot read the G-code file");
  return parse_gcode(in, path, default_speed_mm_s);
}

Toolpath import_gcode(const std::string& path, double default_speed_mm_s) {
  return read_gcode(path, default_speed_mm_s).toolpath;
}

}  // namespace depotwin
