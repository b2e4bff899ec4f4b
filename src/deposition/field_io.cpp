#include "deposition/field_io.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.hpp"

namespace depotwin {

namespace {

constexpr double kMaxLevel = 65535.0;

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

// write bytes to path via path.tmp + rename
void write_atomically(const std::string& path, const std::string& bytes) {
  const std::string temp = path + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw InternalError("cannot open " + temp + " for writing: " + std::strerror(errno));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::remove(temp.c_str());
      throw InternalError("cannot write " + temp);
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp.c_str());
    throw InternalError("cannot rename " + temp + " to " + path + ": " + reason);
  }
}

void put_u32(std::string& out, uint32_t value) {
  out.push_back(static_cast<char>((value >> 24) & 0xff));
  out.push_back(static_cast<char>((value >> 16) & 0xff));
  out.push_back(static_cast<char>((value >> 8) & 0xff));
  out.push_back(static_cast<char>(value & 0xff));
}

// one PNG chunk: length, type, data, CRC over type + data
void put_chunk(std::string& out, const char* type, const std::string& data) {
  put_u32(out, static_cast<uint32_t>(data.size()));
  const size_t type_at = out.size();
  out.append(type, 4);
  out += data;
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(out.data() + type_at),
                          static_cast<uInt>(4 + data.size()));
  put_u32(out, static_cast<uint32_t>(crc));
}

void put_text_chunk(std::string& out, const std::string& keyword, const std::string& text) {
  std::string data = keyword;
  data.push_back('\0');
  data += text;
  put_chunk(out, "tEXt", data);
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

  // raw scanlines, top row first: filter byte 0, then big-endian 16-bit gray samples
  const size_t row_bytes = 1 + 2 * static_cast<size_t>(map.nx);
  std::vector<unsigned char> raw(row_bytes * static_cast<size_t>(map.ny));
  for (int row = 0; row < map.ny; ++row) {
    const int iy = map.ny - 1 - row;
    unsigned char* out = raw.data() + static_cast<size_t>(row) * row_bytes;
    *out++ = 0;
    for (int ix = 0; ix < map.nx; ++ix) {
      const double level =
          std::round(std::max(0.0, static_cast<double>(map.at(ix, iy))) / um_per_level);
      const auto gray = static_cast<uint16_t>(std::min(kMaxLevel, level));
      *out++ = static_cast<unsigned char>(gray >> 8);
      *out++ = static_cast<unsigned char>(gray & 0xff);
    }
  }

  // zlib stream for IDAT
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size, raw.data(),
                static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw InternalError("thickness PNG: zlib compression failed for " + path);
  packed.resize(packed_size);

  // signature, IHDR (16-bit grayscale), metadata, IDAT, IEND
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  put_u32(header, static_cast<uint32_t>(map.nx));
  put_u32(header, static_cast<uint32_t>(map.ny));
  header +=
      std::string("\x10\x00\x00\x00\x00", 5);  // depth 16, gray, deflate, filter 0, no interlace
  put_chunk(png, "IHDR", header);
  put_text_chunk(png, "um_per_level", format_number(um_per_level));
  put_text_chunk(png, "origin_x_mm", format_number(map.origin_x_mm));
  put_text_chunk(png, "origin_y_mm", format_number(map.origin_y_mm));
  put_text_chunk(png, "cell_mm", format_number(map.cell_mm));
  put_text_chunk(png, "Description",
                 "DepoTwin thickness map: thickness_um = gray * um_per_level; top row is the "
                 "largest y; origin = centre of the bottom-left cell");
  put_chunk(png, "IDAT", packed);
  put_chunk(png, "IEND", std::string());
  write_atomically(path, png);
  return um_per_level;
}

void write_heightmap_csv(const HeightMap& map, const std::string& path, double um_per_level) {
  check_map(map);
  std::ostringstream out;
  out << "# depotwin thickness map, values in um\n"
      << "# origin_x_mm=" << format_number(map.origin_x_mm)
      << " origin_y_mm=" << format_number(map.origin_y_mm)
      << " cell_mm=" << format_number(map.cell_mm) << " nx=" << map.nx << " ny=" << map.ny << "\n"
      << "# um_per_level=" << format_number(um_per_level)
      << " (scale of the 16-bit PNG: thickness_um = gray * um_per_level)\n"
      << "# origin = centre of the bottom-left cell; first data row = top row (y = origin_y_mm "
         "+ (ny - 1) * cell_mm); columns along +x\n";
  char value[32];
  for (int row = 0; row < map.ny; ++row) {
    const int iy = map.ny - 1 - row;
    for (int ix = 0; ix < map.nx; ++ix) {
      std::snprintf(value, sizeof(value), "%.7g", static_cast<double>(map.at(ix, iy)));
      if (ix > 0) out << ',';
      out << value;
    }
    out << '\n';
  }
  write_atomically(path, out.str());
}

}  // namespace depotwin
