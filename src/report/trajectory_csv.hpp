// trajectory.csv: the plan sampled every 1 ms, and, after a simulation, the simulated
// nozzle beside it (same rows). Every column name ends in its unit: t_s (s), positions _mm
// (work frame), velocities _mm_s; `depositing` is 1 where material is commanded on, 0
// elsewhere; `path` is the print path being printed, 0-based in print order (the numbers on
// path.png and thickness_profile.png), and -1 in a transition (a travel between paths,
// nothing deposited); desired_speed_mm_s is that path's print speed (0 in transitions).
#pragma once

#include <string>

#include "metrics/motion_metrics.hpp"

namespace depotwin {

// the planned columns (the plan) and the simulated ones (the nozzle read back from MuJoCo)
constexpr const char* kPlannedColumns =
    "t_s,x_mm,y_mm,z_mm,vx_mm_s,vy_mm_s,vz_mm_s,speed_mm_s,depositing,path,desired_speed_mm_s";
constexpr const char* kSimulatedColumns =
    "sim_x_mm,sim_y_mm,sim_z_mm,sim_vx_mm_s,sim_vy_mm_s,sim_vz_mm_s,sim_speed_mm_s";

// the planned columns only
std::string planned_trajectory_csv(const MotionSamples& planned);

// the planned columns, then the simulated ones;
// `simulated` must have the same time stamps as `planned`
std::string planned_and_simulated_csv(const MotionSamples& planned, const MotionSamples& simulated);

}  // namespace depotwin
