#include "viewer/viewer.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <vector>

#include <unistd.h>

#include "core/error.hpp"
#include "core/file_io.hpp"
#include "core/number_text.hpp"
#include "core/png.hpp"
#include "render/video.hpp"
#include "report/replay_io.hpp"

namespace depotwin {

const char* const kViewControls =
    "  space: play / pause (at the end: from the start)\n"
    "  left / right arrow: one frame back / on; with shift: one second of video\n"
    "  home / end: the first / last frame\n"
    "  click or drag on the timeline bar: go to that time\n"
    "  drag elsewhere: turn the whole-machine view; scroll: zoom it\n"
    "  c: the close-up panel on / off; q or escape: quit";

namespace {

// GL entry points for the deposit mesh in the window's context
void* glfw_proc_address(const char* name) {
  return reinterpret_cast<void*>(glfwGetProcAddress(name));
}

// the message of GLFW's last error (its error callback)
std::string& glfw_error() {
  static std::string message;
  return message;
}

// The interactive state, reached from GLFW's callbacks through the window's user pointer.
struct Viewer {
  ReplayView* view = nullptr;
  size_t frames = 0;
  double position = 0.0;  // the frame shown, fractional while playing
  bool playing = false;
  bool closeup = true;
  bool scrubbing = false;  // the left button went down on the timeline
  bool turning = false;    // ... or in the scene
  bool redraw = true;      // something changed since the last frame drawn
  double last_x = 0.0, last_y = 0.0;

  size_t frame() const { return static_cast<size_t>(std::lround(position)); }
  void go_to(double frame) { position = std::clamp(frame, 0.0, static_cast<double>(frames - 1)); }
};

Viewer& viewer_of(GLFWwindow* window) {
  return *static_cast<Viewer*>(glfwGetWindowUserPointer(window));
}

// the framebuffer's viewport, and a window point (screen coordinates, y down) in it
mjrRect framebuffer_viewport(GLFWwindow* window) {
  int width = 0, height = 0;
  glfwGetFramebufferSize(window, &width, &height);
  return {0, 0, width, height};
}
void to_framebuffer(GLFWwindow* window, double x, double y, int& px, int& py) {
  int window_width = 1, window_height = 1;
  glfwGetWindowSize(window, &window_width, &window_height);
  const mjrRect viewport = framebuffer_viewport(window);
  px = static_cast<int>(x * viewport.width / std::max(1, window_width));
  py = viewport.height - 1 - static_cast<int>(y * viewport.height / std::max(1, window_height));
}

void on_key(GLFWwindow* window, int key, int, int action, int mods) {
  if (action == GLFW_RELEASE) return;
  Viewer& v = viewer_of(window);
  v.redraw = true;
  const double step = (mods & GLFW_MOD_SHIFT) ? v.view->replay().timing.fps : 1.0;
  switch (key) {
    case GLFW_KEY_SPACE:
      if (!v.playing && v.frame() + 1 >= v.frames) v.go_to(0);
      v.playing = !v.playing;
      break;
    case GLFW_KEY_LEFT:
      v.playing = false;
      v.go_to(std::round(v.position) - step);
      break;
    case GLFW_KEY_RIGHT:
      v.playing = false;
      v.go_to(std::round(v.position) + step);
      break;
    case GLFW_KEY_HOME:
      v.go_to(0);
      break;
    case GLFW_KEY_END:
      v.go_to(static_cast<double>(v.frames - 1));
      break;
    case GLFW_KEY_C:
      v.closeup = !v.closeup;
      break;
    case GLFW_KEY_Q:
    case GLFW_KEY_ESCAPE:
      glfwSetWindowShouldClose(window, GLFW_TRUE);
      break;
    default:
      break;
  }
}

// the left button on the timeline scrubs; elsewhere it turns the whole-machine view
void on_button(GLFWwindow* window, int button, int action, int) {
  Viewer& v = viewer_of(window);
  v.redraw = true;
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  if (action == GLFW_RELEASE) {
    v.scrubbing = v.turning = false;
    return;
  }
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(window, &x, &y);
  int px = 0, py = 0;
  to_framebuffer(window, x, y, px, py);
  const mjrRect viewport = framebuffer_viewport(window);
  const mjrRect bar = ReplayView::timeline_rect(viewport);
  v.last_x = x;
  v.last_y = y;
  if (py <= bar.bottom + bar.height + 4) {
    v.scrubbing = true;
    v.playing = false;
    v.go_to(static_cast<double>(v.view->frame_at(viewport, px)));
  } else {
    v.turning = true;
  }
}

void on_move(GLFWwindow* window, double x, double y) {
  Viewer& v = viewer_of(window);
  v.redraw = v.redraw || v.scrubbing || v.turning;
  if (v.scrubbing) {
    int px = 0, py = 0;
    to_framebuffer(window, x, y, px, py);
    v.go_to(static_cast<double>(v.view->frame_at(framebuffer_viewport(window), px)));
  } else if (v.turning) {
    int height = 1;
    glfwGetWindowSize(window, nullptr, &height);
    const double dx = (x - v.last_x) / std::max(1, height),
                 dy = (y - v.last_y) / std::max(1, height);
    mjv_moveCamera(&v.view->model(), mjMOUSE_ROTATE_V, dx, dy, nullptr, &v.view->whole_camera());
  }
  v.last_x = x;
  v.last_y = y;
}

void on_scroll(GLFWwindow* window, double, double dy) {
  Viewer& v = viewer_of(window);
  v.redraw = true;
  mjv_moveCamera(&v.view->model(), mjMOUSE_ZOOM, 0.0, -0.05 * dy, nullptr, &v.view->whole_camera());
}

// GLFW set up and torn down with the window (its context current on this thread)
struct GlfwWindow {
  GLFWwindow* window = nullptr;
  GlfwWindow(int width, int height, const std::string& title, bool visible) {
    glfwSetErrorCallback([](int, const char* description) { glfw_error() = description; });
    if (!glfwInit())
      throw InputError("DISPLAY", "cannot open a window (" + glfw_error() +
                                      "): the viewer needs a display; on a machine without one, "
                                      "xvfb-run -a depotwin view RUN_DIR --screenshot FILE.png");
    glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_SAMPLES, 4);
    window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window) {
      // without multisampling, which not every display offers
      glfwWindowHint(GLFW_SAMPLES, 0);
      window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    }
    if (!window) {
      glfwTerminate();
      throw InputError("DISPLAY", "cannot create an OpenGL window (" + glfw_error() + ")");
    }
    glfwMakeContextCurrent(window);
    glfwSwapInterval(1);
  }
  ~GlfwWindow() {
    glfwDestroyWindow(window);
    glfwTerminate();
  }
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;
};

