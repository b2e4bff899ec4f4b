// The deposit drawn as a smooth surface: a height-field triangle mesh built from a HeightMap,
// one vertex per (resampled) grid cell, its height the exaggerated thickness and its colour the
// thickness on viridis (a perceptually uniform colormap: dark purple = thin, yellow = the
// colour scale's top), laid on the substrate or, on a part, on the part's surface along its
// normal. Drawn in any current legacy (fixed-function) GL context after MuJoCo 2.2.2's
// mjr_render, with the scene camera's projection, depth-tested against what MuJoCo drew: the
// offscreen scene renderer (scene.cpp) and an interactive window use the same code.
//
// Sampling is honest: a grid larger than the vertex budget is resampled by the MAXIMUM over
// square blocks, not the mean or a point sample. A narrow bead then keeps its crest thickness
// in every block it crosses, whatever its offset to the block grid; a mean or a point sample
// would make a uniform line look mottled, alternating between blocks that hold its crest and
// blocks that straddle its flank.
#pragma once

#include <mujoco/mujoco.h>

#include <functional>
#include <optional>
#include <vector>

#include "core/heightmap.hpp"
#include "core/types.hpp"

namespace depotwin {

struct DepositMeshOptions {
  // drawn height (mm) of a deposit as thick as colour_top_um (films are micrometres thick: the
  // relief is exaggerated and the colour carries the value)
  double relief_mm = 0.0;
  // the thickness at the colour scale's top (viridis 1); 0: the map's peak. A series of frames
  // (a video) passes the final map's so colours and heights do not shift as the deposit grows
  double colour_top_um = 0.0;
  // the part's top surface (conformal work): its height (mm) at (x, y) in the substrate frame,
  // nullopt off the part (the deposit there lies on z = 0). Empty: a flat substrate. Called
  // once per drawn vertex; must be safe to call from any thread
  std::function<std::optional<double>(double x_mm, double y_mm)> surface_height_mm;
  // on a surface, the relief stands along the surface's normal (else vertically)
  bool along_normal = true;
  // at most this many vertices: a larger grid is resampled by the maximum over square blocks
  int max_vertices = 250000;
  // triangles whose every vertex is thinner than this fraction of colour_top_um are left out
  // (the substrate shows there)
  double min_relative_thickness = 0.02;
  // the mesh floats this far above the surface (mm), so that it never z-fights with it
  double lift_mm = 0.005;
};

// A height-field triangle mesh in the SUBSTRATE frame (mm), per-vertex colour and normal.
struct DepositMesh {
  std::vector<float> positions_mm;  // x, y, z per vertex
  std::vector<float> normals;       // unit, per vertex (for shading)
  std::vector<float> colours;       // r, g, b in [0, 1] per vertex: viridis(thickness / top)
  std::vector<float> thickness_um;  // per vertex: the (block maximum) thickness it shows
  std::vector<unsigned> triangles;  // 3 vertex indices each, counter-clockwise from above
  double colour_top_um = 0.0;       // the thickness at viridis 1 (the colour bar's top)
  double relief_mm = 0.0;           // drawn height of colour_top_um
  int stride = 1;                   // grid cells per vertex in x and y (the resampling block)
  Vec3 lo_mm = Vec3::Zero();        // bounds of the vertices (substrate frame)
  Vec3 hi_mm = Vec3::Zero();
  bool empty() const { return triangles.empty(); }
  size_t vertex_count() const { return positions_mm.size() / 3; }
};

// The mesh of `map`: the grid resampled by block maxima to at most options.max_vertices
// vertices (only cells near the deposit count: a vertex exists where its block, or a
// neighbouring block, reaches min_relative_thickness of the top), each at its block's centre
// (x, y), at height z = surface + (lift_mm + relief_mm * min(t / top, 1)) along the surface
// normal (+z on a flat substrate), coloured viridis(t / top). Deterministic.
DepositMesh build_deposit_mesh(const HeightMap& map, const DepositMeshOptions& options);

// An OpenGL entry point by name: OSMesaGetProcAddress for the offscreen renderer,
// glfwGetProcAddress in a GLFW window. The mesh is drawn through pointers resolved this way,
// so that the library never binds GL symbols at link time (an executable may link both
// OSMesa and the system libGL).
using GlProcAddress = void* (*)(const char* name);

// Draw `mesh` into the current GL context, after mjr_render(viewport, &scene, ...) drew
// `scene` there: projection and modelview from the scene's cameras (mjv_averageCamera and its
// frustum, as mjr_render sets them), depth-tested against MuJoCo's depth buffer (depth
// convention read from GL_DEPTH_FUNC), shaded by a headlight, both faces. `substrate_pos` (m)
// and `substrate_mat` (row-major 3x3) place the substrate frame in the world (mjData xpos /
// xmat of the body "substrate"). GL state is saved and restored. InternalError when
// `gl_proc_address` cannot resolve a GL function.
void draw_deposit_mesh(const DepositMesh& mesh, const mjvScene& scene, const mjrRect& viewport,
                       const mjtNum substrate_pos[3], const mjtNum substrate_mat[9],
                       GlProcAddress gl_proc_address);
// the same with the substrate placed from the body "substrate" of model/data
void draw_deposit_mesh(const DepositMesh& mesh, const mjvScene& scene, const mjrRect& viewport,
                       const mjModel& model, const mjData& data, GlProcAddress gl_proc_address);

// viridis from 0 (left) to 1 (right) across `rect` (framebuffer pixels) of the current GL
// context, the colour bar's ramp; GL state saved and restored
void draw_viridis_ramp(const mjrRect& rect, GlProcAddress gl_proc_address);

// viridis colour of a value in [0, 1] (clamped), RGB in [0, 1]
void viridis(double value, float rgb[3]);

}  // namespace depotwin
