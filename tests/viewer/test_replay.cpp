// The replay data every run writes (report/replay_io, pipeline/replay): its timing in closed
// form, the files read back as written, the deposit growing as the run deposited it, and the
// machine put back where the run had it (the delta's passive rods and platform included).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "pipeline/pipeline_test_util.hpp"
#include "pipeline/quiet_settings.hpp"
#include "pipeline/replay.hpp"
#include "pipeline/run.hpp"
#include "report/replay_io.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"
#include "viewer/replay_test_fixture.hpp"

namespace depotwin {
namespace {

namespace fs = std::filesystem;
using testing_support::fresh_directory;
using testing_support::quiet;
using testing_support::scenario_path;
using testing_support::write_text;

TEST(ReplayTiming, RealTimeWhenItFitsElseTheSmallestListedSpeedup) {
  // thompson_fig7's 19.355 s: real time, ceil(19.355 * 15) + 1 frames
  const ReplayTiming fig7 = replay_timing(19.355, 30.0, 15.0);
  EXPECT_EQ(fig7.speedup, 1.0);
  EXPECT_EQ(fig7.frames, 292);
  EXPECT_DOUBLE_EQ(fig7.time_of(0), 0.0);
  EXPECT_DOUBLE_EQ(fig7.time_of(15), 1.0);
  EXPECT_DOUBLE_EQ(fig7.time_of(291), 19.355);  // the last frame shows the end itself
  // 100 s in 30 s: 3.33 needed, 4 is the next listed; 558 s: 18.6 -> 20
  const ReplayTiming hundred = replay_timing(100.0, 30.0, 15.0);
  EXPECT_EQ(hundred.speedup, 4.0);
  EXPECT_EQ(hundred.frames, 376);  // ceil(100 * 15 / 4) + 1
  EXPECT_LE(hundred.video_length_s(), 30.0);
  EXPECT_EQ(replay_timing(558.0, 30.0, 15.0).speedup, 20.0);
  // the frames at both ends count: 60 s at 2x is 451 frames, 30.07 s; 10 s at 5x, 2.07 s
  EXPECT_EQ(replay_timing(60.0, 30.0, 15.0).speedup, 2.5);
  EXPECT_EQ(replay_timing(10.0, 2.0, 15.0).speedup, 6.0);
  EXPECT_EQ(replay_timing(29.9, 30.0, 15.0).speedup, 1.0);      // 450 frames, 30 s
  EXPECT_EQ(replay_timing(1e6, 0.01, 15.0).frames, 2);          // too short for more: both ends
  EXPECT_EQ(replay_timing(2500.0, 30.0, 15.0).speedup, 100.0);  // 83.3 -> 100
  // nothing simulated: one frame
  EXPECT_EQ(replay_timing(0.0, 30.0, 15.0).frames, 1);
  EXPECT_THROW(replay_timing(10.0, 0.0, 15.0), InputError);
  EXPECT_THROW(replay_timing(10.0, 30.0, -1.0), InputError);
  EXPECT_EQ(speedup_text(1.0), "real time");
  EXPECT_EQ(speedup_text(2.5), "2.5x speed-up");
  EXPECT_EQ(speedup_text(20.0), "20x speed-up");
}

// a hand-made replay of three frames on a 3 x 2 grid
ReplayData small_replay() {
  ReplayData replay;
  replay.scenario = "s";
  replay.run_label = "p";
  replay.machine = "xy_stage";
  replay.process = "aerosol";
  replay.has_shutter = true;
  replay.model_source = "/nowhere/model.xml";
  replay.model_text = "<mujoco/>\n";
  replay.timing = replay_timing(2.0, 30.0, 1.0);  // frames at 0, 1, 2 s
  replay.nq = 2;
  for (int k = 0; k < 3; ++k) {
    replay.t_s.push_back(k);
    replay.qpos.push_back(0.1 * k);
    replay.qpos.push_back(-0.2 * k);
    replay.open_fraction.push_back(k == 1 ? 1.0f : 0.0f);
    replay.flow_fraction.push_back(0.0f);
    replay.depositing.push_back(k == 1);
    replay.path_index.push_back(k == 1 ? 0 : -1);
    replay.layer.push_back(0);
    replay.nozzle_mm.emplace_back(k, 2.0 * k, 0.5);
  }
  ReplayDeposit& d = replay.deposit;
  d.origin_x_mm = -1.0;
  d.origin_y_mm = 2.0;
  d.cell_mm = 0.5;
  d.nx = 3;
  d.ny = 2;
  d.peak_um = 4.0f;
  // frame 0: nothing; frame 1: cells 1 and 4; frame 2: cell 4 thicker, cell 5 new
  d.frame_begin = {0, 0, 2, 4};
  d.cell = {1, 4, 4, 5};
  d.thickness_um = {1.0f, 2.0f, 4.0f, 0.5f};
  return replay;
}

TEST(ReplayIo, ReadsBackWhatItWrote) {
  const std::string dir = fresh_directory("replay_io");
  const ReplayData written = small_replay();
  write_replay(written, dir);
  for (const char* file : {kReplayJson, kReplayModel, kReplayDeposit})
    EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / file)) << file;
  // header 8 + 6 x 4 bytes, offsets 4 x 4, cells 4 x 4, values 4 x 4
  EXPECT_EQ(fs::file_size(fs::path(dir) / kReplayDeposit), 8u + 24u + 16u + 16u + 16u);

