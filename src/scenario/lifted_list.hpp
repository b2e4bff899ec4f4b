// Private to scenario/: a long `toolpath.segments` list of plain numbers read without
// yaml-cpp. yaml-cpp builds a node per scalar and takes about 55 us and 3.5 kB per segment
// (11 s and 690 MB for 200 000 segments); a list in the one form a generator writes,
// `- [[x, y], [x, y]]` (or with z) one per line, is read here directly and its lines blanked in
// the text yaml-cpp then parses, so every other line keeps its number and every other key is
// read as before. Anything else in the list (a comment, a quote, an anchor, a number that is
// not finite or is beyond the coordinates' range, another layout) leaves the whole file to
// yaml-cpp, whose messages name it.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace depotwin::scenario_detail {

struct LiftedSegments {
  int key_line = 0;                           // the line of `segments:` (1-based)
  std::vector<std::array<Vec3, 2>> segments;  // each segment's two points, z = 0 when not given
  std::vector<int> lines;                     // each segment's line
};

// the segments list lifted out of `text` (its lines blanked, `segments:` made `segments: []`),
// or nothing (text untouched) when the file has no such list of at least `min_items` entries
std::optional<LiftedSegments> lift_segments(std::string& text, std::size_t min_items = 256);

}  // namespace depotwin::scenario_detail
