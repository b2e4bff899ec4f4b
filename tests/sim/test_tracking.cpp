// The XY stage in MuJoCo following hand-built trajectories: speed and position tracking on a
// straight print, servo lag without feed-forward against its closed form, the nozzle read
// from MuJoCo against the kinematics, and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kinematics/xy_stage.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace depotwin {
namespace {

using testing_util::straight_print;
using testing_util::xy_stage_model;

// Thompson & Yoon's limits and print speed (papers/000, Fig. 7): 4 mm/s, 30 mm/s^2, 3 mm/s
const MachineLimits kPaperLimits = MachineLimits::uniform(4.0, 30.0);
constexpr double kPrintSpeed_mm_s = 3.0;

// Settling interval after the print starts. The feed-forward uses the model's own inertia,
// damping and servo gains, so what is left when the acceleration ends is the bearing
// friction (joint frictionloss 0.5 N, not compensated; in MuJoCo a soft constraint with a
// 20 ms time constant) still building up, which the PD loop (double pole at about 165 rad/s,
// 6 ms) takes up. Measured: 0.69 % speed error at the print start, under 0.5 % after 6 ms,
// 0.03 % after 30 ms. The first 30 ms (0.09 mm of a 10 mm line at 3 mm/s) are excluded.
constexpr double kSettle_s = 0.030;

struct TrackingFigures {
  double max_speed_error_rel = 0.0;
  double max_position_error_mm = 0.0;
  double rms_position_error_mm = 0.0;
};

TrackingFigures tracking_over_print(const RecordedRun& run, const Trajectory& trajectory,
                                    double from_s, double to_s) {
  TrackingFigures figures;
  double sum_squares = 0.0;
  long count = 0;
  for (size_t k = 0; k < run.size(); ++k) {
    const double t = run.t_s[k];
    if (t < from_s || t > to_s) continue;
    const TrajectorySample planned = trajectory.at(t);
    const double speed = run.nozzle_velocity_mm_s[k].norm();
    figures.max_speed_error_rel = std::max(figures.max_speed_error_rel,
                                           std::abs(speed - kPrintSpeed_mm_s) / kPrintSpeed_mm_s);
    const double error = (run.nozzle_mm[k] - planned.position_mm).norm();
    figures.max_position_error_mm = std::max(figures.max_position_error_mm, error);
    sum_squares += error * error;
    ++count;
  }
  figures.rms_position_error_mm = std::sqrt(sum_squares / std::max(1L, count));
  return figures;
}

TEST(Tracking, StraightDiagonalPrintHoldsTheSpeedWithinHalfAPercent) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(-5, -4, 0), Vec3(3, 4, 0), kPrintSpeed_mm_s, 10.0, kPaperLimits);
  Simulation simulation(xy_stage_model(), *machine, SimSettings{});
  const RecordedRun run = simulation.run(print.trajectory);

  const TrackingFigures settled = tracking_over_print(
      run, print.trajectory, print.print_begin_s + kSettle_s, print.print_end_s);
  const TrackingFigures whole =
      tracking_over_print(run, print.trajectory, print.print_begin_s, print.print_end_s);
  std::printf(
      "straight print 10 mm at 3 mm/s: after %.0f ms settling max speed error %.4f %%, "
      "max position error %.5f mm (rms %.5f mm); from the print start max speed error %.3f %%\n",
      kSettle_s * 1e3, 100 * settled.max_speed_error_rel, settled.max_position_error_mm,
      settled.rms_position_error_mm, 100 * whole.max_speed_error_rel);
  RecordProperty("max_speed_error_pct", std::to_string(100 * settled.max_speed_error_rel));
  RecordProperty("max_position_error_mm", std::to_string(settled.max_position_error_mm));
  EXPECT_LT(settled.max_speed_error_rel, 0.005);
  // a few micrometres: the friction lag 0.5 N / kp (3.3 um on x, 7 um on y)
  EXPECT_LT(settled.max_position_error_mm, 0.01);
  // the whole run ends at rest on the last point
  EXPECT_NEAR((run.nozzle_mm.back() - print.trajectory.at(1e9).position_mm).norm(), 0.0, 0.01);
}

