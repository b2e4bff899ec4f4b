// The character classes the G-code readers (gcode.cpp, slicer_notes.cpp) read text by: ASCII
// only, independent of the C locale (<cctype> would follow it). A line's spaces are blanks,
// tabs and a CR left by a CR LF line end.
#pragma once

namespace depotwin::ascii {

inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}
inline bool is_digit(char c) {
  return c >= '0' && c <= '9';
}
inline bool is_letter(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}
inline char upper(char c) {
  return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
}
inline char lower(char c) {
  return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
}

}  // namespace depotwin::ascii
