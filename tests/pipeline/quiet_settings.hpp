// Run settings for the end-to-end tests that call the pipeline directly.
#pragma once

#include "pipeline/run.hpp"

namespace depotwin::testing_support {

// no progress line; images only when asked
inline RunSettings quiet(bool render = false) {
  RunSettings settings;
  settings.render = render;
  settings.progress = false;
  return settings;
}

}  // namespace depotwin::testing_support
