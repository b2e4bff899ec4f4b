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

// a PNG decoded to 8-bit RGB (stb_image), freed with it; empty when it cannot decode
class DecodedRgb {
 public:
  explicit DecodedRgb(const std::string& bytes)
      : pixels_(stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                                      static_cast<int>(bytes.size()), &width_, &height_, &channels_,
                                      3)) {}
  ~DecodedRgb() { stbi_image_free(pixels_); }
  DecodedRgb(const DecodedRgb&) = delete;
  DecodedRgb& operator=(const DecodedRgb&) = delete;

  bool empty() const { return pixels_ == nullptr; }
  int width() const { return width_; }
  int height() const { return height_; }
  // the mean of pixel (x, y)'s three channels
  double grey(int x, int y) const {
    const unsigned char* rgb = pixels_ + 3 * (static_cast<size_t>(y) * width_ + x);
    return (rgb[0] + rgb[1] + rgb[2]) / 3.0;
  }

 private:
  int width_ = 0, height_ = 0, channels_ = 0;
  unsigned char* pixels_ = nullptr;
};

// variance of the grey level over all pixels (0 for a blank image), -1 when it cannot decode
inline double pixel_variance(const std::string& bytes) {
  const DecodedRgb image(bytes);
  if (image.empty()) return -1.0;
  double sum = 0.0, sum_sq = 0.0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const double grey = image.grey(x, y);
      sum += grey;
      sum_sq += grey * grey;
    }
  const double count = static_cast<double>(image.width()) * image.height();
  const double mean = sum / count;
  return sum_sq / count - mean * mean;
}

// true when the image's `columns` rightmost pixel columns are all white (grey above 250): nothing
// drawn runs past its right edge; false too when it cannot decode
inline bool right_edge_blank(const std::string& bytes, int columns) {
  const DecodedRgb image(bytes);
  if (image.empty()) return false;
  for (int y = 0; y < image.height(); ++y)
    for (int x = std::max(0, image.width() - columns); x < image.width(); ++x)
      if (!(image.grey(x, y) > 250.0)) return false;
  return true;
}

}  // namespace depotwin::testing_support
