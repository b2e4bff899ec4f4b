// A dense, axis-aligned grid of thickness values over part of the substrate: what the
// deposition field hands to images and exports (the field itself is sparse).
#pragma once

#include <vector>

namespace depotwin {

struct HeightMap {
  double origin_x_mm = 0.0;  // centre of cell (0, 0)
  double origin_y_mm = 0.0;
  double cell_mm = 0.0;
  int nx = 0;                       // columns (x)
  int ny = 0;                       // rows (y)
  std::vector<float> thickness_um;  // row-major, index = iy * nx + ix

  float at(int ix, int iy) const { return thickness_um[static_cast<size_t>(iy) * nx + ix]; }
  // the edges of the outer cells (the map covers [x_lo, x_hi] x [y_lo, y_hi], mm)
  double x_lo_mm() const { return origin_x_mm - 0.5 * cell_mm; }
  double x_hi_mm() const { return origin_x_mm + (nx - 0.5) * cell_mm; }
  double y_lo_mm() const { return origin_y_mm - 0.5 * cell_mm; }
  double y_hi_mm() const { return origin_y_mm + (ny - 0.5) * cell_mm; }
  float max_value() const;
};

inline float HeightMap::max_value() const {
  float peak = 0.0f;
  for (float v : thickness_um) peak = v > peak ? v : peak;
  return peak;
}

}  // namespace depotwin
