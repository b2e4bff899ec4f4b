#include "render/video.hpp"

#include <GL/osmesa.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>

#include "core/child_process.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/types.hpp"
#include "render/deposit_mesh.hpp"
#include "render/scene.hpp"
#include "sim/mujoco_boundary.hpp"

namespace depotwin {

namespace fs = std::filesystem;

namespace {

// the timeline bar's margin (px)
constexpr int kTimelineMargin = 6;
// scene geoms beyond the model's own (the backdrop)
constexpr int kExtraGeoms = 16;

// The part's surface under a point of the replay grid: bilinear between the four cell centres
// around it when all are on the part, else the nearest cell's; nullopt off the part (NaN) or
// off the grid. Empty grid heights: no part.
std::function<std::optional<double>(double, double)> grid_surface(const ReplayDeposit& deposit) {
  if (deposit.surface_z_mm.empty() || deposit.nx <= 0 || deposit.ny <= 0) return {};
  return [&deposit](double x_mm, double y_mm) -> std::optional<double> {
    const double u = (x_mm - deposit.origin_x_mm) / deposit.cell_mm;
    const double v = (y_mm - deposit.origin_y_mm) / deposit.cell_mm;
    if (u < -0.5 || v < -0.5 || u > deposit.nx - 0.5 || v > deposit.ny - 0.5) return std::nullopt;
    auto at = [&deposit](int ix, int iy) {
      ix = std::clamp(ix, 0, deposit.nx - 1);
      iy = std::clamp(iy, 0, deposit.ny - 1);
      return deposit.surface_z_mm[static_cast<size_t>(iy) * deposit.nx + ix];
    };
    const int ix = static_cast<int>(std::floor(u)), iy = static_cast<int>(std::floor(v));
    const double fx = u - ix, fy = v - iy;
    const float z00 = at(ix, iy), z10 = at(ix + 1, iy), z01 = at(ix, iy + 1),
                z11 = at(ix + 1, iy + 1);
    if (!std::isnan(z00) && !std::isnan(z10) && !std::isnan(z01) && !std::isnan(z11))
      return (1 - fy) * ((1 - fx) * z00 + fx * z10) + fy * ((1 - fx) * z01 + fx * z11);
    const float nearest = at(static_cast<int>(std::lround(u)), static_cast<int>(std::lround(v)));
    if (std::isnan(nearest)) return std::nullopt;
    return static_cast<double>(nearest);
  };
}

// GL entry points for the deposit mesh in an OSMesa context
void* osmesa_proc_address(const char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}

std::string format(const char* pattern, double a) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, a);
  return text;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// ReplayView

struct ReplayView::Impl {
  GlProcAddress gl_proc_address = nullptr;
  ModelPtr model;
  DataPtr data;
  mjvScene scene;
  mjvOption visual;
  mjvPerturb perturb;
  mjvCamera whole, closeup;
  SceneFraming framing;
  // the close-up looks at this point of the substrate frame (m), wherever the substrate is: an
  // XY stage or a delta moves its substrate under the nozzle
  Vec3 closeup_lookat_substrate = Vec3::Zero();
  int substrate = -1;
  DepositMeshOptions mesh_options;
  DepositPlayback playback;
  DepositMesh mesh;
  // the finished deposit's bounds (substrate frame): what the close-up clears its view of
  Vec3 final_lo_mm = Vec3::Zero(), final_hi_mm = Vec3::Zero();
  size_t mesh_frame = std::numeric_limits<size_t>::max();
  size_t state_frame = std::numeric_limits<size_t>::max();

  Impl(const ReplayData& replay, GlProcAddress proc_address)
      : gl_proc_address(proc_address), playback(replay.deposit) {
    mjv_defaultScene(&scene);
    mjv_defaultOption(&visual);
    mjv_defaultPerturb(&perturb);
    mjv_defaultCamera(&whole);
    mjv_defaultCamera(&closeup);
  }
  ~Impl() { mjv_freeScene(&scene); }

