// Where the shipped MJCF models are: beside an installed binary, or in the source tree of a
// build that was not installed.
#pragma once

#include <string>

namespace depotwin {

// The first of: $DEPOTWIN_MODELS_DIR; <directory of the running binary>/../share/depotwin/models
// (what `cmake --install` lays out); the source tree's models/ this binary was built from.
std::string models_directory();

}  // namespace depotwin
