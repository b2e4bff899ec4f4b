// Moving pictures of a run: a replay (report/replay_io.hpp) drawn frame by frame, into an
// offscreen OSMesa buffer piped to ffmpeg (run.mp4) or into the viewer's window (viewer/).
//
// A frame is the scene at that frame's state (every joint, passive ones included) with the
// deposit as it was then, drawn as the scene draws it (deposit_mesh.hpp), in two panels: the
// whole machine left, the deposit close up right (views and colour scale fixed for the whole
// replay, framed on the last frame). An overlay names the run and gives the time, the
// speed-up and the process state ("shutter open" / "shutter closed", or "flow 82 %").
#pragma once

#include <mujoco/mujoco.h>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "render/deposit_mesh.hpp"
#include "report/replay_io.hpp"

namespace depotwin {

struct ReplayViewOptions {
  bool closeup = true;    // two panels (whole machine, close-up); false: the whole machine
  bool timeline = false;  // a timeline bar along the bottom (the viewer scrubs on it)
  bool paused = false;    // the overlay says "paused"
};

// A replay drawn into the current GL context. Owns the compiled model, a state and a scene;
// the caller owns the GL context and an mjrContext made for model().
class ReplayView {
 public:
  // compiles the replay's model (InputError naming replay_model.xml when it does not) and
  // frames the views and the colour scale on the last frame; `gl_proc_address` resolves the
  // GL functions the deposit mesh is drawn with (OSMesa's or the window's)
  // (panels_width x panels_height: the size the panels will have, for the framing's aspect)
  ReplayView(const ReplayData& replay, GlProcAddress gl_proc_address, int panels_width,
             int panels_height);
  ~ReplayView();
  ReplayView(const ReplayView&) = delete;
  ReplayView& operator=(const ReplayView&) = delete;

  const mjModel& model() const;
  const ReplayData& replay() const { return replay_; }
  // the whole-machine panel's camera (the viewer turns and zooms it)
  mjvCamera& whole_camera();

  // Draws frame `frame` (clamped) over `viewport` of the current buffer, laid out as
  // scene.png (scene_layout): the panels, the colour bar strip below them, the scale bar, the
  // overlay text and, when asked, the timeline along the bottom. `context` made with
  // mjFONTSCALE_100.
  void draw(size_t frame, const mjrRect& viewport, const mjrContext& context,
            const ReplayViewOptions& options = {});

  // the timeline strip's height (pixels) along the bottom of a viewport
  static constexpr int kTimelineHeight = 22;
  // the timeline bar within a viewport, and the frame under a pixel column of it
  static mjrRect timeline_rect(const mjrRect& viewport);
  size_t frame_at(const mjrRect& viewport, int x) const;
  // the frame shown at run time t_s (the last frame at or before it)
  size_t frame_at_time(double t_s) const;
  // the overlay's lines for frame k (left block, right block), e.g. for tests
  std::pair<std::string, std::string> overlay_text(size_t frame, bool paused = false) const;

 private:
  struct Impl;
  const ReplayData& replay_;
  std::unique_ptr<Impl> impl_;
};

struct VideoOptions {
  int width = 960;   // even (H.264 4:2:0); two panels of width / 2
  int height = 480;  // even
  bool closeup = true;
  int crf = 23;  // x264 quality (lower: better, larger)
};

struct VideoStats {
  int frames = 0;
  double length_s = 0.0;
  double render_s = 0.0;  // wall time rendering and encoding
};

// The replay as an H.264 (yuv420p) MP4 at its timing's frame rate: frames rendered through
// OSMesa and piped as raw RGB to Debian's ffmpeg, written to a temporary name beside
// `mp4_path` and renamed over it. InputError ("--video") when ffmpeg is not installed;
// InternalError with ffmpeg's message when it fails (nothing is left), or for an odd size.
VideoStats write_replay_video(const ReplayData& replay, const std::string& mp4_path,
                              const VideoOptions& options = {});

// true when an ffmpeg executable is on PATH
bool ffmpeg_available();

}  // namespace depotwin
