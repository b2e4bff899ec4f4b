#include "planners/random_instances.hpp"

#include "core/error.hpp"

namespace depotwin {

// TODO(issue 6): the generator
Toolpath make_random_segments(const RandomSegmentsSpec&) {
  throw InputError("toolpath.random_segments", "random instances are not available yet");
}

}  // namespace depotwin
