// The print-ordering experiment of Ganganath et al. (papers/004, Sec. IV, Table I):
// random instances (toolpath/random_segments.hpp), every sequencer and refinement on each, and
// the averages of path length, operation time and the gap to the matching lower bound.
// bench/ordering_table.cpp prints it beside the paper's table; tests run a small one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/limits.hpp"
#include "planners/ordering/sequencer.hpp"
#include "toolpath/random_segments.hpp"

namespace depotwin {

struct ExperimentConfig {
  std::vector<int> sizes{5, 20, 100};  // N, print segments per instance
  int instances = 100;                 // per N
  // Sec. IV-A: 100 x 100 mm bed, lengths in [10, 40] mm, print at 3 mm/s, v_max 4 mm/s,
  // a_max 30 mm/s^2, the paper's along-line transition model
  RandomSegmentsSpec instance;
  MachineLimits limits = MachineLimits::uniform(4.0, 30.0);
  std::string cost_model = "along_line";
  std::vector<OrderSpec> methods = paper_methods();

  // the nine rows of Table I: random, nearest neighbour, Christofides, each alone and
  // followed by 2-opt and 3-opt
  static std::vector<OrderSpec> paper_methods();
};

struct MethodAverages {
  OrderSpec method;
  double path_length_mm = 0.0;  // printed length + straight-line transition length
  double time_s = 0.0;          // print time + transition times ("operation time")
  double gap = 0.0;             // mean of (time - lower bound) / lower bound
  double max_gap = 0.0;
  double below_bound = 0.0;  // largest amount (s) by which a time fell below the bound; 0 if never
};

struct SizeAverages {
  int size = 0;
  double segment_length_mm = 0.0;  // mean print segment length
  double print_time_s = 0.0;       // mean print time alone
  double lower_bound_s = 0.0;      // mean lower bound (print time + exact matching)
  std::vector<MethodAverages> methods;
};

// Seeds: instance i (0-based) of size N uses seed 1000 * N + i + 1 for the instance and
// for the random sequencer.
std::vector<SizeAverages> run_ordering_experiment(const ExperimentConfig& config);

}  // namespace depotwin
