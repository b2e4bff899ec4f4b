// The thickness field: deposited material on the substrate, one value per square cell.
//
// Units: thickness in mm (double) internally; heightmaps hand out micrometres.
// Lattice: cell (ix, iy) is centred at (ix * cell_mm, iy * cell_mm) in the substrate
// frame, so every field with the same cell size shares one lattice. A cell's
// thickness times cell_mm^2 is the volume that landed in it; total_volume_mm3() is
// therefore exactly what the deposition kernel put down.
// Storage: sparse 64 x 64 tiles (SparseTiles), allocated when material first lands
// near them; a 100 x 100 mm bed at 10 um cells only pays for the printed band.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "core/heightmap.hpp"
#include "deposition/sparse_tiles.hpp"

namespace depotwin {

// Extent of the cells holding material (cell centres, mm); empty when nothing landed.
struct FieldBounds {
  bool empty = true;
  double x_lo_mm = 0.0;
  double y_lo_mm = 0.0;
  double x_hi_mm = 0.0;
  double y_hi_mm = 0.0;
};

// Where a point lies on the lattice of cell centres (ThicknessField): the cell below and left
// of it and its fractional position from there, the weights of bilinear interpolation.
struct BilinearPoint {
  int ix0 = 0, iy0 = 0;
  double wx = 0.0, wy = 0.0;
};
inline BilinearPoint bilinear_point(double x_mm, double y_mm, double cell_mm) {
  const double fx = x_mm / cell_mm;
  const double fy = y_mm / cell_mm;
  const double ix0_real = std::floor(fx);
  const double iy0_real = std::floor(fy);
  return BilinearPoint{static_cast<int>(ix0_real), static_cast<int>(iy0_real), fx - ix0_real,
                       fy - iy0_real};
}

// Bilinear interpolation between cell centres of the values cell(ix, iy) at a point
// (bilinear_point once, for a point read many times): thickness_mm_at's rule, for readers that
// look their cells up their own way.
template <class CellFn>
double bilinear_between_cells(const BilinearPoint& p, CellFn&& cell) {
  const double v00 = cell(p.ix0, p.iy0);
  const double v10 = cell(p.ix0 + 1, p.iy0);
  const double v01 = cell(p.ix0, p.iy0 + 1);
  const double v11 = cell(p.ix0 + 1, p.iy0 + 1);
  return (1.0 - p.wy) * ((1.0 - p.wx) * v00 + p.wx * v10) +
         p.wy * ((1.0 - p.wx) * v01 + p.wx * v11);
}
template <class CellFn>
double bilinear_between_cells(double x_mm, double y_mm, double cell_mm, CellFn&& cell) {
  return bilinear_between_cells(bilinear_point(x_mm, y_mm, cell_mm), cell);
}

class ThicknessField {
 public:
  using Tiles = SparseTiles<double>;

  // cell_mm must be > 0 (InputError "sim.cell_mm" otherwise)
  explicit ThicknessField(double cell_mm);

  double cell_mm() const { return cell_mm_; }

  // thickness (mm) of one cell; 0 where nothing landed
  double cell_thickness_mm(int ix, int iy) const;
  // bilinear interpolation between cell centres (mm)
  double thickness_mm_at(double x_mm, double y_mm) const;
  // sum of thickness x cell area over every cell (tiles in sorted order: deterministic)
  double total_volume_mm3() const;
  // cells with thickness > 0
  FieldBounds bounds() const;

  // dense copy (thickness in um) of the cells whose centres lie in [lo, hi]; with
  // stride > 1 each output cell is the mean of stride x stride field cells (volume
  // preserving), origin at the block centre. Throws InternalError above 2^28 cells.
  HeightMap to_heightmap(double x_lo_mm, double y_lo_mm, double x_hi_mm, double y_hi_mm,
                         int stride = 1) const;
  // the same over bounds() (an empty 0 x 0 map when nothing landed)
  HeightMap to_heightmap(int stride = 1) const;
  // smallest stride whose export of [lo, hi] has at most max_cells cells (>= 1)
  int stride_for_max_cells(double x_lo_mm, double y_lo_mm, double x_hi_mm, double y_hi_mm,
                           size_t max_cells) const;

  // memory statistics, for the sparsity contract
  size_t allocated_tiles() const { return tiles_.tile_count(); }
  size_t allocated_cells() const { return tiles_.allocated_cells(); }

  // add material to one cell (thickness in mm); used by tests and importers
  void add_to_cell(int ix, int iy, double thickness_mm);
  // add another field's material cell by cell (the same cell size; InternalError otherwise):
  // the layers of a multi-layer print stacked into one deposit
  void add(const ThicknessField& other);
  // every cell multiplied by factor(x, y) at its centre (mm): e.g. the vertical thickness of a
  // deposit on a sloped surface turned into the thickness along the surface normal
  void scale_cells(const std::function<double(double x_mm, double y_mm)>& factor);
  void clear() {
    tiles_.clear();
    written_ = CellBox{};
  }
  // every cell 0, its memory kept for the next deposit (a scratch field reused): only the
  // cells written since the last zero() are cleared (their bounding box)
  void zero();

  // The cells a deposit will be read at, when that is not all of them (a prediction compared
  // with its targets): in row iy, cells [first, last] of its span, rows [iy_lo, iy_lo + rows).
  // The deposition kernel (GaussianFootprint) then skips every other cell, so those hold only
  // part of the deposit (total_volume_mm3 and the metrics no longer add up); the cells within
  // are exactly as without the region.
  struct WriteRegion {
    int iy_lo = 0;
    std::vector<std::pair<int, int>> spans;  // per row from iy_lo: first > last for none
    int iy_hi() const { return iy_lo + static_cast<int>(spans.size()) - 1; }
  };
  void limit_writes(WriteRegion region) {
    region_ = std::move(region);
    limited_ = true;
  }
  void write_everywhere() {
    limited_ = false;
    region_.spans.clear();
  }
  // the region writes are limited to; nullptr when every cell is written
  const WriteRegion* write_region() const { return limited_ ? &region_ : nullptr; }

  // raw tile access for the metrics; writing through it (non-const) makes the next zero()
  // clear every tile
  Tiles& tiles() {
    written_.everything = true;
    return tiles_;
  }
  const Tiles& tiles() const { return tiles_; }
  // tile access for a writer that changes cells [ix_lo, ix_hi] x [iy_lo, iy_hi] only (the
  // deposition kernel)
  Tiles& tiles_for_writing(int ix_lo, int ix_hi, int iy_lo, int iy_hi) {
    written_.include(ix_lo, ix_hi, iy_lo, iy_hi);
    return tiles_;
  }

 private:
  // the bounding box of the cells written since the last zero() (empty: lo > hi)
  struct CellBox {
    int ix_lo = 1, ix_hi = 0, iy_lo = 1, iy_hi = 0;
    bool everything = false;
    void include(int x_lo, int x_hi, int y_lo, int y_hi) {
      if (ix_lo > ix_hi) {
        ix_lo = x_lo, ix_hi = x_hi, iy_lo = y_lo, iy_hi = y_hi;
        return;
      }
      ix_lo = std::min(ix_lo, x_lo), ix_hi = std::max(ix_hi, x_hi);
      iy_lo = std::min(iy_lo, y_lo), iy_hi = std::max(iy_hi, y_hi);
    }
  };
  double cell_mm_;
  Tiles tiles_;
  CellBox written_;
  bool limited_ = false;
  WriteRegion region_;
};

}  // namespace depotwin
