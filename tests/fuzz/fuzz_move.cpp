// Fuzz target: `depotwin move`'s arguments (cli/move_verb.hpp) as main.cpp handles them. The
// input is up to seven lines, the option values in order: --q0, --q1, --v0, --v1, --vmax,
// --amax, --jmax (a missing line is an option not given: --v0 and --v1 then default to 0, --jmax
// to none; --q0, --q1, --vmax and --amax are required, so missing means given empty). Bad
// input must be an InputError; a move computed must be all finite numbers, with a duration no
// shorter than any axis's own minimum.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "cli/move_verb.hpp"
#include "core/error.hpp"
#include "fuzz/fuzz_check.hpp"

namespace {

using depotwin::fuzz::is_finite;
using depotwin::fuzz::require;

// every number in the JSON is finite (nlohmann writes NaN and inf as null)
void require_finite(const nlohmann::ordered_json& json) {
  if (json.is_number_float()) require(is_finite(json.get<double>()), "finite numbers in the JSON");
  if (json.is_structured())
    for (const auto& item : json) require_finite(item);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> values;
  std::stringstream text(std::string(reinterpret_cast<const char*>(data), size));
  for (std::string line; values.size() < 7 && std::getline(text, line);) values.push_back(line);
  values.resize(7, "");
  const bool v0_given = !values[2].empty(), v1_given = !values[3].empty();
  const bool jmax_given = !values[6].empty();
  try {
    depotwin::MoveRequest request;
    request.q0 = depotwin::parse_number_list(values[0], "--q0");
    request.q1 = depotwin::parse_number_list(values[1], "--q1");
    request.v0 = depotwin::parse_number_list(v0_given ? values[2] : "0", "--v0");
    request.v1 = depotwin::parse_number_list(v1_given ? values[3] : "0", "--v1");
    request.v_max = depotwin::parse_number_list(values[4], "--vmax");
    request.a_max = depotwin::parse_number_list(values[5], "--amax");
    if (jmax_given) request.j_max = depotwin::parse_number_list(values[6], "--jmax");
    const nlohmann::ordered_json move = depotwin::minimum_time_move_json(request);
    require_finite(move);
    (void)move.dump(2);
    const double duration_s = move.at("duration_s").get<double>();
    require(duration_s >= 0.0, "a duration >= 0");
    for (const auto& axis : move.at("axes"))
      require(duration_s >= axis.at("min_duration_s").get<double>() * (1.0 - 1e-9),
              "no axis faster than its own minimum time");
  } catch (const depotwin::InputError&) {
    // rejected with a message: expected
  }
  return 0;
}
