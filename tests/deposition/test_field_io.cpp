// Thickness exports: 16-bit PNG read back with stb_image, CSV read back by hand.
#include <gtest/gtest.h>
#include <stb_image.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "deposition/field_io.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;

HeightMap ramp_map() {
  HeightMap map;
  map.origin_x_mm = -1.25;
  map.origin_y_mm = 2.5;
  map.cell_mm = 0.05;
  map.nx = 7;
  map.ny = 5;
  for (int iy = 0; iy < map.ny; ++iy)
    for (int ix = 0; ix < map.nx; ++ix) map.thickness_um.push_back(0.1f * ix + 1.0f * iy);
  return map;
}

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(DEPOTWIN_BINARY_DIR) / "test_scratch" / name;
  fs::create_directories(dir);
  return dir;
}

TEST(FieldIo, Png16RoundTripsThroughStbImage) {
  const HeightMap map = ramp_map();
  const fs::path file = scratch_dir("png") / "thickness.png";
  const double scale = write_heightmap_png16(map, file.string());
  EXPECT_DOUBLE_EQ(scale, map.max_value() / 65535.0);
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));

  int width = 0, height = 0, channels = 0;
  stbi_us* pixels = stbi_load_16(file.string().c_str(), &width, &height, &channels, 1);
  ASSERT_NE(pixels, nullptr) << stbi_failure_reason();
  EXPECT_EQ(width, map.nx);
  EXPECT_EQ(height, map.ny);
  EXPECT_EQ(channels, 1);
  for (int row = 0; row < height; ++row) {
    for (int ix = 0; ix < width; ++ix) {
      const int iy = map.ny - 1 - row;  // top row = largest y
      const double expected = std::round(map.at(ix, iy) / scale);
      EXPECT_EQ(pixels[row * width + ix], expected) << ix << "," << iy;
    }
  }
  EXPECT_EQ(pixels[0 * width + (width - 1)], 65535);  // the maximum sits top right
  stbi_image_free(pixels);

  // the scale travels in a tEXt chunk
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find(std::string("tEXtum_per_level\0", 17)), std::string::npos);
}

// a header row of x_mm (cell centres) under `y_mm`, then per row its y and its values (um)
TEST(FieldIo, CsvCarriesOriginCellScaleAndValues) {
  const HeightMap map = ramp_map();
  const fs::path file = scratch_dir("csv") / "thickness.csv";
  write_heightmap_csv(map, file.string(), 0.0001);
  std::ifstream in(file);
  std::string line;
  std::string header;
  std::vector<std::string> column_names;
  int row = 0;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) {
      header += line + "\n";
      continue;
    }
    std::stringstream cells(line);
    std::string cell;
    std::vector<std::string> fields;
    while (std::getline(cells, cell, ',')) fields.push_back(cell);
    ASSERT_EQ(fields.size(), static_cast<size_t>(map.nx) + 1) << line;
    // the header row: y_mm, then x of every column
    if (column_names.empty()) {
      column_names = fields;
      EXPECT_EQ(fields[0], "y_mm");
      for (int ix = 0; ix < map.nx; ++ix)
        EXPECT_NEAR(std::stod(fields[ix + 1]), -1.25 + 0.05 * ix, 1e-9);
      continue;
    }
    const int iy = map.ny - 1 - row;
    EXPECT_NEAR(std::stod(fields[0]), 2.5 + 0.05 * iy, 1e-9);
    for (int ix = 0; ix < map.nx; ++ix)
      EXPECT_NEAR(std::stod(fields[ix + 1]), map.at(ix, iy), 1e-6);
    ++row;
  }
  EXPECT_EQ(row, map.ny);
  EXPECT_NE(header.find("thickness in um"), std::string::npos) << header;
  EXPECT_NE(header.find("origin_x_mm=-1.25 "), std::string::npos) << header;
  EXPECT_NE(header.find("origin_y_mm=2.5 "), std::string::npos);
  EXPECT_NE(header.find("cell_mm=0.050000000000000003"), std::string::npos);
  EXPECT_NE(header.find("um_per_level=0.0001"), std::string::npos);
}

TEST(FieldIo, UnwritablePathIsInternalError) {
  const HeightMap map = ramp_map();
  EXPECT_THROW(write_heightmap_png16(map, "/nonexistent-dir/x.png"), InternalError);
  EXPECT_THROW(write_heightmap_csv(HeightMap{}, scratch_dir("bad").string() + "/x.csv", 1.0),
               InternalError);
}

}  // namespace
}  // namespace depotwin
