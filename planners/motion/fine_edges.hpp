// Fine edges merged: a polyline given as many short chords (a slicer's or CAM's curve) becomes
// fewer, longer edges within a distance, so the planners that blend each corner (uniform,
// bezier) have room for their blends instead of clipping them to the chords.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "core/types.hpp"

namespace depotwin {

struct FineEdgeMerge {
  std::vector<size_t> kept;           // the points kept, in order (the first and last always)
  std::vector<double> edge_error_mm;  // per merged edge, the largest distance of a dropped
                                      // point from it (0 where nothing was dropped)
};

// From each kept point the edge extends over the next points while edge k may join the one
// started at `anchor` (`joinable(anchor, k)`: the same path and speed, not an arc, ...), the
// merged edge is at least as long as each edge it replaces (no reversal folded into it), every
// point passed stays within max_error_mm of it and it replaces at most max_points edges.
FineEdgeMerge merge_polyline_edges(const std::vector<Vec3>& points, double max_error_mm,
                                   size_t max_points,
                                   const std::function<bool(size_t anchor, size_t edge)>& joinable);

}  // namespace depotwin
