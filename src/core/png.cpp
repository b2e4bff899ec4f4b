#include "core/png.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstdint>

#include "core/error.hpp"

namespace depotwin {

namespace {

void put_u32(std::string& out, uint32_t value) {
  out.push_back(static_cast<char>((value >> 24) & 0xff));
  out.push_back(static_cast<char>((value >> 16) & 0xff));
  out.push_back(static_cast<char>((value >> 8) & 0xff));
  out.push_back(static_cast<char>(value & 0xff));
}

// one chunk: length, type, data, CRC over type and data
void put_chunk(std::string& out, const char* type, const std::string& data) {
  put_u32(out, static_cast<uint32_t>(data.size()));
  const size_t type_at = out.size();
  out.append(type, 4);
  out += data;
  const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(out.data() + type_at),
                          static_cast<uInt>(4 + data.size()));
  put_u32(out, static_cast<uint32_t>(crc));
}

}  // namespace

std::string encode_png(int width, int height, PngPixels format, const unsigned char* pixels,
                       const PngOptions& options) {
  if (width <= 0 || height <= 0)
    throw InternalError("PNG: image size must be positive, got " + std::to_string(width) + " x " +
                        std::to_string(height));
  const size_t bpp = format == PngPixels::rgb8 ? 3 : 2;
  const size_t row_bytes = bpp * static_cast<size_t>(width);

  // scanlines: filter type 0 (none), then the row's bytes. The adaptive filters of the PNG
  // specification make these images larger, not smaller: renders and plots are mostly flat
  // areas, which deflate already encodes as long repeats.
  std::vector<unsigned char> scanlines((row_bytes + 1) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    unsigned char* out = scanlines.data() + static_cast<size_t>(y) * (row_bytes + 1);
    out[0] = 0;
    std::copy_n(pixels + static_cast<size_t>(y) * row_bytes, row_bytes, out + 1);
  }

  // the zlib stream of the scanlines
  uLongf packed_size = compressBound(static_cast<uLong>(scanlines.size()));
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size, scanlines.data(),
                static_cast<uLong>(scanlines.size()), options.zlib_level) != Z_OK)
    throw InternalError("PNG: zlib compression failed");
  packed.resize(packed_size);

  // signature, IHDR, tEXt metadata, IDAT, IEND
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  put_u32(header, static_cast<uint32_t>(width));
  put_u32(header, static_cast<uint32_t>(height));
  header.push_back(format == PngPixels::rgb8 ? 8 : 16);  // bit depth
  header.push_back(format == PngPixels::rgb8 ? 2 : 0);   // colour type: RGB / gray
  header.append(3, '\0');  // deflate, adaptive filtering, no interlace
  put_chunk(png, "IHDR", header);
  for (const auto& [keyword, text] : options.text) {
    std::string data = keyword;
    data.push_back('\0');
    data += text;
    put_chunk(png, "tEXt", data);
  }
  put_chunk(png, "IDAT", packed);
  put_chunk(png, "IEND", std::string());
  return png;
}

}  // namespace depotwin
