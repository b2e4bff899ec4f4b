// Numbers written to data files (core/number_text.hpp): append_number and append_fixed give
// the text printf's "%.<n>g" and "%.<n>f" give, character for character, on the values a
// trajectory or a thickness map holds and on the edge cases of both formats.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/number_text.hpp"

namespace depotwin {
namespace {

std::string printf_text(const char* format, int precision, double value) {
  char text[400];
  std::snprintf(text, sizeof text, format, precision, value);
  return text;
}

std::vector<double> edge_values() {
  const double inf = std::numeric_limits<double>::infinity();
  return {0.0,
          -0.0,
          1.0,
          -1.0,
          0.5,
          2.5,
          1e-5,
          1e-4,
          9.9999999e-5,
          123456789.0,
          1234567890.0,
          999999999.5,
          0.1 + 0.2,
          1e300,
          -1e-300,
          4.9e-324,
          std::numeric_limits<double>::max(),
          1e9,
          1e-9,
          3.0000005,
          0.0000015,
          2.675,
          inf,
          -inf,
          std::nan("")};
}

// a value just outside a bound never reads as the bound: digits are added until it differs
TEST(NumberText, AValueBesideItsBoundReadsDifferently) {
  EXPECT_EQ(message_number_beside(1000005.0, 1e6), "1000005");
  EXPECT_EQ(message_number_beside(50.0001, 50.0, 4), "50.0001");
  EXPECT_EQ(message_number_beside(-50.00002, -50.0, 4), "-50.00002");
  EXPECT_EQ(message_number_beside(55.00001, 55.0, 4), "55.00001");
  // outside a range: beside the end it passes
  EXPECT_EQ(message_number_outside(-1000005.0, -1e6, 1e6), "-1000005");
  EXPECT_EQ(message_number_outside(50.0001, -50.0, 50.0, 4), "50.0001");
  // far from the bound, or equal to it: as message_number writes it
  EXPECT_EQ(message_number_beside(1.5e6, 1e6), message_number(1.5e6));
  EXPECT_EQ(message_number_beside(1e6, 1e6), "1e+06");
  // doubles that differ in the 17th digit only: 17 digits, never more
  const double next = std::nextafter(1.0, 2.0);
  EXPECT_EQ(message_number_beside(next, 1.0), "1.0000000000000002");
}

TEST(NumberText, AppendNumberIsPrintfsG) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 12);
  std::vector<double> values = edge_values();
  for (int i = 0; i < 20000; ++i)
    values.push_back(mantissa(random) * std::pow(10.0, exponent(random)));
  for (const int digits : {1, 6, 7, 9, 17}) {
    for (const double value : values) {
      std::string text = "x";
      append_number(text, value, digits);
      ASSERT_EQ(text, "x" + printf_text("%.*g", digits, value)) << digits << " digits";
    }
  }
}

TEST(NumberText, AppendFixedIsPrintfsF) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> seconds(0.0, 1e5);
  std::vector<double> values = edge_values();
  // the 1 ms sample times of a long job, whose last digits round both ways
  for (int k = 0; k < 20000; ++k) values.push_back(k * 0.001);
  for (int i = 0; i < 20000; ++i) values.push_back(seconds(random));
  for (const int decimals : {0, 3, 6, 17}) {
    for (const double value : values) {
      std::string text;
      append_fixed(text, value, decimals);
      ASSERT_EQ(text, printf_text("%.*f", decimals, value)) << decimals << " decimals";
    }
  }
}

// a message for the terminal keeps its lines, tabs and UTF-8, and writes every byte a
// terminal would act on (escape sequences, CR, NUL, broken UTF-8) as \xNN
TEST(NumberText, TerminalTextDisarmsControlBytes) {
  EXPECT_EQ(terminal_text("plain: a/b.yaml\n\tnext line"), "plain: a/b.yaml\n\tnext line");
  EXPECT_EQ(terminal_text("d\xC3\xA9p\xC3\xB4t \xE2\x80\x94 \xF0\x9F\x99\x82"),
            "d\xC3\xA9p\xC3\xB4t \xE2\x80\x94 \xF0\x9F\x99\x82");
  EXPECT_EQ(terminal_text("a\x1B[31mred\x1B[0m"), "a\\x1B[31mred\\x1B[0m");
  EXPECT_EQ(terminal_text(std::string("over\rwrite\0end", 14)), "over\\x0Dwrite\\x00end");
  // a Latin-1 byte, a C1 control in UTF-8 (U+009B, the one-byte CSI) and a DEL
  EXPECT_EQ(terminal_text("caf\xE9 \xC2\x9B"
                          "2J \x7F"),
            "caf\\xE9 \\xC2\\x9B2J \\x7F");
  // already-escaped text is left as it is: escaping twice changes nothing
  const std::string once = terminal_text("x\x1By\rz");
  EXPECT_EQ(terminal_text(once), once);
}

}  // namespace
}  // namespace depotwin
