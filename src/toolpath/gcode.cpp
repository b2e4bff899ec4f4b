#include "toolpath/gcode.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <tuple>

#ifdef __linux__
#include <sys/mman.h>
#endif

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/number_text.hpp"
#include "toolpath/ascii_text.hpp"

namespace depotwin {

namespace {

constexpr const char* kKey = "toolpath.gcode";
constexpr double kMmPerInch = 25.4;
constexpr double kSecondsPerMinute = 60.0;
// report this many malformed lines, then only count the rest
constexpr std::size_t kMaxListedProblems = 20;
// a move shorter than this is no move (mm): the toolpath's own tolerance for one point
// (kJoinTolerance_mm), so a CAM program's sub-micron move is not a zero-length segment
constexpr double kMinMove_mm = kJoinTolerance_mm;
// the largest magnitude a number may have (beyond: a typo or garbage)
constexpr double kMaxMagnitude = 1e9;
// the least feed rate read (per minute, in the file's unit)
constexpr double kLeastFeedPerMinute = 1e-6;
// M220's speed factor, in percent: 1 % to 100 x (Marlin's dial stops at 10 %); a smaller one
// could take a feed rate under the least one read
constexpr double kLeastSpeedFactorPercent = 1.0;
constexpr double kMostSpeedFactorPercent = 10000.0;
// the largest G or M code number (Marlin's and RepRapFirmware's run to a few thousand); its
// tenths must fit an int
constexpr int kMaxCodeNumber = 99999;
// z levels closer than this are one layer (mm)
constexpr double kLayerTolerance_mm = 1e-6;
// an arc's end may miss its centre's radius by this much (absolute mm, relative)
constexpr double kArcRadiusTolerance_mm = 0.005;
constexpr double kArcRadiusTolerance_rel = 1e-3;
// G60 S: save slots read (Marlin's SAVED_POSITIONS, RepRapFirmware's restore points)
constexpr int kSavedPositionSlots = 10;
// the modal motion after a refused cycle or spline: its repeating lines are not read as moves
constexpr int kRefusedMotion = -2;

// text for a message: printable ASCII kept, other bytes as \xNN, at most 32 characters
std::string printable(const char* begin, const char* end) {
  std::string out;
  for (const char* c = begin; c < end && out.size() < 32; ++c) {
    const auto byte = static_cast<unsigned char>(*c);
    if (byte >= 0x20 && byte < 0x7F) {
      out += *c;
    } else {
      static const char* kHex = "0123456789ABCDEF";
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 15];
    }
  }
  if (end - begin > 32) out += "...";
  return out;
}

using ascii::is_digit;
using ascii::is_letter;
using ascii::is_space;
using ascii::upper;

// A command code: G or M and its number times 10 (G90.1 = 901).
struct Code {
  char letter = 0;
  int tenths = 0;
};

// The words of one line: at most one value per parameter letter, any number of G/M codes.
struct LineWords {
  std::array<double, 26> value{};
  std::uint32_t present = 0;
  std::array<const char*, 26> text{};  // where each word starts, for messages
  std::array<Code, 16> codes{};
  int n_codes = 0;

