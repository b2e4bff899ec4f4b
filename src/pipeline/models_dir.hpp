// Where the shipped MJCF models are: beside an installed binary, or in the source tree of a
// build that was not installed.
#pragma once

#include <string>

namespace depotwin {

// The first of: $DEPOTWIN_MODELS_DIR; <directory of the running binary>/../share/depotwin/models
// (what `cmake --install` lays out); the source tree's models/ this binary was built from.
std::string models_directory();
// models_directory() and where that choice came from, for a message about a missing model:
// "<folder> (from $DEPOTWIN_MODELS_DIR)", "(beside the installed binary)" or "(the source tree
// this binary was built from)"
std::string models_directory_text();

}  // namespace depotwin
