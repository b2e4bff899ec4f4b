// Numbers in text files (scenarios, G-code): the whole text as a double, independent of the
// locale (std::from_chars), with an optional leading '+'.
#pragma once

#include <optional>
#include <string>

namespace depotwin {

// the whole text as a double (inf and nan included), or nothing
std::optional<double> parse_double(const std::string& text);

}  // namespace depotwin