  bool has(char letter) const { return (present >> (letter - 'A')) & 1u; }
  double get(char letter) const { return value[letter - 'A']; }
  // the word `letter` read as `number`, written at `start`
  void set(char letter, double number, const char* start) {
    present |= 1u << (letter - 'A');
    value[letter - 'A'] = number;
    text[letter - 'A'] = start;
  }
};

// Why a line that does not split into words uses RS274/NGC's programming (LinuxCNC): O-word
// subroutines and control flow, # parameters, [ ] expressions; nullptr when it does not. A
// slicer's placeholder (`[bed_temperature]`, `{...}`) is not an expression.
const char* ngc_programming_reason(const char* p, const char* end) {
  const char* first = p;
  while (first < end && is_space(*first)) ++first;
  if (first < end && upper(*first) == 'O') {
    // `O100 sub`, `o<probe> call`, `O101 while [...]`: a keyword after the O word's number
    const char* q = first + 1;
    if (q < end && *q == '<') q = std::find(q, end, '>');
    while (q < end && (is_digit(*q) || *q == '>')) ++q;
    while (q < end && is_space(*q)) ++q;
    const char* word_end = q;
    while (word_end < end && is_letter(*word_end)) ++word_end;
    std::string keyword(q, word_end);
    for (char& ch : keyword) ch = static_cast<char>(ch | 0x20);
    for (const char* name : {"sub", "endsub", "call", "return", "if", "elseif", "else", "endif",
                             "while", "endwhile", "do", "repeat", "endrepeat", "break", "continue"})
      if (keyword == name)
        return "O-word subroutines and control flow (`O100 sub`, `call`, `if`, `while`) are "
               "not supported: export the program expanded, every move written out";
  }
  for (const char* q = p; q < end; ++q) {
    if (*q == ';') break;
    if (*q == '(') {
      q = std::find(q, end, ')');
      if (q == end) break;
      continue;
    }
    if (*q == '#' && q + 1 < end && (is_digit(q[1]) || q[1] == '<'))
      return "RS274/NGC parameters (`#1`, `#<depth>`) are not supported: export the program "
             "with their values written in";
    if (*q == '[') {
      const char* close = std::find(q, end, ']');
      if (std::any_of(q + 1, close, [](char ch) { return !is_letter(ch) && ch != '_'; }))
        return "RS274/NGC expressions (`X[2*3]`) are not supported: export the program with "
               "their values written in";
    }
  }
  return nullptr;
}

// What a file that begins with a container's signature is and how to get its G-code out;
// nullptr for any other file
const char* packed_gcode_reason(const std::string& text) {
  // PrusaSlicer's binary G-code: "GCDE" and a 32-bit little-endian version (1 so far)
  if (text.size() >= 8 && text.compare(0, 4, "GCDE") == 0 && text.compare(5, 3, "\0\0\0", 3) == 0)
    return "a binary G-code file (PrusaSlicer's .bgcode, signature GCDE): export text G-code "
           "instead (Printer Settings > General > Firmware: binary G-code off)";
  if (text.compare(0, 4, "PK\x03\x04") == 0)
    return "a zip archive, not G-code (Bambu Studio's and OrcaSlicer's .gcode.3mf, or a 3MF "
           "project): unzip it; the G-code is Metadata/plate_1.gcode";
  if (text.compare(0, 2, "\x1f\x8b") == 0)
    return "a gzip-compressed file: decompress it first (gunzip)";
  // UTF-16 text (a byte order mark, or a NUL beside every ASCII character): a Windows editor's
  // "Unicode" save
  const bool utf16_mark =
      text.compare(0, 2, "\xFF\xFE") == 0 || text.compare(0, 2, "\xFE\xFF") == 0;
  const bool utf16_ascii =
      text.size() >= 4 &&
      ((text[0] != '\0' && text[1] == '\0' && text[2] != '\0' && text[3] == '\0') ||
       (text[0] == '\0' && text[1] != '\0' && text[2] == '\0' && text[3] != '\0'));
  if (utf16_mark || utf16_ascii)
    return "UTF-16 text, where G-code is read as ASCII or UTF-8: save it as UTF-8 (e.g. "
           "iconv -f UTF-16 -t UTF-8)";
  return nullptr;
}

// whether text (up to a comment) holds a G word: G, spaces, a digit, after a space or the start,
// in a token of words only (letters, digits, points and signs: `G1X5` is one, Bambu's flag name
// `g29_before_print_flag` is none)
bool has_g_word(const char* p, const char* end) {
  for (const char* c = p; c < end && *c != ';' && *c != '(' && *c != '"'; ++c) {
    if (upper(*c) != 'G' || (c > p && !is_space(c[-1]))) continue;
    const char* d = c + 1;
    while (d < end && is_space(*d)) ++d;
    if (d == end || !is_digit(*d)) continue;
    const char* token_end = d;
    while (token_end < end && (is_letter(*token_end) || is_digit(*token_end) || *token_end == '.' ||
                               *token_end == '+' || *token_end == '-'))
      ++token_end;
    if (token_end == end || is_space(*token_end) || *token_end == ';' || *token_end == '(' ||
        *token_end == '*')
      return true;
  }
  return false;
}

// G codes the reader knows as modes that change no geometry here and take no axis words: a
// line's axis words beside them are a move in the modal motion (RS274/NGC), `G90 X5`
bool is_modal_setting(int tenths) {
  switch (tenths) {
    case 80:   // G8: a lathe's radius mode, X words are radii (G7, diameters: refused)
    case 150:  // G15 polar coordinates off
    case 400:  // G40 cutter compensation off
    case 430:  // G43 tool length offset (H), G49 off
    case 490:
    case 500:  // G50, G50.1: scaling and mirroring off
    case 501:
    case 541:  // G54.1 P: Fanuc's extended work systems (offsets not in the file)
    case 611:  // G61.1, G64: path control (G61 is read where it is executed)
    case 640:
    case 690:  // G69 rotation off
    case 940:  // G94 feed per minute
    case 960:  // G96, G97 spindle speed modes
    case 970:
    case 980:  // G98, G99 canned-cycle return levels
    case 990:
      return true;
    default:
      return false;
  }
}

// M codes of RS274/NGC, grbl and Fanuc that take no axis words (program stops and ends,
// spindle, tool change, coolant, overrides, the fan): on a line with axis words and no G code
// those words are the modal move's (Fanuc's `X20. M8`, Haas's `G43 H01 Z0.1 M08`), which runs
// with them; every other M code's axis words are its settings (M201 X1000, M92, M906, ...)
bool m_code_takes_no_axis_words(int tenths) {
  switch (tenths) {
    case 0:  // M0, M1: pause
    case 10:
    case 20:  // M2, M30: program end
    case 300:
    case 30:  // M3, M4, M5: spindle or laser
    case 40:
    case 50:
    case 60:  // M6: tool change
    case 70:  // M7, M8, M9: coolant
    case 80:
    case 90:
    case 480:  // M48, M49: overrides on and off
    case 490:
    case 1060:  // M106, M107: the fan
    case 1070:
      return true;
    default:
      return false;
  }
}

// whether the rest of a line from p is empty or a comment (`M30` alone ends a program, where
// Marlin's `M30 file.gco` deletes a file)
bool rest_is_blank(const char* p, const char* end) {
  while (p < end && is_space(*p)) ++p;
  return p == end || *p == ';' || *p == '(';
}

// whether a comment line (p at its ';') is a slicer's mark of a new layer: Cura's and
// ideaMaker's `;LAYER:3` (`;LAYER:-1` for a raft; not `;LAYER_COUNT:`), PrusaSlicer's,
// SuperSlicer's and OrcaSlicer's `;LAYER_CHANGE`, Bambu Studio's `; CHANGE_LAYER`, Simplify3D's
// `; layer 3, Z = 0.600`
bool is_layer_mark(const char* p, const char* end) {
  const auto starts_with = [&](const char* q, const char* word) {
    const size_t n = std::strlen(word);
    return static_cast<size_t>(end - q) >= n && std::equal(word, word + n, q);
  };
  const auto ends_word = [&](const char* q) { return q == end || is_space(*q); };
  ++p;  // the ';'
  if (starts_with(p, "LAYER:")) {
    const char* q = p + 6;
    if (q < end && *q == '-') ++q;
    const char* digits = q;
    while (q < end && is_digit(*q)) ++q;
    return q > digits && ends_word(q);
  }
  if (starts_with(p, "LAYER_CHANGE")) return ends_word(p + 12);
  while (p < end && is_space(*p)) ++p;
  if (starts_with(p, "CHANGE_LAYER")) return ends_word(p + 12);
  if (starts_with(p, "layer ")) {
    const char* q = p + 6;
    const char* digits = q;
    while (q < end && is_digit(*q)) ++q;
    return q > digits && q < end && *q == ',';
  }
  return false;
}

// whether the code number at p (after its letter, spaces allowed) is `number`, whole
bool code_number_is(const char* p, const char* end, int number) {
  while (p < end && is_space(*p)) ++p;
  int value = 0;
  const auto [stop, error] = std::from_chars(p, end, value);
  return error == std::errc() && stop > p && value == number && (stop == end || *stop != '.');
}

// Why a line that starts with a name (Klipper's `SET_VELOCITY_LIMIT VELOCITY=100`, a macro)
// would move the path the reader cannot follow: Sinumerik's frames and contours (`TRANS X10`,
// `ROT RPL=45`, `CIP X20 Y10 I1=20 J1=0`), or any name with axis words not written NAME=VALUE
// (Klipper's parameters always are); "" for a command that is no geometry
std::string named_command_problem(const char* p, const char* end) {
  const char* name_end = p;
  while (name_end < end && (is_letter(*name_end) || is_digit(*name_end) || *name_end == '_'))
    ++name_end;
  std::string name(p, name_end);
  std::transform(name.begin(), name.end(), name.begin(), [](char c) { return upper(c); });
  static const char* const kSinumerikGeometry[] = {
      "TRANS",   "ATRANS", "ROT", "AROT", "SCALE",   "ASCALE",  "MIRROR",
      "AMIRROR", "CIP",    "CT",  "POLY", "ASPLINE", "BSPLINE", "CSPLINE",
      "RND",     "RNDM",   "CHF", "CHR",  "AROTS"};
  for (const char* keyword : kSinumerikGeometry)
    if (name == keyword)
      return "`" + name +
             "`: Sinumerik's frames and contour commands (TRANS, ROT, SCALE, MIRROR, CIP, CT, "
             "splines, roundings) are not supported: they move every point that follows or cut "
             "a path the file does not write out (export the toolpath as plain G-code)";
  // the parameters, outside quotes and before a comment: an axis word without '='
  bool quoted = false;
  const char* token = name_end;
  while (token < end) {
    if (*token == '"') quoted = !quoted;
    if (!quoted && (*token == ';' || *token == '#')) break;
    if (quoted || is_space(*token)) {
      ++token;
      continue;
    }
    const char* token_end = token;
    while (token_end < end && !is_space(*token_end) && *token_end != ';' && *token_end != '"')
      ++token_end;
    const bool axis_letter = std::strchr("XYZIJKABCUVW", upper(*token)) != nullptr;
    const char next = token + 1 < token_end ? token[1] : '\0';
    if (axis_letter && (is_digit(next) || next == '-' || next == '+' || next == '.') &&
        std::find(token, token_end, '=') == token_end)
      return "`" + name + " " + std::string(token, token_end) +
             "`: a named command with axis words is not supported (Sinumerik's and other "
             "controllers' commands move the path; Klipper's parameters are written NAME=VALUE)";
    token = token_end;
  }
  return {};
}

// Marlin's text commands (M117 message, M23 file name, ...): the rest of the line is text
bool is_text_command(int number) {
  switch (number) {
    case 0:
    case 1:
    case 16:
    case 23:
    case 28:
    case 30:
    case 32:
    case 33:
    case 117:
    case 118:
    case 928:
      return true;
    default:
      return false;
  }
}

// "M3" -> Code{M, 30}; nothing if not a G/M code
std::optional<Code> code_of(const std::string& text) {
  if (text.size() < 2 || (upper(text[0]) != 'G' && upper(text[0]) != 'M')) return std::nullopt;
  double number = 0.0;
  const auto [end, error] = std::from_chars(text.data() + 1, text.data() + text.size(), number);
  if (error != std::errc() || end != text.data() + text.size() || !(number >= 0.0) ||
      number > kMaxCodeNumber)
    return std::nullopt;
  return Code{upper(text[0]), static_cast<int>(std::lround(number * 10.0))};
}

// whether `code` in a file is the shutter code `given`: the same code, or M3 and M4, which both
// switch a spindle or a laser on (clockwise and counter-clockwise in RS274/NGC, constant and
// dynamic power in grbl), so an open code of either opens with both
bool is_shutter_code(const std::optional<Code>& given, const Code& code) {
  if (!given) return false;
  if (given->letter == code.letter && given->tenths == code.tenths) return true;
  const auto spindle_on = [](const Code& c) {
    return c.letter == 'M' && (c.tenths == 30 || c.tenths == 40);
  };
  return spindle_on(*given) && spindle_on(code);
}

// Ask for 2 MB pages over a large buffer not yet written (Linux transparent huge pages in
// `madvise` mode): a 10^6-line file's moves take ~140 MB, and first touching them 4 kB at a
// time costs more than parsing them. Only advice: nothing changes where it is not honoured.
void advise_huge_pages(void* data, std::size_t bytes) {
#ifdef __linux__
  constexpr std::uintptr_t kHugePage = 2u << 20;
  const auto begin = (reinterpret_cast<std::uintptr_t>(data) + kHugePage - 1) & ~(kHugePage - 1);
  const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHugePage - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

// the parser's state: modal settings and the position reached so far
class GcodeParser {
 public:
  GcodeParser(std::string file_label, const GcodeOptions& options)
      : open_code_(code_of(options.open_code)), close_code_(code_of(options.close_code)) {
    program_.file_label = std::move(file_label);
    work_offset_mm_.fill(Vec3::Zero());
  }

  void line(const char* begin, const char* end, int line_number);
  GcodeProgram finish(int n_lines);
  // room for up to n moves at once (untouched room costs no memory until written)
  void reserve_moves(std::size_t n) {
    program_.moves.reserve(n);
    advise_huge_pages(program_.moves.data(), n * sizeof(GcodeMove));
  }

 private:
  void problem(int line_number, const std::string& message);
  // words of the line from `p` on into words_; false (and a problem) when malformed
  bool split_words(const char* p, const char* end, int line_number);
  void execute(int line_number);
  // M2 or M30, unless it is the shutter's open or close code: the program's end
  bool ends_program(const Code& code) const {
    return code.letter == 'M' && (code.tenths == 20 || code.tenths == 300) &&
           !is_shutter_code(open_code_, code) && !is_shutter_code(close_code_, code);
  }
  void move(int motion, int line_number);
  // a move's record from the present position to target (and there the position)
  void append_move(int motion, const Vec3& target_mm, double e_delta, const EdgeArc& arc,
                   int line_number);
  // G60 S / G61 S / G1 R: a save slot's number from `letter` (0 if absent); -1 and a problem
  // when it is not one
  int save_slot(char letter, const std::string& command, int line_number);
  // Marlin's G61: a travel back to the position G60 saved
  void return_to_saved(int line_number);
  // M220 (its words from `begin` to the line's `end`): the speed factor saved, restored or
  // set; false (and a problem) when S is no percentage from 1 to 10000
  bool set_speed_factor(const char* begin, const char* end, int line_number);
  bool arc_geometry(int motion, const Vec3& target, int line_number, EdgeArc& arc);
  void set_position();
  // G10 L2 / L20: a work system's offsets; false (and a problem) when malformed
  bool set_work_offsets(int line_number);
  void home(const Vec3* stored_mm);  // G28 / G30: to 0, or to the stored position
  // machine = programmed + this (the active work system's offsets and G92's)
  Vec3 frame_offset() const { return work_offset_mm_[work_system_] + offset_mm_; }
  void extrude(double delta);

  std::optional<Code> open_code_;
  std::optional<Code> close_code_;
  std::vector<Problem> problems_;
  std::size_t problem_count_ = 0;
  LineWords words_;

  // modal state
  Vec3 position_mm_ = Vec3::Zero();  // machine frame
  Vec3 offset_mm_ = Vec3::Zero();    // machine = programmed + work offset + offset (G92)
  // work coordinate systems 1-9 (G54..G59.3), as G10 L2/L20 set them; the controller's own,
  // which the file does not give, are read as 0 (index 0 unused)
  std::array<Vec3, 10> work_offset_mm_;  // zeroed in the constructor
  int work_system_ = 1;                  // G54
  Vec3 saved_offset_mm_ = Vec3::Zero();  // G92.2 suspended these, G92.3 restores them
  double extruder_ = 0.0;                // programmed E
  bool axes_relative_ = false;           // G91
  bool arc_centre_absolute_ = false;     // G90.1
  bool extruder_relative_ = false;       // M83
  double unit_mm_ = 1.0;                 // G20: 25.4
  double feed_mm_s_ = 0.0;               // 0: no F given yet
  double speed_factor_ = 1.0;            // M220 S / 100: the moves run at F times it
  double saved_speed_factor_ = 1.0;      // M220 B's
  int motion_mode_ = -1;                 // last G0..G3, -1: none, kRefusedMotion: a cycle
  int plane_ = 17;                       // G17, G18, G19
  bool open_ = false;                    // the shutter's open code is active
  bool power_off_ = false;               // the modal S is 0 (a laser's or spindle's power)
  bool machine_frame_ = false;           // this line's G53
  bool opened_by_percent_ = false;       // a `%` came before any code (RS274/NGC tape)
  bool closed_by_percent_ = false;       // and its closing `%` came (at or after the end)
  bool retracting_ = false;              // the last E change was a decrease
  // where G28 and G30 go (machine frame), once G28.1 / G30.1 stored them (RS274/NGC, grbl);
  // G28 goes to 0 before, and G30, a probe in Marlin, is then ignored
  std::optional<Vec3> g28_position_mm_, g30_position_mm_;
  // positions G60 saved (machine frame) with the programmed E, per slot
  struct SavedPosition {
    Vec3 machine_mm;
    double extruder = 0.0;
  };
  std::array<std::optional<SavedPosition>, kSavedPositionSlots> saved_positions_;

  GcodeProgram program_;
};

// a comment with a '(' inside (LinuxCNC refuses it too)
// a '(' without its ')' on the line (LinuxCNC: "Unclosed comment found")
constexpr const char* kUnclosedComment =
    "comment '(' not closed on its line (a comment ends on its line: close it with ')', or use "
    "';' for a comment to the line's end)";
constexpr const char* kNestedComment =
    "a comment inside a comment: '(' ... '(' ... ')' (comments do not nest; the first ')' ends "
    "both)";

// A G code the reader refuses: why it would move the path in a way the reader cannot follow
// (nullptr for the codes it reads or may ignore), and whether it is modal motion (splines,
// threading, canned cycles, a modal macro call), whose following lines of axis words repeat
// it (`G81 X20 Y20 Z-5 R2`, then `X30`): those are no G0..G3 of the mode before, and the code
// is refused once, at its line.
struct RefusedGCode {
  const char* reason = nullptr;
  bool modal_motion = false;
};
constexpr const char* kChangesThePath =
    " is not supported (splines, canned cycles, threading and inverse-time or per-revolution "
    "feed change the path)";
constexpr const char* kRunsAMacro =
    " is not supported: a macro call runs moves this file does not hold (export the program "
    "expanded)";
RefusedGCode refused_g_code(int tenths) {
  switch (tenths) {
    case 50:   // G5 cubic spline
    case 51:   // G5.1 quadratic spline
    case 52:   // G5.2 NURBS
    case 330:  // G33 spindle-synchronised motion
    case 331:  // G33.1 rigid tapping
    case 730:  // G73 and G76..G89: canned cycles
    case 760:
    case 810:
    case 820:
    case 830:
    case 840:
    case 850:
    case 860:
    case 870:
    case 880:
    case 890:
      return {kChangesThePath, true};
    case 930:  // G93 inverse-time feed
    case 950:  // G95 feed per revolution
      return {kChangesThePath, false};
    case 720:  // G72, G74, G75, G77, G78, G79: Fanuc's turning and tapping cycles, Haas's G74
    case 740:  // tapping cycle, whose repeat lines are more cycles
    case 750:
    case 770:
    case 780:
    case 790:
      return {
          " is not supported: a canned cycle (tapping, or a lathe's turning cycle) cuts "
          "moves this file does not hold, and its following lines repeat it",
          true};
    case 700:  // G70, G71: inch and mm in Sinumerik, Heidenhain ISO and Fanuc's system B, but
    case 710:  // finishing and roughing cycles in Fanuc's lathe system A
      return {
          " is not supported: it means inch or mm in Sinumerik and Fanuc's system B but a "
          "lathe's turning cycle in Fanuc's system A; write G20 (inch) or G21 (mm)"};
    case 410:  // G41, G41.1, G42, G42.1: cutter radius compensation
    case 411:
    case 420:
    case 421:
      return {
          " is not supported: cutter radius compensation offsets the path by a tool radius "
          "the file does not give (export the toolpath without it, G40)"};
    case 70:  // G7: LinuxCNC's lathe diameter mode
      return {
          " is not supported: a lathe's diameter mode reads every X that follows as a "
          "diameter, twice the distance moved (write the program in radius mode, G8)"};
    case 121:  // G12.1, G13.1: Fanuc's polar interpolation
    case 131:
    case 160:  // G16 polar coordinates
    case 520:  // G52 local coordinate offset (RS274/NGC, Fanuc, Mach3)
    case 510:  // G51 scaling
    case 511:  // G51.1 mirroring
    case 680:  // G68 rotation
      return {
          " is not supported: polar coordinates, local offsets, scaling, mirroring and "
          "rotation change every point that follows (export the toolpath with them "
          "applied)"};
    case 650:  // G65 macro call
      return {kRunsAMacro, false};
    case 660:  // G66 and G66.1 modal macro calls (Fanuc): at every move, at every line after
    case 661:
      return {kRunsAMacro, true};
    default:
      return {};
  }
}

void GcodeParser::problem(int line_number, const std::string& message) {
  ++problem_count_;
  if (problems_.size() < kMaxListedProblems)
    problems_.push_back(Problem{program_.file_label, line_number, kKey, message});
}

void GcodeParser::line(const char* begin, const char* end, int line_number) {
  // after the program's end nothing runs: what follows is counted, not read (but the `%` that
  // closes a program opened by one, after its M2 or M30, is the tape's end, as CAM writes it)
  if (program_.program_end_line > 0) {
    const char* first = std::find_if(begin, end, [](char c) { return !is_space(c); });
    if (first == end) return;
    if (*first == '%' && opened_by_percent_ && !closed_by_percent_) {
      closed_by_percent_ = true;
      return;
    }
    ++program_.n_lines_after_end;
    return;
  }
  // control bytes: a binary file, or a broken one (never echoed raw)
  for (const char* c = begin; c < end; ++c) {
    const auto byte = static_cast<unsigned char>(*c);
    if ((byte < 0x20 && *c != '\t' && *c != '\r') || byte == 0x7F) {
      problem(line_number, "binary or control byte " + printable(c, c + 1) + " at column " +
                               std::to_string(c - begin + 1) + " (is this a G-code text file?)");
      return;
    }
  }
  const char* p = begin;
  // the line's leading comments, each `(...)` in turn (a loop: a line of 10^5 of them is
  // read once, with no recursion as deep)
  for (;;) {
    while (p < end && is_space(*p)) ++p;
    if (p < end && *p == '/') ++p;  // block delete: the line runs (block delete off)
    while (p < end && is_space(*p)) ++p;
    // a `%` before any code opens an RS274/NGC program; the next `%` ends it
    if (p < end && *p == '%') {
      if (program_.n_code_lines == 0)
        opened_by_percent_ = true;
      else if (opened_by_percent_) {
        program_.program_end_line = line_number;
        closed_by_percent_ = true;
      }
      return;
    }
    if (p == end) return;
    if (*p == ';') {
      if (is_layer_mark(p, end))
        ++program_.n_layer_marks;
      else
        read_slicer_note(p, end, program_.slicer_notes);
      return;
    }
    if (*p != '(') break;
    // a line that is a comment, or a comment then words
    const char* close = std::find(p, end, ')');
    // (unclosed: refused as after words, as LinuxCNC does; it could hide the line's words)
    if (close == end) {
      problem(line_number, kUnclosedComment);
      return;
    }
    if (std::find(p + 1, close, '(') != close) {
      problem(line_number, kNestedComment);
      return;
    }
    p = close + 1;
  }
  // grbl's system commands ($H homing, $X unlock, $$ settings): not G-code
  if (*p == '$') return;
  // Prusa's MMU `T?` (its firmware asks which filament to load; `Tx` and `Tc`, the same in two
  // steps, read as named commands below): a tool choice, no geometry, as T0 is
  if (upper(*p) == 'T' && p + 1 < end && p[1] == '?' &&
      (p + 2 == end || is_space(p[2]) || p[2] == ';' || p[2] == '('))
    return;
  // Klipper's extended commands (a name, not a letter and a number; a macro's may start with
  // `_`, as `_CLIENT_RETRACT`): not motion, unless the name is another controller's geometry
  if (*p == '_' || (is_letter(*p) && p + 1 < end && (is_letter(p[1]) || p[1] == '_'))) {
    if (const std::string reason = named_command_problem(p, end); !reason.empty())
      problem(line_number, reason);
    else
      read_klipper_settings(p, end, line_number, program_.firmware_settings);
    return;
  }
  ++program_.n_code_lines;
  // the first code after an optional line number: Marlin's text commands end here
  const char* q = p;
  if (upper(*q) == 'N') {
    ++q;
    while (q < end && (is_digit(*q) || is_space(*q))) ++q;
  }
  if (q < end && upper(*q) == 'M') {
    const char* digits = q + 1;
    while (digits < end && is_space(*digits)) ++digits;
    int number = 0;
    const auto [stop, error] = std::from_chars(digits, end, number);
    // the code in tenths (M862.3: 8623); -1 when it is no code number (split_words refuses it)
    int tenths = -1;
    if (error == std::errc() && stop > digits && number >= 0 && number <= kMaxCodeNumber) {
      tenths = number * 10;
      if (stop + 1 < end && *stop == '.' && is_digit(stop[1])) tenths += stop[1] - '0';
    }
    const bool shutter_code = tenths >= 0 && (is_shutter_code(open_code_, Code{'M', tenths}) ||
                                              is_shutter_code(close_code_, Code{'M', tenths}));
    // M2 or M30 alone: the program's end (RS274/NGC, grbl)
    if (ends_program(Code{'M', tenths}) && rest_is_blank(stop, end)) {
      program_.program_end_line = line_number;
      return;
    }
    if (tenths >= 0 && !shutter_code && tenths % 10 == 0 && is_text_command(number)) return;
    // Fanuc's M98 P1000 runs subprogram O1000, whose moves would be skipped (RepRapFirmware's
    // M98 P"macro.g" runs a macro: the firmware's, not the print's)
    if (tenths == 980 && !shutter_code) {
      const char* word = stop;
      while (word < end && upper(*word) != 'P' && *word != ';' && *word != '(') ++word;
      if (word < end && upper(*word) == 'P') {
        ++word;
        while (word < end && is_space(*word)) ++word;
        if (word < end && is_digit(*word)) {
          const char* digits_end = std::find_if(word, end, [](char ch) { return !is_digit(ch); });
          problem(line_number, "M98 P" + std::string(word, digits_end) +
                                   ": subprogram calls are not supported (the subprogram's "
                                   "moves would be skipped): export the program expanded, "
                                   "every move written out");
          return;
        }
      }
    }
    // a firmware setting (M201 X1000, M204 P800), listed as written
    if (tenths >= 0 && !shutter_code)
      read_m_code_settings(tenths, stop, end, line_number, program_.firmware_settings);
    if (tenths == 2200 && !shutter_code && !set_speed_factor(stop, end, line_number)) return;
    // any other M code but M82, M83 and the shutter's: the firmware's settings, whose
    // parameters need not be numbers (M862.3 P "MK3S", M115 U3.13.2); no geometry, unless the
    // line also holds a G code (checked below, as a whole line)
    if (tenths >= 0 && !shutter_code && tenths != 820 && tenths != 830 &&
        !m_code_takes_no_axis_words(tenths) && !has_g_word(q, end))
      return;
  }
  // G29 (bed levelling, probing) takes flags without numbers (Prusa's G29 A, G29 G): no
  // geometry here (the next move names its point)
  if (q < end && upper(*q) == 'G' && code_number_is(q + 1, end, 29)) return;
  if (!split_words(p, end, line_number)) return;
  execute(line_number);
  // M2 or M30 with other words: the program ends after the line (its move made)
  for (int i = 0; i < words_.n_codes; ++i)
    if (ends_program(words_.codes[i])) program_.program_end_line = line_number;
}

bool GcodeParser::split_words(const char* p, const char* end, int line_number) {
  words_.present = 0;
  words_.n_codes = 0;
  const char* const line_begin = p;
  while (p < end) {
    const char c = *p;
    if (is_space(c)) {
      ++p;
      continue;
    }
    if (c == ';' || c == '*') break;  // comment or checksum to the end
    if (c == '(') {
      const char* close = std::find(p, end, ')');
      if (close == end) {
        problem(line_number, kUnclosedComment);
        return false;
      }
      // (RS274/NGC comments do not nest: the first ')' ends it, and what follows would read as
      // words)
      if (std::find(p + 1, close, '(') != close) {
        problem(line_number, kNestedComment);
        return false;
      }
      p = close + 1;
      continue;
    }
    if (!is_letter(c)) {
      const char* reason = ngc_programming_reason(line_begin, end);
      // a number after a space that follows a word's number: `X1 0.5`, a space inside it
      const char* before = p;
      while (before > line_begin && is_space(before[-1])) --before;
      const bool number_split = (is_digit(c) || c == '.') && before < p && before > line_begin &&
                                (is_digit(before[-1]) || before[-1] == '.');
      problem(line_number, reason
                               ? std::string(reason)
                               : "unexpected '" + printable(p, p + 1) +
                                     "' (expected a letter followed by a number" +
                                     (number_split ? "; a space inside a number is not read: write "
                                                     "X10.5, not X1 0.5)"
                                                   : ")"));
      return false;
    }
    const char letter = upper(c);
    const char* word_start = p;
    ++p;
    while (p < end && is_space(*p)) ++p;  // spaces inside a word: `Z  15.000`
    // the number: sign, digits and one point, a lowercase exponent glued to it (`X1e-05`,
    // from a script's floats); after a lowercase letter an `e` is the next word (`y0e1`: a
    // file written in lowercase, Y 0 and E 1)
    const bool lowercase_word = c >= 'a' && c <= 'z';
    const char* number_start = p;
    if (p < end && (*p == '+' || *p == '-')) ++p;
    const char* mantissa = p;
    int digits = 0;
    bool point = false;
    while (p < end && (is_digit(*p) || (*p == '.' && !point))) {
      point = point || *p == '.';
      digits += is_digit(*p) ? 1 : 0;
      ++p;
    }
    if (digits > 0 && !lowercase_word && p + 1 < end && *p == 'e' &&
        (is_digit(p[1]) || ((p[1] == '+' || p[1] == '-') && p + 2 < end && is_digit(p[2])))) {
      p += 2;
      while (p < end && is_digit(*p)) ++p;
    }
    // the word as written, to the next space, for messages
    const char* word_end = p;
    while (word_end < end && !is_space(*word_end) && *word_end != ';' && *word_end != '(')
      ++word_end;
    // homing's axes may be named without a number (Marlin's G28 X Y, Prusa's G28 W, G161 and
    // G162 homing to the axes' minimum or maximum in MakerBot's and Repetier's files), and so
    // may the axes Marlin's G61 returns to a saved position (`G61 S0 X Y`): flags; and so is
    // the I of Marlin's M3, M4 and M5 (`M3 I`: the laser's inline mode, power set per move)
    if (digits == 0 && p == number_start &&
        (p == end || is_space(*p) || *p == ';' || is_letter(*p)) && letter != 'G' &&
        letter != 'M' && !words_.has(letter) &&
        std::any_of(words_.codes.begin(), words_.codes.begin() + words_.n_codes,
                    [letter](const Code& code) {
                      if (code.letter == 'M')
                        return letter == 'I' &&
                               (code.tenths == 30 || code.tenths == 40 || code.tenths == 50);
                      return code.letter == 'G' && (code.tenths == 280 || code.tenths == 610 ||
                                                    code.tenths == 1610 || code.tenths == 1620);
                    })) {
      if (letter != 'I') words_.set(letter, 0.0, word_start);  // (M3 I: no arc's I)
      continue;
    }
    const bool clean = digits > 0 && (p == end || !(is_digit(*p) || *p == '.'));
    if (!clean ||
        (p < end && !is_space(*p) && !is_letter(*p) && *p != ';' && *p != '(' && *p != '*')) {
      // a slicer's placeholder left in (`Z{+0.0}`, `S[bed_temperature]`): a template
      const bool placeholder = std::any_of(word_start, word_end, [](char ch) {
        return ch == '{' || ch == '[' || ch == '}' || ch == ']';
      });
      // except on Bambu's z trim, whose start block keeps `G29.1 Z{+0.0}` in the files it
      // exports (the printer evaluates it): its axis words are never a move, so its value is
      // not needed (inspect still lists the code's axis words)
      const bool bambu_z_trim = placeholder && words_.n_codes == 1 &&
                                words_.codes[0].letter == 'G' && words_.codes[0].tenths == 291 &&
                                !words_.has(letter);
      if (bambu_z_trim) {
        words_.set(letter, 0.0, word_start);
        p = word_end;
        continue;
      }
      if (const char* reason = ngc_programming_reason(line_begin, end)) {
        problem(line_number, reason);
        return false;
      }
      problem(line_number, "malformed word '" + printable(word_start, word_end) + "' (expected " +
                               std::string(1, letter) + " followed by a number" +
                               (placeholder ? "; a slicer's placeholder not filled in: this "
                                              "looks like a start G-code template, not an "
                                              "exported print)"
                                            : ")"));
      return false;
    }
    double value = 0.0;
    const char* convert_from = *number_start == '+' ? number_start + 1 : number_start;
    const auto [stop, error] = std::from_chars(convert_from, p, value);
    (void)mantissa;
    if (error != std::errc() || stop != p || !std::isfinite(value) ||
        std::abs(value) > kMaxMagnitude) {
      // (a number too close to 0 for a double, `X1e-400`, is no "at most 1e9" case)
      const bool underflow = error == std::errc::result_out_of_range &&
                             std::strtod(std::string(convert_from, p).c_str(), nullptr) == 0.0;
      problem(line_number, "number out of range in '" + printable(word_start, p) +
                               (underflow ? "' (too close to 0 to be read; write 0)"
                                          : "' (at most 1e9 in magnitude)"));
      return false;
    }
    if (letter == 'G' || letter == 'M') {
      const double tenths = value * 10.0;
      if (value > kMaxCodeNumber) {
        problem(line_number, "code number out of range in '" + printable(word_start, p) +
                                 "' (at most " + std::to_string(kMaxCodeNumber) + ")");
        return false;
      }
      if (value < 0.0 || std::abs(tenths - std::round(tenths)) > 1e-6) {
        problem(line_number, "malformed code '" + printable(word_start, p) + "'");
        return false;
      }
      if (words_.n_codes == static_cast<int>(words_.codes.size())) {
        problem(line_number, "more than " + std::to_string(words_.codes.size()) +
                                 " G and M codes on one line (at '" + printable(word_start, p) +
                                 "')");
        return false;
      }
      words_.codes[words_.n_codes++] = Code{letter, static_cast<int>(std::lround(tenths))};
      continue;
    }
    if (letter == 'N' && words_.present == 0 && words_.n_codes == 0) continue;  // line number
    if (words_.has(letter)) {
      problem(line_number, std::string(1, letter) + " given twice on one line");
      return false;
    }
    words_.set(letter, value, word_start);
  }
  return true;
}

void GcodeParser::execute(int line_number) {
  // feed rate first (RS274/NGC order): per minute, in the current unit
  if (words_.has('F')) {
    // (a feed of 1e-200 per minute underflowed the time estimates' squared speeds to 0)
    if (!(words_.get('F') >= kLeastFeedPerMinute)) {
      problem(line_number, words_.get('F') <= 0.0
                               ? "feed rate F must be > 0 (per minute)"
                               : "feed rate F must be at least 1e-6 (per minute): F" +
                                     message_number(words_.get('F')) + " is no speed to print at");
      return;
    }
  }
  // G/M codes: check, then modes before motion
  int motion = -1;
  machine_frame_ = false;
  bool uses_axes = false;  // G92, G28, G10, G4, M codes: the axis words belong to the command
  bool dwell = false, set_position = false, home = false, work_offsets = false;
  const Vec3* home_position = nullptr;  // where G28 or G30 goes (nullptr: machine 0)
  bool save_position = false, g61 = false;
  int foreign_code = -1;  // a G code whose axis words are its own (unknown here, Prusa G80)
  bool opens = false;     // the line holds the open code
  bool closes = false;    // and the close code
  for (int i = 0; i < words_.n_codes; ++i) {
    const Code code = words_.codes[i];
    if (is_shutter_code(open_code_, code)) {
      open_ = opens = true;
      program_.has_shutter_codes = true;
      // Marlin's M106 without S runs the fan at full speed (255), whatever S was before
      if (code.letter == 'M' && code.tenths == 1060 && !words_.has('S')) power_off_ = false;
    } else if (is_shutter_code(close_code_, code)) {
      open_ = false;
      closes = true;
      program_.has_shutter_codes = true;
    }
    // both on one line: which holds for its move is no order's (RS274/NGC refuses two codes of
    // one modal group, M3 and M5, on a line); before, the last won silently
    if (opens && closes) {
      problem(line_number,
              "the open code and the close code on one line: write them on lines "
              "of their own, in the order they should act");
      return;
    }
    if (code.letter == 'M') {
      if (code.tenths == 820 || code.tenths == 830) extruder_relative_ = code.tenths == 830;
      // M66, M67, M68 (LinuxCNC's analog input and outputs, synchronised with the line's move):
      // E names the channel, never the extruder
      if (code.tenths == 660 || code.tenths == 670 || code.tenths == 680)
        words_.present &= ~(1u << ('E' - 'A'));
      // an M code's axis words are its parameters (M201 X1000: the x acceleration, M92, M203,
      // M205, M906, ...), never a modal move, but for the codes that take none (M8, M3, ...)
      if (!m_code_takes_no_axis_words(code.tenths) && !is_shutter_code(open_code_, code) &&
          !is_shutter_code(close_code_, code))
        uses_axes = true;
      continue;
    }
    if (const RefusedGCode refused = refused_g_code(code.tenths); refused.reason != nullptr) {
      problem(line_number, g_code_name(code.tenths) + refused.reason);
      if (refused.modal_motion) motion_mode_ = kRefusedMotion;
      return;
    }
    // G12 and G13 with a radius I: Mach3's circular pocket, a circle cut about the position
    // (Marlin's G12, a nozzle clean, takes P, S, T and R: the firmware's own, never printed)
    if ((code.tenths == 120 || code.tenths == 130) && words_.has('I')) {
      problem(line_number, g_code_name(code.tenths) +
                               " I: circular pockets (Mach3) are not supported: they cut a "
                               "circle the file does not write out (write it as G2/G3 moves)");
      return;
    }
    switch (code.tenths) {
      case 0:
      case 10:
      case 20:
      case 30:
        if (motion >= 0) {
          problem(line_number, "two motion commands (G0-G3) on one line");
          return;
        }
        motion = code.tenths / 10;
        break;
      case 40:
        dwell = uses_axes = true;
        break;
      case 170:
      case 180:
      case 190:
        plane_ = code.tenths / 10;
        break;
      case 200:
      case 210:
        unit_mm_ = code.tenths == 200 ? kMmPerInch : 1.0;
        break;
      case 280:
        home = uses_axes = true;
        home_position = g28_position_mm_ ? &*g28_position_mm_ : nullptr;
        break;
      case 281:  // G28.1, G30.1: the current position stored for G28, G30
      case 301:
        uses_axes = true;  // (grbl and LinuxCNC take no axis words here)
        (code.tenths == 281 ? g28_position_mm_ : g30_position_mm_) = position_mm_;
        break;
      case 300:
        // G30: to the stored position as G28 goes to its own, once G30.1 stored one; else a
        // firmware's probe (Marlin), whose axis words are its parameters
        uses_axes = true;
        if (g30_position_mm_) {
          home = true;
          home_position = &*g30_position_mm_;
        } else {
          foreign_code = code.tenths;
        }
        break;
      case 800:
        // the canned cycle cancelled (RS274/NGC), or Prusa's mesh bed levelling, whose axis
        // words name its area (`G80 X32.5 Y40.2 W150 H120`): never a move
        motion_mode_ = -1;
        uses_axes = true;
        foreign_code = code.tenths;
        break;
      case 900:
      case 910:
        axes_relative_ = code.tenths == 910;
        break;
      case 901:
      case 911:
        arc_centre_absolute_ = code.tenths == 901;
        break;
      case 920:
        set_position = uses_axes = true;
        break;
      case 921:  // G92.1: the G92 offsets cleared
        offset_mm_ = saved_offset_mm_ = Vec3::Zero();
        break;
      case 922:  // G92.2: suspended (G92.3 restores them)
        saved_offset_mm_ = offset_mm_;
        offset_mm_ = Vec3::Zero();
        break;
      case 923:
        offset_mm_ = saved_offset_mm_;
        break;
      case 100: {
        // G10 L2 / L20 set a work system's offsets (RS274/NGC, grbl, RepRapFirmware); other
        // G10s' axis words are tool offsets or tool-table entries (RepRapFirmware's G10 P0
        // X..): listed as ignored, never a move (Marlin's bare G10 retracts)
        uses_axes = true;
        const double l_word = words_.has('L') ? words_.get('L') : -1.0;
        if (l_word == 2.0 || l_word == 20.0) {
          work_offsets = true;
        } else {
          foreign_code = code.tenths;
          // a bare G10 is a firmware retraction (Marlin, Klipper; G11 recovers): one run of
          // retractions as an E decrease counts (GcodeProgram::n_retractions)
          if (!words_.has('L') && !words_.has('P')) {
            if (!retracting_) ++program_.n_retractions;
            retracting_ = true;
          }
        }
        break;
      }
      case 110:  // G11: the firmware's recovery after a G10 retraction
        retracting_ = false;
        break;
      case 600:  // G60: Marlin's and RepRapFirmware's save of the position (S the slot)
        save_position = uses_axes = true;
        break;
      case 610:  // G61: exact-path mode (RS274/NGC), or Marlin's return to a saved position
        g61 = true;
        break;
      case 530:  // G53: this line's axis words in the machine frame
        machine_frame_ = true;
        break;
      case 540:  // G54..G59, G59.1..G59.3: work systems 1-9
      case 550:
      case 560:
      case 570:
      case 580:
      case 590:
      case 591:
      case 592:
      case 593:
        work_system_ = code.tenths < 590 ? (code.tenths - 540) / 10 + 1 : code.tenths - 584;
        break;
      default:
        // a firmware's own code (Bambu's G380 probe, G29.1 z trim, G38.2 probing, G30, ...):
        // what its axis words do is unknown here, so they are its parameters, never a move
        if (!is_modal_setting(code.tenths)) {
          uses_axes = true;
          foreign_code = code.tenths;
        }
        break;
    }
  }
  // a G61 without a motion, with its axes, slot or E named or after a G60 S0: Marlin's
  // return, whose F holds for that move alone (a bare G61 with slot 0 empty: a path mode)
  const bool returns = g61 && motion < 0 &&
                       (saved_positions_[0] || words_.has('X') || words_.has('Y') ||
                        words_.has('Z') || words_.has('E') || words_.has('S'));
  uses_axes = uses_axes || returns;
  const double feed_before = feed_mm_s_;
  if (words_.has('F')) {
    feed_mm_s_ = words_.get('F') * unit_mm_ / kSecondsPerMinute;
  }
  if (dwell) {
    // S in seconds over P in milliseconds (Marlin: S wins when both are given; Klipper's and
    // RepRapFirmware's P in ms too); Fanuc's X in seconds. grbl's and LinuxCNC's P, in
    // seconds, reads as ms here
    double dwell_s = 0.0;
    // a negative dwell is no firmware's wait (Marlin's wraps its clock): refused, not read as 0
    for (const char letter : {'S', 'P', 'X'})
      if (words_.has(letter) && words_.get(letter) < 0.0) {
        problem(line_number, std::string("G4 ") + letter + message_number(words_.get(letter)) +
                                 ": a dwell must be 0 or more");
        return;
      }
    if (words_.has('S'))
      dwell_s = std::max(0.0, words_.get('S'));
    else if (words_.has('P'))
      dwell_s = std::max(0.0, words_.get('P')) / 1000.0;
    else if (words_.has('X'))
      dwell_s = std::max(0.0, words_.get('X'));
    program_.dwell_s += dwell_s;
    program_.pauses.push_back(GcodePause{program_.moves.size(), dwell_s, line_number});
  }
  if (set_position) this->set_position();
  if (work_offsets && !set_work_offsets(line_number)) return;
  if (home) this->home(home_position);
  if (save_position) {
    if (words_.has('X') || words_.has('Y') || words_.has('Z')) {
      problem(line_number,
              "G60 with axis words (a one-direction positioning move) is not supported; G60 "
              "saves the position in Marlin and RepRapFirmware (S the slot)");
      return;
    }
    const int slot = save_slot('S', "G60 S", line_number);
    if (slot < 0) return;
    saved_positions_[slot] = SavedPosition{position_mm_, extruder_};
  }
  if (returns) {
    return_to_saved(line_number);
    feed_mm_s_ = feed_before;
    return;
  }
  const bool axis_words = words_.has('X') || words_.has('Y') || words_.has('Z') ||
                          words_.has('E') || words_.has('I') || words_.has('J') ||
                          words_.has('K') || words_.has('R');
  // (a position's words: RepRapFirmware's `G10 P0 R150 S210` sets temperatures)
  const bool position_words =
      words_.has('X') || words_.has('Y') || words_.has('Z') || words_.has('E');
  if (foreign_code >= 0 && motion < 0 && position_words) {
    // reported (inspect's ignored_axis_words): the position did not change at this line
    auto& ignored = program_.ignored_axis_codes;
    auto it = std::find_if(ignored.begin(), ignored.end(),
                           [&](const IgnoredAxisCode& c) { return c.tenths == foreign_code; });
    if (it == ignored.end())
      ignored.push_back(IgnoredAxisCode{foreign_code, 1, line_number});
    else
      ++it->n_lines;
  }
  if (motion < 0 && !uses_axes && axis_words) {
    if (motion_mode_ == kRefusedMotion) return;  // repeats the refused cycle, reported once
    if (motion_mode_ < 0) {
      problem(line_number, "axis words without a motion command (G0, G1, G2 or G3)");
      return;
    }
    motion = motion_mode_;
  }
  // S on a move, on the open code or alone: the power, modal (grbl's laser `G1 X5 S0`, `M4
  // S0`: open and off); S elsewhere is a temperature, a dwell or a setting
  if (words_.has('S') && (opens || motion >= 0 || words_.n_codes == 0))
    power_off_ = words_.get('S') <= 0.0;
  if (motion >= 0) {
    motion_mode_ = motion;
    move(motion, line_number);
  }
}

void GcodeParser::extrude(double delta) {
  // net extrusion and retractions (a run of decreases is one)
  program_.extrusion_e_total += delta;
  if (delta < 0.0 && !retracting_) ++program_.n_retractions;
  if (delta != 0.0) retracting_ = delta < 0.0;
}

void GcodeParser::move(int motion, int line_number) {
  // a multi-axis file's other axes (rotary A B C, or U V W) moved: their tool orientation or
  // second carriage cannot be followed by reading X Y Z alone (0, or no move in G91, is fine)
  for (const char letter : {'A', 'B', 'C', 'U', 'V', 'W'}) {
    if (!words_.has(letter) || words_.get(letter) == 0.0) continue;
    problem(
        line_number,
        std::string("axis word ") + letter + " (" + message_number(words_.get(letter)) +
            ") on a move: only X, Y, Z and E are read, so a multi-axis "
            "file's rotary or extra axes would be dropped silently; "
            "convert it to 3-axis G-code first" +
            // MakerBot/Sailfish files name their extruders A and B
            (letter == 'A' || letter == 'B' ? std::string(" (or, if ") + letter +
                                                  " is a MakerBot-flavour extruder, export with "
                                                  "RepRap/Marlin flavour: E)"
                                            : std::string()));
    return;
  }
  if (machine_frame_ && motion >= 2) {
    problem(line_number, "G53 (the machine frame) with an arc: only G0 and G1 move there");
    return;
  }
  // RepRapFirmware's `G1 R1 X0 Y0 Z2`: back to restore point 1, the named axes offset by
  // their values (the others stay)
  const SavedPosition* restore_point = nullptr;
  if (motion <= 1 && words_.has('R')) {
    const std::string command = "G" + std::to_string(motion) + " R";
    const int slot = save_slot('R', command, line_number);
    if (slot < 0) return;
    if (!saved_positions_[slot]) {
      problem(line_number, command + std::to_string(slot) + " returns to restore point " +
                               std::to_string(slot) + ", which no earlier G60 S" +
                               std::to_string(slot) +
                               " in this file saved (the firmware's own, from a pause or a tool "
                               "change, are not in the file)");
      return;
    }
    restore_point = &*saved_positions_[slot];
  }
  // target position and extrusion of this move
  Vec3 target_mm = position_mm_;
  const Vec3 frame_mm = frame_offset();
  for (int axis = 0; axis < 3; ++axis) {
    const char letter = static_cast<char>('X' + axis);
    if (!words_.has(letter)) continue;
    const double value = words_.get(letter) * unit_mm_;
    if (restore_point) target_mm[axis] = restore_point->machine_mm[axis] + value;
    // G53: the machine frame, absolute (RS274/NGC, grbl)
    else if (machine_frame_)
      target_mm[axis] = value;
    else
      target_mm[axis] = axes_relative_ ? target_mm[axis] + value : value + frame_mm[axis];
  }
  double e_delta = 0.0;
  if (words_.has('E')) {
    program_.has_e_values = true;
    const double value = words_.get('E') * unit_mm_;
    const bool relative = axes_relative_ || extruder_relative_;
    e_delta = relative ? value : value - extruder_;
    extruder_ = relative ? extruder_ + value : value;
    extrude(e_delta);
  }
  EdgeArc arc;
  if (motion >= 2 && !arc_geometry(motion, target_mm, line_number, arc)) return;
  append_move(motion, target_mm, e_delta, arc, line_number);
}

void GcodeParser::append_move(int motion, const Vec3& target_mm, double e_delta, const EdgeArc& arc,
                              int line_number) {
  GcodeMove record;
  record.line = line_number;
  record.motion = motion;
  record.from_mm = position_mm_;
  record.to_mm = target_mm;
  record.arc = arc;
  if (arc.is_arc()) {
    const Vec3 radius = position_mm_ - arc.center_mm;
    const double rise = (target_mm - position_mm_).dot(arc.axis);
    record.length_mm =
        std::hypot((radius - radius.dot(arc.axis) * arc.axis).norm() * arc.sweep_rad, rise);
  } else {
    record.length_mm = (target_mm - position_mm_).norm();
  }
  record.e_delta = e_delta;
  record.feed_mm_s = feed_mm_s_ * speed_factor_;
  record.has_e = words_.has('E');
  record.open = open_ && !power_off_;
  record.layer_mark = program_.n_layer_marks;
  position_mm_ = target_mm;
  if (record.length_mm > kMinMove_mm) {
    record.motion_limits = program_.firmware_settings.motion_limits_for_move();
    program_.moves.push_back(record);
    if (speed_factor_ != 1.0 && feed_mm_s_ > 0.0) ++program_.n_speed_factor_moves;
  } else if (e_delta != 0.0)  // the extruder alone: a retraction or a prime, at the feed rate
    program_.pauses.push_back(GcodePause{
        program_.moves.size(),
        feed_mm_s_ > 0.0 ? std::abs(e_delta) / (feed_mm_s_ * speed_factor_) : 0.0, line_number});
}

bool GcodeParser::arc_geometry(int motion, const Vec3& target, int line_number, EdgeArc& arc) {
  // the plane's axes (a0, a1) and its normal, right-handed: G17 XY/Z, G18 ZX/Y, G19 YZ/X
  const int a0 = plane_ == 17 ? 0 : plane_ == 18 ? 2 : 1;
  const int a1 = plane_ == 17 ? 1 : plane_ == 18 ? 0 : 2;
  const int normal = 3 - a0 - a1;
  const char offset_letters[3] = {'I', 'J', 'K'};
  const bool has_offset = words_.has(offset_letters[a0]) || words_.has(offset_letters[a1]);
  const std::string plane_name = "G" + std::to_string(plane_);
  if (has_offset == words_.has('R')) {
    problem(line_number, std::string("an arc needs either R or the centre offsets ") +
                             offset_letters[a0] + "/" + offset_letters[a1] + " (plane " +
                             plane_name + "), not " + (has_offset ? "both" : "neither"));
    return false;
  }
  // the offset along the plane's normal is none of its centre's (LinuxCNC refuses it); a
  // non-zero one means the file was written for another plane (0, as some posts write, passes)
  if (words_.has(offset_letters[normal]) && words_.get(offset_letters[normal]) != 0.0) {
    problem(line_number, std::string("an arc in the ") + plane_name + " plane takes " +
                             offset_letters[a0] + " and " + offset_letters[a1] + ", not " +
                             offset_letters[normal] +
                             message_number(words_.get(offset_letters[normal])) +
                             " (is the plane G17, G18 or G19 as the file means it?)");
    return false;
  }
  // P counts the turns in RS274/NGC (LinuxCNC; Bambu's spiral lifts write P1) but the extra
  // circles in Marlin: one turn is read, more would be a guess
  if (words_.has('P') && words_.get('P') != 1.0) {
    problem(line_number, std::string(motion == 3 ? "G3" : "G2") + " P" +
                             message_number(words_.get('P')) +
                             ": arcs of more than one turn are not supported (P counts the "
                             "turns in LinuxCNC, the extra circles in Marlin); write one arc "
                             "per turn");
    return false;
  }
  // G3 turns positively about the plane's normal, G2 negatively (seen from its + end)
  const double turn = motion == 3 ? 1.0 : -1.0;
  const Vec3 start = position_mm_;
  const double s0 = start[a0], s1 = start[a1];
  const double e0 = target[a0], e1 = target[a1];
  const double chord0 = e0 - s0, chord1 = e1 - s1;
  const double chord = std::hypot(chord0, chord1);
  double c0 = 0.0, c1 = 0.0;
  bool full_circle = false;
  if (has_offset) {
    const double i0 =
        words_.has(offset_letters[a0]) ? words_.get(offset_letters[a0]) * unit_mm_ : 0.0;
    const double i1 =
        words_.has(offset_letters[a1]) ? words_.get(offset_letters[a1]) * unit_mm_ : 0.0;
    c0 = arc_centre_absolute_ ? i0 + frame_offset()[a0] : s0 + i0;
    c1 = arc_centre_absolute_ ? i1 + frame_offset()[a1] : s1 + i1;
    const double r_start = std::hypot(s0 - c0, s1 - c1);
    const double r_end = std::hypot(e0 - c0, e1 - c1);
    if (r_start <= kMinMove_mm) {
      problem(line_number, "arc of radius 0 (the centre is the start point)");
      return false;
    }
    const double radius_tolerance =
        std::max(kArcRadiusTolerance_mm, kArcRadiusTolerance_rel * r_start);
    if (std::abs(r_end - r_start) > radius_tolerance) {
      // (the rule applied, with its figure for this arc)
      std::ostringstream message;
      message << "the arc's end is " << r_end << " mm from its centre, its start " << r_start
              << " mm (they must agree within " << radius_tolerance
              << " mm: " << kArcRadiusTolerance_mm << " mm or " << kArcRadiusTolerance_rel * 100.0
              << " % of the radius, the larger)";
      problem(line_number, message.str());
      return false;
    }
    full_circle = chord <= kMinMove_mm;
    if (!full_circle) {
      // the centre moved onto the chord's bisector: one exact circle through both ends. An end
      // a hair off a full circle's start, along the radius, has its bisector far from the
      // centre (by about r x offset / chord): the given centre stays, the circle is cut nearly
      // whole (as LinuxCNC and Marlin cut it), its end mismatch within the radius tolerance
      const double m0 = 0.5 * (s0 + e0), m1 = 0.5 * (s1 + e1);
      const double p0 = -chord1 / chord, p1 = chord0 / chord;
      const double along = (c0 - m0) * p0 + (c1 - m1) * p1;
      const double on_bisector0 = m0 + along * p0, on_bisector1 = m1 + along * p1;
      if (std::hypot(on_bisector0 - c0, on_bisector1 - c1) <= radius_tolerance) {
        c0 = on_bisector0;
        c1 = on_bisector1;
      }
    }
  } else {
    const double radius = words_.get('R') * unit_mm_;
    if (chord <= kMinMove_mm) {
      problem(line_number, "an R arc cannot end where it starts (give I/J/K for a full circle)");
      return false;
    }
    const double half = 0.5 * chord;
    if (std::abs(radius) <
        half - std::max(kArcRadiusTolerance_mm, kArcRadiusTolerance_rel * std::abs(radius))) {
      std::ostringstream message;
      message << "radius R" << words_.get('R');
      if (unit_mm_ != 1.0) message << " (" << std::abs(radius) << " mm)";  // G20: in inches
      message << " is shorter than half the chord (" << half << " mm)";
      problem(line_number, message.str());
      return false;
    }
    // centre on the left of the chord (seen turning) for the short arc, right for R < 0
    const double height = std::sqrt(std::max(0.0, radius * radius - half * half));
    const double side = (radius > 0.0 ? 1.0 : -1.0) * turn;
    c0 = 0.5 * (s0 + e0) + side * height * (-chord1 / chord);
    c1 = 0.5 * (s1 + e1) + side * height * (chord0 / chord);
  }
  // the sweep in the turning direction, (0, 2 pi]
  double sweep = 2.0 * kPi;
  if (!full_circle) {
    const double u0 = s0 - c0, u1 = s1 - c1, v0 = e0 - c0, v1 = e1 - c1;
    const double angle = turn * std::atan2(u0 * v1 - u1 * v0, u0 * v0 + u1 * v1);
    sweep = angle > 0.0 ? angle : angle + 2.0 * kPi;
  }
  arc.center_mm = start;
  arc.center_mm[a0] = c0;
  arc.center_mm[a1] = c1;
  arc.axis = Vec3::Zero();
  arc.axis[normal] = turn;
  arc.sweep_rad = sweep;
  return true;
}

void GcodeParser::set_position() {
  // G92 without words: every axis and E become 0 here
  const bool any = words_.has('X') || words_.has('Y') || words_.has('Z') || words_.has('E');
  for (int axis = 0; axis < 3; ++axis) {
    const char letter = static_cast<char>('X' + axis);
    if (words_.has(letter))
      offset_mm_[axis] =
          position_mm_[axis] - work_offset_mm_[work_system_][axis] - words_.get(letter) * unit_mm_;
    else if (!any)
      offset_mm_[axis] = position_mm_[axis] - work_offset_mm_[work_system_][axis];
  }
  if (words_.has('E')) extruder_ = words_.get('E') * unit_mm_;
  if (!any) extruder_ = 0.0;
}

bool GcodeParser::set_work_offsets(int line_number) {
  // P names the system: 1-9 for G54..G59.3, 0 the active one
  const bool l20 = words_.get('L') == 20.0;
  const std::string command = l20 ? "G10 L20" : "G10 L2";
  const double p_word = words_.has('P') ? words_.get('P') : -1.0;
  if (!(p_word >= 0.0 && p_word <= 9.0 && p_word == std::floor(p_word))) {
    problem(line_number, command +
                             " needs P0-P9 (the work system: 1-9 for G54..G59.3, 0 the "
                             "active one)" +
                             (words_.has('P') ? ", not P" + message_number(p_word) : ""));
    return false;
  }
  if (words_.has('R') && words_.get('R') != 0.0) {
    problem(line_number, command + " R" + message_number(words_.get('R')) +
                             " is not supported: a rotated work system changes every point "
                             "that follows (export the toolpath with it applied)");
    return false;
  }
  const int system = p_word == 0.0 ? work_system_ : static_cast<int>(p_word);
  for (int axis = 0; axis < 3; ++axis) {
    const char letter = static_cast<char>('X' + axis);
    if (!words_.has(letter)) continue;
    const double value = words_.get(letter) * unit_mm_;
    // L2: the offset itself; L20: the one that makes the present position read `value`
    // (G92's offsets on top, as before). G91 changes neither.
    work_offset_mm_[system][axis] = l20 ? position_mm_[axis] - offset_mm_[axis] - value : value;
  }
  return true;
}

bool GcodeParser::set_speed_factor(const char* begin, const char* end, int line_number) {
  const SpeedFactorWords words = read_speed_factor_words(begin, end);
  if (words.has_percent &&
      !(words.percent >= kLeastSpeedFactorPercent && words.percent <= kMostSpeedFactorPercent)) {
    problem(line_number, "M220 S" + message_number(words.percent) +
                             ": a speed factor must be a percentage from 1 to 10000 (S100: the "
                             "feed rates as written)");
    return false;
  }
  if (words.backup) saved_speed_factor_ = speed_factor_;
  if (words.restore) speed_factor_ = saved_speed_factor_;
  if (words.has_percent) speed_factor_ = words.percent / 100.0;
  if (speed_factor_ != 1.0 && program_.first_speed_factor_line == 0)
    program_.first_speed_factor_line = line_number;
  return true;
}

int GcodeParser::save_slot(char letter, const std::string& command, int line_number) {
  const double slot = words_.has(letter) ? words_.get(letter) : 0.0;
  if (slot >= 0.0 && slot < kSavedPositionSlots && slot == std::floor(slot))
    return static_cast<int>(slot);
  problem(line_number, command + message_number(slot) +
                           ": the save slot must be a whole number 0-" +
                           std::to_string(kSavedPositionSlots - 1));
  return -1;
}

void GcodeParser::return_to_saved(int line_number) {
  const int slot = save_slot('S', "G61 S", line_number);
  if (slot < 0) return;
  if (!saved_positions_[slot]) {
    problem(line_number, "G61 with axis words or a slot is Marlin's return to the position G60 S" +
                             std::to_string(slot) + " saved, and no G60 S" + std::to_string(slot) +
                             " came before it (RS274/NGC's G61, exact-path mode, takes none)");
    return;
  }
  // no axis named: X, Y, Z and E as saved; else the named ones, their values offsets from it
  const SavedPosition& saved = *saved_positions_[slot];
  const bool any_axis = words_.has('X') || words_.has('Y') || words_.has('Z') || words_.has('E');
  Vec3 target_mm = position_mm_;
  for (int axis = 0; axis < 3; ++axis) {
    const char letter = static_cast<char>('X' + axis);
    if (words_.has(letter))
      target_mm[axis] = saved.machine_mm[axis] + words_.get(letter) * unit_mm_;
    else if (!any_axis)
      target_mm[axis] = saved.machine_mm[axis];
  }
  // E is set, not moved: the return is a travel
  if (words_.has('E'))
    extruder_ = saved.extruder + words_.get('E') * unit_mm_;
  else if (!any_axis)
    extruder_ = saved.extruder;
  append_move(0, target_mm, 0.0, EdgeArc{}, line_number);
}

void GcodeParser::home(const Vec3* stored_mm) {
  // homing goes to 0, or to the position G28.1 / G30.1 stored, on the named axes (all when
  // none is named)
  const bool any_axis = words_.has('X') || words_.has('Y') || words_.has('Z');
  for (int axis = 0; axis < 3; ++axis) {
    if (any_axis && !words_.has(static_cast<char>('X' + axis))) continue;
    position_mm_[axis] = stored_mm ? (*stored_mm)[axis] : 0.0;
    offset_mm_[axis] = 0.0;
  }
}

GcodeProgram GcodeParser::finish(int n_lines) {
  program_.n_lines = n_lines;
  if (problem_count_ > problems_.size())
    problems_.push_back(
        Problem{program_.file_label, 0, kKey,
                std::to_string(problem_count_ - problems_.size()) + " more problems not listed"});
  if (!problems_.empty()) throw InputError(problems_);
  return std::move(program_);
}

// the index of z among ascending levels (grouped within the layer tolerance)
int level_index(const std::vector<double>& levels, double z) {
  const auto it = std::lower_bound(levels.begin(), levels.end(), z - kLayerTolerance_mm);
  return static_cast<int>(it - levels.begin());
}

// Calls on_run(first_move, end_move) for every uninterrupted run of print moves (a slicer's
// layer mark between two moves interrupts it: a spiral vase's climb is cut into its layers).
template <typename OnRun>
void for_each_print_run(const GcodeProgram& program, PrintRule rule, OnRun on_run) {
  const std::vector<GcodeMove>& moves = program.moves;
  std::size_t i = 0;
  while (i < moves.size()) {
    if (!move_prints(moves[i], rule)) {
      ++i;
      continue;
    }
    std::size_t end = i + 1;
    while (end < moves.size() && move_prints(moves[end], rule) &&
           continues_print_run(moves[end - 1], moves[end]))
      ++end;
    on_run(i, end);
    i = end;
  }
}

// The z level of the print run first..end: the height of its first move in a plane of
// constant z, a line or a G17 arc (a CAM program's run may plunge from its safe height with the
// spindle or shutter already on, a dispenser's may ramp down), else, where every move changes z (a
// spiral vase's climb, a lone plunge), where the run starts.
double print_run_level(const GcodeProgram& program, std::size_t first, std::size_t end) {
  for (std::size_t i = first; i < end; ++i) {
    const GcodeMove& move = program.moves[i];
    const bool in_xy = !move.arc.is_arc() || move.arc.axis.z() != 0.0;  // a line or a G17 arc
    if (in_xy && std::abs(move.to_mm.z() - move.from_mm.z()) <= kLayerTolerance_mm)
      return move.from_mm.z();
  }
  return program.moves[first].from_mm.z();
}

}  // namespace

std::string g_code_name(int tenths) {
  return "G" + std::to_string(tenths / 10) +
         (tenths % 10 != 0 ? "." + std::to_string(tenths % 10) : "");
}

const char* print_rule_name(PrintRule rule) {
  switch (rule) {
    case PrintRule::automatic:
      return "auto";
    case PrintRule::e:
      return "e";
    case PrintRule::shutter:
      return "shutter";
    case PrintRule::feed:
      return "feed";
  }
  return "auto";
}

std::optional<PrintRule> print_rule_from_name(const std::string& name) {
  for (PrintRule rule : {PrintRule::automatic, PrintRule::e, PrintRule::shutter, PrintRule::feed})
    if (name == print_rule_name(rule)) return rule;
  return std::nullopt;
}

namespace {

// the G codes the reader follows itself: motion, dwell, plane, unit, homing, positioning modes
bool reads_as_motion_or_mode(int tenths) {
  switch (tenths) {
    case 0:
    case 10:
    case 20:
    case 30:
    case 40:
    case 170:
    case 180:
    case 190:
    case 200:
    case 210:
    case 280:
    case 900:
    case 910:
    case 920:
      return true;
    default:
      return false;
  }
}

}  // namespace

std::vector<ShutterCodeProblem> shutter_code_problems(const std::string& open,
                                                      const std::string& close) {
  std::vector<ShutterCodeProblem> problems;
  const std::optional<Code> open_code = code_of(open), close_code = code_of(close);
  // each a G or M code
  for (const auto& [at_close, given, code] :
       {std::tuple<bool, const std::string*, const std::optional<Code>*>{false, &open, &open_code},
        {true, &close, &close_code}})
    if (!*code)
      problems.push_back({at_close, "'" + printable(given->data(), given->data() + given->size()) +
                                        "' is not a G or M code (e.g. M3, M5, M106, M107)"});
  // a code the reader follows as motion or a mode cannot switch the shutter as well (`--open
  // G1` read every G1 line as opening it)
  for (const auto& [at_close, given, code] :
       {std::tuple<bool, const std::string*, const std::optional<Code>*>{false, &open, &open_code},
        {true, &close, &close_code}})
    if (*code && (*code)->letter == 'G' && reads_as_motion_or_mode((*code)->tenths))
      problems.push_back(
          {at_close, "'" + printable(given->data(), given->data() + given->size()) +
                         "' is a motion or mode code the reader follows (G0-G4, G17-G21, G28, "
                         "G90-G92); a shutter code is a switch (e.g. M3 and M5, M106 and M107)"});
  // two different switches, else nothing can be read under them
  if (open_code && close_code && is_shutter_code(open_code, *close_code)) {
    const std::string why = open_code->tenths == close_code->tenths
                                ? "the open and close codes must differ"
                                : "M3 and M4 both switch a spindle or laser on, so either opens";
    problems.push_back({true, "'" + close + "' would close what '" + open + "' opens: " + why +
                                  " (e.g. open M3, close M5)"});
  }
  return problems;
}

GcodeProgram parse_gcode_program(const std::string& text, const std::string& file_label,
                                 const GcodeOptions& options) {
  // the shutter codes must be G or M codes (M3, M106, ...), and two different switches
  for (const ShutterCodeProblem& problem :
       shutter_code_problems(options.open_code, options.close_code))
    throw InputError(std::string(kKey) + (problem.at_close ? ".close" : ".open"), problem.message);
  GcodeParser parser(file_label, options);
  const char* p = text.data();
  const char* end = p + text.size();
  // a UTF-8 byte order mark is not part of the first command
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) p += 3;
  // DOS's end-of-file byte (Ctrl-Z), which old CAM posts append, with nothing but blanks and
  // line ends after it: the file ends there
  {
    const char* last = end;
    while (last > p && (is_space(last[-1]) || last[-1] == '\n')) --last;
    if (last > p && last[-1] == '\x1A') end = last - 1;
  }
  // containers a slicer may write instead of text: named, rather than a byte at a column
  if (const char* container = packed_gcode_reason(text))
    throw InputError(file_label, 1, kKey, container);
  // at most one move per line: one reservation instead of a copy at every doubling (capped:
  // beyond 2^23 moves the vector grows as usual)
  const auto n_line_ends = static_cast<std::size_t>(std::count(p, end, '\n')) +
                           static_cast<std::size_t>(std::count(p, end, '\r'));
  parser.reserve_moves(std::min<std::size_t>(n_line_ends + 1, std::size_t{1} << 23));
  // every line ends at LF, CR LF or a CR alone (classic Mac), mixed as they may be in one file
  // (a CR-only file with one LF added by another tool), as a firmware reads them: either byte
  // ends a command
  int line_number = 0;
  while (p < end) {
    const char* line_end = std::find_if(p, end, [](char c) { return c == '\n' || c == '\r'; });
    parser.line(p, line_end, ++line_number);
    if (line_end < end && *line_end == '\r' && line_end + 1 < end && line_end[1] == '\n')
      ++line_end;  // CR LF: one line end
    p = line_end + 1;
  }
  return parser.finish(line_number);
}

