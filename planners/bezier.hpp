// Giberti, Sbaglia & Urgo 2017 (papers/001): straight lines joined by quadratic (rational)
// Bezier blends with fillet distance delta, traversed at constant speed by a 2nd-order
// Taylor update of the curve parameter.
#pragma once

#include <memory>
#include <vector>

#include "planners/planner.hpp"

namespace depotwin {

std::vector<PlannerParameter> bezier_parameters();
std::unique_ptr<Planner> make_bezier_planner(const PlannerSpec& spec);

}  // namespace depotwin
