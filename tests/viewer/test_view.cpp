// `depotwin view RUN_DIR` (viewer/): its help names the keys, a folder without replay data is
// bad input, and under Xvfb a screenshot rendered in the window shows the machine and, at the
// end of the run but not at its start, the deposit in its viridis colours.
#define STB_IMAGE_IMPLEMENTATION  // stb_image.h, included once by png_check.hpp
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "pipeline/pipeline_test_util.hpp"
#include "plots/png_check.hpp"
#include "render/deposit_mesh.hpp"
#include "viewer/small_scenario.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::CliResult;
using testing_support::depotwin;
using testing_support::fresh_directory;

TEST(View, HelpNamesTheKeys) {
  const CliResult help = depotwin("view --help");
  EXPECT_EQ(help.status, 0);
  for (const char* words : {"run_dir", "--screenshot", "--at", "space: play / pause",
                            "left / right arrow", "timeline bar"})
    EXPECT_NE(help.output.find(words), std::string::npos) << words << "\n" << help.output;
}

TEST(View, AFolderWithoutReplayDataIsBadInput) {
  const std::string dir = fresh_directory("view_no_replay");
  const CliResult view = depotwin("view " + dir + " --screenshot " + dir + "/shot.png");
  EXPECT_EQ(view.status, 2) << view.output;
  EXPECT_NE(view.output.find("error: " + dir + ": RUN_DIR: holds no replay data"),
            std::string::npos)
      << view.output;
  EXPECT_FALSE(fs::exists(dir + "/shot.png"));
  EXPECT_EQ(depotwin("view").status, 2);  // the folder is required
}

// --screenshot replaces only a PNG (it was written over the run's replay.json and over a
// scenario), in a folder that exists; --at must be a time of the run (NaN and -1 showed the
// end); each named by its flag, exit 2, before any window opens and with nothing written
TEST(View, ScreenshotPathsAndTimesAreChecked) {
  const std::string dir = fresh_directory("view_bad_options");
  const std::string data = dir + "/replay.json";
  { std::ofstream(data) << "{\"kind\": \"replay data\"}\n"; }
  const CliResult over_data = depotwin("view " + dir + " --screenshot " + data);
  EXPECT_EQ(over_data.status, 2) << over_data.output;
  EXPECT_NE(
      over_data.output.find("error: --screenshot: '" + data + "' exists and is not a PNG image"),
      std::string::npos)
      << over_data.output;
  std::ifstream kept(data);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), "{\"kind\": \"replay data\"}\n");
  const CliResult no_folder = depotwin("view " + dir + " --screenshot " + dir + "/none/x.png");
  EXPECT_EQ(no_folder.status, 2) << no_folder.output;
  EXPECT_NE(no_folder.output.find("error: --screenshot: '" + dir + "/none' is not a directory"),
            std::string::npos)
      << no_folder.output;
  for (const char* at : {"nan", "-1", "inf"}) {
    const CliResult bad_time = depotwin("view " + dir + " --at " + at);
    EXPECT_EQ(bad_time.status, 2) << at << ": " << bad_time.output;
    EXPECT_NE(bad_time.output.find("error: --at: a run time in seconds, 0 or more"),
              std::string::npos)
        << bad_time.output;
  }
  const CliResult narrow = depotwin("view " + dir + " --width -1");
  EXPECT_EQ(narrow.status, 2) << narrow.output;
  EXPECT_NE(
      narrow.output.find("error: --width: the window must be 64 to 16384 pixels wide, got -1"),
      std::string::npos)
      << narrow.output;
  // beyond the largest window (it wrapped round: 65636 made a 100-pixel window, exit 0)
  for (const char* option : {"--width", "--height"}) {
    const CliResult huge = depotwin("view " + dir + " " + option + " 65636");
    EXPECT_EQ(huge.status, 2) << huge.output;
    EXPECT_NE(huge.output.find(std::string("error: ") + option +
                               ": the window must be 64 to 16384 pixels"),
              std::string::npos)
        << huge.output;
  }
}

