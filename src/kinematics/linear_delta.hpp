// Linear delta robot (Giberti et al., Fig. 8): three vertical carriages at 120 degrees,
// parallelogram rods to the platform. Analytic inverse kinematics, forward kinematics
// by trilateration.
#pragma once

#include <memory>

#include "kinematics/machine.hpp"

namespace depotwin {

std::unique_ptr<Machine> make_linear_delta();

}  // namespace depotwin