// MuJoCo's render context for the window (after the GL context is current)
struct WindowContext {
  mjrContext context;
  explicit WindowContext(const mjModel& model) {
    mjr_defaultContext(&context);
    mjr_makeContext(&model, &context, mjFONTSCALE_100);
    mjr_setBuffer(mjFB_WINDOW, &context);
  }
  ~WindowContext() { mjr_freeContext(&context); }
  WindowContext(const WindowContext&) = delete;
  WindowContext& operator=(const WindowContext&) = delete;
};

// --screenshot names a new file or a PNG to replace, in a folder that can be written: never
// the run's replay.json or a scenario (a PNG was once written over both), checked before the
// window opens
void check_screenshot_path(const std::string& path) {
  namespace fs = std::filesystem;
  if (const std::string problem = replaceable_file_problem(path); !problem.empty())
    throw InputError("--screenshot", problem);
  std::error_code error;
  if (fs::is_regular_file(path, error)) {
    static const char kPngSignature[] = "\x89PNG\r\n\x1a\n";
    std::ifstream file(path, std::ios::binary);
    std::string start(8, '\0');
    file.read(start.data(), 8);
    if (!file || start != std::string(kPngSignature, 8))
      throw InputError("--screenshot", "'" + path +
                                           "' exists and is not a PNG image (only a PNG is "
                                           "replaced); name a new file, e.g. frame.png");
  }
  const fs::path parent =
      fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  if (!fs::is_directory(parent, error))
    throw InputError("--screenshot",
                     "'" + parent.string() + "' is not a directory (for '" + path + "')");
  if (access(parent.c_str(), W_OK) != 0)
    throw InputError("--screenshot",
                     "cannot write in '" + parent.string() + "' (for '" + path + "')");
}

// the largest window side: OpenGL's usual largest framebuffer
constexpr int kMaxWindowSide_px = 16384;

}  // namespace

