// summary.png of a parameter study (`depotwin sweep --merge`): each metric against each swept
// parameter, one curve per planner (the mean over the other parameters at each value, every
// task a faint point behind it), and time against line CV with the Pareto front marked.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plots/plots.hpp"

namespace depotwin::plots {

struct SweepPlotInput {
  std::string title;  // e.g. "corner_study: 27 tasks (25 ok, 2 failed)"
  // one curve per name (planners); a point's curve indexes it. Empty: one curve, no key
  std::vector<std::string> curves;
  // a column of panels per parameter: its key, and for words its values in order (a point's x
  // is then the value's position)
  struct Parameter {
    std::string key;
    std::vector<std::string> categories;  // empty: x is the number itself
  };
  std::vector<Parameter> parameters;
  // a row of panels per metric, drawn as value x scale against its label
  struct Metric {
    std::string label;  // "waste (%)"
    double scale = 1.0;
  };
  std::vector<Metric> metrics;
  // the points, one per task that ran
  std::vector<std::size_t> curve;      // per point
  std::vector<std::vector<double>> x;  // per parameter, per point
  std::vector<std::vector<double>> y;  // per metric, per point (unscaled; NaN: none)
  // the Pareto panel: the metrics (indices into `metrics`) on its x and y axes, both smaller
  // is better; -1: no panel
  int pareto_x = -1, pareto_y = -1;
};

// the points (indices) no other point beats in both x and y (smaller is better), by
// increasing x; non-finite points take no part. Points equal in both are all kept.
std::vector<std::size_t> pareto_front(const std::vector<double>& x, const std::vector<double>& y);

// The mean of y at each distinct x, per curve: (x, mean) pairs by increasing x, over the finite
// y of the points of that curve.
std::vector<std::pair<double, double>> curve_means(const std::vector<double>& x,
                                                   const std::vector<double>& y,
                                                   const std::vector<std::size_t>& curve,
                                                   std::size_t which);

// Render summary.png at `png_path` (one gnuplot run). InternalError for an input whose counts
// differ; GnuplotNotFound without gnuplot.
PlotResult render_sweep_summary(const SweepPlotInput& input, const std::string& png_path,
                                const PlotOptions& options = {});

}  // namespace depotwin::plots
