// The step loop allocates nothing (STYLE.md: no allocation in per-step loops): every
// operator new between the first and the last on_step call is counted.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "kinematics/xy_stage.hpp"
#include "sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// counting replacements of the global allocation functions (this test binary only)
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}

namespace depotwin {
namespace {

TEST(StepLoop, AllocatesNothingBetweenSteps) {
  const auto machine = make_xy_stage();
  const auto print = testing_util::straight_print(Vec3(0, 0, 0), Vec3(1, 2, 0), 3.0, 2.0,
                                                  MachineLimits::uniform(4, 30));
  Simulation simulation(testing_util::xy_stage_model(), *machine);
  long first = -1, last = -1, calls = 0;
  simulation.run(print.trajectory, [&](const StepState&, const StepState&) {
    const long now = g_allocations.load(std::memory_order_relaxed);
    if (calls == 0) first = now;
    last = now;
    ++calls;
  });
  ASSERT_GT(calls, 500);
  EXPECT_EQ(last - first, 0) << "allocations inside the step loop";
}

}  // namespace
}  // namespace depotwin