int view_verb(const ViewOptions& options) {
  // the window's size in [64, kMaxWindowSide_px] (a larger one wrapped round in the window
  // system's 16-bit sizes: --width 65636 gave a 100-pixel window)
  if (options.width < 64 || options.width > kMaxWindowSide_px)
    throw InputError("--width", "the window must be 64 to " + std::to_string(kMaxWindowSide_px) +
                                    " pixels wide, got " + std::to_string(options.width));
  if (options.height < 64 || options.height > kMaxWindowSide_px)
    throw InputError("--height", "the window must be 64 to " + std::to_string(kMaxWindowSide_px) +
                                     " pixels high, got " + std::to_string(options.height));
  if (options.at_s && !(*options.at_s >= 0.0 && std::isfinite(*options.at_s)))
    throw InputError("--at", "a run time in seconds, 0 or more, is required, got " +
                                 message_number(*options.at_s));
  const bool screenshot = !options.screenshot.empty();
  if (screenshot) check_screenshot_path(options.screenshot);
  const ReplayData replay = read_replay(options.run_directory);
  if (options.at_s && *options.at_s > replay.timing.duration_s)
    throw InputError("--at", message_number(*options.at_s) + " s is after the run's end, " +
                                 message_number(replay.timing.duration_s) + " s");

  // the window, then the replay's scene and MuJoCo's context in it
  GlfwWindow glfw(options.width, options.height,
                  "depotwin view: " + replay.scenario + " / " + replay.run_label, true);
  const mjrRect window_viewport = framebuffer_viewport(glfw.window);
  ReplayView view(replay, glfw_proc_address, window_viewport.width,
                  window_viewport.height - ReplayView::kTimelineHeight);
  WindowContext gl(view.model());
  Viewer viewer;
  viewer.view = &view;
  viewer.frames = replay.frame_count();
  viewer.closeup = options.closeup;
  const double start_s = options.at_s ? *options.at_s : screenshot ? replay.timing.duration_s : 0.0;
  viewer.go_to(static_cast<double>(view.frame_at_time(start_s)));

  // one frame in the window, read back from its back buffer, written as a PNG
  if (screenshot) {
    const mjrRect viewport = framebuffer_viewport(glfw.window);
    ReplayViewOptions draw_options;
    draw_options.closeup = viewer.closeup;
    draw_options.timeline = true;
    draw_options.paused = true;
    view.draw(viewer.frame(), viewport, gl.context, draw_options);
    std::vector<unsigned char> bottom_up(static_cast<size_t>(viewport.width) * viewport.height * 3);
    mjr_readPixels(bottom_up.data(), nullptr, viewport, &gl.context);
    std::vector<unsigned char> top_down(bottom_up.size());
    const size_t row = static_cast<size_t>(viewport.width) * 3;
    for (int y = 0; y < viewport.height; ++y)
      std::memcpy(top_down.data() + y * row, bottom_up.data() + (viewport.height - 1 - y) * row,
                  row);
    write_file_atomically(options.screenshot, encode_png(viewport.width, viewport.height,
                                                         PngPixels::rgb8, top_down.data()));
    glfwSwapBuffers(glfw.window);
    std::cout << "screenshot of t = " << replay.t_s[viewer.frame()] << " s written to "
              << options.screenshot << " (" << viewport.width << " x " << viewport.height << ")\n";
    return kExitOk;
  }

  // interactive: callbacks move the state, the loop plays and draws
  glfwSetWindowUserPointer(glfw.window, &viewer);
  glfwSetKeyCallback(glfw.window, on_key);
  glfwSetMouseButtonCallback(glfw.window, on_button);
  glfwSetCursorPosCallback(glfw.window, on_move);
  glfwSetScrollCallback(glfw.window, on_scroll);
  glfwSetWindowRefreshCallback(glfw.window, [](GLFWwindow* w) { viewer_of(w).redraw = true; });
  glfwSetFramebufferSizeCallback(glfw.window,
                                 [](GLFWwindow* w, int, int) { viewer_of(w).redraw = true; });
  std::cout << "depotwin view: " << replay.scenario << " / " << replay.run_label << ", "
            << replay.frame_count() << " frames, " << speedup_text(replay.timing.speedup) << "\n"
            << kViewControls << std::endl;
  double last_s = glfwGetTime();
  while (!glfwWindowShouldClose(glfw.window)) {
    // playing: on at the video's frame rate (the run's time at the stated speed-up)
    const double now_s = glfwGetTime();
    if (viewer.playing) {
      viewer.go_to(viewer.position + (now_s - last_s) * replay.timing.fps);
      if (viewer.frame() + 1 >= viewer.frames) viewer.playing = false;
      viewer.redraw = true;
    }
    last_s = now_s;
    // drawn when something changed (software GL: an idle window costs nothing)
    if (viewer.redraw) {
      ReplayViewOptions draw_options;
      draw_options.closeup = viewer.closeup;
      draw_options.timeline = true;
      draw_options.paused = !viewer.playing;
      view.draw(viewer.frame(), framebuffer_viewport(glfw.window), gl.context, draw_options);
      glfwSwapBuffers(glfw.window);
      viewer.redraw = false;
    }
    if (viewer.playing)
      glfwPollEvents();
    else
      glfwWaitEvents();
  }
  return kExitOk;
}

}  // namespace depotwin
