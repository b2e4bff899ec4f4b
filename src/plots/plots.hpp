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
#include "core/toolpath.hpp"
#include "metrics/motion_metrics.hpp"
#include "plots/gnuplot.hpp"
#include "plots/plot_data.hpp"

namespace depotwin::plots {

// Thickness sampled along one print line's centreline.
struct LineProfile {
  int path_index = 0;  // index into Toolpath::paths
  std::vector<double> arc_length_mm, thickness_um;
};

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
  double mean_thickness_um = 0.0;    // <= 0: no mean line
  double feature_size_mm = 0.0;      // <= 0: feature_size_mm(*toolpath)
};

enum class RunPlot { path, axes, errors, thickness_profile, thickness };
// "path.png", "axes.png", "errors.png", "thickness_profile.png", "thickness.png"
const char* file_name(RunPlot plot);
// the plots the input has data for: path, axes, errors always; the thickness plots when
// a non-empty map / at least one profile is given
std::vector<RunPlot> available_plots(const RunPlotInput& input);

struct PlotOptions {
  std::string gnuplot = "gnuplot";  // program name (PATH) or path
  size_t max_points_per_curve = 1200;
  int max_map_cells_per_side = 400;  // thickness maps are block-averaged down to this
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
  // key metrics; nullopt prints "n/a"
  std::optional<double> max_speed_error_rel, rms_speed_error_rel, thickness_cv, waste_fraction,
      total_time_s;
};
// fill t_s and speed_error_rel from samples (the simulated ones when there are)
void set_speed_error(ComparisonColumn& column, const MotionSamples& samples);

struct ComparisonInput {
  std::string title;                   // e.g. the scenario name
  const Toolpath* toolpath = nullptr;  // optional: print paths drawn over each map
  std::vector<ComparisonColumn> columns;
};

// the colour range every map shares: [0, max over all maps] (1 um when all are empty)
double shared_thickness_max_um(const ComparisonInput& input);

// comparison.png at png_path: one column per planner (thickness map on a shared colour scale,
// speed error against time on shared axes, key metrics). One gnuplot process.
PlotResult render_comparison(const ComparisonInput& input, const std::string& png_path,
                             const PlotOptions& options = {});

}  // namespace depotwin::plots
