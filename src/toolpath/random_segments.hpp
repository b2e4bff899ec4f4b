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
  // false (default): each length is drawn once and only its placement is retried (a
  // midpoint uniform over the positions inside the bed), so the lengths stay uniform.
  // true: a segment is a uniform start point, direction and length, and any rejection
  // (leaving the bed, crossing another) redraws all three. Shorter segments survive
  // more often, so the mean length drops as the bed fills (about 23.5, 22.5, 18.8 mm at
  // N = 5, 20, 100): one reading of the paper that matches its implied segment lengths.
  bool redraw_length_on_reject = false;
};

// Throws InputError when the segments cannot be placed (e.g. longer than the bed).
Toolpath make_random_segments(const RandomSegmentsSpec& spec);

}  // namespace depotwin
