// Random print-ordering instances as Ganganath et al. (papers/004) describe them:
// N non-intersecting segments with lengths uniform in [min, max], uniform on the bed,
// start and end points uniform on the bed. Seeded: same seed, same instance.
#pragma once

#include <cstdint>

#include "core/toolpath.hpp"

namespace depotwin {

struct RandomSegmentsSpec {
  int count = 20;
  double bed_x_mm = 100.0, bed_y_mm = 100.0;
  double length_min_mm = 10.0, length_max_mm = 40.0;
  std::uint64_t seed = 1;
  double speed_mm_s = 3.0;
};

// Throws InputError when the segments cannot be placed (e.g. longer than the bed).
Toolpath make_random_segments(const RandomSegmentsSpec& spec);

}  // namespace depotwin