  // the model's state at frame k: qpos, then the positions the scene reads
  void set_state(const ReplayData& replay, size_t frame) {
    if (frame == state_frame) return;
    std::copy(replay.qpos_of(frame), replay.qpos_of(frame) + replay.nq, data->qpos);
    mj_kinematics(model.get(), data.get());
    mj_comPos(model.get(), data.get());
    mj_camlight(model.get(), data.get());
    state_frame = frame;
    // the close-up follows the substrate
    if (substrate >= 0) {
      const mjtNum* origin = data->xpos + 3 * substrate;
      const mjtNum* rotation = data->xmat + 9 * substrate;
      for (int row = 0; row < 3; ++row) {
        closeup.lookat[row] = origin[row];
        for (int col = 0; col < 3; ++col)
          closeup.lookat[row] += rotation[3 * row + col] * closeup_lookat_substrate[col];
      }
    }
  }
  // the substrate-frame point (m) at world point `world_m` in the current state
  Vec3 to_substrate(const Vec3& world_m) const {
    const mjtNum* origin = data->xpos + 3 * substrate;
    const mjtNum* rotation = data->xmat + 9 * substrate;
    Vec3 local = Vec3::Zero();
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row)
        local[col] += rotation[3 * row + col] * (world_m[row] - origin[row]);
    return local;
  }
  // the deposit mesh of frame k (rebuilt when the frame changes)
  void set_deposit(size_t frame) {
    if (frame == mesh_frame) return;
    mesh = build_deposit_mesh(playback.at(frame), mesh_options);
    mesh_frame = frame;
  }
  // one panel: the scene from `camera`, the backdrop, the deposit; returns the scene's
  // pixels per mm at `scale_point_m` (for the scale bar)
  // (`ghosts`: the close-up's see-through print head, as scene.png's)
  double draw_panel(const mjrRect& panel, mjvCamera& camera, const Vec3& scale_point_m,
                    const mjrContext& context, bool ghosts = false) {
    mjv_updateScene(model.get(), data.get(), &visual, &perturb, &camera, mjCAT_ALL, &scene);
    scene.flags[mjRND_SHADOW] = 0;  // as scene.png: shadows cost a second pass in software
    if (ghosts && substrate >= 0)
      ghost_over_deposit(*model, *data, substrate, final_lo_mm, final_hi_mm, scene);
    add_backdrop(*model, *data, scene);
    mjr_render(panel, &scene, &context);
    if (!mesh.empty()) draw_deposit_mesh(mesh, scene, panel, *model, *data, gl_proc_address);
    const mjvGLCamera eye = mjv_averageCamera(scene.camera, scene.camera + 1);
    return pixels_per_mm(eye, panel, scale_point_m);
  }
};