GcodeProgram read_gcode_program(const std::string& path, const GcodeOptions& options) {
  if (const std::string problem = missing_file_problem("G-code", "", path); !problem.empty())
    throw InputError(path, 0, kKey, problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, kKey, "cannot read the G-code file");
  std::string text;
  in.seekg(0, std::ios::end);
  text.resize(static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg())));
  in.seekg(0, std::ios::beg);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) throw InputError(path, 0, kKey, "cannot read the G-code file");
  return parse_gcode_program(text, path, options);
}

PrintRule resolve_print_rule(const GcodeProgram& program, PrintRule rule, std::string* reason) {
  if (rule != PrintRule::automatic) {
    if (reason) *reason = std::string("rule ") + print_rule_name(rule) + " (as given)";
    return rule;
  }
  if (program.has_e_values) {
    if (reason) *reason = "auto chose e: the file has E values (printing while E increases)";
    return PrintRule::e;
  }
  if (program.has_shutter_codes) {
    if (reason)
      *reason =
          "auto chose shutter: no E values, and the file opens or closes the shutter "
          "(G1/G2/G3 print while it is open and the power S is not 0)";
    return PrintRule::shutter;
  }
  if (reason)
    *reason = "auto chose feed: no E values and no shutter codes (G1/G2/G3 print, G0 travels)";
  return PrintRule::feed;
}

