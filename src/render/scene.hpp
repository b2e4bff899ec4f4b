// The MuJoCo scene at the end of a job (or at any state: a video frame), rendered headless
// through OSMesa to a PNG (MuJoCo sample/record.cc as one straight line: set up, update,
// render, read, free).
//
// The image has two panels over a strip: on the left the whole machine, framed from the
// bounds of its visible geoms, the deposit and the nozzle; on the right a close-up of the
// deposit, framed from its bounds, whatever is above the substrate (the print head) ghosted so
// that it hides nothing; below them a colour bar (viridis, thickness in um) and, in each
// panel, a scale bar (mm, at the deposit's distance). The deposit is a smooth height-field
// mesh with per-vertex colour (render/deposit_mesh.hpp), drawn after mjr_render in the same
// GL context, depth-tested against the machine.
//
// The model must have a camera `render_cam` (its direction sets the views' direction) and a
// body `substrate` (the frame the HeightMap is given in); its <visual><global offwidth
// offheight> bounds the image size.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Core>

#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/types.hpp"
#include "render/deposit_mesh.hpp"

namespace depotwin {

class Simulation;

// a free camera (MuJoCo's mjCAMERA_FREE): looks at lookat_m from distance_m, its direction
// given by azimuth and elevation (deg; elevation < 0 looks down)
struct FreeCamera {
  Vec3 lookat_m = Vec3::Zero();
  double distance_m = 1.0;
  double azimuth_deg = 90.0;
  double elevation_deg = -45.0;
};

// The views and the colour scale of a scene. render_* frames them from the deposit it is given;
// a series of frames (a video) computes them once from the final deposit (frame_scene) and
// passes them in SceneRenderOptions::framing, so that the cameras and colours stay put.
struct SceneFraming {
  FreeCamera whole;                    // the whole machine, the deposit and the nozzle
  bool whole_from_render_cam = false;  // true: render_cam's own pose instead of `whole`
  FreeCamera closeup;                  // the deposit only
  double colour_top_um = 0.0;          // the thickness at the colour scale's top (0: no deposit)
  double relief_mm = 0.0;              // the drawn height of colour_top_um
};

struct SceneRenderOptions {
  int width = 640;  // the whole image, both panels and the strip
  int height = 480;
  // two panels: the whole machine on the left, a close-up of the deposit on the right;
  // false: the machine view alone
  bool closeup = true;
  // the strip below the panels with the colour bar, and the scale bars in the panels
  bool overlays = true;
  // true: the machine view is framed from the machine's, the deposit's and the nozzle's
  // bounds, seen from render_cam's direction (a machine carrying the nozzle on a chain of
  // bodies, an arm, from beside its part: see frame_scene); false: render_cam's own pose
  bool frame_deposit = true;
  // fixed views and colour scale (a video's frames); nullopt: framed from the deposit given
  std::optional<SceneFraming> framing;
  // The part's top surface under the deposit (conformal work): its height (mm) at (x, y) in
  // the substrate frame, nullopt where there is no part (the deposit there lies on z = 0).
  // Empty: a flat substrate. The part itself is a mesh geom of the model. Called from the
  // rendering thread (prepare's options are copied): it must be safe to call from any thread,
  // e.g. a SurfaceProjector::height_at held by a shared_ptr to const.
  std::function<std::optional<double>(double x_mm, double y_mm)> surface_height_mm;
  // on a surface, the deposit's relief stands along its normal (else vertically)
  bool tilt_to_surface = true;
  // drawn height of the thickest deposit as a fraction of the deposit region's size
  double relief_fraction = 0.04;
  // at most this many mesh vertices (the grid is resampled by block maxima to fit)
  int max_mesh_vertices = 250000;
  // the deposit thinner than this fraction of the colour scale's top is not drawn
  double min_relative_thickness = 0.02;
  // anti-aliasing: the scene is rendered this many times larger in each direction and each
  // image pixel is the mean of its block (1 = none). Supersampling rather than the model's
  // multisampling, which in software GL costs more (its own shader compilation, a resolve)
  int supersampling = 2;
  // shadow mapping: off by default. It costs a second pass in software (about 0.1 s per
  // image) and the delta's platform throws its shadow over the deposit it should show
  bool shadows = false;
};

// where the parts of an image are, in image pixels from its top-left corner (y down)
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};
struct SceneLayout {
  PixelRect whole;    // the machine
  PixelRect closeup;  // the deposit (width 0 without a close-up)
  PixelRect strip;    // colour bar (height 0 without overlays)
};
SceneLayout scene_layout(const SceneRenderOptions& options);

// The framing render_rgb uses for this state and deposit: the deposit mesh's colour top and
// relief, the machine view fitted to the bounds of the model's visible geoms (planes left
// out), the deposit and the nozzle site, the close-up to the deposit's (at least a few mm
// around the nozzle's point on the substrate without a deposit), both tightly to their panels'
// aspect. Both look from render_cam's azimuth (for a nozzle on a chain of bodies, an arm: the
// part broadside with the arm behind it), the close-up more steeply.
SceneFraming frame_scene(const mjModel& model, const mjData& data, const HeightMap& deposit,
                         const SceneRenderOptions& options);

