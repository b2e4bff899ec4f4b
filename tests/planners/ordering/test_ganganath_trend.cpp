// A reduced Table I of Ganganath et al. (papers/004): 5 instances at N = 20 under the
// paper's along-line model. The paper's trend must hold on the averages, and no
// method may beat the lower bound on any instance.
#include <gtest/gtest.h>

#include <map>

#include "bench/ordering_experiment.hpp"

namespace depotwin {
namespace {

TEST(GanganathTable, TrendHoldsAndNothingBeatsTheBound) {
  ExperimentConfig config;
  config.sizes = {20};
  config.instances = 5;
  const std::vector<SizeAverages> table = run_ordering_experiment(config);
  ASSERT_EQ(table.size(), 1u);
  std::map<std::string, double> time_s;
  for (const MethodAverages& m : table[0].methods) {
    time_s[m.method.label()] = m.time_s;
    EXPECT_EQ(m.below_bound, 0.0) << m.method.label();
    EXPECT_GE(m.gap, 0.0) << m.method.label();
  }
  ASSERT_EQ(time_s.size(), 9u);
  // random >> nearest neighbour > Christofides > + 2-opt > + 3-opt (Sec. IV-B)
  EXPECT_GT(time_s["random"], 1.3 * time_s["nearest_neighbor"]);
  EXPECT_GT(time_s["nearest_neighbor"], time_s["christofides"]);
  EXPECT_GT(time_s["christofides"], time_s["christofides+two_opt"]);
  EXPECT_GE(time_s["christofides+two_opt"], time_s["christofides+three_opt"]);
  for (const char* method : {"random", "nearest_neighbor"}) {
    EXPECT_GT(time_s[method], time_s[std::string(method) + "+two_opt"]) << method;
    EXPECT_GE(time_s[std::string(method) + "+two_opt"], time_s[std::string(method) + "+three_opt"])
        << method;
  }
  // "random selection followed by 2-opt swap has achieved faster completion time
  // compared to nearest neighbor selection and Christofides algorithm" (N = 20, 100)
  EXPECT_LT(time_s["random+two_opt"], time_s["nearest_neighbor"]);
  // the averages sit above the mean lower bound, which sits above the print time
  EXPECT_GT(table[0].lower_bound_s, table[0].print_time_s);
  EXPECT_GT(time_s["christofides+three_opt"], table[0].lower_bound_s);
}

}  // namespace
}  // namespace depotwin