ReplayView::ReplayView(const ReplayData& replay, GlProcAddress gl_proc_address, int panels_width,
                       int panels_height)
    : replay_(replay) {
  install_mujoco_handlers();
  if (replay.frame_count() == 0) throw InputError(kReplayJson, 0, "t_s", "the replay has no frame");
  impl_ = std::make_unique<Impl>(replay, gl_proc_address);
  // the model as the run compiled it; its assets resolve against the file it came from
  try {
    impl_->model = load_model_from_string(replay.model_text, replay.model_source);
  } catch (const InputError& error) {
    throw InputError(kReplayModel, 0, "model",
                     std::string("does not compile: ") + error.problems().front().message);
  }
  if (impl_->model->nq != replay.nq)
    throw InputError(kReplayJson, 0, "nq",
                     "is " + std::to_string(replay.nq) + " but the model has " +
                         std::to_string(impl_->model->nq));
  impl_->data = make_data(*impl_->model);
  mjv_makeScene(impl_->model.get(), &impl_->scene, 4 * impl_->model->ngeom + kExtraGeoms);

  // views and colour scale fixed for the whole replay: framed on the last frame, for panels of
  // the video's or the window's shape (the close-up then follows the substrate)
  const size_t last = replay.frame_count() - 1;
  impl_->substrate = mj_name2id(impl_->model.get(), mjOBJ_BODY, "substrate");
  impl_->set_state(replay, last);
  SceneRenderOptions options;
  options.width = panels_width;
  options.height = panels_height;
  options.surface_height_mm = grid_surface(replay.deposit);
  impl_->framing = frame_scene(*impl_->model, *impl_->data, impl_->playback.at(last), options);
  set_free_camera(impl_->framing.whole, impl_->whole);
  if (impl_->framing.whole_from_render_cam) {
    impl_->whole.type = mjCAMERA_FIXED;
    impl_->whole.fixedcamid = mj_name2id(impl_->model.get(), mjOBJ_CAMERA, "render_cam");
    if (impl_->whole.fixedcamid < 0) set_free_camera(impl_->framing.whole, impl_->whole);
  }
  set_free_camera(impl_->framing.closeup, impl_->closeup);
  if (impl_->substrate >= 0)
    impl_->closeup_lookat_substrate = impl_->to_substrate(impl_->framing.closeup.lookat_m);
  impl_->mesh_options.relief_mm = impl_->framing.relief_mm;
  impl_->mesh_options.colour_top_um = impl_->framing.colour_top_um;
  impl_->mesh_options.surface_height_mm = options.surface_height_mm;
  const DepositMesh final_mesh = build_deposit_mesh(impl_->playback.at(last), impl_->mesh_options);
  if (!final_mesh.empty()) {
    impl_->final_lo_mm = final_mesh.lo_mm;
    impl_->final_hi_mm = final_mesh.hi_mm;
  }
}

ReplayView::~ReplayView() = default;

const mjModel& ReplayView::model() const {
  return *impl_->model;
}
mjvCamera& ReplayView::whole_camera() {
  return impl_->whole;
}

mjrRect ReplayView::timeline_rect(const mjrRect& viewport) {
  return {viewport.left + kTimelineMargin, viewport.bottom + kTimelineMargin / 2,
          std::max(1, viewport.width - 2 * kTimelineMargin), kTimelineHeight - kTimelineMargin};
}

size_t ReplayView::frame_at(const mjrRect& viewport, int x) const {
  const mjrRect bar = timeline_rect(viewport);
  const double fraction = std::clamp(static_cast<double>(x - bar.left) / bar.width, 0.0, 1.0);
  return static_cast<size_t>(std::lround(fraction * (replay_.frame_count() - 1)));
}

size_t ReplayView::frame_at_time(double t_s) const {
  const auto next = std::upper_bound(replay_.t_s.begin(), replay_.t_s.end(), t_s + 1e-9);
  return next == replay_.t_s.begin() ? 0 : static_cast<size_t>(next - replay_.t_s.begin()) - 1;
}

std::pair<std::string, std::string> ReplayView::overlay_text(size_t frame, bool paused) const {
  frame = std::min(frame, replay_.frame_count() - 1);
  // the machine's panel: the run, the time, the speed-up
  std::string run = replay_.scenario + " / " + replay_.run_label + "\n" +
                    format("t = %.2f s", replay_.t_s[frame]) +
                    format(" of %.2f s", replay_.timing.duration_s) + "\n" +
                    speedup_text(replay_.timing.speedup) + (paused ? ", paused" : "");
  // the deposit's panel: the process state, then where the head is in the job
  std::string process;
  if (replay_.process == "extrusion") {
    process = format("flow %.0f %%", 100.0 * replay_.flow_fraction[frame]);
  } else {
    const double open = replay_.open_fraction[frame];
    process = open >= 0.995   ? std::string("shutter open")
              : open <= 0.005 ? std::string("shutter closed")
                              : format("shutter %.0f %% open", 100.0 * open);
  }
  const int path = replay_.path_index[frame];
  process += path >= 0 ? "\npath " + std::to_string(path) : std::string("\ntravel");
  process += ", layer " + std::to_string(replay_.layer[frame]);
  return {run, process};
}

