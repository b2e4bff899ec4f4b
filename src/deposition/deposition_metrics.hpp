// Deposition metrics: pure functions of the thickness field, the toolpath and the
// material account (ARCHITECTURE.md "Definitions"). Paths are taken in the substrate
// plane (x, y); r = half the line width.
//
//  target region  the band within r of any print path's centreline (capsules: round caps
//                 at the path ends), on the field's cells (centres on its lattice): each
//                 cell by its share w of the band, the fraction of its 8 x 8 sub-points
//                 within r of some centreline (bands that touch or overlap count once); a
//                 cell the band's edge crosses is read at those sub-points from the field
//                 interpolated between cell centres (its inside part's thickness, the share
//                 of its material inside), so the metrics hardly depend on where the lines
//                 fall between cell centres.
//  end zones      cells of a path's band whose nearest centreline point lies within r
//                 (arc length) of the path's start or end, caps included.
//  stats region   target region minus every path's end zones.
//  thickness      over the stats region, cell values weighted by w: mean_um, cv = std /
//                 mean (population std); min_rel = min / mean, max_rel = max / mean over
//                 its cells whose centre lies within r (all of them when none does);
//                 `cells` counts the cells with a share. line_cv = CV of the field sampled
//                 bilinearly on each centreline every cell length, from arc length r to
//                 length - r. Empty region or zero mean: all zeros.
//  material       on_target = landed in the target region (each cell's material inside
//                 the band), overspray = the rest that landed, captured = blocked by the
//                 shutter; fraction = (overspray + captured) / emitted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/toolpath.hpp"
#include "deposition/process.hpp"
#include "deposition/sparse_tiles.hpp"
#include "deposition/thickness_field.hpp"

namespace depotwin {

struct ThicknessStats {
  double mean_um = 0.0;
  double cv = 0.0;
  double min_rel = 0.0;
  double max_rel = 0.0;
  double line_cv = 0.0;
  size_t cells = 0;         // cells in the stats region
  size_t line_samples = 0;  // centreline samples behind line_cv
};

struct MaterialSplit {
  double emitted_mm3 = 0.0;
  double on_target_mm3 = 0.0;
  double overspray_mm3 = 0.0;
  double captured_mm3 = 0.0;
  double fraction = 0.0;  // (overspray + captured) / emitted; 0 when nothing was emitted
  double closed_time_s = 0.0;
};

struct DepositionMetrics {
  ThicknessStats thickness;
  MaterialSplit material;
};

// The target region and end zones on a field's cell lattice (sparse, like the field).
class TargetRegion {
 public:
  struct Cell {
    double best_arc_mm = 0.0;         // arc length of the nearest point along `path`
    float best_distance2_mm2 = 0.0f;  // squared distance to that point
    uint64_t inside_mask = 0;         // its 8 x 8 sub-points within r of a centreline
    int32_t path = -1;                // path being resolved (construction scratch)
    uint8_t flags = 0;
    // the cell's share of the band, in [0, 1]
    double weight() const { return __builtin_popcountll(inside_mask) / 64.0; }
  };
  static constexpr uint8_t kTarget = 1;        // a share of the band (weight > 0)
  static constexpr uint8_t kEndZone = 2;       // in a path's end zone
  static constexpr uint8_t kCentreInside = 4;  // its centre within r of a centreline
  static constexpr uint64_t kWholeCell = ~uint64_t{0};
  using Tiles = SparseTiles<Cell>;

  TargetRegion(const Toolpath& toolpath, double line_width_mm, double cell_mm);

  double cell_mm() const { return cell_mm_; }
  double half_width_mm() const { return half_width_mm_; }
  // the cell's centre within r of a centreline; in the stats region (a share of the band,
  // outside every end zone); its share of the band
  bool in_target(int ix, int iy) const { return flags(ix, iy) & kCentreInside; }
  bool in_stats(int ix, int iy) const { return (flags(ix, iy) & (kTarget | kEndZone)) == kTarget; }
  uint8_t flags(int ix, int iy) const;
  double weight(int ix, int iy) const;
  // cells whose centre lies within r of a centreline
  size_t target_cells() const;
  const Tiles& tiles() const { return tiles_; }

 private:
  void finish_cell(Cell& cell) const;

  double cell_mm_;
  double half_width_mm_;
  std::vector<double> path_length_mm_;
  Tiles tiles_;
};

ThicknessStats thickness_stats(const ThicknessField& field, const TargetRegion& region,
                               const Toolpath& toolpath);
MaterialSplit split_material(const ThicknessField& field, const TargetRegion& region,
                             const MaterialAccount& account);
// both, building the region once (line_width_mm: Process::line_width_mm())
DepositionMetrics evaluate_deposition(const ThicknessField& field, const Toolpath& toolpath,
                                      double line_width_mm, const MaterialAccount& account);

}  // namespace depotwin
