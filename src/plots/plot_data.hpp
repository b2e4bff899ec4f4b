// The data behind the plots, computed before any drawing so tests can check it: transition
// bands, min/max-preserving decimation, error series, display-sized thickness maps and the
// fixed-format text that gnuplot reads. Pure functions; no gnuplot here.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/toolpath.hpp"
#include "core/trajectory.hpp"
#include "core/triangle_mesh.hpp"
#include "metrics/motion_metrics.hpp"

namespace depotwin::plots {

// One time interval [begin_s, end_s] (s).
struct TimeInterval {
  double begin_s = 0.0;
  double end_s = 0.0;
};
bool operator==(const TimeInterval& a, const TimeInterval& b);

// the transitions of a plan: maximal runs of consecutive pieces that deposit nothing, with
// the pieces' exact boundary times; empty when material is on for the whole job
std::vector<TimeInterval> transition_intervals(const Trajectory& trajectory);
// the same from samples (when no Trajectory is at hand): each maximal run of non-depositing
// samples, from its first sample's time to the time of the next depositing sample (or the
// last sample); exact to the sampling period
std::vector<TimeInterval> transition_intervals(const MotionSamples& samples);

// A print path's number (0-based, in print order) at a point of it.
struct PathLabel {
  double x_mm = 0.0, y_mm = 0.0;
  int path = 0;
};
// each path's number at the point halfway along its length (its arcs followed exactly)
std::vector<PathLabel> halfway_path_labels(const Toolpath& toolpath);

// A label as drawn: the path numbers it stands for ("3", "0–2", "0, 4") at a point.
struct DrawnLabel {
  std::string text;
  double x_mm = 0.0, y_mm = 0.0;
};
// The labels to draw, so that numbers do not cover one another: taken in order, a label within
// merge_within_mm (in x-y) of a drawn label's point joins it (a part's stacked layers share
// one); a new one is drawn at its own point. Empty when more than max_drawn would be drawn.
std::vector<DrawnLabel> drawn_path_labels(const std::vector<PathLabel>& labels,
                                          double merge_within_mm, size_t max_drawn);
// path.png and the orders comparison: numbers closer than kLabelMergeShare of the plot's
// larger side share a label; none are drawn when more than kMaxPathLabels labels would be
constexpr double kLabelMergeShare = 0.03;
constexpr size_t kMaxPathLabels = 40;

// Whether a toolpath's print paths drawn over a map of the window [x_lo, x_hi] x [y_lo, y_hi]
// (mm) would hide it: they pass through more than kCrowdedShare of the cells (a grid of
// kCrowdGrid cells along the window's longer side, about 4 px each on a map) that their bounds
// cover in the window, as a slicer's infill does, its lines closer than two cells. Arcs are
// followed exactly; layers stacked on one another count once.
constexpr int kCrowdGrid = 100;
constexpr double kCrowdedShare = 0.5;
bool paths_crowd_window(const Toolpath& toolpath, double x_lo, double x_hi, double y_lo,
                        double y_hi);

// A curve as gnuplot draws it: points in order, a NaN in x marks a break in the line.
struct Curve {
  std::vector<double> x, y;

  size_t size() const { return x.size(); }
  void add(double px, double py);
  void add_break();
  // points that are not breaks
  size_t point_count() const;
};

// A curve in 3-D (splot): points in order, a NaN in x marks a break in the line.
struct Curve3 {
  std::vector<double> x, y, z;