void ReplayView::draw(size_t frame, const mjrRect& viewport, const mjrContext& context,
                      const ReplayViewOptions& options) {
  frame = std::min(frame, replay_.frame_count() - 1);
  impl_->set_state(replay_, frame);
  impl_->set_deposit(frame);
  mjr_rectangle(viewport, 0.12f, 0.12f, 0.14f, 1.0f);

  // scene.png's layout (image pixels, y down) above the timeline, as GL rects (y up)
  const int timeline = options.timeline ? kTimelineHeight : 0;
  SceneRenderOptions layout_options;
  layout_options.width = viewport.width;
  layout_options.height = std::max(1, viewport.height - timeline);
  layout_options.closeup = options.closeup;
  const SceneLayout layout = scene_layout(layout_options);
  const int top = viewport.bottom + viewport.height;
  auto to_gl = [&](const PixelRect& r) {
    return mjrRect{viewport.left + r.x, top - r.y - r.height, r.width, r.height};
  };
  const mjrRect whole = to_gl(layout.whole);
  const Vec3 deposit_centre_m(impl_->closeup.lookat[0], impl_->closeup.lookat[1],
                              impl_->closeup.lookat[2]);
  const double whole_px_per_mm = impl_->draw_panel(whole, impl_->whole, deposit_centre_m, context);
  draw_scale_bar(whole, whole_px_per_mm, 1, context);
  const auto [run_text, process_text] = overlay_text(frame, options.paused);
  mjr_overlay(mjFONT_SHADOW, mjGRID_TOPLEFT, whole, run_text.c_str(), nullptr, &context);
  if (options.closeup && layout.closeup.width > 0) {
    const mjrRect closeup = to_gl(layout.closeup);
    draw_scale_bar(closeup,
                   impl_->draw_panel(closeup, impl_->closeup, deposit_centre_m, context, true), 1,
                   context);
    mjr_overlay(mjFONT_SHADOW, mjGRID_TOPLEFT, closeup, process_text.c_str(), nullptr, &context);
  } else {
    mjr_overlay(mjFONT_SHADOW, mjGRID_TOPRIGHT, whole, process_text.c_str(), nullptr, &context);
  }
  if (layout.strip.height > 0)
    draw_colour_bar(to_gl(layout.strip), impl_->framing.colour_top_um, 1, context);

  // the timeline: the run's length, the part played, the frame's mark
  if (options.timeline) {
    const mjrRect bar = timeline_rect(viewport);
    mjr_rectangle(bar, 0.35f, 0.35f, 0.38f, 1.0f);
    const double fraction =
        replay_.frame_count() > 1 ? static_cast<double>(frame) / (replay_.frame_count() - 1) : 1.0;
    mjrRect played = bar;
    played.width = std::max(1, static_cast<int>(std::lround(fraction * bar.width)));
    mjr_rectangle(played, 0.27f, 0.55f, 0.85f, 1.0f);
    const mjrRect mark = {bar.left + played.width - 2, bar.bottom - 2, 4, bar.height + 4};
    mjr_rectangle(mark, 0.95f, 0.95f, 0.95f, 1.0f);
  }
}

// ---------------------------------------------------------------------------------------
// ffmpeg

