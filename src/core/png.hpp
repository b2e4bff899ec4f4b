// PNG encoding on zlib: 8-bit RGB images (scene renders) and 16-bit grayscale ones
// (thickness maps), unfiltered, with tEXt metadata. stb_image_write has no 16-bit output,
// and on a 640 x 480 scene it takes 12-17 ms for a file up to twice the size that zlib
// makes in 4-6 ms.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace depotwin {

enum class PngPixels {
  rgb8,    // 3 bytes per pixel: red, green, blue
  gray16,  // 2 bytes per pixel: big-endian 16-bit gray
};

struct PngOptions {
  int zlib_level = 6;                                     // 1 (fastest) .. 9 (smallest)
  std::vector<std::pair<std::string, std::string>> text;  // tEXt chunks: keyword, text
};

// The PNG file of a width x height image; `pixels` holds the rows top first, unpadded.
// InternalError when zlib fails or the size is not positive.
std::string encode_png(int width, int height, PngPixels format, const unsigned char* pixels,
                       const PngOptions& options = {});

}  // namespace depotwin
