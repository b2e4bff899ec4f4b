// One contract test over every registered planner (OMPL's PlannerTest, toppra's typed suites).
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "planners/planner.hpp"
#include "planner_checks.hpp"

namespace depotwin {
namespace {

class PlannerContract : public ::testing::TestWithParam<std::string> {};

TEST_P(PlannerContract, SeededRandomToolpaths) {
  const PlannerSpec spec{GetParam(), {}, 0};
  const auto planner = make_planner(spec);
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    const Toolpath toolpath = testing_support::random_toolpath(seed, 3.0);
    const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
    testing_support::expect_contract(planner->plan(toolpath, limits), toolpath, limits);
    if (HasFatalFailure()) return;
  }
}

TEST_P(PlannerContract, DeterministicPlans) {
  const auto planner = make_planner(PlannerSpec{GetParam(), {}, 0});
  const Toolpath toolpath = testing_support::random_toolpath(99, 2.0);
  const MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  const Trajectory a = planner->plan(toolpath, limits), b = planner->plan(toolpath, limits);
  ASSERT_EQ(a.duration_s(), b.duration_s());
  for (double t = 0; t < a.duration_s(); t += 0.01)
    ASSERT_EQ(a.at(t).position_mm, b.at(t).position_mm);
}

std::vector<std::string> registered_names() {
  std::vector<std::string> names;
  for (const PlannerInfo& info : planner_registry()) names.push_back(info.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(EveryPlanner, PlannerContract, ::testing::ValuesIn(registered_names()),
                         [](const auto& info) { return info.param; });

TEST(PlannerRegistry, UnknownNamesAndParametersAreRejected) {
  EXPECT_NE(check_planner_spec({"warp_drive", {}, 0}).find("unknown planner"), std::string::npos);
  EXPECT_NE(check_planner_spec({"lspb_mtt", {{"delta", {0.3}}}, 0}).find("no parameter 'delta'"),
            std::string::npos);
  EXPECT_EQ(check_planner_spec({"lspb_mtt", {}, 0}), "");
  EXPECT_THROW(make_planner({"warp_drive", {}, 0}), InputError);
}

}  // namespace
}  // namespace depotwin