  size_t size() const { return x.size(); }
  void add(const Vec3& p);
  void add_break();
  size_t point_count() const;
};

// Min/max-preserving decimation of values[begin, end): the range is cut into buckets of
// equal sample count and each bucket keeps its smallest and its largest sample (in index
// order); the first and the last sample are always kept. At most max_points indices
// (max_points >= 4), sorted; the global extrema of the range are always among them.
std::vector<size_t> decimate_min_max(const std::vector<double>& values, size_t begin, size_t end,
                                     size_t max_points);

// y(t) as a curve of at most about max_points points: NaN values in y are gaps (the line
// breaks there); each finite run is decimated with decimate_min_max, the point budget shared
// in proportion to the runs' sample counts (every run keeps at least its ends)
Curve time_curve(const std::vector<double>& t_s, const std::vector<double>& y, size_t max_points);

// which samples an XY path curve shows
enum class PathPart { printing, transition, all };
// XY path of the samples in `part` (one line per maximal run; a transition run reaches the
// print samples on both sides), thinned to points a minimum spacing apart (run ends always
// kept); the spacing starts below a pixel (extent / 1500) and grows until the curve has at
// most max_points points
Curve xy_path_curve(const MotionSamples& samples, PathPart part, size_t max_points);

// the same in 3-D: the samples in `part` (a transition run reaching the print samples on
// both sides), thinned to points a minimum 3-D spacing apart (run ends kept), at most about
// max_points points
Curve3 path_curve_3d(const MotionSamples& samples, PathPart part, size_t max_points);
// polylines (one line each) thinned the same way: each keeps its ends and the points at least
// the spacing from the last kept one; the spacing grows until at most max_points remain
Curve3 polylines_3d(const std::vector<const std::vector<Vec3>*>& lines, size_t max_points);

// The part's surface for display: the triangles seen from above, i.e. those that face up
// (facet normal z > 0.05) and those facing down (z < -0.05) with nothing of the mesh above
// their centre, turned over (an open surface seen from its back, as the hatch prints it),
// decimated by vertex clustering on an x-y grid (each grid cell's vertices merged into the
// one nearest the cell's centre, so every vertex stays on the surface; triangles that collapse
// or repeat dropped), the grid coarsened until at most max_triangles remain.
TriangleMesh display_surface(const TriangleMesh& mesh, size_t max_triangles);

// the size the relative path error is divided by: the largest extent of the print paths'
// bounding box (Thompson & Yoon's 10-mm feature); falls back to Toolpath::bounds when no
// print path is given and to 1 mm for a degenerate toolpath
double feature_size_mm(const Toolpath& toolpath);

// e = | |v| - v_des | / v_des (relative_speed_error) where material is deposited, NaN elsewhere
std::vector<double> speed_error_with_gaps(const MotionSamples& samples);
// distance to the print path being printed / feature size where material is deposited on a
// valid path, NaN elsewhere
std::vector<double> relative_position_error(const MotionSamples& samples, const Toolpath& toolpath,
                                            double feature_mm);

// A thickness map reduced for display: each output cell is the largest of a block of
// `factor` x `factor` input cells (cells beyond the edge ignored; max-pooling, so a line
// narrower than a block keeps its peak and stays visible), centred on the block, so that
// neither side has more than max_cells_per_side cells. factor 1 copies the map.
HeightMap downsample_for_display(const HeightMap& map, int max_cells_per_side);

// `text` broken at spaces into lines of at most max_chars characters (UTF-8 code points; a
// word longer than that stays whole on a line of its own)
std::vector<std::string> wrap_text(const std::string& text, size_t max_chars);

// the smallest step of 1, 2 or 5 x 10^n at least `rough` (> 0)
double round_step_up(double rough);
// the characters of the widest "%g" label of the ticks (multiples of step) inside [lo, hi]
size_t widest_tick_label(double lo, double hi, double step);
// the number of ticks (multiples of step) inside [lo, hi]
int tick_count(double lo, double hi, double step);
// a tick step for an axis over [lo, hi]: preferred_step (e.g. one shared by both axes of a
// map) when it puts at least min_ticks ticks on the axis, else the largest step of 1, 2 or 5 x
// 10^n below it that does; a preferred_step <= 0 starts from the span. 1 for an empty span.
double axis_tick_step(double lo, double hi, double preferred_step, int min_ticks = 3);

// `map` on its own cell lattice, grown with zero cells to cover [x_lo, x_hi] x [y_lo, y_hi]
// (cell edges; never shrunk): maps of several runs drawn on shared axes then all fill them,
// with no white strip where one run's grid ends
HeightMap pad_to_extent(const HeightMap& map, double x_lo, double x_hi, double y_lo, double y_hi);

// `value` with as many decimals as give `largest` three significant digits (none from 100 up):
// one fixed format for numbers shown side by side ("2000" and "1034", not "2e+03" and "1.03e+03")
std::string fixed_text(double value, double largest);

// the text gnuplot reads: "x y" per line in fixed %.9g format, a blank line per break
std::string format_curve(const Curve& curve);
// "x y z" per line, two blank lines per break (one would make splot join the lines into a grid)
std::string format_curve3(const Curve3& curve);
// each triangle as a closed polygon: its three corners ("x y z"), a blank line after each
std::string format_triangles(const TriangleMesh& mesh);
// float32 cells in row-major order (x fastest), host byte order, for `binary array=(nx,ny)`
std::string format_binary_map(const HeightMap& map);

// printf into a std::string (C locale number formatting)
std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));

}  // namespace depotwin::plots
