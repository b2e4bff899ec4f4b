// trajectory.csv: the plan sampled every 1 ms, and, after a simulation, the simulated
// nozzle beside it (same rows).
#pragma once

#include <string>

#include "metrics/motion_metrics.hpp"

namespace depotwin {

// columns: t, x, y, z, vx, vy, vz, speed, depositing, segment, desired_speed
std::string planned_trajectory_csv(const MotionSamples& planned);

// planned columns as above, then sim_x, sim_y, sim_z, sim_vx, sim_vy, sim_vz, sim_speed;
// `simulated` must have the same time stamps as `planned`
std::string planned_and_simulated_csv(const MotionSamples& planned, const MotionSamples& simulated);

}  // namespace depotwin
