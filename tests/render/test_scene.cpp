// The scene render: a PNG of the requested size that shows something, with the deposit
// visible on the substrate (a printed line changes the middle of the picture, nothing else).
#include <gtest/gtest.h>
#include <stb_image.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "../sim/sim_test_util.hpp"
#include "core/error.hpp"
#include "kinematics/xy_stage.hpp"
#include "render/scene.hpp"
#include "sim/simulation.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_util::straight_print;
using testing_util::xy_stage_model;

// a 20 x 12 mm grid (0.1 mm cells) in the plate frame, optionally with a printed line:
// a Gaussian bead (sigma 0.25 mm, 3 um peak) along y = 0 from x = -8 to 8 mm
HeightMap deposit_grid(bool with_line) {
  HeightMap map;
  map.cell_mm = 0.1;
  map.nx = 200;
  map.ny = 120;
  map.origin_x_mm = -10.0 + 0.05;
  map.origin_y_mm = -6.0 + 0.05;
  map.thickness_um.assign(static_cast<size_t>(map.nx) * map.ny, 0.0f);
  if (!with_line) return map;
  for (int iy = 0; iy < map.ny; ++iy)
    for (int ix = 0; ix < map.nx; ++ix) {
      const double x = map.origin_x_mm + ix * map.cell_mm;
      const double y = map.origin_y_mm + iy * map.cell_mm;
      if (std::abs(x) > 8.0) continue;
      map.thickness_um[static_cast<size_t>(iy) * map.nx + ix] =
          static_cast<float>(3.0 * std::exp(-0.5 * y * y / (0.25 * 0.25)));
    }
  return map;
}

// render options for an image of this size, the rest default
SceneRenderOptions sized(int width, int height) {
  SceneRenderOptions options;
  options.width = width;
  options.height = height;
  return options;
}

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "depotwin_" + std::to_string(::getpid()) + "_" + name;
}

TEST(Scene, WritesAPngOfTheRequestedSizeThatIsNotBlank) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  const std::string path = temp_path("scene.png");
  SceneRenderOptions options;  // 640 x 480
  render_scene_png(simulation, deposit_grid(true), path, options);

  int width = 0, height = 0, channels = 0;
  unsigned char* pixels = stbi_load(path.c_str(), &width, &height, &channels, 3);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(width, 640);
  EXPECT_EQ(height, 480);
  // grey-level variance well above a blank (single colour) picture's 0
  double sum = 0.0, sum_squares = 0.0;
  const long count = static_cast<long>(width) * height;
  for (long i = 0; i < count; ++i) {
    const double grey = (pixels[3 * i] + pixels[3 * i + 1] + pixels[3 * i + 2]) / 3.0;
    sum += grey;
    sum_squares += grey * grey;
  }
  stbi_image_free(pixels);
  const double mean = sum / count;
  const double variance = sum_squares / count - mean * mean;
  std::printf("scene.png grey mean %.1f, variance %.1f\n", mean, variance);
  EXPECT_GT(variance, 100.0);
  // written through a temporary file that is gone afterwards
  for (const auto& entry : fs::directory_iterator(fs::path(path).parent_path()))
    EXPECT_EQ(entry.path().string().find(path + ".tmp"), std::string::npos) << entry.path();
}

TEST(Scene, APrintedLineChangesTheMiddleOfThePictureOnly) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  SceneRenderOptions options = sized(320, 240);
  const auto empty = render_scene_rgb(simulation, deposit_grid(false), options);
  const auto printed = render_scene_rgb(simulation, deposit_grid(true), options);
  ASSERT_EQ(empty.size(), 320u * 240u * 3u);
  ASSERT_EQ(printed.size(), empty.size());
  // pixels that changed clearly, and where they are
  long changed = 0, changed_in_top_rows = 0;
  double row_sum = 0.0, column_sum = 0.0;
  for (int row = 0; row < options.height; ++row)
    for (int column = 0; column < options.width; ++column) {
      const size_t i = 3 * (static_cast<size_t>(row) * options.width + column);
      int difference = 0;
      for (int c = 0; c < 3; ++c)
        difference = std::max(difference, std::abs(printed[i + c] - empty[i + c]));
      if (difference > 40) {
        ++changed;
        if (row < options.height / 10) ++changed_in_top_rows;
        row_sum += row;
        column_sum += column;
      }
    }
  std::printf("changed pixels: %ld of %d\n", changed, options.width * options.height);
  // the 16 mm line spans much of the framed view: hundreds of pixels
  EXPECT_GT(changed, 500);
  // and sits in the middle of the picture (the camera is aimed at the deposit region)
  ASSERT_GT(changed, 0);
  EXPECT_NEAR(row_sum / changed, 0.5 * options.height, 0.25 * options.height);
  EXPECT_NEAR(column_sum / changed, 0.5 * options.width, 0.25 * options.width);
  // far from the substrate (the top of the picture: the print head and beyond) nothing moves
  EXPECT_EQ(changed_in_top_rows, 0);
  // the same inputs render the same picture
  EXPECT_EQ(render_scene_rgb(simulation, deposit_grid(true), options), printed);
}

TEST(Scene, RendersTheStateAfterARunFromTheModelCamera) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  const auto print =
      straight_print(Vec3(-8, 0, 0), Vec3(1, 0, 0), 3.0, 16.0, MachineLimits::uniform(4, 30));
  simulation.run(print.trajectory);
  SceneRenderOptions options = sized(320, 240);
  options.frame_deposit = false;  // render_cam as placed in the MJCF
  const auto before = render_scene_rgb(simulation, deposit_grid(false), options);
  const auto after = render_scene_rgb(simulation, deposit_grid(true), options);
  long changed = 0;
  for (size_t i = 0; i < after.size(); ++i) changed += std::abs(after[i] - before[i]) > 40;
  EXPECT_GT(changed, 50);
}

