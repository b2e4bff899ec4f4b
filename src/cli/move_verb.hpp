// `depotwin move`: the synchronised minimum-time move of one to six axes, as JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace depotwin {

struct MoveRequest {
  std::vector<double> q0, q1, v0, v1, v_max, a_max, j_max;  // comma lists; one value = every axis
};

// Throws InputError naming the option for bad lists, limits or boundary velocities.
nlohmann::ordered_json minimum_time_move_json(const MoveRequest& request);

// "1,2.5,-3" -> {1, 2.5, -3}; InputError naming `option` for anything that is not a number
std::vector<double> parse_number_list(const std::string& text, const std::string& option);

}  // namespace depotwin
