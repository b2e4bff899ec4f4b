// The MuJoCo scene at the end of a job, rendered headless through OSMesa to a PNG
// (MuJoCo sample/record.cc as one straight line: set up, update, render, read, free),
// with the deposited material drawn on the substrate as thin boxes coloured by thickness.
//
// The model must have a camera `render_cam` and a body `substrate` (the frame the
// HeightMap is given in); its <visual><global offwidth offheight> bounds the image size.
// Deposited films are micrometres thick: their height is exaggerated (the tallest deposit
// is drawn as a fraction of the deposit region's size) and the colour carries the value
// (viridis, a perceptually uniform colormap: dark purple = thin, yellow = the thickest).
// On a part (conformal work) each box stands on the part's surface, tilted to its slope.
#pragma once

#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/types.hpp"

namespace depotwin {

class Simulation;

struct SceneRenderOptions {
  int width = 640;
  int height = 480;
  // true: look along render_cam's direction at the deposit region and the nozzle, from a
  // distance that fits them (and, for a machine that carries the nozzle on a chain of bodies,
  // such as an arm, its tool and, on a large enough part, its wrist, seen from beside the part
  // with the arm behind it: see frame_camera in scene.cpp); false: render_cam's own pose and
  // field of view
  bool frame_deposit = true;
  // The part's top surface under the deposit (conformal work): its height (mm) at (x, y) in
  // the substrate frame, nullopt where there is no part (the deposit there lies on z = 0).
  // Empty: a flat substrate, every box on z = 0. The part itself is a mesh geom of the model.
  // Called from the rendering thread (prepare's options are copied): it must be safe to call
  // from any thread, e.g. a SurfaceProjector::height_at held by a shared_ptr to const.
  std::function<std::optional<double>(double x_mm, double y_mm)> surface_height_mm;
  // on a surface, boxes are tilted to its slope (their axis the normal the heights around them
  // give) rather than standing upright as a staircase
  bool tilt_to_surface = true;
  // drawn height of the thickest deposit as a fraction of the framed region's size
  double relief_fraction = 0.04;
  // at most this many grid cells are drawn (the grid is averaged over square blocks to fit)
  int max_boxes = 10000;
  // cells thinner than this fraction of the thickest are not drawn (footprint tails)
  double min_relative_thickness = 0.02;
  // anti-aliasing: the scene is rendered this many times larger in each direction and each
  // image pixel is the mean of its block (1 = none). Supersampling rather than the model's
  // multisampling, which in software GL costs more (its own shader compilation, a resolve)
  int supersampling = 2;
  // shadow mapping: off by default. It costs a second pass in software (about 0.1 s per
  // image) and the delta's platform throws its shadow over the deposit it should show
  bool shadows = false;
};

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

// One box of the drawn deposit, in the substrate frame (mm): it stands on `base_mm` (a point of
// the surface, or of z = 0) along `axis` (unit: the surface normal, or +z), a square of
// 2 half_width_mm across and 2 half_height_mm tall (the exaggerated relief), lifted
// `lift_mm` off the surface so it never z-fights with it; `relative` is its thickness over
// the colour scale's top (its viridis value).
struct DepositBox {
  Vec3 base_mm = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double half_width_mm = 0.0;
  double half_height_mm = 0.0;
  double lift_mm = 0.0;
  double relative = 0.0;
};
// The boxes render_scene_* draw for `deposit`: the grid averaged over square blocks so that
// at most options.max_boxes remain, one box per block at least min_relative_thickness of the
// thickest block; the tallest relief_mm tall.
std::vector<DepositBox> deposit_boxes(const HeightMap& deposit, double relief_mm,
                                      const SceneRenderOptions& options);

// the largest SceneRenderOptions::supersampling
constexpr int kMaxSupersampling = 4;

// viridis colour of a value in [0, 1] (clamped), RGB in [0, 1]
void viridis(double value, float rgb[3]);

}  // namespace depotwin