bool ffmpeg_available() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string directories(path);
  size_t start = 0;
  while (start <= directories.size()) {
    const size_t end = std::min(directories.find(':', start), directories.size());
    const std::string dir = directories.substr(start, end - start);
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

namespace {

// ffmpeg reading raw RGB frames on its stdin and writing an H.264 MP4. Its stderr goes to an
// unlinked temporary file, read back when it fails. SIGPIPE is blocked on the writing
// thread, so an ffmpeg that dies makes write() fail instead of killing the process.
class FfmpegPipe {
 public:
  FfmpegPipe(const std::string& output, int width, int height, double fps, int crf) {
    char log_template[] = "/tmp/depotwin-ffmpeg-XXXXXX";
    log_fd_ = ::mkostemp(log_template, O_CLOEXEC);
    if (log_fd_ < 0) throw InternalError("video: cannot create a temporary file for ffmpeg's log");
    ::unlink(log_template);
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw InternalError("video: cannot create a pipe to ffmpeg");
    write_fd_ = fds[1];

    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const std::string rate = format("%g", fps);
    const std::string quality = std::to_string(crf);
    std::vector<std::string> args = {
        "ffmpeg",  "-nostdin",  "-hide_banner", "-loglevel", "error", "-y",
        "-f",      "rawvideo",  "-pix_fmt",     "rgb24",     "-s",    size,
        "-r",      rate,        "-i",           "pipe:0",    "-an",   "-c:v",
        "libx264", "-preset",   "veryfast",     "-crf",      quality, "-pix_fmt",
        "yuv420p", "-movflags", "+faststart",   "-f",        "mp4",   output};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, log_fd_, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, log_fd_, STDERR_FILENO);
    // under depotwin's control: a signal that stops the run ends it (core/child_process.hpp)
    const int spawned = spawn_child_process(pid_, args, &actions);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[0]);
    if (spawned != 0) {
      ::close(write_fd_);
      ::close(log_fd_);
      throw InputError("--video", std::string("cannot start ffmpeg (") + std::strerror(spawned) +
                                      "): install it (apt-get install ffmpeg, or "
                                      "scripts/setup.sh) or run without --video");
    }
    // SIGPIPE held back on this thread while it writes
    sigset_t pipe_signal;
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_signal, &saved_mask_);
  }
  ~FfmpegPipe() {
    // not finished: an error or an interrupt stopped the frames, and the half-written file is
    // discarded, so ffmpeg is ended rather than left to encode what it has
    if (pid_ > 0) {
      if (write_fd_ >= 0) ::close(write_fd_);
      end_child_process(pid_);
    }
    if (log_fd_ >= 0) ::close(log_fd_);
    restore_signals();
  }
  FfmpegPipe(const FfmpegPipe&) = delete;
  FfmpegPipe& operator=(const FfmpegPipe&) = delete;

  // false when ffmpeg stopped reading (it failed: finish() says why)
  bool write_frame(const unsigned char* bytes, size_t size) {
    while (size > 0) {
      const ssize_t written = ::write(write_fd_, bytes, size);
      if (written < 0) {
        if (errno == EINTR) continue;
        return false;
      }
      bytes += written;
      size -= static_cast<size_t>(written);
    }
    return true;
  }
  // closes the pipe and waits; InternalError with ffmpeg's own words when it failed
  void finish() {
    ::close(write_fd_);
    write_fd_ = -1;
    const int status = wait_child_process(pid_);
    pid_ = -1;
    restore_signals();
    throw_if_interrupted();  // killed because a signal stopped the run: it did not fail
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
    std::string log;
    char buffer[4096];
    ::lseek(log_fd_, 0, SEEK_SET);
    for (ssize_t n; (n = ::read(log_fd_, buffer, sizeof buffer)) > 0;) log.append(buffer, n);
    while (!log.empty() && (log.back() == '\n' || log.back() == '\r')) log.pop_back();
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
      throw InputError("--video",
                       "ffmpeg could not be run: install it (apt-get install ffmpeg, "
                       "or scripts/setup.sh) or run without --video");
    throw InternalError("ffmpeg failed (" +
                        (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                           : std::string("killed by a signal")) +
                        ")" + (log.empty() ? "" : ": " + log));
  }

 private:
  void restore_signals() {
    if (!signals_blocked_) return;
    // a SIGPIPE raised while blocked is taken here, not delivered later
    sigset_t pipe_signal;
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    const timespec no_wait = {0, 0};
    while (::sigtimedwait(&pipe_signal, nullptr, &no_wait) > 0) {
    }
    pthread_sigmask(SIG_SETMASK, &saved_mask_, nullptr);
    signals_blocked_ = false;
  }

  pid_t pid_ = -1;
  int write_fd_ = -1;
  int log_fd_ = -1;
  sigset_t saved_mask_;
  bool signals_blocked_ = true;
};

