// Conformal zig-zag hatching on a part's top surface: Shembekar et al. 2018, Algorithm 1
// (sec. 3.2-3.4), with the projection done by ray casting (surface_projection.hpp).
//
// Per layer k (0-based) with hatch angle theta = angles_deg[k % size] (from +x about +z):
//  - the grid: in the hatch frame (d = (cos theta, sin theta) along the lines, e = (-sin,
//    cos) across), lines at spacing hatch_mm across and points every hatch_mm along each
//    line, over the extent of the part's vertices in that frame, centred on it (so the grid
//    is symmetric over the part and does not depend on where the part's bounds begin);
//  - each grid point is projected straight down onto the top surface;
//  - a line is broken where the surface is absent (no hit: a hole or beyond an edge; or a
//    normal with n_z <= min_normal_z: a wall) and where consecutive surface points are more
//    than max_jump_ratio * hatch_mm apart in 3-D where the surface between them is no even
//    slope (a step: rises_evenly in hatching.cpp); every piece of at least two
//    points is a PrintPath (the planner joins pieces by travels);
//  - beyond the paper, a chord between two points that the surface rises above by more than
//    chord_tolerance_mm halfway (a ridge between grid points: the nozzle would cut into the
//    part) gets the surface point there, one that the chord lifted by chord_tolerance_mm
//    still meets (a step's edge off the midpoint) the surface where it meets it, and its
//    halves are checked again;
//  - lines go in order across the part (increasing e), every other printed line reversed
//    (zig-zag; the alternation counts lines that have a piece, so a line lost entirely to a
//    hole does not break it); a reversed line's pieces come in reverse order, each reversed;
//  - points are offset from the surface by k * layer_height_mm along the smooth surface
//    normal (Offset::normal: parallel layers of equal thickness) or along +z (Offset::z, as
//    in the paper); along the normal, a line that folds back over a concave crease (the
//    points either side pushed past each other) is cut at the crossing of its two sides, a
//    point on such a crease offset over the far side is dropped, and over a convex crease
//    the offset's arc about it is added within chord_tolerance_mm;
//  - the tool axis is the smooth surface normal tilted back toward vertical by alpha: the
//    slerp from +z (alpha = 0) to the normal (alpha = 1). The paper scales its rotation angles
//    R_x = -atan(n_y / n_z), R_y = atan(n_x / n_z) by alpha; the slerp scales the single
//    tilt angle instead: the same for a normal tilted about x or about y alone, and free of
//    the order in which two Euler rotations are applied otherwise.
// Both the offset and the tool axis use the smooth (vertex-interpolated) normal, not the
// facet normal: facet normals jump at every triangle edge, which would turn the tool in
// steps at each edge and, for offset layers, tear the offset points apart at convex edges
// and fold them over at concave ones.
#pragma once

#include <string>
#include <vector>

#include "core/toolpath.hpp"
#include "core/triangle_mesh.hpp"
#include "toolpath/surface_projection.hpp"

namespace depotwin {

struct SurfaceHatchSpec {
  double hatch_mm = 0.5;                     // line spacing and point spacing along lines
  std::vector<double> angles_deg = {0, 90};  // layer k hatches at angles_deg[k % size]
  int layers = 1;
  double layer_height_mm = 0.5;
  double alpha = 0.5;  // tool axis: 0 vertical, 1 along the surface normal
  enum class Offset { normal, z };
  Offset offset = Offset::normal;
  double speed_mm_s = 10.0;
  double min_normal_z = 0.1;    // a surface whose normal has n_z <= this is no surface
  double max_jump_ratio = 3.0;  // farther apart than this * hatch_mm, no slope between: a break
  // a chord between consecutive points that the surface rises more than this above (halfway,
  // or where the chord lifted by this meets it) is refined by the surface point there (0: the
  // grid's points only, as in the paper; else at least kLeastChordTolerance_mm)
  double chord_tolerance_mm = 0.05;
  static constexpr double kLeastChordTolerance_mm = 1e-4;
  // a convex crease's offset arc takes at most this many chords (finer than the tolerance
  // where the offset is large: 2^10 chords of a 90 deg arc keep within 1.2e-6 of its radius)
  static constexpr int kMaxCreaseChords = 1024;
};

// Where each path came from and what the surface is like under it.
struct HatchPathInfo {
  int layer = 0;
  int line = 0;                         // the grid line's index in its layer (0 at the -e side)
  bool reversed = false;                // printed against the line's direction d
  std::vector<int> point_index;         // per point: its index along the grid line
  std::vector<Vec3> surface_points_mm;  // per point: the projected point on the surface
  std::vector<Vec3> surface_normals;    // per point: the smooth surface normal (the deposit's
                                        // normal; the tool axis is PrintPath::normals)
};

// The up-facing grid points of one hatch angle that no line prints although the same grid
// line prints on both sides of them: each stands alone between steps or walls (a line needs
// two points), as on a groove's floor or a ridge's top narrower than two spacings (a line
// that stops one point short of a rim is not counted). lower/upper bound them (0 when none).
struct LoneGridPoints {
  double angle_deg = 0.0;
  int count = 0;
  int grid_points = 0;  // the grid points printed at this angle and the lone ones
  Vec3 lower_mm = Vec3::Zero();
  Vec3 upper_mm = Vec3::Zero();
};

struct SurfaceHatch {
  // print paths in print order: layer by layer, line by line; source_index = the path's
  // position, layer = its layer, normals = tool axes; start and end left at the origin
  Toolpath toolpath;
  std::vector<HatchPathInfo> info;  // one per path
  // grid lines per layer (printed or not) and grid points per line, for reports
  std::vector<int> lines_per_layer;
  std::vector<int> points_per_line;
  // per distinct angle, in the layers' order: the grid points no line prints
  std::vector<LoneGridPoints> lone_points;

  // "layer 3, line 12, point 40" for point i of path p
  std::string describe(std::size_t path, std::size_t point) const;
};

// The hatch of the part (a mesh placed in the work frame, mm). InputError (key
// "toolpath.surface.<field>") for a bad spec: hatch_mm not positive, no angles, a non-finite
// angle, layers < 1, a negative layer height, alpha outside [0, 1], speed not positive, a
// grid of more than 2e7 points per layer.
SurfaceHatch hatch_surface(const TriangleMesh& placed_part_mm, const SurfaceHatchSpec& spec);
// the same with a projector built once (several hatches of one part)
SurfaceHatch hatch_surface(const SurfaceProjector& projector, const SurfaceHatchSpec& spec);

// The up-facing area the hatch cannot reach: every grid point is projected straight down, so
// only the top surface is printed; an up-facing triangle (facet n_z > min_normal_z) with
// another part of the surface above it (a shelf under an overhang, a cavity's floor) gets no
// deposit. Each triangle is sampled at the four centroids of its midpoint subdivision, a
// quarter of its area each; a sample is hidden when the first surface above it is more than
// 1e-3 mm (or 1e-6 of the part's size) higher.
struct HiddenSurface {
  double up_area_mm2 = 0.0;      // the up-facing area
  double hidden_area_mm2 = 0.0;  // the part of it under another part of the surface
  Vec3 lower_mm = Vec3::Zero();  // the bounds of the triangles with a hidden sample, if any
  Vec3 upper_mm = Vec3::Zero();
};
HiddenSurface hidden_top_surface(const SurfaceProjector& projector, double min_normal_z = 0.1);

}  // namespace depotwin
