// The replay data of a run: what `depotwin view` and run.mp4 need to show a finished run
// again, sampled at frame times. Every run folder holds it (format version 1):
//
//   replay.json         the frames' times and the machine's state at each: MuJoCo's qpos
//                       (SI units, the model's joint order), the shutter's open fraction, the
//                       flow command, the depositing flag, the print path and layer, the nozzle
//                       in the substrate frame (mm); the timing (fps, speed-up) and the deposit
//                       grid (origin, cell, size, peak)
//   replay_model.xml    the MJCF the run simulated (a conformal job's with its part added);
//                       its relative asset paths resolve against `model.source`, the file it
//                       came from
//   replay_deposit.bin  the deposit's growth on the grid: for each frame, the cells whose
//                       thickness changed since they were last stored, little-endian:
//                         char[8] "DTREPLAY", u32 version (1), u32 nx, u32 ny, u32 frames,
//                         u32 entries, u32 has_surface (0|1);
//                         f32 surface_z_mm[nx * ny] if has_surface (NaN: off the part);
//                         u32 frame_begin[frames + 1] (frame k's entries: [begin[k], begin[k+1]));
//                         u32 cell[entries] (iy * nx + ix); f32 thickness_um[entries]
//
// The deposit at frame k is every cell's last entry at or before frame k (0 before its
// first): the thickness along the surface normal (um) at that frame's time, to 0.1 % of the
// peak so far (smaller changes wait until they add up to that; the last frame is exact on the
// grid). How the grid and its values are made: pipeline/replay.hpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/types.hpp"

namespace depotwin {

// The frames of a replay or video, 1 / fps apart in video time, the first at t = 0 and the last
// at the run's end: real time when those frames fit in max_length_s of video, else sped up by
// the smallest of 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 15, 20, ... that makes them fit.
struct ReplayTiming {
  double duration_s = 0.0;  // the run's simulated time (the last frame's time)
  double fps = 0.0;         // frames per second of video
  double speedup = 1.0;     // run seconds per video second
  int frames = 0;           // ceil(duration * fps / speedup) + 1: t = 0 and the end included

  // run time of frame k: k * speedup / fps, the last one the run's end
  double time_of(int frame) const;
  // the video's length (frames / fps)
  double video_length_s() const { return frames / fps; }
};
// InputError ("--video-length" / "--video-fps") for a length or rate that is not positive
ReplayTiming replay_timing(double duration_s, double max_length_s, double fps);
// "real time", "2x speed-up", "12.5x speed-up"
std::string speedup_text(double speedup);

// the default video: at most 30 s, 15 frames a second
constexpr double kDefaultVideoLength_s = 30.0;
constexpr double kDefaultVideoFps = 15.0;

// The deposit's growth on a fixed grid (the final deposit's bounds), as stored.
struct ReplayDeposit {
  double origin_x_mm = 0.0;  // centre of cell (0, 0), substrate frame
  double origin_y_mm = 0.0;
  double cell_mm = 0.0;
  int nx = 0, ny = 0;
  float peak_um = 0.0f;  // the final deposit's thickest cell
  // the part's surface height under each cell (conformal work; NaN off the part); empty: flat
  std::vector<float> surface_z_mm;
  std::vector<uint32_t> frame_begin;  // frames + 1 offsets into cell / thickness_um
  std::vector<uint32_t> cell;
  std::vector<float> thickness_um;
};

struct ReplayData {
  std::string scenario;  // names, for the overlay
  std::string run_label;
  std::string machine;
  std::string process;  // "aerosol" | "extrusion"
  bool has_shutter = false;
  std::string model_source;  // the MJCF file the run used (absolute)
  std::string model_text;    // the MJCF it compiled (replay_model.xml)
  ReplayTiming timing;
  std::vector<double> t_s;  // per frame
  int nq = 0;
  std::vector<double> qpos;  // frame-major, nq per frame
  std::vector<float> open_fraction, flow_fraction;
  std::vector<uint8_t> depositing;
  std::vector<int> path_index, layer;  // -1: a transition
  std::vector<Vec3> nozzle_mm;
  ReplayDeposit deposit;

  size_t frame_count() const { return t_s.size(); }
  const double* qpos_of(size_t frame) const { return qpos.data() + frame * nq; }
};

// the three files into `directory` (each written atomically; the run folder is staged)
void write_replay(const ReplayData& replay, const std::string& directory);
// InputError naming the folder or the file and key when `run_directory` holds no replay data
// (an older run, another folder) or a malformed one
ReplayData read_replay(const std::string& run_directory);

constexpr const char* kReplayJson = "replay.json";
constexpr const char* kReplayModel = "replay_model.xml";
constexpr const char* kReplayDeposit = "replay_deposit.bin";

// The deposit at any frame, built from the stored changes: forward steps apply the frames in
// between, a step back starts again from frame 0 (a few ms for a full grid).
class DepositPlayback {
 public:
  explicit DepositPlayback(const ReplayDeposit& deposit);
  const HeightMap& at(size_t frame);

 private:
  const ReplayDeposit& deposit_;
  HeightMap map_;
  size_t applied_ = 0;  // frames applied to map_ (0: none)
};

}  // namespace depotwin