// an OSMesa context current on its own RGBA buffer, with MuJoCo's render context for a model
// whose offscreen buffer is width x height
class OffscreenContext {
 public:
  OffscreenContext(const mjModel& model, int width, int height)
      : buffer_(static_cast<size_t>(width) * height * 4) {
    gl_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
    if (!gl_) throw InternalError("OSMesa could not create a rendering context");
    if (!OSMesaMakeCurrent(gl_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      OSMesaDestroyContext(gl_);
      throw InternalError("OSMesa could not make its rendering context current");
    }
    const ModelPtr sized(mj_copyModel(nullptr, &model));
    sized->vis.global.offwidth = width;
    sized->vis.global.offheight = height;
    sized->vis.quality.offsamples = 0;
    sized->vis.quality.shadowsize = 0;  // no shadows (as scene.png): a second pass in software
    mjr_defaultContext(&context_);
    mjr_makeContext(sized.get(), &context_, mjFONTSCALE_100);
    mjr_setBuffer(mjFB_OFFSCREEN, &context_);
    if (context_.currentBuffer != mjFB_OFFSCREEN) {
      mjr_freeContext(&context_);
      OSMesaDestroyContext(gl_);
      throw InternalError("MuJoCo could not select its offscreen buffer");
    }
  }
  ~OffscreenContext() {
    mjr_freeContext(&context_);
    OSMesaDestroyContext(gl_);
  }
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  const mjrContext& context() const { return context_; }

 private:
  std::vector<unsigned char> buffer_;
  OSMesaContext gl_ = nullptr;
  mjrContext context_;
};

}  // namespace

VideoStats write_replay_video(const ReplayData& replay, const std::string& mp4_path,
                              const VideoOptions& options) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  if (options.width < 16 || options.height < 16 || options.width % 2 || options.height % 2)
    throw InternalError("video: width and height must be even and at least 16 pixels");
  if (!ffmpeg_available())
    throw InputError("--video",
                     "ffmpeg is not installed (not found on PATH): install it "
                     "(apt-get install ffmpeg, or scripts/setup.sh) or run without "
                     "--video");

  // set up: the replay's scene, GL, ffmpeg writing to a temporary name beside the target
  ReplayView view(replay, osmesa_proc_address, options.width,
                  options.height - ReplayView::kTimelineHeight);
  OffscreenContext gl(view.model(), options.width, options.height);
  const fs::path target(mp4_path);
  const std::string temporary = (target.parent_path() / ("." + target.filename().string() +
                                                         ".partial-" + std::to_string(::getpid())))
                                    .string();
  struct RemoveUnlessRenamed {
    std::string path;
    bool renamed = false;
    ~RemoveUnlessRenamed() {
      if (!renamed) std::remove(path.c_str());
    }
  } cleanup{temporary};
  FfmpegPipe ffmpeg(temporary, options.width, options.height, replay.timing.fps, options.crf);

  // every frame: draw, read back (bottom row first), flip, pipe
  const mjrRect viewport = {0, 0, options.width, options.height};
  const size_t row = static_cast<size_t>(options.width) * 3;
  std::vector<unsigned char> bottom_up(row * options.height), top_down(row * options.height);
  ReplayViewOptions view_options;
  view_options.closeup = options.closeup;
  view_options.timeline = true;
  for (size_t frame = 0; frame < replay.frame_count(); ++frame) {
    throw_if_interrupted();
    view.draw(frame, viewport, gl.context(), view_options);
    mjr_readPixels(bottom_up.data(), nullptr, viewport, &gl.context());
    for (int y = 0; y < options.height; ++y)
      std::memcpy(top_down.data() + y * row, bottom_up.data() + (options.height - 1 - y) * row,
                  row);
    if (!ffmpeg.write_frame(top_down.data(), top_down.size())) break;  // finish() says why
  }
  ffmpeg.finish();

  // in place only when whole
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) throw EnvironmentError("cannot write " + mp4_path + ": " + error.message());
  cleanup.renamed = true;

  VideoStats stats;
  stats.frames = static_cast<int>(replay.frame_count());
  stats.length_s = stats.frames / replay.timing.fps;
  stats.render_s = std::chrono::duration<double>(Clock::now() - start).count();
  return stats;
}

}  // namespace depotwin