  const ReplayData read = read_replay(dir);
  EXPECT_EQ(read.scenario, "s");
  EXPECT_EQ(read.run_label, "p");
  EXPECT_EQ(read.process, "aerosol");
  EXPECT_TRUE(read.has_shutter);
  EXPECT_EQ(read.model_source, "/nowhere/model.xml");
  EXPECT_EQ(read.model_text, "<mujoco/>\n");
  EXPECT_EQ(read.timing.frames, 3);
  EXPECT_EQ(read.t_s, written.t_s);
  EXPECT_EQ(read.qpos, written.qpos);
  EXPECT_EQ(read.open_fraction, written.open_fraction);
  EXPECT_EQ(read.depositing, written.depositing);
  EXPECT_EQ(read.path_index, written.path_index);
  EXPECT_EQ(read.nozzle_mm[2], Vec3(2.0, 4.0, 0.5));
  EXPECT_EQ(read.deposit.cell, written.deposit.cell);
  EXPECT_EQ(read.deposit.thickness_um, written.deposit.thickness_um);
  EXPECT_EQ(read.deposit.nx, 3);
  EXPECT_DOUBLE_EQ(read.deposit.origin_y_mm, 2.0);

  // the deposit at each frame, forwards and back again
  DepositPlayback playback(read.deposit);
  const std::vector<float> at0(6, 0.0f), at1 = {0, 1, 0, 0, 2, 0}, at2 = {0, 1, 0, 0, 4, 0.5f};
  EXPECT_EQ(playback.at(2).thickness_um, at2);
  EXPECT_EQ(playback.at(0).thickness_um, at0);
  EXPECT_EQ(playback.at(1).thickness_um, at1);
  EXPECT_EQ(playback.at(2).thickness_um, at2);
  EXPECT_EQ(playback.at(99).thickness_um, at2);  // clamped to the last frame
  EXPECT_DOUBLE_EQ(playback.at(0).cell_mm, 0.5);

  // the same replay gives the same bytes
  const std::string again = fresh_directory("replay_io_again");
  write_replay(written, again);
  for (const char* file : {kReplayJson, kReplayDeposit})
    EXPECT_EQ(read_text_file((fs::path(dir) / file).string()),
              read_text_file((fs::path(again) / file).string()))
        << file;
}

// the first problem's text of an InputError thrown by f
template <class F>
std::string input_error(F f) {
  try {
    f();
  } catch (const InputError& error) {
    return error.problems().front().str();
  }
  return "(no InputError)";
}

TEST(ReplayIo, AFolderWithoutReplayDataOrABrokenFileIsNamed) {
  const std::string empty = fresh_directory("replay_none");
  const std::string none = input_error([&] { read_replay(empty); });
  EXPECT_NE(none.find(empty), std::string::npos) << none;
  EXPECT_NE(none.find("holds no replay data (replay.json)"), std::string::npos) << none;
  EXPECT_NE(input_error([&] { read_replay(empty + "/missing"); }).find("is not a folder"),
            std::string::npos);

  // a truncated deposit file, a per-frame array of the wrong length
  const std::string dir = fresh_directory("replay_broken");
  write_replay(small_replay(), dir);
  const std::string deposit = (fs::path(dir) / kReplayDeposit).string();
  const std::string bytes = read_text_file(deposit);
  write_file_atomically(deposit, bytes.substr(0, bytes.size() - 3));
  const std::string truncated = input_error([&] { read_replay(dir); });
  EXPECT_NE(truncated.find(deposit), std::string::npos) << truncated;
  EXPECT_NE(truncated.find("truncated or corrupt"), std::string::npos) << truncated;
  write_file_atomically(deposit, bytes);
  const std::string json = (fs::path(dir) / kReplayJson).string();
  std::string text = read_text_file(json);
  const size_t at = text.find("\"t_s\":[0.0,1.0,2.0]");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, 19, "\"t_s\":[0.0,1.0]");
  write_file_atomically(json, text);
  const std::string short_array = input_error([&] { read_replay(dir); });
  EXPECT_NE(short_array.find(json + ": t_s: has 2 entries, expected 3"), std::string::npos)
      << short_array;
}

