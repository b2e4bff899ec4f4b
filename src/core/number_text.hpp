// Numbers and text in messages and text files: the whole text as a double, independent of the
// locale (std::from_chars), with an optional leading '+'; a number as a message prints it
// (%.6g, never hundreds of digits); numbers appended to a text file's rows as printf would
// write them, several times faster (std::to_chars); a user's text made safe to print on a
// terminal.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace depotwin {

// the whole text as a double (inf and nan included; beyond the doubles: +-inf, or 0 and the
// subnormals for tiny ones), or nothing
std::optional<double> parse_double(const std::string& text);

// a number as messages print it: at most 6 significant digits (%.6g: 3, 0.25, 1e-05, 1e+300),
// or as many as given (1 to 17; the machines' travel messages give 4)
std::string message_number(double value, int significant_digits = 6);

// `value` as message_number writes it, with as many more digits (up to 17) as it takes to
// read differently from `bound` when it differs: a value just outside a limit never reads as
// the limit ("1000005" beside 1e+06, "50.0001" beside 50, not "1e+06" or "50")
std::string message_number_beside(double value, double bound, int significant_digits = 6);
// the same beside whichever end of [min, max] a value outside it passes
std::string message_number_outside(double value, double min, double max,
                                   int significant_digits = 6);

// `value` appended to `out` as printf's "%.<digits>g" writes it in the C locale (std::to_chars
// with chars_format::general, which the standard defines so): for data files of millions of
// numbers (trajectory.csv, thickness.csv, plot data). digits: 1 to 17.
void append_number(std::string& out, double value, int significant_digits);
// the same for "%.<decimals>f" (decimals: 0 to 17)
void append_fixed(std::string& out, double value, int decimals);

// a user's text (a YAML value, a key, a G-code word) as messages echo it: printable ASCII and
// well-formed UTF-8 kept, every other byte (control bytes, escape sequences, broken UTF-8) as
// \xNN, cut after max_chars characters with "..."
std::string printable_text(const std::string& text, std::size_t max_chars = 40);

// the offset of the first byte of `text` that is not text (not printable ASCII, a tab, LF or
// CR, or well-formed UTF-8 of a printable code point: a NUL, another control byte, broken or
// Latin-1 bytes), or std::string::npos when there is none
std::size_t first_non_text_byte(const std::string& text);

// a message for the terminal: line breaks and tabs kept, printable ASCII and well-formed UTF-8
// kept, every other byte (an escape sequence, a carriage return, a NUL, broken UTF-8) as \xNN,
// so a file name or a word in an error cannot recolour the terminal or overwrite the line
std::string terminal_text(const std::string& text);

}  // namespace depotwin
