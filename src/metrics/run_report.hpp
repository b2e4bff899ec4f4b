// The simulated sections of metrics.json: pure functions of the recorded run, the toolpath
// and the deposit (docs/ARCHITECTURE.md, "Metrics").
#pragma once

#include <vector>

#include "core/limits.hpp"
#include "core/recorded_run.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"
#include "deposition/deposition_metrics.hpp"
#include "deposition/layered_deposit.hpp"
#include "metrics/metrics_report.hpp"
#include "metrics/motion_metrics.hpp"

namespace depotwin {

// the recorded nozzle as motion samples (the same shape as the plan's)
MotionSamples recorded_motion(const RecordedRun& record);
// the plan at the given times
MotionSamples trajectory_motion_at(const Trajectory& trajectory, const std::vector<double>& times);

// Per joint: the peaks of velocity, acceleration and force against the joint's limits and
// actuator force range (0: none), and the simulated acceleration peak against the plan's own
// (RecordedRun::reference_peak_acceleration). Prismatic joints in mm/s, mm/s^2 and N;
// revolute ones (JointLimit::revolute) in deg/s, deg/s^2 and N m (the record's rad converted).
ActuatorStats actuator_stats(const RecordedRun& record, const std::vector<JointLimit>& limits,
                             const std::vector<double>& force_limits);

// One line per joint and quantity whose simulated peak exceeds its limit (speed, acceleration,
// actuator force), for metrics.json's warnings: "joint y: peak speed 733 mm/s above its
// limit 200 mm/s in the simulation"
std::vector<std::string> actuator_limit_warnings(const ActuatorStats& stats);

// fewer target cells or centreline samples than score a deposit's evenness
inline constexpr size_t kFewestScoredCells = 10;
inline constexpr size_t kFewestScoredSamples = 3;
// The warning for metrics.json when the thickness scores rest on fewer cells or samples than
// that ("" when they do not): a run of paths shorter than the line is wide reads cv 0
std::string thickness_coverage_warning(const ThicknessStats& stats);

// An arm's collisions for metrics.json's warnings ("" without any): the contact events by kind
// (ArmStats) and the first MuJoCo contact (its time and the two geoms) where one was recorded
std::string arm_collision_warning(const ArmStats& arm, const ContactLog& contacts);

// Adds to a planned report (plan_job's) what the simulation scored: the simulated velocity
// error (whole and steady: outside the plan's ramps, report.speed_ramps) and path error,
// thickness, material and waste from the deposit, and the simulation's own statistics.
void add_simulated_metrics(MetricsReport& report, const RecordedRun& record,
                           const MotionSamples& simulated, const Toolpath& toolpath,
                           const DepositionMetrics& deposited);

// The samples with material off wherever another layer's path is printed (path_index names a
// path of `toolpath`)
MotionSamples only_layer(const MotionSamples& samples, const Toolpath& toolpath, int layer);

// Every layer's metrics: its paths, the planned and simulated velocity and path error over the
// samples printing it, its own deposit's thickness (along the normal) and material. `planned`
// is the plan's samples; `simulated` may be empty (a plan only: no deposit either).
std::vector<LayerReport> layer_reports(const Toolpath& toolpath, const MotionSamples& planned,
                                       const MotionSamples& simulated,
                                       const LayeredDeposit& deposit);

}  // namespace depotwin
