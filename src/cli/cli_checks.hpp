// Checks of command-line values shared by the verbs' option tables.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include "core/number_text.hpp"

namespace depotwin {

// a finite number above 0 (CLI11's PositiveNumber would print its range as a 300-digit number,
// and let inf through)
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(value) || value <= 0.0)
          return "expected a number above 0, got '" + printable_text(text) + "'";
        return "";
      },
      "POSITIVE");
}

// a finite number in [lo, hi] (a value far outside it would write inf or 0 into a file)
inline CLI::Validator number_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const std::optional<double> value = parse_double(text);
        if (!value || !std::isfinite(*value) || *value < lo || *value > hi)
          return "expected a number in [" + message_number(lo) + ", " + message_number(hi) +
                 "], got '" + printable_text(text) + "'";
        return "";
      },
      "[" + message_number(lo) + ", " + message_number(hi) + "]");
}

}  // namespace depotwin