// pixels of a PNG as RGB
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};
Image load(const std::string& path) {
  Image image;
  int channels = 0;
  unsigned char* pixels = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  if (pixels == nullptr) return image;
  image.rgb.assign(pixels, pixels + static_cast<size_t>(image.width) * image.height * 3);
  stbi_image_free(pixels);
  return image;
}

// pixels of the close-up panel (the right half, above the colour bar strip in the bottom
// quarter) within a small distance of a viridis colour past its dark end: the deposit's
// colours (the machine and the floor are greys, blues and an orange flap)
size_t viridis_pixels(const Image& image) {
  std::array<std::array<float, 3>, 41> palette;
  for (size_t i = 0; i < palette.size(); ++i)
    viridis(0.2 + 0.8 * static_cast<double>(i) / (palette.size() - 1), palette[i].data());
  size_t count = 0;
  for (int y = 0; y < image.height * 3 / 4; ++y)
    for (int x = image.width / 2; x < image.width; ++x) {
      const unsigned char* pixel =
          image.rgb.data() + 3 * (static_cast<size_t>(y) * image.width + x);
      float best = 1e9f;
      for (const auto& colour : palette) {
        float distance = 0.0f;
        for (int c = 0; c < 3; ++c) {
          const float d = pixel[c] / 255.0f - colour[c];
          distance += d * d;
        }
        best = std::min(best, distance);
      }
      if (best < 0.04f * 0.04f) ++count;
    }
  return count;
}

TEST(View, AScreenshotInTheWindowUnderXvfbShowsTheDepositGrown) {
  if (testing_support::depotwin("--version").status != 0) GTEST_FAIL() << "no depotwin binary";
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/setup.sh installs xvfb and xauth)";
  const std::string dir = fresh_directory("view_screenshot");
  const std::string scenario = testing_support::write_small_scenario(dir);
  const CliResult run = depotwin("run " + scenario + " --out " + dir + "/out --no-render --quiet");
  ASSERT_EQ(run.status, 0) << run.output;
  const std::string run_dir = dir + "/out/lspb_mtt";

  // the end of the run (the default) and its start, 640 x 320 in the window
  const std::string xvfb = "xvfb-run -a -s '-screen 0 800x600x24' ";
  auto screenshot = [&](const std::string& png, const std::string& extra) {
    const std::string command = xvfb + std::string(DEPOTWIN_BINARY_DIR) + "/depotwin view " +
                                run_dir + " --screenshot " + png + " --width 640 --height 320 " +
                                extra + " 2>&1";
    CliResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
    const int status = ::pclose(pipe);
    result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
  };
  const std::string end_png = dir + "/end.png", start_png = dir + "/start.png";
  const CliResult end = screenshot(end_png, "");
  ASSERT_EQ(end.status, 0) << end.output;
  EXPECT_NE(end.output.find("screenshot of t = "), std::string::npos) << end.output;
  const CliResult start = screenshot(start_png, "--at 0");
  ASSERT_EQ(start.status, 0) << start.output;

  const Image end_image = load(end_png), start_image = load(start_png);
  ASSERT_EQ(end_image.width, 640);
  ASSERT_EQ(end_image.height, 320);
  EXPECT_GT(testing_support::pixel_variance(testing_support::read_bytes(end_png)), 100.0);
  // the deposit's colours in the close-up: plenty at the end, none before anything was printed
  const size_t at_end = viridis_pixels(end_image), at_start = viridis_pixels(start_image);
  EXPECT_GT(at_end, 300u);
  EXPECT_LT(at_start, 10u) << at_start << " at the start, " << at_end << " at the end";
  // a time after the run's end is named (it showed the end), and the PNG there stays
  const CliResult late = screenshot(end_png, "--at 1e308");
  EXPECT_EQ(late.status, 2) << late.output;
  EXPECT_NE(late.output.find("error: --at: 1e+308 s is after the run's end"), std::string::npos)
      << late.output;
  EXPECT_EQ(load(end_png).width, 640);
}

}  // namespace
}  // namespace depotwin