TEST(Tracking, WithoutFeedForwardTheServoLagsByTheClosedForm) {
  // plain PD on the reference: at constant velocity v the carriage trails by
  // e = ((damping + kv) v + friction) / kp (models/xy_stage.xml: x axis
  // damping 20, kv 1800, kp 1.5e5 N/m, frictionloss 0.5 N)
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(-10, 0, 0), Vec3(1, 0, 0), kPrintSpeed_mm_s, 6.0, kPaperLimits);
  SimSettings settings;
  settings.feedforward = false;
  Simulation simulation(xy_stage_model(), *machine, settings);
  const RecordedRun run = simulation.run(print.trajectory);
  const double velocity_m_s = kPrintSpeed_mm_s / 1000.0;
  const double expected_lag_mm = ((20.0 + 1800.0) * velocity_m_s + 0.5) / 1.5e5 * 1000.0;
  // sample in the middle of the print, long after the start transient
  const double t = 0.5 * (print.print_begin_s + print.print_end_s);
  const size_t k = static_cast<size_t>(std::lround(t / run.timestep_s));
  const double lag_mm = run.nozzle_mm[k].x() - print.trajectory.at(run.t_s[k]).position_mm.x();
  std::printf("lag without feed-forward: %.5f mm (closed form %.5f mm)\n", lag_mm, expected_lag_mm);
  // the plate lags behind, so the nozzle (= -plate) is behind the TCP reference
  EXPECT_NEAR(-lag_mm, expected_lag_mm, 0.02 * expected_lag_mm);
  // with feed-forward the same print is an order of magnitude closer
  Simulation with_feedforward(xy_stage_model(), *machine, SimSettings{});
  const RecordedRun better = with_feedforward.run(print.trajectory);
  const double better_lag_mm =
      better.nozzle_mm[k].x() - print.trajectory.at(better.t_s[k]).position_mm.x();
  EXPECT_LT(std::abs(better_lag_mm), 0.1 * expected_lag_mm);
}

TEST(Tracking, KpScaleStiffensTheServoWithTheSameDampingRatio) {
  // kp_scale s multiplies kp by s and kv by sqrt(s): lag ((b + sqrt(s) kv) v + f) / (s kp)
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(-10, 0, 0), Vec3(1, 0, 0), kPrintSpeed_mm_s, 6.0, kPaperLimits);
  SimSettings settings;
  settings.feedforward = false;
  settings.kp_scale = 4.0;
  Simulation simulation(xy_stage_model(), *machine, settings);
  const RecordedRun run = simulation.run(print.trajectory);
  const double velocity_m_s = kPrintSpeed_mm_s / 1000.0;
  const double expected_lag_mm =
      ((20.0 + 2.0 * 1800.0) * velocity_m_s + 0.5) / (4.0 * 1.5e5) * 1000.0;
  const double t = 0.5 * (print.print_begin_s + print.print_end_s);
  const size_t k = static_cast<size_t>(std::lround(t / run.timestep_s));
  const double lag_mm = print.trajectory.at(run.t_s[k]).position_mm.x() - run.nozzle_mm[k].x();
  EXPECT_NEAR(lag_mm, expected_lag_mm, 0.02 * expected_lag_mm);
}

TEST(Tracking, FeedForwardHookAddsItsForce) {
  // a constant extra 15 N on joint x shifts the carriage by 15 N / kp = 0.1 mm on the
  // constant-speed part (the PD loop balances it)
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(-10, 0, 0), Vec3(1, 0, 0), kPrintSpeed_mm_s, 6.0, kPaperLimits);
  Simulation plain(xy_stage_model(), *machine);
  const RecordedRun reference_run = plain.run(print.trajectory);
  Simulation hooked(xy_stage_model(), *machine);
  long calls = 0;
  double worst_reference_mismatch_mm = 0.0;
  hooked.set_feedforward_hook([&](const JointReference& reference, double* force) {
    ASSERT_EQ(reference.count, 2);
    // the references are the machine's inverse of the plan, in metres
    JointVector joints;
    machine->inverse(print.trajectory.at(reference.t_s).position_mm, joints);
    worst_reference_mismatch_mm =
        std::max(worst_reference_mismatch_mm, std::abs(reference.position[0] * 1000 - joints[0]));
    force[0] += 15.0;
    ++calls;
  });
  const RecordedRun run = hooked.run(print.trajectory);
  EXPECT_EQ(calls, run.steps + 1);  // one controller update per step at the default 1 kHz
  EXPECT_LT(worst_reference_mismatch_mm, 1e-9);
  const size_t k = static_cast<size_t>(
      std::lround(0.5 * (print.print_begin_s + print.print_end_s) / run.timestep_s));
  const double shift_mm =
      run.joint(run.joint_position, k, 0) - reference_run.joint(reference_run.joint_position, k, 0);
  EXPECT_NEAR(shift_mm, 15.0 / 1.5e5 * 1000.0, 1e-3);
}