bool move_prints(const GcodeMove& move, PrintRule resolved_rule) {
  switch (resolved_rule) {
    case PrintRule::e:
      return move.e_delta > 0.0;
    case PrintRule::shutter:
      return move.motion >= 1 && move.open;
    case PrintRule::feed:
      return move.motion >= 1;
    case PrintRule::automatic:
      break;
  }
  return false;
}

bool continues_print_run(const GcodeMove& previous, const GcodeMove& next) {
  return (next.from_mm - previous.to_mm).norm() <= kJoinTolerance_mm &&
         next.layer_mark == previous.layer_mark;
}

std::vector<double> print_layer_levels(const GcodeProgram& program, PrintRule resolved_rule) {
  std::vector<double> levels;
  for_each_print_run(program, resolved_rule, [&](std::size_t first, std::size_t end) {
    levels.push_back(print_run_level(program, first, end));
  });
  std::sort(levels.begin(), levels.end());
  // levels within the tolerance of the previous kept one are that layer
  std::vector<double> distinct;
  for (const double z : levels)
    if (distinct.empty() || z - distinct.back() > kLayerTolerance_mm) distinct.push_back(z);
  return distinct;
}

std::string no_code_problem(int n_lines, int n_code_lines) {
  if (n_code_lines > 0) return "";
  if (n_lines == 0) return "is empty (no G-code)";
  return "holds no G-code: " +
         (n_lines == 1 ? std::string("its one line has no")
                       : "none of its " + std::to_string(n_lines) + " lines has a") +
         " G or M code (only comments, blank lines or named commands): is it a G-code file?";
}

