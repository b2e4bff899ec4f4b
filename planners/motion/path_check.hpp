// The check a planner makes of each print path before planning it (conformal and uniform):
// the scenario loader checks its own paths, but a planner is also called on toolpaths built
// in code (tests, benchmarks, generators).
#pragma once

#include <string>

#include "core/toolpath.hpp"

namespace depotwin {

// At least two finite points, no edge of length <= same_point_mm, a positive finite speed, one
// unit normal and one roll per point where given. InputError under `name` (e.g. "toolpath
// path 3") naming the first problem.
void validate_print_path(const PrintPath& path, const std::string& name, double same_point_mm);

}  // namespace depotwin