// MuJoCo's free camera for `camera`
void set_free_camera(const FreeCamera& camera, mjvCamera& view);

// Where a world point (m) appears through an OpenGL camera of a scene (mjv_averageCamera of
// an updated mjvScene) drawn into `viewport` (mjr_render's projection): pixels from the
// viewport's bottom-left corner; nullopt behind the camera.
std::optional<Eigen::Vector2d> project_to_viewport(const mjvGLCamera& camera,
                                                   const mjrRect& viewport, const Vec3& world_m);
// viewport pixels per mm at a world point (m) seen through `camera` (a scale bar's length)
double pixels_per_mm(const mjvGLCamera& camera, const mjrRect& viewport, const Vec3& world_m);

// The overlays, drawn in the current GL context with MuJoCo's renderer (mjr_rectangle,
// mjr_label; `context` made with a font scale of about 100 x `pixel_scale`); rects in
// framebuffer pixels, sizes multiplied by `pixel_scale` (a supersampled render's factor).
// The close-up's view of a deposit with bounds [deposit_lo_mm, deposit_hi_mm] (substrate frame;
// both zero: none yet) on body `substrate`: geoms outside the substrate's tree above the
// deposit become see-through near it (the nozzle's tip, a shutter blade) and are left out
// higher up, where they would loom over the panel. scene.png, the videos and the viewer share it.
void ghost_over_deposit(const mjModel& model, const mjData& data, int substrate,
                        const Vec3& deposit_lo_mm, const Vec3& deposit_hi_mm, mjvScene& scene);

// Add a floor under the machine to `scene`, so that no view shows the empty background (the
// models have no skybox: in software GL each texture costs a shader compilation per process).
// Left out when the model has a plane of its own. scene.png, the videos and the viewer share it.
void add_backdrop(const mjModel& model, const mjData& data, mjvScene& scene);

// A colour bar over `strip`: viridis from 0 to colour_top_um with its values in um ("no
// deposit" without one).
// `gl_proc_address` draws the ramp as one smooth-shaded strip; without it, one mjr_rectangle
// per pixel column (slower in software GL).
void draw_colour_bar(const mjrRect& strip, double colour_top_um, int pixel_scale,
                     const mjrContext& context, GlProcAddress gl_proc_address = nullptr);
// a scale bar in the bottom-left corner of `panel`: a round length in mm about a fifth of its
// width, at `px_per_mm` (nothing when not positive)
void draw_scale_bar(const mjrRect& panel, double px_per_mm, int pixel_scale,
                    const mjrContext& context);
// a panel's title in its top-left corner
void draw_panel_title(const mjrRect& panel, const char* title, int pixel_scale,
                      const mjrContext& context);

// Renders scenes, keeping its GL and MuJoCo render contexts between images (rebuilt when
// a model of another shape, another image size or another shadow setting comes). Callable
// from several threads: renders take turns (there is one GL context).
class SceneRenderer {
 public:
  SceneRenderer();
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Build the contexts for the MJCF at `model_path` and images made with `options` on a
  // background thread, so that the costly set-up overlaps the simulation; the first render
  // waits for it. Errors surface there, or are dropped when the render needs other contexts
  // and they are rebuilt.
  // `model_text`: the MJCF to compile in place of the file's (Simulation's constructor)
  void prepare(const std::string& model_path, const SceneRenderOptions& options,
               const std::string& model_text = {});

  // as render_scene_rgb / render_scene_png below
  std::vector<unsigned char> render_rgb(const Simulation& simulation, const HeightMap& deposit,
                                        const SceneRenderOptions& options = {});
  void render_png(const Simulation& simulation, const HeightMap& deposit,
                  const std::string& png_path, const SceneRenderOptions& options = {});
  // at an explicit MuJoCo state (a replayed frame: qpos set and mj_forward done); `data` is
  // not modified (the renderer works on a copy). The contexts are reused for models of the
  // same shape (the same MJCF)
  std::vector<unsigned char> render_rgb(const mjModel& model, const mjData& data,
                                        const HeightMap& deposit,
                                        const SceneRenderOptions& options = {});

 private:
  struct Contexts;
  // wait for prepare() and adopt its contexts; rethrows its error
  void finish_preparation();

  std::mutex mutex_;  // one render or preparation at a time
  std::unique_ptr<Contexts> contexts_;
  std::future<std::unique_ptr<Contexts>> preparing_;
};

// Render the state after Simulation::run (its initial state before any) to RGB bytes, rows
// top to bottom (width * height * 3); the simulation is not modified (the renderer works on
// a copy of its state). InputError for an image larger than the model's offscreen buffer or a
// model without render_cam/substrate; InternalError when OSMesa or MuJoCo's renderer fails.
std::vector<unsigned char> render_scene_rgb(const Simulation& simulation, const HeightMap& deposit,
                                            const SceneRenderOptions& options = {});
// Render and write a PNG: to a temporary file beside `png_path`, then renamed over it.
void render_scene_png(const Simulation& simulation, const HeightMap& deposit,
                      const std::string& png_path, const SceneRenderOptions& options = {});

// the largest SceneRenderOptions::supersampling
constexpr int kMaxSupersampling = 4;

}  // namespace depotwin