GcodeImport import_gcode_program(const GcodeProgram& program, const GcodeOptions& options) {
  GcodeImport result;
  result.n_lines = program.n_lines, result.n_code_lines = program.n_code_lines;
  result.n_speed_factor_moves = program.n_speed_factor_moves;
  result.first_speed_factor_line = program.first_speed_factor_line;
  result.rule = resolve_print_rule(program, options.rule, &result.rule_reason);
  result.layer_z_mm = print_layer_levels(program, result.rule);
  const int n_layers = static_cast<int>(result.layer_z_mm.size());
  const int last_layer = options.last_layer < 0 ? n_layers - 1 : options.last_layer;
  if (n_layers > 0 &&
      (options.first_layer < 0 || options.first_layer > last_layer || last_layer >= n_layers))
    throw InputError(program.file_label, 0, std::string(kKey) + ".layers",
                     "layers [" + std::to_string(options.first_layer) + ", " +
                         std::to_string(options.last_layer) + "] not in the file's " +
                         std::to_string(n_layers) + " layers (0 to " +
                         std::to_string(n_layers - 1) + ")");
  result.first_layer = options.first_layer;
  std::vector<Problem> problems;
  bool reported_missing_feed = false;
  for_each_print_run(program, result.rule, [&](std::size_t first, std::size_t end) {
    const int layer = level_index(result.layer_z_mm, print_run_level(program, first, end));
    if (layer < options.first_layer || layer > last_layer) return;
    PrintPath path;
    std::vector<int> lines;
    // a new path at every change of feed rate, at the same point
    const auto close_path = [&] {
      if (path.points.size() >= 2) {
        path.source_index = static_cast<int>(result.toolpath.paths.size());
        path.layer = layer - options.first_layer;
        if (!path.has_arcs()) path.arcs.clear();
        result.toolpath.paths.push_back(std::move(path));
        result.point_lines.push_back(std::move(lines));
      }
      path = PrintPath{};
      lines.clear();
    };
    for (std::size_t i = first; i < end; ++i) {
      const GcodeMove& move = program.moves[i];
      const double speed = move.feed_mm_s > 0.0 ? move.feed_mm_s : options.default_speed_mm_s;
      if (speed <= 0.0) {
        if (!reported_missing_feed)
          problems.push_back(Problem{program.file_label, move.line, kKey,
                                     "print move before any feed rate: give F (mm/min) or "
                                     "toolpath.speed in the scenario"});
        reported_missing_feed = true;
        close_path();
        continue;
      }
      if (!path.points.empty() && path.speed_mm_s != speed) close_path();
      if (path.points.empty()) {
        path.points.push_back(move.from_mm);
        path.speed_mm_s = speed;
        lines.push_back(move.line);
      }
      path.points.push_back(move.to_mm);
      path.arcs.push_back(move.arc);
      lines.push_back(move.line);
    }
    close_path();
  });
  if (!problems.empty()) throw InputError(problems);
  if (!result.toolpath.paths.empty()) result.first_point_mm = result.toolpath.paths[0].front();
  return result;
}

GcodeImport parse_gcode(std::istream& in, const std::string& file_label,
                        const GcodeOptions& options) {
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return import_gcode_program(parse_gcode_program(text, file_label, options), options);
}

GcodeImport read_gcode(const std::string& path, const GcodeOptions& options) {
  return import_gcode_program(read_gcode_program(path, options), options);
}

GcodeImport parse_gcode(std::istream& in, const std::string& file_label,
                        double default_speed_mm_s) {
  GcodeOptions options;
  options.default_speed_mm_s = default_speed_mm_s;
  return parse_gcode(in, file_label, options);
}

GcodeImport read_gcode(const std::string& path, double default_speed_mm_s) {
  GcodeOptions options;
  options.default_speed_mm_s = default_speed_mm_s;
  return read_gcode(path, options);
}

Toolpath import_gcode(const std::string& path, double default_speed_mm_s) {
  return read_gcode(path, default_speed_mm_s).toolpath;
}

}  // namespace depotwin
