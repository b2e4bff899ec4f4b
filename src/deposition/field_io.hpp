// Thickness-map exports: a 16-bit grayscale PNG and a CSV, both written to a temporary
// file beside the target and renamed into place (a reader never sees half a file).
//
// Orientation (both files): the first image row / first CSV data row is the TOP row of
// the map (largest y, iy = ny - 1); columns run along +x from origin_x_mm.
// PNG: gray = round(thickness_um / um_per_level), 0..65535, big-endian 16-bit samples,
// zlib-compressed (core/png.hpp). tEXt chunks carry um_per_level,
// origin_x_mm, origin_y_mm and cell_mm.
// CSV: '#' comment lines with the same metadata, a header row `y_mm,<x of column 0>,...`
// (mm, cell centres), then ny rows `<y of the row>,<nx thickness values in um>`: loads as a
// table indexed by y with one column per x (pandas: read_csv(path, comment='#',
// index_col='y_mm')).
// I/O failures throw InternalError naming the file.
#pragma once

#include <string>

#include "core/heightmap.hpp"

namespace depotwin {

// um_per_level <= 0: max(map) / 65535 (full range); returns the scale used
double write_heightmap_png16(const HeightMap& map, const std::string& path,
                             double um_per_level = 0.0);

// um_per_level: the scale of the companion PNG, recorded in the header
void write_heightmap_csv(const HeightMap& map, const std::string& path, double um_per_level);

// the scale write_heightmap_png16 picks for um_per_level <= 0
double default_um_per_level(const HeightMap& map);

}  // namespace depotwin
