// A small XY-stage scenario (two connected segments, about 10 s) for the video and viewer
// tests: the minimal scenario form of docs/ARCHITECTURE.md.
#pragma once

#include <string>

#include "pipeline/pipeline_test_util.hpp"

namespace depotwin::testing_support {

inline std::string write_small_scenario(const std::string& directory) {
  return write_text(directory, "two_segments.yaml",
                    "name: two_segments\n"
                    "machine: xy_stage\n"
                    "limits: {v_max: 4, a_max: 30}\n"
                    "process: {type: aerosol}\n"
                    "toolpath:\n"
                    "  speed: 3\n"
                    "  start: [0, 0]\n"
                    "  end: [10, 0]\n"
                    "  segments:\n"
                    "    - [[2, 2], [8, 2]]\n"
                    "    - [[8, 2], [5, 7]]\n"
                    "order: as_given\n"
                    "planners: [lspb_mtt]\n");
}

}  // namespace depotwin::testing_support
