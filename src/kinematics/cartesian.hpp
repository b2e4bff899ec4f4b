// A cartesian (XYZ gantry) printer, Klipper's `cartesian` kinematics: the print head rides an
// X carriage on a Y gantry, and the bed drops in Z as the layers rise. Each joint moves the
// TCP along one axis, so the map is the identity within the travel: joints (x, y, z) = tcp.
// Travel: x and y in [-100, 100] mm around the bed's centre (200 x 200 mm), z in [-10, 150] mm
// (the bed may rise 10 mm past the nozzle tip, as for probing and z-offset calibration).
#pragma once

#include <memory>

#include "kinematics/machine.hpp"

namespace depotwin {

std::unique_ptr<Machine> make_cartesian();

}  // namespace depotwin
