// summary.png from the merged table: the headline metrics (time, line CV, steady speed error,
// path error, waste, thickness CV: those the tasks have) against each swept parameter, one
// curve per planner when `planner` is swept (the mean over the other parameters at each
// value; every task a faint point), and time against line CV with the Pareto front marked.
#pragma once

#include <string>

#include "plots/sweep_plot.hpp"
#include "sweep/results.hpp"

namespace depotwin {

// what summary.png draws from the table (exposed for tests)
plots::SweepPlotInput summary_plot_input(const ResultsTable& table, const Sweep& sweep);

// summary_plot_input drawn to `png_path`; false (nothing written) when no task ran
bool write_summary_plot(const ResultsTable& table, const Sweep& sweep, const std::string& png_path);

}  // namespace depotwin
