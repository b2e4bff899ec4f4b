#include "core/number_text.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <system_error>

namespace depotwin {

std::optional<double> parse_double(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (*first == '+') ++first;
  double value = 0.0;
  const auto [end, error] = std::from_chars(first, last, value);
  if (end != last) return std::nullopt;
  // beyond the doubles (1e400, 1e-400): what strtod makes of it, +-inf or (nearly) 0, so the
  // caller can say "not finite" or "out of range" instead of "not a number"
  if (error == std::errc::result_out_of_range) return std::strtod(text.c_str(), nullptr);
  if (error != std::errc()) return std::nullopt;
  return value;
}

std::string message_number(double value, int significant_digits) {
  char text[40];
  std::snprintf(text, sizeof text, "%.*g", std::clamp(significant_digits, 1, 17), value);
  return text;
}

std::string message_number_beside(double value, double bound, int significant_digits) {
  // the fewest digits from significant_digits on at which the two texts differ
  char text[40], bound_text[40];
  for (int digits = significant_digits;; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    std::snprintf(bound_text, sizeof bound_text, "%.*g", digits, bound);
    if (value == bound || digits >= 17 || std::string(text) != bound_text) return text;
  }
}

std::string message_number_outside(double value, double min, double max, int significant_digits) {
  return message_number_beside(value, value < min ? min : max, significant_digits);
}

void append_number(std::string& out, double value, int significant_digits) {
  char text[32];  // "-1.2345678901234567e-308": 24 characters at 17 digits
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, value,
                                                 std::chars_format::general, significant_digits);
  out.append(text, end.ptr);
}

void append_fixed(std::string& out, double value, int decimals) {
  char text[340];  // the largest double in "%.17f": 309 digits before the point
  const std::to_chars_result end =
      std::to_chars(text, text + sizeof text, value, std::chars_format::fixed, decimals);
  out.append(text, end.ptr);
}

namespace {

// the length of the well-formed UTF-8 sequence of a printable code point (>= U+00A0) at
// `at`, or 0
std::size_t printable_utf8_length(const std::string& text, std::size_t at) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(at);
  std::size_t length = 0;
  unsigned int code_point = 0;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
    code_point = lead & 0x1Fu;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    code_point = lead & 0x0Fu;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    code_point = lead & 0x07u;
  } else {
    return 0;
  }
  if (at + length > text.size()) return 0;
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(at + i) & 0xC0u) != 0x80u) return 0;
    code_point = (code_point << 6) | (byte(at + i) & 0x3Fu);
  }
  // overlong forms, surrogates, beyond U+10FFFF and the C1 controls are not printed as such
  const unsigned int smallest[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (code_point < smallest[length] || code_point < 0xA0 ||
      (code_point >= 0xD800 && code_point <= 0xDFFF) || code_point > 0x10FFFF)
    return 0;
  return length;
}

}  // namespace

std::size_t first_non_text_byte(const std::string& text) {
  std::size_t at = 0;
  while (at < text.size()) {
    const auto byte = static_cast<unsigned char>(text[at]);
    if ((byte >= 0x20 && byte < 0x7F) || byte == '\t' || byte == '\n' || byte == '\r') {
      ++at;
    } else if (const std::size_t length = printable_utf8_length(text, at); length > 0) {
      at += length;
    } else {
      return at;
    }
  }
  return std::string::npos;
}

namespace {

// the character of `text` at `at` appended to `out` as it is (printable ASCII, well-formed
// UTF-8 of a printable code point, and a tab or line feed when `line_breaks`) or as \xNN for
// one byte; returns the offset after it
std::size_t append_shown_char(std::string& out, const std::string& text, std::size_t at,
                              bool line_breaks) {
  static const char* kHex = "0123456789ABCDEF";
  const auto byte = static_cast<unsigned char>(text[at]);
  if ((byte >= 0x20 && byte < 0x7F) || (line_breaks && (byte == '\t' || byte == '\n'))) {
    out += text[at];
    return at + 1;
  }
  if (const std::size_t length = printable_utf8_length(text, at); length > 0) {
    out.append(text, at, length);
    return at + length;
  }
  out += "\\x";
  out += kHex[byte >> 4];
  out += kHex[byte & 15];
  return at + 1;
}

}  // namespace

std::string printable_text(const std::string& text, std::size_t max_chars) {
  std::string out;
  std::size_t at = 0;
  for (std::size_t chars = 0; at < text.size() && chars < max_chars; ++chars)
    at = append_shown_char(out, text, at, false);
  if (at < text.size()) out += "...";
  return out;
}

std::string terminal_text(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) at = append_shown_char(out, text, at, true);
  return out;
}

}  // namespace depotwin
