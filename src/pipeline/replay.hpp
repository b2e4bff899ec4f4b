// The replay data of a simulated run (report/replay_io.hpp): what run.mp4 and `depotwin view`
// show, at the frames of a ReplayTiming.
//
// The machine: MuJoCo's qpos at each frame (render/state_samples.hpp: the actuated joints from
// the record at that time, the passive ones from states sampled every 64 ms), with the
// shutter, flow and path from the record's step nearest the frame.
//
// The deposit as it was at each frame's time, the cheapest honest way: the run's recorded
// steps are deposited again, by the same process, on a coarser grid (at most kReplayGridCells
// a side, never coarser than the footprint's sigma, so a footprint still spans ten cells and
// the lattice adds no ripple), and the grid is read at every frame; only the cells that
// changed by more than 0.1 % of the peak so far are stored. A replayed deposit is therefore
// the run's own on that grid, to the batching's 1e-6 and that 0.1 %, at the frame's time
// (to the 1 ms step); on a part, each layer is turned to thickness along the normal as the
// run's is.
#pragma once

#include "pipeline/job.hpp"
#include "report/replay_io.hpp"

namespace depotwin {

struct SimulatedRun;

// the replay grid's cells per side, at most
constexpr int kReplayGridCells = 256;

// the timing of a run's replay (its simulated time, at most max_length_s of video)
ReplayTiming run_replay_timing(const SimulatedRun& run, double max_length_s = kDefaultVideoLength_s,
                               double fps = kDefaultVideoFps);

// InternalError when the run was simulated without state samples (SimulatedRun::states)
ReplayData build_replay(const PreparedJob& job, const SimulatedRun& run,
                        const ReplayTiming& timing);

// the deposit part alone (the deposit's growth on the replay grid)
ReplayDeposit replay_deposit(const PreparedJob& job, const SimulatedRun& run,
                             const ReplayTiming& timing);

}  // namespace depotwin
