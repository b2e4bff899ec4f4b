// PNG checks for the plot tests: the size from the IHDR chunk, the pixels via stb_image.
#pragma once

#include <stb_image.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace depotwin::testing_support {

inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

struct PngHeader {
  bool valid = false;
  std::uint32_t width = 0, height = 0;
};

// the signature, then the first chunk must be IHDR: width and height big-endian
inline PngHeader png_header(const std::string& bytes) {
  PngHeader header;
  static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 24 || bytes.compare(0, 8, reinterpret_cast<const char*>(signature), 8) != 0 ||
      bytes.compare(12, 4, "IHDR") != 0)
    return header;
  auto be32 = [&](size_t at) {
    std::uint32_t v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  header.valid = true;
  header.width = be32(16);
  header.height = be32(20);
  return header;
}

// variance of the grey level over all pixels (0 for a blank image), -1 when it cannot decode
inline double pixel_variance(const std::string& bytes) {
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels =
      stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                            static_cast<int>(bytes.size()), &width, &height, &channels, 3);
  if (pixels == nullptr) return -1.0;
  double sum = 0.0, sum_sq = 0.0;
  const size_t count = static_cast<size_t>(width) * height;
  for (size_t i = 0; i < count; ++i) {
    const double grey = (pixels[3 * i] + pixels[3 * i + 1] + pixels[3 * i + 2]) / 3.0;
    sum += grey;
    sum_sq += grey * grey;
  }
  stbi_image_free(pixels);
  const double mean = sum / count;
  return sum_sq / count - mean * mean;
}

// true when the image's `columns` rightmost pixel columns are all white (grey above 250): nothing
// drawn runs past its right edge; false too when it cannot decode
inline bool right_edge_blank(const std::string& bytes, int columns) {
  int width = 0, height = 0, channels = 0;
  unsigned char* pixels =
      stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                            static_cast<int>(bytes.size()), &width, &height, &channels, 3);
  if (pixels == nullptr) return false;
  bool blank = true;
  for (int y = 0; y < height && blank; ++y)
    for (int x = std::max(0, width - columns); x < width && blank; ++x) {
      const unsigned char* rgb = pixels + 3 * (static_cast<size_t>(y) * width + x);
      blank = (rgb[0] + rgb[1] + rgb[2]) / 3.0 > 250.0;
    }
  stbi_image_free(pixels);
  return blank;
}

}  // namespace depotwin::testing_support
