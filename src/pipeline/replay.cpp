#include "pipeline/replay.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "deposition/job_deposition.hpp"
#include "deposition/layered_deposit.hpp"
#include "pipeline/run.hpp"
#include "render/state_samples.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

// a change smaller than this fraction of the peak so far waits for the next frame
constexpr double kStoredChange = 1e-3;

// the record's entry k as the state the deposition reads
StepState state_of(const RecordedRun& record, size_t k) {
  StepState state;
  state.t_s = record.t_s[k];
  state.nozzle_mm = record.nozzle_mm[k];
  state.nozzle_velocity_mm_s = record.nozzle_velocity_mm_s[k];
  state.open_fraction = record.open_fraction[k];
  state.deposit_command = record.deposit_command[k] != 0;
  state.flow_fraction = record.flow_fraction[k];
  state.desired_speed_mm_s = record.desired_speed_mm_s[k];
  state.path_index = record.path_index[k];
  return state;
}

// the record's entry nearest t (entries are timestep_s apart from t_s[0])
size_t entry_at(const RecordedRun& record, double t_s) {
  const double dt = record.timestep_s > 0.0 ? record.timestep_s : 1.0;
  const double position = std::round((t_s - record.t_s.front()) / dt);
  return static_cast<size_t>(std::clamp(position, 0.0, static_cast<double>(record.size() - 1)));
}

// the deposit grid: the final deposit's bounds on the replay lattice, and per grid cell the
// part's slope (n_z) and height
struct ReplayGrid {
  double process_cell_mm = 0.0;  // the replay deposition's cell
  int stride = 1;                // process cells per grid cell (a side)
  double x_lo_mm = 0, y_lo_mm = 0, x_hi_mm = 0, y_hi_mm = 0;
  HeightMap shape;  // origin, cell, nx, ny (thickness zero)
  std::vector<double> normal_z;
};

ReplayGrid replay_grid(const PreparedJob& job, const SimulatedRun& run, const FieldBounds& b) {
  ReplayGrid grid;
  const double fine_cell_mm = run.deposit->normal_field().cell_mm();
  const double sigma_mm = run.deposit->footprint_sigma_mm();
  const double extent_mm = std::max(b.x_hi_mm - b.x_lo_mm, b.y_hi_mm - b.y_lo_mm) + fine_cell_mm;
  grid.process_cell_mm = std::min(sigma_mm, std::max(fine_cell_mm, extent_mm / kReplayGridCells));
  grid.stride = std::max(
      1, static_cast<int>(std::ceil(extent_mm / (kReplayGridCells * grid.process_cell_mm) - 1e-9)));
  // the bounds widened to whole process cells (the coarse footprint reaches as far)
  const double c = grid.process_cell_mm;
  grid.x_lo_mm = std::floor(b.x_lo_mm / c) * c;
  grid.y_lo_mm = std::floor(b.y_lo_mm / c) * c;
  grid.x_hi_mm = std::ceil(b.x_hi_mm / c) * c;
  grid.y_hi_mm = std::ceil(b.y_hi_mm / c) * c;
  grid.shape = ThicknessField(c).to_heightmap(grid.x_lo_mm, grid.y_lo_mm, grid.x_hi_mm,
                                              grid.y_hi_mm, grid.stride);
  // on a part: vertical thickness -> along the normal, as the run's deposit (job_deposit)
  grid.normal_z.assign(grid.shape.thickness_um.size(), 1.0);
  if (job.surface)
    for (int iy = 0; iy < grid.shape.ny; ++iy)
      for (int ix = 0; ix < grid.shape.nx; ++ix) {
        const std::optional<SurfaceHit> hit =
            job.surface->project_down(grid.shape.origin_x_mm + ix * grid.shape.cell_mm,
                                      grid.shape.origin_y_mm + iy * grid.shape.cell_mm);
        if (hit && hit->faces_up())
          grid.normal_z[static_cast<size_t>(iy) * grid.shape.nx + ix] = hit->normal.z();
      }
  return grid;
}

// The grid blocks a set of nozzle positions can have deposited on: their bounding box widened
// by the footprint's reach (a node's footprint fades out by truncation_sigmas + 0.25 sigma)
// and one block, as an inclusive range of grid columns and rows.
class DirtyBox {
 public:
  void add(const Vec3& p_mm) {
    x_lo_ = std::min(x_lo_, p_mm.x());
    y_lo_ = std::min(y_lo_, p_mm.y());
    x_hi_ = std::max(x_hi_, p_mm.x());
    y_hi_ = std::max(y_hi_, p_mm.y());
  }
  bool empty() const { return !(x_lo_ <= x_hi_); }
  void clear() { *this = DirtyBox(); }
  // grid blocks [ix0, ix1] x [iy0, iy1]; false when none
  bool blocks(const HeightMap& grid, double reach_mm, int& ix0, int& ix1, int& iy0,
              int& iy1) const {
    if (empty() || grid.nx <= 0 || grid.ny <= 0) return false;
    auto column = [&](double x_mm) {
      return static_cast<int>(std::floor((x_mm - grid.origin_x_mm) / grid.cell_mm + 0.5));
    };
    auto row = [&](double y_mm) {
      return static_cast<int>(std::floor((y_mm - grid.origin_y_mm) / grid.cell_mm + 0.5));
    };
    ix0 = std::max(0, column(x_lo_ - reach_mm) - 1);
    iy0 = std::max(0, row(y_lo_ - reach_mm) - 1);
    ix1 = std::min(grid.nx - 1, column(x_hi_ + reach_mm) + 1);
    iy1 = std::min(grid.ny - 1, row(y_hi_ + reach_mm) + 1);
    return ix0 <= ix1 && iy0 <= iy1;
  }

