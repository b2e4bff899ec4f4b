// Linear segments with parabolic blends for one axis over a fixed duration,
// Thompson & Yoon 2014 (papers/000), eqs. (1)-(18).
#pragma once

#include <limits>
#include <optional>

#include "core/profile.hpp"

namespace depotwin {

// Boundary conditions of a one-axis move, eqs. (1)-(4), with t0 = 0.
struct AxisBoundary {
  double q0 = 0.0, q1 = 0.0;  // mm
  double v0 = 0.0, v1 = 0.0;  // mm/s
};

struct LspbSolution {
  int candidate = 0;  // which of v_c1..v_c6 (eqs. 11-16) was valid
  double v_c = 0.0;   // cruise velocity
  double a0 = 0.0;    // first blend acceleration (+-alpha)
  double a1 = 0.0;    // second blend acceleration (+-alpha)
  double t_b0 = 0.0;  // end of the first blend, eq. (5)
  double t_b1 = 0.0;  // start of the second blend, eq. (6)
  double duration_s = 0.0;

  AxisProfile profile(const AxisBoundary& b) const;
};

// The paper's LSPB: try the six v_c candidates of eqs. (11)-(16) in the order of
// its flowchart (Fig. 3) and return the first that is real (17), has ordered blend
// times (18) and, beyond the paper, keeps |v_c| <= v_max. nullopt when none is valid.
std::optional<LspbSolution> solve_lspb(const AxisBoundary& b, double duration_s, double alpha,
                                       double v_max = std::numeric_limits<double>::infinity());

}  // namespace depotwin
