// The step loop's fast paths give what the plain ones gave: the trajectory cursor samples
// exactly as Trajectory::at; subnormals are flushed only inside the physics, never in the
// caller's code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "kinematics/xy_stage.hpp"
#include "sim/mujoco_boundary.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace depotwin {
namespace {

using testing_util::straight_print;
using testing_util::xy_stage_model;

void expect_same_sample(const TrajectorySample& expected, const TrajectorySample& actual) {
  EXPECT_EQ(expected.t_s, actual.t_s);
  EXPECT_EQ(expected.position_mm, actual.position_mm);
  EXPECT_EQ(expected.velocity_mm_s, actual.velocity_mm_s);
  EXPECT_EQ(expected.acceleration_mm_s2, actual.acceleration_mm_s2);
  EXPECT_EQ(expected.depositing, actual.depositing);
  EXPECT_EQ(expected.path_index, actual.path_index);
  EXPECT_EQ(expected.piece_index, actual.piece_index);
  EXPECT_EQ(expected.desired_speed_mm_s, actual.desired_speed_mm_s);
}

TEST(TrajectoryCursor, SamplesBitForBitAsTrajectoryAt) {
  const auto print =
      straight_print(Vec3(0, 0, 0), Vec3(1, 2, 0), 3.0, 2.0, MachineLimits::uniform(4, 30));
  const Trajectory& trajectory = print.trajectory;
  ASSERT_EQ(trajectory.pieces().size(), 3u);
  // the transitions accelerate then cruise or brake: several phases per axis
  const auto& first = std::get<PhaseMotion>(trajectory.pieces().front().motion);
  ASSERT_GE(first.axes[0].phases().size(), 2u);
  // the simulation's steps past the end, every piece boundary exactly, then times that go back
  std::vector<double> times;
  for (int k = 0; k * 1e-3 < trajectory.duration_s() + 0.05; ++k) times.push_back(k * 1e-3);
  for (const TrajectoryPiece& piece : trajectory.pieces()) {
    times.push_back(std::nextafter(piece.t_begin_s, -1.0));
    times.push_back(piece.t_begin_s);
    times.push_back(piece.t_end_s);
  }
  // forwards then backwards inside each piece (every phase of its axes)
  for (const TrajectoryPiece& piece : trajectory.pieces())
    for (double fraction : {0.1, 0.35, 0.6, 0.9, 0.5, 0.05})
      times.push_back(piece.t_begin_s + fraction * (piece.t_end_s - piece.t_begin_s));
  times.push_back(0.0);
  times.push_back(-1.0);
  times.push_back(0.5 * trajectory.duration_s());
  times.push_back(std::numeric_limits<double>::quiet_NaN());
  TrajectoryCursor cursor(trajectory);
  for (double t : times) {
    SCOPED_TRACE(t);
    const TrajectorySample expected = trajectory.at(t);
    const TrajectorySample actual = cursor.at(t);
    if (std::isnan(t)) {
      EXPECT_EQ(expected.piece_index, actual.piece_index);
      continue;
    }
    expect_same_sample(expected, actual);
  }
}

#if defined(__SSE2__)
TEST(FlushSubnormalsScope, FlushesInsideAndRestoresTheCallersMode) {
  volatile double tiny = 1e-300;  // volatile: computed at run time, under the current mode
  const auto product = [&]() { return tiny * 1e-10; };
  ASSERT_EQ(std::fpclassify(product()), FP_SUBNORMAL);
  {
    FlushSubnormalsScope flush;
    EXPECT_EQ(product(), 0.0);
    flush.suspend();
    EXPECT_EQ(std::fpclassify(product()), FP_SUBNORMAL);
    flush.resume();
    EXPECT_EQ(product(), 0.0);
  }
  EXPECT_EQ(std::fpclassify(product()), FP_SUBNORMAL);
}
#endif

// the physics runs with subnormals flushed; on_step and progress run in the caller's mode
TEST(StepLoop, CallbacksRunInTheCallersFloatingPointMode) {
  const auto machine = make_xy_stage();
  const auto print =
      straight_print(Vec3(0, 0, 0), Vec3(1, 0, 0), 3.0, 1.0, MachineLimits::uniform(4, 30));
  Simulation simulation(xy_stage_model(), *machine);
  volatile double tiny = 1e-300;
  const auto keeps_subnormals = [&]() { return std::fpclassify(tiny * 1e-10) == FP_SUBNORMAL; };
  ASSERT_TRUE(keeps_subnormals());
  long steps_seen = 0, steps_flushed = 0, progress_flushed = 0;
  simulation.run(
      print.trajectory,
      [&](const StepState&, const StepState&) {
        ++steps_seen;
        if (!keeps_subnormals()) ++steps_flushed;
      },
      [&](double) {
        if (!keeps_subnormals()) ++progress_flushed;
      });
  EXPECT_GT(steps_seen, 500);
  EXPECT_EQ(steps_flushed, 0);
  EXPECT_EQ(progress_flushed, 0);
  EXPECT_TRUE(keeps_subnormals()) << "run() must give the caller's mode back";
}

}  // namespace
}  // namespace depotwin
