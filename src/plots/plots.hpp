// Plots of a run and of a planner comparison, drawn by gnuplot (pngcairo) from data this
// module prepares: the style of Thompson & Yoon's Figs. 8-12 (file 000), one gnuplot process
// per call, PNGs rendered in a temporary directory and renamed into place.
//
// A missing gnuplot throws GnuplotNotFound (an InternalError: exit 1) naming the package;
// callers skip these functions entirely under --no-render.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/heightmap.hpp"
#include "core/limits.hpp"
#include "core/recorded_run.hpp"
#include "core/toolpath.hpp"
#include "core/triangle_mesh.hpp"
#include "metrics/motion_metrics.hpp"
#include "plots/gnuplot.hpp"
#include "plots/plot_data.hpp"

namespace depotwin::plots {

// Thickness sampled along one print line's centreline.
struct LineProfile {
  int path_index = 0;  // index into Toolpath::paths
  std::vector<double> arc_length_mm, thickness_um;
};

// The machine's joint positions over a run (joints.png), every joint on one clock.
struct JointSeries {
  std::vector<std::string> names;  // per joint, e.g. "j1"
  // per joint, the unit of its values: "rad" (a revolute joint, drawn in degrees), "deg", or
  // "mm" (a prismatic joint); any other is drawn as given
  std::vector<std::string> units;
  std::vector<double> t_s;
  std::vector<std::vector<double>> position;  // per joint, one value per t_s
  // per joint, its range in its unit; a joint with !(min < max) (or non-finite) has none
  std::vector<double> min, max;
};
// The joints of a recorded run (RecordedRun::joint_position, its own units: rad for hinges,
// mm for slides) with the machine's ranges; `revolute` per joint (true: "rad", false: "mm").
// InternalError when the counts differ.
JointSeries joint_series(const RecordedRun& run, const std::vector<JointLimit>& limits,
                         const std::vector<bool>& revolute);

// The colour range maps drawn side by side share, [0, top_um]: the largest peak of all maps,
// capped at kSharedScaleCap (2) x the median map's 95th percentile of its deposit cells (cells
// above a 10^4th of its peak; the lower middle one of an even count), so one blob (a run's, or a
// layer start's) does not wash the other maps' lines out (its cells above the top take the
// top colour; the colour bar's label then gives the peak). 1 um when all are empty.
struct SharedThicknessScale {
  double top_um = 1.0;
  double peak_um = 0.0;  // the largest cell of all maps
  bool capped = false;   // top_um < peak_um
};
constexpr double kSharedScaleCap = 2.0;
// null or empty maps are skipped
SharedThicknessScale capped_thickness_scale(const std::vector<const HeightMap*>& maps);
// what a capped scale's colour bar says under its title ("topped at 2 × the median <map_noun>'s
// 95th percentile (thicker: the top colour); peak N µm", "2 × the 95th percentile" for one map,
// map_noun ""); empty when not capped
std::string capped_scale_note(const SharedThicknessScale& scale, const std::string& map_noun);

// Everything the run plots show. Pointers are borrowed for the call; the struct owns nothing.
struct RunPlotInput {
  std::string title;                         // e.g. "two_segments / lspb_mtt", on every plot
  const Toolpath* toolpath = nullptr;        // required
  const MotionSamples* planned = nullptr;    // required: the plan every 1 ms
  const MotionSamples* simulated = nullptr;  // optional: same timestamps; null/empty = plan only
  // the shaded transition bands: transition_intervals(trajectory) for exact boundaries;
  // nullopt derives them from the planned samples
  std::optional<std::vector<TimeInterval>> transitions;
  // thickness (optional; needed for thickness.png and thickness_profile.png)
  const HeightMap* thickness = nullptr;
  std::vector<LineProfile> profiles;
  double target_thickness_um = 0.0;  // <= 0: no target line
  // where the target comes from, printed under thickness_profile.png (target_thickness_note);
  // empty: the general rule
  std::string target_note;
  // metrics.json's thickness.mean_um: the mean over the lines' whole width (the target region),
  // named in a note under thickness_profile.png (<= 0: none); the plot's mean line is the
  // centreline mean, computed from the profiles
  double mean_thickness_um = 0.0;
  // the job's layers: with several, each profile is its own layer's deposit and
  // mean_thickness_um is the stack's (both said on the plot)
  int layer_count = 1;
  double feature_size_mm = 0.0;  // <= 0: feature_size_mm(*toolpath)
  // joints.png (optional): the joints against time, with their ranges
  const JointSeries* joints = nullptr;
  // layers.png (optional): each layer's thickness map (index = PrintPath::layer, 0-based as in
  // metrics.json); null or empty: nothing deposited on that layer
  std::vector<const HeightMap*> layer_maps;
  // per layer, its hatch angle (deg); missing or NaN: unknown (the panel says "layer k" only)
  std::vector<double> layer_angles_deg;
  // paths3d.png: the part's surface under the paths (optional; work frame, mm)
  const TriangleMesh* part = nullptr;
};

// thickness_profile.png's note on the target: the centreline peak of a straight line at
// its print speed, with the numbers of the process (aerosol: Q / (v sigma sqrt(2 pi));
// extrusion: the bead's w x h cross-section as a Gaussian, w h / (sigma sqrt(2 pi)), sigma =
// w / 4: 1.60 h); short enough for one line under the plot
std::string target_thickness_note(bool extrusion, double target_um, double speed_mm_s,
                                  double sigma_mm, double flow_mm3_s, double bead_width_mm,
                                  double layer_height_mm);

enum class RunPlot { path, axes, errors, thickness_profile, thickness, joints, layers, paths3d };
// "path.png", "axes.png", "errors.png", "thickness_profile.png", "thickness.png",
// "joints.png", "layers.png", "paths3d.png"
const char* file_name(RunPlot plot);
// the plots the input has data for: path, axes, errors always; the thickness plots when
// a non-empty map / at least one profile is given; joints.png with a JointSeries of at least
// one joint; layers.png when some layer map is non-empty; paths3d.png for a conformal job (a
// part is given, or the toolpath has tool axes or several layers)
std::vector<RunPlot> available_plots(const RunPlotInput& input);

struct PlotOptions {
  std::string gnuplot = "gnuplot";  // program name (PATH) or path
  size_t max_points_per_curve = 1200;
  int max_map_cells_per_side = 400;  // thickness maps are max-pooled down to this
  int max_layer_panels = 8;          // layers.png: more layers are shown evenly chosen
  size_t max_part_triangles = 3000;  // paths3d.png: the part's surface is decimated to this
  size_t max_tool_axes = 120;        // paths3d.png: at most this many tool-axis segments
};

// One joint's panel of joints.png, in display units.
struct JointPanel {
  std::string name;
  std::string unit;  // as drawn: "deg" for a revolute joint, "mm" for a prismatic one
  Curve position;    // decimated, against time
  bool limited = false;
  double min = 0.0, max = 0.0;  // the range (limited only)
  // the panel's y range; limited: y_lo < min < max < y_hi, and the forbidden bands shaded
  // are [y_lo, min] and [max, y_hi]
  double y_lo = 0.0, y_hi = 0.0;
  // the smallest distance of any sample from the nearer limit (negative: beyond it); NaN
  // without limits or samples
  double closest_to_limit = 0.0;
};

// One panel of layers.png.
struct LayerPanel {
  int layer = 0;      // index into RunPlotInput::layer_maps
  std::string title;  // "layer k (θ°)" or "layer k"
  HeightMap map;      // at display resolution; empty: nothing deposited on it
  Curve paths;        // the layer's print paths, x-y
};

struct PlotResult {
  std::vector<std::string> files;     // the PNGs written, in request order
  std::vector<std::string> warnings;  // what gnuplot printed on stderr (empty when clean)
};

// The data behind the run plots, exactly what gets drawn (decimated curves in plot units).
struct RunPlotData {
  std::vector<TimeInterval> transitions;  // shaded in axes.png and errors.png
  double duration_s = 0.0;
  double feature_size_mm = 1.0;
  bool simulated = false;
  // path.png
  Curve planned_print_xy, planned_transition_xy, simulated_xy;
  // axes.png: per axis x, y, z; an axis is drawn when it moves in the plan or the simulation
  Curve planned_position[3], planned_velocity[3], simulated_position[3], simulated_velocity[3];
  bool axis_moves[3] = {false, false, false};
  // errors.png, in percent (gaps where nothing is deposited)
  Curve planned_speed_error_pct, simulated_speed_error_pct;
  Curve planned_position_error_pct, simulated_position_error_pct;
  // thickness_profile.png
  std::vector<Curve> profiles;
  // thickness.png: the map at display resolution
  HeightMap display_map;
  // joints.png
  std::vector<JointPanel> joint_panels;
  // layers.png: the shown layers, the layer count, the shared colour range (the shown layers'
  // capped_thickness_scale: a blob where the layers start does not wash the beads out) and
  // the x-y extent every panel shows
  std::vector<LayerPanel> layer_panels;
  int layer_count = 0;
  SharedThicknessScale layer_scale;
  double layers_x_lo = 0.0, layers_x_hi = 0.0, layers_y_lo = 0.0, layers_y_hi = 0.0;
  // paths3d.png: print paths per layer (index = layer; the toolpath's points, thinned),
  // travels (the planned samples where not depositing), tool-axis segments (two points each:
  // a print path's point and that point + tool_axis_length_mm * its tool axis), the part's
  // surface seen from above, decimated (display_surface)
  std::vector<Curve3> layer_paths;
  Curve3 travels;
  Curve3 tool_axes;
  double tool_axis_length_mm = 0.0;
  TriangleMesh part_surface;
};
// InternalError when a required input is missing
RunPlotData prepare_run_plot_data(const RunPlotInput& input, const PlotOptions& options = {});

// Render `plots` (default: available_plots(input)) into directory/<file_name>; one gnuplot
// process for all of them. Throws GnuplotNotFound / InternalError.
PlotResult render_run_plots(const RunPlotInput& input, const std::string& directory,
                            const std::vector<RunPlot>& plots = {},
                            const PlotOptions& options = {});

// One planner's column of the comparison sheet.
struct ComparisonColumn {
  std::string planner;
  const HeightMap* thickness = nullptr;  // null or empty: "no deposition" (plan only)
  // relative speed error against time; NaN = not depositing (speed_error_with_gaps)
  std::vector<double> t_s, speed_error_rel;
  std::vector<TimeInterval> transitions;  // shaded under the speed error
  // the print order (MetricsReport::sequencer); columns of different orders make an orders
  // comparison, which shows each column's travels instead of its (identical) thickness map
  std::string order;
  // the plan's x-y path: printing and travelling (set_travels), and each path's number
  Curve print_xy, travel_xy;
  std::vector<PathLabel> path_labels;
  // key metrics; nullopt prints "n/a"
  std::optional<double> max_speed_error_rel, steady_speed_error_rel, rms_speed_error_rel,
      thickness_cv, waste_fraction, total_time_s;
};
// fill t_s and speed_error_rel from samples (the simulated ones when there are)
void set_speed_error(ComparisonColumn& column, const MotionSamples& samples);
// fill print_xy, travel_xy and path_labels from the plan's samples: each printed run is
// labelled with its path index (0-based print order) at its middle sample
void set_travels(ComparisonColumn& column, const MotionSamples& planned);

// The comparison sheet's zoom: a square window around the thickest cell of all the maps (the
// largest deviation above the target), the same window in every column.
struct ZoomWindow {
  bool found = false;  // false: every map is empty or zero
  double centre_x_mm = 0.0, centre_y_mm = 0.0, peak_um = 0.0;
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;  // mm
};
// the window: an eighth of the largest map extent a side, at least 24 cells, centred on the
// first thickest cell (maps in order, cells row by row), inside the maps' joint extent
ZoomWindow thickest_spot_window(const std::vector<const HeightMap*>& maps);
// the cells of `map` whose centres lie inside the window (an empty map when none)
HeightMap crop_map(const HeightMap& map, const ZoomWindow& window);
// true when the columns' orders differ (an orders comparison)
bool is_orders_comparison(const std::vector<ComparisonColumn>& columns);

struct ComparisonInput {
  std::string title;                   // e.g. the scenario name
  const Toolpath* toolpath = nullptr;  // optional: print paths drawn over each map
  std::vector<ComparisonColumn> columns;
};

// the comparison sheet's scale: capped_thickness_scale over the columns' maps
SharedThicknessScale shared_thickness_scale(const ComparisonInput& input);

// comparison.png at png_path: one column per run: its thickness map on a shared colour scale
// with, below it, a zoom on the thickest spot (or, in an orders comparison, its print paths
// numbered in print order and its travels), its speed error against time on shared axes and
// its key metrics under the summary tables' names. One gnuplot process.
PlotResult render_comparison(const ComparisonInput& input, const std::string& png_path,
                             const PlotOptions& options = {});

}  // namespace depotwin::plots