TEST(Replay, TheDepositGrowsAsTheRunDepositedIt) {
  testing_support::ReplayFixture fixture(scenario_path("thompson_fig7.yaml"));
  const ReplayData& replay = fixture.replay;
  const ReplayTiming& timing = replay.timing;
  ASSERT_EQ(replay.frame_count(), static_cast<size_t>(timing.frames));
  EXPECT_DOUBLE_EQ(replay.t_s.front(), 0.0);
  EXPECT_DOUBLE_EQ(replay.t_s.back(), fixture.run.record.t_s.back());

  // each frame's deposit volume against the aerosol that passed the shutter up to its time:
  // Q times the integral of the open fraction (trapezoids over the recorded steps)
  const RecordedRun& record = fixture.run.record;
  const double flow_mm3_s = deposition_settings(fixture.job.scenario).aerosol_flow_mm3_s();
  const double job_end_s = fixture.run.plan.trajectory.duration_s();
  DepositPlayback playback(replay.deposit);
  const double cell_area_mm2 = replay.deposit.cell_mm * replay.deposit.cell_mm;
  double previous_mm3 = -1.0, landed_mm3 = 0.0;
  size_t step = 0;
  for (size_t frame = 0; frame < replay.frame_count(); ++frame) {
    const HeightMap& map = playback.at(frame);
    double volume_mm3 = 0.0;
    for (const float t_um : map.thickness_um) volume_mm3 += 1e-3 * t_um * cell_area_mm2;
    for (; step + 1 < record.size() && record.t_s[step] < replay.t_s[frame] - 1e-9 &&
           record.t_s[step] < job_end_s;
         ++step)
      landed_mm3 += flow_mm3_s * (record.t_s[step + 1] - record.t_s[step]) * 0.5 *
                    (record.open_fraction[step] + record.open_fraction[step + 1]);
    EXPECT_GE(volume_mm3, previous_mm3) << "frame " << frame;  // a deposit only grows
    EXPECT_NEAR(volume_mm3, landed_mm3, 5e-3 * fixture.run.deposit->account().landed_mm3 + 1e-12)
        << "frame " << frame << " t = " << replay.t_s[frame];
    previous_mm3 = volume_mm3;
  }
  EXPECT_EQ(playback.at(0).max_value(), 0.0f);  // nothing at t = 0
  // the last frame holds the run's whole deposit
  EXPECT_NEAR(previous_mm3, fixture.run.deposit->field().total_volume_mm3(),
              1e-4 * fixture.run.deposit->field().total_volume_mm3());
  // and its peak: the run's on a grid at most as fine, block-averaged
  EXPECT_GT(replay.deposit.peak_um, 0.5f * fixture.run_peak_um());
  EXPECT_LE(replay.deposit.peak_um, 1.02f * fixture.run_peak_um());
  // small: at most a few entries per cell
  EXPECT_LT(replay.deposit.cell.size(), 8u * replay.deposit.nx * replay.deposit.ny);
}

TEST(Replay, TheMachineIsWhereTheRunHadIt) {
  // the nozzle site placed by each frame's qpos against the record's nozzle. The XY stage's
  // joints come from the record at the frame's time, whose nearest step is up to half a step
  // away (0.5 ms at <= 4 mm/s: 2 um). The delta's rods and free platform are interpolated
  // between states sampled every 64 ms (0.019 mm at worst on thompson_fig7_delta; 0.21 mm on
  // giberti_circle, where linear interpolation misses up to a T^2 / 8 = 0.26 mm of the move
  // from the centre, accelerating at 500 mm/s^2). The
  // first frame holds the first sample, 1 ms in (before, 64 ms in: the platform, settling on
  // its rods and moving at once on giberti_circle, showed 1.4 mm off at frame 0).
  struct Case {
    const char* scenario;
    double bound_mm;
  };
  for (const Case& c : {Case{"thompson_fig7.yaml", 0.005}, Case{"thompson_fig7_delta.yaml", 0.05},
                        Case{"giberti_circle.yaml", 0.25}}) {
    testing_support::ReplayFixture fixture(scenario_path(c.scenario));
    size_t frame = 0;
    const double worst_mm = fixture.worst_nozzle_error_mm(&frame, 1);
    EXPECT_LT(worst_mm, c.bound_mm)
        << c.scenario << ": frame " << frame << " at t = " << fixture.replay.t_s[frame] << " s";
    EXPECT_LT(fixture.worst_nozzle_error_mm(nullptr, 0, 1), 0.01) << c.scenario;
  }
}

}  // namespace
}  // namespace depotwin
