// `depotwin move`: the synchronised minimum-time move of one to six axes, as JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace depotwin {

// Comma lists. q0 and q1 give one position per axis (1 to 6 axes, the same count in both:
// positions are never broadcast). v0, v1, v_max, a_max and j_max give one value per axis, or
// one value for every axis; j_max may be empty (no jerk limit), 0 on an axis is none too.
struct MoveRequest {
  std::vector<double> q0, q1, v0, v1, v_max, a_max, j_max;
};

// Throws InputError naming the options and their counts for mismatched lists, and the
// option for bad limits or boundary velocities: |q0|, |q1| at most 1e9; v_max, a_max and a
// non-zero j_max within [1e-6, 1e9]; |v0|, |v1| at most v_max.
nlohmann::ordered_json minimum_time_move_json(const MoveRequest& request);

// "1,2.5,-3" -> {1, 2.5, -3}; InputError naming `option` for anything that is not a number
std::vector<double> parse_number_list(const std::string& text, const std::string& option);

}  // namespace depotwin