 private:
  double x_lo_ = std::numeric_limits<double>::infinity();
  double y_lo_ = std::numeric_limits<double>::infinity();
  double x_hi_ = -std::numeric_limits<double>::infinity();
  double y_hi_ = -std::numeric_limits<double>::infinity();
};

// Stores the cells of the grid that moved away from what was stored last (by more than
// kStoredChange of the peak so far; by anything at all on the last frame), a frame at a time.
class ChangeEncoder {
 public:
  ChangeEncoder(ReplayDeposit& out, size_t cells) : out_(out), stored_(cells, 0.0f) {
    out_.frame_begin.push_back(0);
  }
  // the cells of `grid` (nx wide) in blocks [ix0, ix1] x [iy0, iy1] (none: an empty range)
  void add_frame(const std::vector<float>& grid, int nx, int ix0, int ix1, int iy0, int iy1,
                 bool last) {
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix)
        peak_ = std::max(peak_, grid[static_cast<size_t>(iy) * nx + ix]);
    const float tolerance = static_cast<float>(kStoredChange) * peak_;
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        const size_t i = static_cast<size_t>(iy) * nx + ix;
        const float change = std::abs(grid[i] - stored_[i]);
        if (last ? change == 0.0f : change <= tolerance) continue;
        stored_[i] = grid[i];
        out_.cell.push_back(static_cast<uint32_t>(i));
        out_.thickness_um.push_back(grid[i]);
      }
    out_.frame_begin.push_back(static_cast<uint32_t>(out_.cell.size()));
  }
  float peak() const { return peak_; }

 private:
  ReplayDeposit& out_;
  std::vector<float> stored_;
  float peak_ = 0.0f;
};

}  // namespace

ReplayTiming run_replay_timing(const SimulatedRun& run, double max_length_s, double fps) {
  const double duration_s = run.record.size() > 0 ? run.record.t_s.back() : 0.0;
  return replay_timing(duration_s, max_length_s, fps);
}