// A renderer that keeps its contexts (prepared on a background thread, then reused, rebuilt
// for another image size) draws exactly what a fresh one draws, from any thread, also when
// two threads render at once.
TEST(Scene, ReusedAndPreparedContextsRenderTheSamePictures) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  const SceneRenderOptions small = sized(160, 120);
  const SceneRenderOptions large = sized(320, 240);
  const auto fresh_small = render_scene_rgb(simulation, deposit_grid(true), small);
  const auto fresh_large = render_scene_rgb(simulation, deposit_grid(false), large);

  SceneRenderer renderer;
  renderer.prepare(simulation.model_path(), small);
  std::vector<unsigned char> reused_small, reused_large;
  std::thread other([&] {  // the prepared contexts move to this thread
    reused_small = renderer.render_rgb(simulation, deposit_grid(true), small);
  });
  other.join();
  reused_large = renderer.render_rgb(simulation, deposit_grid(false), large);
  EXPECT_EQ(reused_small, fresh_small);
  EXPECT_EQ(reused_large, fresh_large);

  // two threads at once: the renders take turns on the one GL context
  std::vector<unsigned char> concurrent_small, concurrent_large;
  std::thread first(
      [&] { concurrent_small = renderer.render_rgb(simulation, deposit_grid(true), small); });
  std::thread second(
      [&] { concurrent_large = renderer.render_rgb(simulation, deposit_grid(false), large); });
  first.join();
  second.join();
  EXPECT_EQ(concurrent_small, fresh_small);
  EXPECT_EQ(concurrent_large, fresh_large);
}

// Anti-aliasing by supersampling: a 2x image is exactly the 2 x 2 block mean (rounded) of
// the render at twice the size without it (the same camera: the aspect ratio is the same).
TEST(Scene, SupersampledImageIsTheBlockMeanOfTheLargerRender) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  SceneRenderOptions supersampled = sized(160, 120);
  supersampled.supersampling = 2;
  SceneRenderOptions large = sized(320, 240);
  large.supersampling = 1;
  const auto small = render_scene_rgb(simulation, deposit_grid(true), supersampled);
  const auto full = render_scene_rgb(simulation, deposit_grid(true), large);
  ASSERT_EQ(small.size(), 160u * 120u * 3u);
  long intermediate = 0;  // pixels on edges: none of their block's colours
  for (int row = 0; row < 120; ++row)
    for (int column = 0; column < 160; ++column)
      for (int channel = 0; channel < 3; ++channel) {
        auto at = [&](int r, int c) {
          return full[3 * (static_cast<size_t>(r) * 320 + c) + channel];
        };
        const int sum = at(2 * row, 2 * column) + at(2 * row, 2 * column + 1) +
                        at(2 * row + 1, 2 * column) + at(2 * row + 1, 2 * column + 1);
        const int value = small[3 * (static_cast<size_t>(row) * 160 + column) + channel];
        ASSERT_EQ(value, (sum + 2) / 4) << "row " << row << " column " << column;
        if (value != at(2 * row, 2 * column) && value != at(2 * row + 1, 2 * column + 1))
          ++intermediate;
      }
  EXPECT_GT(intermediate, 100);  // edges are smoothed
}

// The models have no skybox: the renderer's floor fills every view, so no pixel is the
// empty background's black, from render_cam as placed in the MJCF or framed on a deposit
// that covers the whole plate (the widest framing, which looks past the machine).
TEST(Scene, NoViewShowsTheEmptyBackground) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  HeightMap plate_wide;  // 100 x 100 mm, 1 mm cells, a bead along y = 0
  plate_wide.cell_mm = 1.0;
  plate_wide.nx = plate_wide.ny = 100;
  plate_wide.origin_x_mm = plate_wide.origin_y_mm = -49.5;
  plate_wide.thickness_um.assign(100 * 100, 0.0f);
  for (int ix = 10; ix < 90; ++ix) plate_wide.thickness_um[50 * 100 + ix] = 2.0f;
  for (const bool framed : {false, true}) {
    SceneRenderOptions options = sized(160, 120);
    options.frame_deposit = framed;
    const auto rgb = render_scene_rgb(simulation, plate_wide, options);
    long black = 0;
    for (size_t i = 0; i < rgb.size(); i += 3)
      black += rgb[i] < 8 && rgb[i + 1] < 8 && rgb[i + 2] < 8;
    EXPECT_EQ(black, 0) << (framed ? "framed" : "render_cam");
  }
}

TEST(Scene, ImageLargerThanTheOffscreenBufferIsBadInput) {
  const auto machine = make_xy_stage();
  Simulation simulation(xy_stage_model(), *machine);
  SceneRenderOptions options;
  options.width = 4000;
  try {
    render_scene_rgb(simulation, HeightMap{}, options);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("offwidth"), std::string::npos) << error.what();
  }
}

TEST(Viridis, RunsFromDarkPurpleToYellowWithRisingLightness) {
  float rgb[3];
  viridis(0.0, rgb);
  EXPECT_NEAR(rgb[0], 68 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[1], 1 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[2], 84 / 255.0, 1e-6);
  viridis(1.0, rgb);
  EXPECT_NEAR(rgb[0], 253 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[1], 231 / 255.0, 1e-6);
  EXPECT_NEAR(rgb[2], 37 / 255.0, 1e-6);
  // perceptual: the luma rises monotonically, so thicker always looks lighter
  double previous = -1.0;
  for (int i = 0; i <= 64; ++i) {
    viridis(i / 64.0, rgb);
    const double luma = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    EXPECT_GT(luma, previous) << i;
    previous = luma;
  }
}

}  // namespace
}  // namespace depotwin
