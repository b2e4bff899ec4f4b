// One gnuplot run (internal to the module): data files and PNGs go to a private temporary
// directory beside the outputs, the script is assembled piece by piece, gnuplot runs once
// and the PNGs are renamed into place only when it succeeded.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "plots/gnuplot.hpp"
#include "plots/plots.hpp"

namespace depotwin::plots {

class PlotJob {
 public:
  // finds gnuplot first (GnuplotNotFound before any work), then makes the temporary directory
  PlotJob(const std::string& output_directory, const PlotOptions& options);

  // write a data file into the temporary directory; returns its quoted path for the script
  std::string data_file(const std::string& name, const std::string& content);
  // start a PNG: terminal, output to its temporary name, common settings
  void begin_png(const std::string& final_path, int width_px, int height_px);
  // close the current PNG
  void end_png();
  std::string& script() { return script_; }

  // run gnuplot on the script, then move every PNG into place
  PlotResult finish();

 private:
  std::string gnuplot_;
  TemporaryDirectory temporary_;
  std::string script_;
  std::vector<std::pair<std::string, std::string>> pngs_;  // (temporary, final)
};

// running [lo, hi] of the finite values of curves
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();

  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void add_y(const Curve& c) {
    for (double v : c.y) add(v);
  }
  void add_x(const Curve& c) {
    for (double v : c.x) add(v);
  }
  bool empty() const { return !(hi >= lo); }
  // [lo, hi] padded by a fraction of its width (at least min_half_width either side of a single
  // value)
  std::pair<double, double> padded(double pad_fraction, double min_half_width) const {
    double a = empty() ? 0.0 : lo, b = empty() ? 1.0 : hi;
    if (b - a < 2 * min_half_width) {
      const double mid = 0.5 * (a + b);
      a = mid - min_half_width;
      b = mid + min_half_width;
    }
    const double pad = pad_fraction * (b - a);
    return {a - pad, b + pad};
  }
  // the same as gnuplot's "[lo:hi]"
  std::string gnuplot(double pad_fraction, double min_half_width) const {
    const auto [a, b] = padded(pad_fraction, min_half_width);
    return format("[%.9g:%.9g]", a, b);
  }
};

// A plan view's x and y ranges (drawn at 1:1): each padded, then the shorter one widened
// about its middle to kMinPlanAspect of the longer, so that a long thin job (100 x 2 mm)
// is not drawn as a strip of a few pixels with its tick labels over each other
constexpr double kMinPlanAspect = 1.0 / 3.0;
struct PlanRanges {
  double x_lo = 0.0, x_hi = 1.0, y_lo = 0.0, y_hi = 1.0;
};
PlanRanges plan_ranges(const Range& x, const Range& y, double pad_fraction, double min_half_width);

// "plot a, b, c" from the non-empty elements (`verb`: "plot" or "splot")
std::string plot_command(const std::vector<std::string>& elements, const char* verb = "plot");
// "with lines lw .. dt .. lc rgb .."
std::string line_style(const char* colour, double width, int dash = 1);
// InternalError("plots: what") unless the condition holds
void require(bool condition, const char* what);

// The conformal plots (conformal_plots.cpp): their data, filled into `data` by
// prepare_run_plot_data, and their drawing.
void prepare_joint_panels(const JointSeries& joints, const PlotOptions& options, RunPlotData& data);
void prepare_layer_panels(const RunPlotInput& input, const PlotOptions& options, RunPlotData& data);
void prepare_paths3d(const RunPlotInput& input, const PlotOptions& options, RunPlotData& data);
void joints_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                 const std::string& png);
void layers_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                 const std::string& png);
void paths3d_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                  const std::string& png);

// whether the print paths would hide the map, drawn over it (paths_crowd_window on the map's
// cells, to their edges)
bool paths_crowd_map(const Toolpath& toolpath, const HeightMap& map);
// the thickness map as an image (colours by the current cbrange) with the print paths
// overlaid as thin, translucent dashed lines, unless they would hide it (with `path_key`, the
// key then says so): a plot command; shared by thickness.png and the comparison sheet
std::string thickness_map_elements(PlotJob& job, const HeightMap& map, const Toolpath* toolpath,
                                   const std::string& stem, bool path_key);
// `set xrange/yrange` covering the maps' cells (to their edges) and the print paths
// (plan_ranges), with tick steps
std::string map_ranges(const std::vector<const HeightMap*>& maps, const Toolpath* toolpath);

}  // namespace depotwin::plots
