// `depotwin view RUN_DIR`: a finished run replayed in an interactive MuJoCo window (GLFW),
// from the replay data every run folder holds (report/replay_io.hpp), drawn as run.mp4 is
// (render/video.hpp): the scene with the deposit growing, the overlay, a timeline bar.
#pragma once

#include <optional>
#include <string>

namespace depotwin {

struct ViewOptions {
  std::string run_directory;
  // write this PNG of one frame, rendered in the window, and exit (a test under Xvfb)
  std::string screenshot;
  // start at this run time, s (0 to the run's duration); unset: the start, a screenshot the end
  std::optional<double> at_s;
  int width = 1280;  // window size (pixels)
  int height = 640;
  bool closeup = true;  // the deposit's close-up panel beside the whole machine
};

// the keys and mouse actions, for --help and the README
extern const char* const kViewControls;

// Opens the window and plays until it is closed; returns the exit status. InputError for a
// folder without replay data, a bad option, or no display to open a window on.
int view_verb(const ViewOptions& options);

}  // namespace depotwin