TEST(Tracking, NozzleFromMujocoMatchesTheKinematicsOfTheSimulatedJoints) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(8, -2, 0), Vec3(-1, 2, 0), kPrintSpeed_mm_s, 5.0, kPaperLimits);
  Simulation simulation(xy_stage_model(), *machine, SimSettings{});
  const RecordedRun run = simulation.run(print.trajectory);
  ASSERT_EQ(run.joint_count, 2);
  ASSERT_EQ(run.joint_names, (std::vector<std::string>{"x", "y"}));
  ASSERT_EQ(run.size(), static_cast<size_t>(run.steps) + 1);
  EXPECT_EQ(run.joint_position.size(), run.size() * 2);
  double worst_position = 0.0, worst_velocity = 0.0;
  for (size_t k = 0; k < run.size(); k += 7) {
    const JointVector joints = {run.joint(run.joint_position, k, 0),
                                run.joint(run.joint_position, k, 1)};
    worst_position =
        std::max(worst_position, (machine->forward(joints).position_mm - run.nozzle_mm[k]).norm());
    // the nozzle moves opposite to the carriages
    const Vec3 expected_velocity(-run.joint(run.joint_velocity, k, 0),
                                 -run.joint(run.joint_velocity, k, 1), 0.0);
    worst_velocity =
        std::max(worst_velocity, (expected_velocity - run.nozzle_velocity_mm_s[k]).norm());
  }
  EXPECT_LT(worst_position, 1e-9);
  EXPECT_LT(worst_velocity, 1e-9);
  // time stamps are k * dt; the initial state starts on the reference
  EXPECT_DOUBLE_EQ(run.t_s[0], 0.0);
  EXPECT_DOUBLE_EQ(run.t_s[1000], 1000 * run.timestep_s);
  EXPECT_NEAR((run.nozzle_mm[0] - Vec3(8, -2, 0)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(run.max_constraint_violation_mm, 0.0);
  // the drives' peak forces from the MJCF forcerange
  EXPECT_EQ(simulation.actuator_force_limits(), (std::vector<double>{300.0, 200.0}));
  // the run covers the trajectory
  EXPECT_GE(run.t_s.back(), print.trajectory.duration_s() - 1e-12);
  EXPECT_LT(run.t_s.back(), print.trajectory.duration_s() + run.timestep_s);
}

TEST(Tracking, ActuatorForceIsMassTimesAccelerationWhileAccelerating) {
  // during the first (constant acceleration) piece the x drive pushes the whole moving mass
  // (5.5 kg) plus damping and friction: F = m a + (b) v + f_c, mostly m a
  const auto machine = make_xy_stage();
  const MachineLimits brisk = MachineLimits::uniform(100.0, 1000.0);
  const auto print = straight_print(Vec3(-20, 0, 0), Vec3(1, 0, 0), 50.0, 10.0, brisk);
  Simulation simulation(xy_stage_model(), *machine, SimSettings{});
  const RecordedRun run = simulation.run(print.trajectory);
  // mid-ramp (carriage accelerates towards -x since the nozzle moves +x)
  const size_t k = static_cast<size_t>(std::lround(0.5 * print.print_begin_s / run.timestep_s));
  const double acceleration_m_s2 = run.joint(run.joint_acceleration, k, 0) / 1000.0;
  const double force_N = run.joint(run.actuator_force, k, 0);
  EXPECT_NEAR(acceleration_m_s2, -1.0, 0.02);
  const double velocity_m_s = run.joint(run.joint_velocity, k, 0) / 1000.0;
  const double expected_N = 5.5 * -1.0 + 20.0 * velocity_m_s - 0.5;
  EXPECT_NEAR(force_N, expected_N, 0.1);
}

TEST(Tracking, TwoRunsGiveIdenticalRecords) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(0, 0, 0), Vec3(1, 1, 0), kPrintSpeed_mm_s, 3.0, kPaperLimits);
  SimSettings settings;
  settings.settle_s = 0.05;
  Simulation first(xy_stage_model(), *machine, settings);
  const RecordedRun a = first.run(print.trajectory);
  const RecordedRun b = first.run(print.trajectory);  // same object, reset in between
  Simulation second(xy_stage_model(), *machine, settings);
  const RecordedRun c = second.run(print.trajectory);
  for (const RecordedRun* other : {&b, &c}) {
    EXPECT_EQ(a.t_s, other->t_s);
    EXPECT_EQ(a.nozzle_mm, other->nozzle_mm);
    EXPECT_EQ(a.nozzle_velocity_mm_s, other->nozzle_velocity_mm_s);
    EXPECT_EQ(a.open_fraction, other->open_fraction);
    EXPECT_EQ(a.deposit_command, other->deposit_command);
    EXPECT_EQ(a.path_index, other->path_index);
    EXPECT_EQ(a.desired_speed_mm_s, other->desired_speed_mm_s);
    EXPECT_EQ(a.joint_position, other->joint_position);
    EXPECT_EQ(a.joint_velocity, other->joint_velocity);
    EXPECT_EQ(a.joint_acceleration, other->joint_acceleration);
    EXPECT_EQ(a.actuator_force, other->actuator_force);
    EXPECT_EQ(a.steps, other->steps);
  }
}

