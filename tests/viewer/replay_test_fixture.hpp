// A scenario's first planner simulated and its replay built (pipeline/replay.hpp), with the
// checks that need MuJoCo: where each frame's qpos puts the nozzle.
#pragma once

#include <algorithm>
#include <limits>
#include <string>

#include "pipeline/job.hpp"
#include "pipeline/quiet_settings.hpp"
#include "pipeline/replay.hpp"
#include "pipeline/run.hpp"
#include "scenario/scenario.hpp"
#include "sim/mujoco_boundary.hpp"

namespace depotwin::testing_support {

struct ReplayFixture {
  PreparedJob job;
  SimulatedRun run;
  ReplayData replay;

  explicit ReplayFixture(const std::string& scenario_file)
      : job(prepare_job(load_scenario(scenario_file))) {
    run = simulate_job(job, job.scenario.planners.front(), quiet());
    replay = build_replay(job, run, run_replay_timing(run));
  }

  // the run's own thickest cell (um)
  float run_peak_um() const { return field_heightmap(run.deposit->normal_field()).max_value(); }

  // the largest distance (mm) between the nozzle site placed by a frame's qpos and the
  // recorded nozzle of that frame (both in the substrate frame); its frame in `worst_frame`
  // (frames `first` to `end`, exclusive, at most the last)
  double worst_nozzle_error_mm(size_t* worst_frame = nullptr, size_t first = 0,
                               size_t end = std::numeric_limits<size_t>::max()) const {
    install_mujoco_handlers();
    const ModelPtr model = load_model_from_string(replay.model_text, replay.model_source);
    const DataPtr data = make_data(*model);
    const int nozzle = mj_name2id(model.get(), mjOBJ_SITE, "nozzle");
    const int substrate = mj_name2id(model.get(), mjOBJ_BODY, "substrate");
    double worst_mm = 0.0;
    for (size_t frame = first; frame < std::min(end, replay.frame_count()); ++frame) {
      std::copy(replay.qpos_of(frame), replay.qpos_of(frame) + replay.nq, data->qpos);
      mj_kinematics(model.get(), data.get());
      const mjtNum* site = data->site_xpos + 3 * nozzle;
      const mjtNum* origin = data->xpos + 3 * substrate;
      const mjtNum* rotation = data->xmat + 9 * substrate;
      Vec3 local = Vec3::Zero();
      for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row)
          local[col] += 1e3 * rotation[3 * row + col] * (site[row] - origin[row]);
      const double error_mm = (local - replay.nozzle_mm[frame]).norm();
      if (error_mm > worst_mm && worst_frame) *worst_frame = frame;
      worst_mm = std::max(worst_mm, error_mm);
    }
    return worst_mm;
  }
};

}  // namespace depotwin::testing_support
