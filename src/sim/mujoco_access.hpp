// The MuJoCo state behind a Simulation, for the scene renderer, tests and benchmarks only:
// the one place outside sim/ that sees mjModel and mjData (simulation.hpp does not).
#pragma once

#include <mujoco/mujoco.h>

#include "sim/simulation.hpp"

namespace depotwin {

class SimulationAccess {
 public:
  // the MuJoCo model and its state after the last run (initial state before any)
  static const mjModel& model(const Simulation& simulation);
  static const mjData& data(const Simulation& simulation);
};

}  // namespace depotwin
