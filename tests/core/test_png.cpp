// PNG encoding: what stb_image decodes is what went in (8-bit RGB and 16-bit gray), every
// chunk's CRC checks out against zlib's crc32, and the tEXt chunks carry the metadata.
#include <gtest/gtest.h>
#include <stb_image.h>
#include <zlib.h>

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/png.hpp"

namespace depotwin {
namespace {

struct Chunk {
  std::string type, data;
  bool crc_ok = false;
};

uint32_t read_u32(const std::string& bytes, size_t at) {
  return (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at])) << 24) |
         (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 16) |
         (static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 2])) << 8) |
         static_cast<uint32_t>(static_cast<unsigned char>(bytes[at + 3]));
}

// the chunks after the signature, each with its CRC checked independently
std::vector<Chunk> chunks(const std::string& png) {
  std::vector<Chunk> out;
  for (size_t at = 8; at + 12 <= png.size();) {
    const uint32_t length = read_u32(png, at);
    Chunk chunk;
    chunk.type = png.substr(at + 4, 4);
    chunk.data = png.substr(at + 8, length);
    const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(png.data() + at + 4), 4 + length);
    chunk.crc_ok = crc == read_u32(png, at + 8 + length);
    out.push_back(chunk);
    at += 12 + length;
  }
  return out;
}

TEST(Png, RgbImageDecodesToTheSamePixels) {
  const int width = 37, height = 23;  // odd sizes: no row padding may creep in
  std::vector<unsigned char> pixels(static_cast<size_t>(width) * height * 3);
  std::mt19937 random(7);
  for (unsigned char& value : pixels) value = static_cast<unsigned char>(random() & 0xff);
  const std::string png = encode_png(width, height, PngPixels::rgb8, pixels.data());

  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  int decoded_width = 0, decoded_height = 0, channels = 0;
  unsigned char* decoded = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png.data()),
                                                 static_cast<int>(png.size()), &decoded_width,
                                                 &decoded_height, &channels, 0);
  ASSERT_NE(decoded, nullptr) << stbi_failure_reason();
  EXPECT_EQ(decoded_width, width);
  EXPECT_EQ(decoded_height, height);
  EXPECT_EQ(channels, 3);
  EXPECT_EQ(std::vector<unsigned char>(decoded, decoded + pixels.size()), pixels);
  stbi_image_free(decoded);
}

TEST(Png, Gray16ImageDecodesToTheSameSamplesWithItsMetadata) {
  const int width = 5, height = 3;
  std::vector<uint16_t> samples;
  for (int i = 0; i < width * height; ++i) samples.push_back(static_cast<uint16_t>(4369 * i));
  std::vector<unsigned char> big_endian;
  for (uint16_t sample : samples) {
    big_endian.push_back(static_cast<unsigned char>(sample >> 8));
    big_endian.push_back(static_cast<unsigned char>(sample & 0xff));
  }
  PngOptions options;
  options.text = {{"um_per_level", "0.5"}, {"Description", "a ramp"}};
  const std::string png = encode_png(width, height, PngPixels::gray16, big_endian.data(), options);

  int decoded_width = 0, decoded_height = 0, channels = 0;
  stbi_us* decoded = stbi_load_16_from_memory(reinterpret_cast<const unsigned char*>(png.data()),
                                              static_cast<int>(png.size()), &decoded_width,
                                              &decoded_height, &channels, 0);
  ASSERT_NE(decoded, nullptr) << stbi_failure_reason();
  EXPECT_EQ(channels, 1);
  EXPECT_EQ(std::vector<uint16_t>(decoded, decoded + samples.size()), samples);
  stbi_image_free(decoded);

  // IHDR, the two tEXt chunks in order, IDAT, IEND; every CRC right
  const std::vector<Chunk> found = chunks(png);
  ASSERT_EQ(found.size(), 5u);
  EXPECT_EQ(found[0].type, "IHDR");
  EXPECT_EQ(found[0].data[8], 16);  // bit depth
  EXPECT_EQ(found[0].data[9], 0);   // grayscale
  EXPECT_EQ(found[1].type, "tEXt");
  EXPECT_EQ(found[1].data, std::string("um_per_level\0"
                                       "0.5",
                                       16));
  EXPECT_EQ(found[2].data, std::string("Description\0a ramp", 18));
  EXPECT_EQ(found[3].type, "IDAT");
  EXPECT_EQ(found[4].type, "IEND");
  for (const Chunk& chunk : found) EXPECT_TRUE(chunk.crc_ok) << chunk.type;
}

TEST(Png, EmptyImageIsRefused) {
  const unsigned char pixel[3] = {0, 0, 0};
  EXPECT_THROW(encode_png(0, 1, PngPixels::rgb8, pixel), InternalError);
  EXPECT_THROW(encode_png(1, -2, PngPixels::rgb8, pixel), InternalError);
}

}  // namespace
}  // namespace depotwin
