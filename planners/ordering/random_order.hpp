// Random print order (Ganganath et al., papers/004, Sec. III-A, the reference they
// compare against): a seeded uniform permutation with uniform random directions.
#pragma once

#include <cstdint>

#include "planners/ordering/sequencer.hpp"

namespace depotwin {

OrderResult random_order(int path_count, std::uint64_t seed);

}  // namespace depotwin
