#include "deposition/field_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/interrupt.hpp"
#include "core/number_text.hpp"
#include "core/png.hpp"

namespace depotwin {

namespace {

constexpr double kMaxLevel = 65535.0;

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

void check_map(const HeightMap& map) {
  if (map.nx <= 0 || map.ny <= 0 ||
      map.thickness_um.size() != static_cast<size_t>(map.nx) * static_cast<size_t>(map.ny))
    throw InternalError("thickness export: empty or inconsistent height map (" +
                        std::to_string(map.nx) + " x " + std::to_string(map.ny) + ")");
}

}  // namespace

double default_um_per_level(const HeightMap& map) {
  const double peak_um = map.thickness_um.empty() ? 0.0 : map.max_value();
  return peak_um > 0.0 ? peak_um / kMaxLevel : 1.0 / kMaxLevel;
}

double write_heightmap_png16(const HeightMap& map, const std::string& path, double um_per_level) {
  check_map(map);
  if (!(um_per_level > 0.0)) um_per_level = default_um_per_level(map);

  // big-endian 16-bit gray samples, top row first
  std::vector<unsigned char> samples(2 * static_cast<size_t>(map.nx) * map.ny);
  unsigned char* out = samples.data();
  for (int row = 0; row < map.ny; ++row) {
    const int iy = map.ny - 1 - row;
    for (int ix = 0; ix < map.nx; ++ix) {
      const double level =
          std::round(std::max(0.0, static_cast<double>(map.at(ix, iy))) / um_per_level);
      const auto gray = static_cast<uint16_t>(std::min(kMaxLevel, level));
      *out++ = static_cast<unsigned char>(gray >> 8);
      *out++ = static_cast<unsigned char>(gray & 0xff);
    }
  }

  // metadata in tEXt chunks
  PngOptions png;
  png.text = {{"um_per_level", format_number(um_per_level)},
              {"origin_x_mm", format_number(map.origin_x_mm)},
              {"origin_y_mm", format_number(map.origin_y_mm)},
              {"cell_mm", format_number(map.cell_mm)},
              {"Description",
               "DepoTwin thickness map: thickness_um = gray * um_per_level; top row is the "
               "largest y; origin = centre of the bottom-left cell"}};
  write_file_atomically(path, encode_png(map.nx, map.ny, PngPixels::gray16, samples.data(), png));
  return um_per_level;
}

void write_heightmap_csv(const HeightMap& map, const std::string& path, double um_per_level) {
  check_map(map);
  std::string out =
      "# depotwin thickness map: thickness in um; first column y_mm (the row's y), the "
      "header's other cells x_mm (each column's x), both at the cell centres\n"
      "# origin_x_mm=" +
      format_number(map.origin_x_mm) + " origin_y_mm=" + format_number(map.origin_y_mm) +
      " cell_mm=" + format_number(map.cell_mm) + " nx=" + std::to_string(map.nx) +
      " ny=" + std::to_string(map.ny) + "\n# um_per_level=" + format_number(um_per_level) +
      " (scale of the 16-bit PNG: thickness_um = gray * um_per_level)\n"
      "# origin = centre of the bottom-left cell; first data row = top row (y = origin_y_mm "
      "+ (ny - 1) * cell_mm); columns along +x\n"
      "# pandas: pd.read_csv(path, comment='#', index_col='y_mm')\n";
  // a cell is at most "-1.234567e-308," (15 characters); typical ones half that
  out.reserve(out.size() + static_cast<size_t>(map.nx + 1) * (map.ny + 1) * 8);
  // the header: y_mm, then every column's x (mm), as %.9g
  out += "y_mm";
  for (int ix = 0; ix < map.nx; ++ix) {
    out += ',';
    append_number(out, map.origin_x_mm + ix * map.cell_mm, 9);
  }
  out += '\n';
  // each row: its y (%.9g), then the thickness of its cells (%.7g), top row first
  for (int row = 0; row < map.ny; ++row) {
    throw_if_interrupted();  // a signal asked to stop (core/interrupt.hpp)
    const int iy = map.ny - 1 - row;
    append_number(out, map.origin_y_mm + iy * map.cell_mm, 9);
    for (int ix = 0; ix < map.nx; ++ix) {
      out += ',';
      append_number(out, static_cast<double>(map.at(ix, iy)), 7);
    }
    out += '\n';
  }
  write_file_atomically(path, out);
}

}  // namespace depotwin