ReplayDeposit replay_deposit(const PreparedJob& job, const SimulatedRun& run,
                             const ReplayTiming& timing) {
  ReplayDeposit out;
  const FieldBounds bounds = run.deposit->normal_field().bounds();
  const RecordedRun& record = run.record;
  if (bounds.empty || record.size() < 2) {
    out.frame_begin.assign(static_cast<size_t>(timing.frames) + 1, 0u);
    return out;
  }
  const ReplayGrid grid = replay_grid(job, run, bounds);
  out.origin_x_mm = grid.shape.origin_x_mm;
  out.origin_y_mm = grid.shape.origin_y_mm;
  out.cell_mm = grid.shape.cell_mm;
  out.nx = grid.shape.nx;
  out.ny = grid.shape.ny;
  const size_t cells = grid.shape.thickness_um.size();
  if (job.surface) {
    out.surface_z_mm.assign(cells, std::numeric_limits<float>::quiet_NaN());
    for (int iy = 0; iy < out.ny; ++iy)
      for (int ix = 0; ix < out.nx; ++ix)
        if (const std::optional<double> z = job.surface->height_at(
                out.origin_x_mm + ix * out.cell_mm, out.origin_y_mm + iy * out.cell_mm))
          out.surface_z_mm[static_cast<size_t>(iy) * out.nx + ix] = static_cast<float>(*z);
  }

  // the run's steps again, by the same process on the replay lattice, one process per layer
  const DepositionSettings settings = deposition_settings(job.scenario);
  LayeredDeposit deposit(settings, grid.process_cell_mm, job.toolpath.layer_count());
  const double reach_mm = (settings.truncation_sigmas + 0.5) * deposit.footprint_sigma_mm();
  std::vector<float> current(cells, 0.0f);  // the deposit now, on the grid
  ChangeEncoder encoder(out, cells);
  // the grid read again where steps landed since the last frame (everywhere on the last),
  // every layer summed there, and its changes stored
  DirtyBox dirty;
  auto add_frame = [&](bool last) {
    int ix0 = 0, ix1 = out.nx - 1, iy0 = 0, iy1 = out.ny - 1;
    if (!last && !dirty.blocks(grid.shape, reach_mm, ix0, ix1, iy0, iy1)) {
      encoder.add_frame(current, out.nx, 0, -1, 0, -1, false);
      return;
    }
    // the region of whole grid blocks, in process-cell centres
    const double block_mm = grid.shape.cell_mm, c = grid.process_cell_mm;
    const double x_lo = grid.x_lo_mm + ix0 * block_mm, y_lo = grid.y_lo_mm + iy0 * block_mm;
    const double x_hi = grid.x_lo_mm + (ix1 + 1) * block_mm - c;
    const double y_hi = grid.y_lo_mm + (iy1 + 1) * block_mm - c;
    for (int iy = iy0; iy <= iy1; ++iy)
      std::fill_n(current.begin() + static_cast<size_t>(iy) * out.nx + ix0, ix1 - ix0 + 1, 0.0f);
    for (int k = 0; k < deposit.layer_count(); ++k) {
      deposit.layer(k).flush();
      const HeightMap part =
          deposit.layer(k).field().to_heightmap(x_lo, y_lo, x_hi, y_hi, grid.stride);
      for (int iy = 0; iy < part.ny && iy0 + iy <= iy1; ++iy)
        for (int ix = 0; ix < part.nx && ix0 + ix <= ix1; ++ix) {
          const size_t i = static_cast<size_t>(iy0 + iy) * out.nx + (ix0 + ix);
          current[i] += static_cast<float>(part.at(ix, iy) * grid.normal_z[i]);
        }
    }
    encoder.add_frame(current, out.nx, ix0, ix1, iy0, iy1, last);
    dirty.clear();
  };

  const double job_end_s = run.plan.trajectory.duration_s();
  int layer = 0;
  size_t entry = 0;  // steps [0, entry) deposited
  for (int frame = 0; frame < timing.frames; ++frame) {
    const bool last = frame + 1 == timing.frames;
    // the steps up to the frame's time (all of them for the last)
    const size_t until = last ? record.size() - 1 : entry_at(record, timing.time_of(frame));
    for (; entry < until; ++entry) {
      const StepState before = state_of(record, entry), after = state_of(record, entry + 1);
      if (before.path_index >= 0) layer = job.toolpath.paths[before.path_index].layer;
      DepositionStep step;
      if (deposition_step(before, after, job_end_s, step)) {
        deposit.advance(step, layer);
        dirty.add(step.p0_mm);
        dirty.add(step.p1_mm);
      }
    }
    // extrusion: what still flows when the job ends lands where the nozzle stopped
    if (last)
      deposit_remaining_flow(deposit.layer(std::clamp(layer, 0, deposit.layer_count() - 1)),
                             record.nozzle_mm.back(), job_end_s);
    add_frame(last);
  }
  out.peak_um = encoder.peak();
  return out;
}

ReplayData build_replay(const PreparedJob& job, const SimulatedRun& run,
                        const ReplayTiming& timing) {
  if (!run.states) throw InternalError("replay: the run was simulated without state samples");
  const RecordedRun& record = run.record;
  ReplayData replay;
  replay.scenario = job.scenario.name;
  replay.run_label = run.plan.spec.run_label();
  replay.machine = job.machine->name();
  replay.process = job.scenario.process.type;
  replay.has_shutter = run.simulation->has_shutter();
  replay.model_source = fs::absolute(job.model_path).string();
  replay.model_text = job.model_text.empty() ? read_text_file(job.model_path) : job.model_text;
  replay.timing = timing;
  replay.nq = run.states->nq();

  // each frame's state: qpos at its time, flags from the nearest step, the layer of the last
  // path printed
  const size_t frames = static_cast<size_t>(timing.frames);
  replay.qpos.resize(frames * static_cast<size_t>(replay.nq));
  int layer = 0;
  size_t scanned = 0;
  for (size_t frame = 0; frame < frames; ++frame) {
    const double t_s = timing.time_of(static_cast<int>(frame));
    replay.t_s.push_back(t_s);
    run.states->qpos_at(t_s, record, replay.qpos.data() + frame * replay.nq);
    if (record.size() == 0) {
      replay.open_fraction.push_back(0.0f);
      replay.flow_fraction.push_back(0.0f);
      replay.depositing.push_back(0);
      replay.path_index.push_back(-1);
      replay.layer.push_back(0);
      replay.nozzle_mm.push_back(Vec3::Zero());
      continue;
    }
    const size_t k = entry_at(record, t_s);
    for (; scanned <= k; ++scanned)
      if (record.path_index[scanned] >= 0)
        layer = job.toolpath.paths[static_cast<size_t>(record.path_index[scanned])].layer;
    replay.open_fraction.push_back(record.open_fraction[k]);
    replay.flow_fraction.push_back(record.deposit_command[k] ? record.flow_fraction[k] : 0.0f);
    replay.depositing.push_back(record.deposit_command[k]);
    replay.path_index.push_back(record.path_index[k]);
    replay.layer.push_back(layer);
    replay.nozzle_mm.push_back(record.nozzle_mm[k]);
  }
  replay.deposit = replay_deposit(job, run, timing);
  return replay;
}

}  // namespace depotwin
