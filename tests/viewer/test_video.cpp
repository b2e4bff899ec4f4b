// `depotwin run --video` (render/video.hpp): run.mp4 is H.264 of the stated size with one frame
// per replay frame at the stated rate and speed-up, and without ffmpeg the run fails cleanly.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/pipeline_test_util.hpp"
#include "report/replay_io.hpp"
#include "viewer/small_scenario.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::CliResult;
using testing_support::depotwin;
using testing_support::fresh_directory;
using testing_support::read_text;
using testing_support::shell;

bool has_program(const std::string& name) {
  return shell("command -v " + name + " >/dev/null").status == 0;
}

TEST(Video, RunWritesAnH264OfTheReplaysFramesAtTheStatedSpeedup) {
  if (!has_program("ffmpeg") || !has_program("ffprobe"))
    GTEST_SKIP() << "ffmpeg/ffprobe not installed (scripts/setup.sh installs them)";
  const std::string dir = fresh_directory("video_run");
  const std::string scenario = testing_support::write_small_scenario(dir);
  // the job lasts about 10 s: at most 2 s of video is a 5x speed-up
  const CliResult run = depotwin("run " + scenario + " --out " + dir +
                                 "/out --no-render --quiet --video --video-length 2");
  ASSERT_EQ(run.status, 0) << run.output;
  const std::string run_dir = dir + "/out/lspb_mtt";
  const ReplayData replay = read_replay(run_dir);
  const ReplayTiming expected = replay_timing(replay.timing.duration_s, 2.0, kDefaultVideoFps);
  EXPECT_EQ(replay.timing.speedup, expected.speedup);
  EXPECT_EQ(replay.timing.frames, expected.frames);
  EXPECT_GT(replay.timing.speedup, 1.0);
  EXPECT_LE(replay.timing.video_length_s(), 2.0);
  // the console states the length and the speed-up
  EXPECT_NE(run.output.find("run.mp4, "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(speedup_text(replay.timing.speedup)), std::string::npos) << run.output;

  // what ffprobe reads: H.264, 4:2:0, 960 x 480, one frame per replay frame, at 15 fps
  const std::string mp4 = run_dir + "/run.mp4";
  ASSERT_TRUE(fs::is_regular_file(mp4));
  const CliResult probe = shell(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,pix_fmt,width,height,nb_read_frames,avg_frame_rate "
      "-show_entries format=duration -of json " +
      mp4);
  ASSERT_EQ(probe.status, 0) << probe.output;
  const nlohmann::json info = nlohmann::json::parse(probe.output);
  const nlohmann::json& stream = info["streams"][0];
  EXPECT_EQ(stream["codec_name"], "h264");
  EXPECT_EQ(stream["pix_fmt"], "yuv420p");
  EXPECT_EQ(stream["width"], 960);
  EXPECT_EQ(stream["height"], 480);
  EXPECT_EQ(stream["avg_frame_rate"], "15/1");
  EXPECT_EQ(std::stoi(stream["nb_read_frames"].get<std::string>()), replay.timing.frames);
  EXPECT_NEAR(std::stod(info["format"]["duration"].get<std::string>()),
              replay.timing.frames / kDefaultVideoFps, 0.1);
  // nothing left beside it
  for (const auto& entry : fs::directory_iterator(run_dir))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

TEST(Video, WithoutFfmpegTheRunFailsAndWritesNothing) {
  const std::string dir = fresh_directory("video_no_ffmpeg");
  const std::string scenario = testing_support::write_small_scenario(dir);
  // a PATH without ffmpeg (the binary is called by its full path)
  const CliResult run =
      shell("env PATH=" + dir + " " + std::string(DEPOTWIN_BINARY_DIR) + "/depotwin run " +
            scenario + " --out " + dir + "/out --no-render --quiet --video");
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("error: --video: ffmpeg is not installed"), std::string::npos)
      << run.output;
  EXPECT_FALSE(fs::exists(dir + "/out/lspb_mtt")) << "a run folder was left";
  EXPECT_EQ(depotwin("run " + scenario + " --out " + dir + "/out --video --video-length 0").status,
            2);
}

// a video length without --video would be ignored in silence: it is refused, naming both
TEST(Video, ALengthWithoutTheVideoIsRefused) {
  const std::string dir = fresh_directory("video_length_alone");
  const std::string scenario = testing_support::write_small_scenario(dir);
  for (const char* verb : {"run", "compare"}) {
    const CliResult alone = depotwin(std::string(verb) + " " + scenario + " --out " + dir +
                                     "/alone --quiet --video-length 5");
    EXPECT_EQ(alone.status, 2) << alone.output;
    EXPECT_NE(alone.output.find("--video-length requires --video"), std::string::npos)
        << alone.output;
    EXPECT_FALSE(fs::exists(dir + "/alone")) << verb;
  }
}

}  // namespace
}  // namespace depotwin
