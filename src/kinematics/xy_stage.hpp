// The XY aerosol stage of Thompson & Yoon (Fig. 1): the substrate rides on two stacked
// linear axes under a fixed nozzle, so the nozzle point in the substrate frame moves
// opposite to the carriages: tcp = nozzle_xy - (x_carriage, y_carriage).
#pragma once

#include <memory>

#include "kinematics/machine.hpp"

namespace depotwin {

std::unique_ptr<Machine> make_xy_stage();

}  // namespace depotwin