TEST(Tracking, CallbacksSeeEveryStepInOrder) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(0, 0, 0), Vec3(0, 1, 0), kPrintSpeed_mm_s, 1.0, kPaperLimits);
  SimSettings settings;
  settings.settle_s = 0.02;
  Simulation simulation(xy_stage_model(), *machine, settings);
  long calls = 0;
  bool ordered = true;
  double last_progress = -1.0;
  bool progress_monotonic = true;
  std::vector<StepState> afters;
  const RecordedRun run = simulation.run(
      print.trajectory,
      [&](const StepState& before, const StepState& after) {
        ordered = ordered && std::abs(after.t_s - before.t_s - 0.001) < 1e-12;
        afters.push_back(after);
        ++calls;
      },
      [&](double fraction) {
        progress_monotonic = progress_monotonic && fraction >= last_progress && fraction <= 1.0;
        last_progress = fraction;
      });
  EXPECT_EQ(calls, run.steps);
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(progress_monotonic);
  EXPECT_DOUBLE_EQ(last_progress, 1.0);
  // the states handed to on_step are the recorded ones
  ASSERT_EQ(afters.size() + 1, run.size());
  for (size_t k = 1; k < run.size(); k += 50) {
    EXPECT_EQ(afters[k - 1].nozzle_mm, run.nozzle_mm[k]);
    EXPECT_EQ(afters[k - 1].deposit_command, run.deposit_command[k] != 0);
    EXPECT_EQ(afters[k - 1].path_index, run.path_index[k]);
  }
  // settle_s extends the run past the trajectory with the shutter closed
  EXPECT_GE(run.t_s.back(), print.trajectory.duration_s() + 0.02 - 1e-9);
  EXPECT_EQ(run.deposit_command.back(), 0);
  EXPECT_EQ(run.path_index.back(), -1);
}

TEST(Tracking, SlowerControllerStillTracks) {
  // 2 kHz physics with a 1 kHz controller (ZOH over two steps)
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(0, 0, 0), Vec3(1, 0, 0), kPrintSpeed_mm_s, 3.0, kPaperLimits);
  SimSettings settings;
  settings.timestep_s = 0.0005;
  settings.control_period_s = 0.001;
  Simulation simulation(xy_stage_model(), *machine, settings);
  const RecordedRun run = simulation.run(print.trajectory);
  EXPECT_DOUBLE_EQ(run.timestep_s, 0.0005);
  const TrackingFigures figures = tracking_over_print(
      run, print.trajectory, print.print_begin_s + kSettle_s, print.print_end_s);
  EXPECT_LT(figures.max_speed_error_rel, 0.005);
  EXPECT_LT(figures.max_position_error_mm, 0.01);
}

}  // namespace
}  // namespace depotwin
