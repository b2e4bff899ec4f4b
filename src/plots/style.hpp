// The one look of every DepoTwin plot: fonts, sizes, colours, line styles and the grey
// transition shading of Thompson & Yoon's Figs. 9, 10 and 12. Each function returns gnuplot
// commands; the plot builders compose them and never spell a colour or font themselves.
#pragma once

#include <string>
#include <vector>

#include "plots/plot_data.hpp"

namespace depotwin::plots::style {

// image sizes (px): legible at README width
constexpr int kRunPlotWidth_px = 800;
constexpr int kRunPlotHeight_px = 500;
constexpr int kComparisonColumnWidth_px = 460;
constexpr int kComparisonHeight_px = 1300;

// fonts (DejaVu: fonts-dejavu-core, installed with gnuplot-nox by scripts/setup.sh)
constexpr const char* kFont = "DejaVu Sans";
constexpr int kFontSize_pt = 11;
constexpr int kTitleFontSize_pt = 13;
constexpr const char* kMonoFont = "DejaVu Sans Mono";

// colours
constexpr const char* kPlannedColour = "#1f77b4";          // planned motion
constexpr const char* kSimulatedColour = "#d62728";        // simulated nozzle
constexpr const char* kSimulatedPathColour = "#40d62728";  // the same, 25 % transparent (ARGB)
constexpr const char* kTransitionPathColour = "#8c8c8c";
constexpr const char* kShadingColour = "#d9d9d9";  // transition bands
constexpr const char* kStartColour = "#2ca02c";
constexpr const char* kEndColour = "#d62728";
constexpr const char* kTargetColour = "#000000";
constexpr const char* kMeanColour = "#d62728";
// the print paths over a thickness map: white, 60 % transparent (ARGB) and thin, so that a
// bead only a few pixels wide still shows its colour under them
constexpr const char* kPathOverlayColour = "#99ffffff";
constexpr double kPathOverlayLineWidth = 0.8;
constexpr const char* kMapKeyColour = "#440154";  // key box behind the white overlay sample
constexpr const char* kAxisColours[3] = {"#1f77b4", "#ff7f0e", "#2ca02c"};  // x, y, z
// the same, lightened (40 % of the colour on white): the wide band of the simulated axis,
// under the planned line, so that both show where they coincide
constexpr const char* kAxisBandColours[3] = {"#a5c9e1", "#ffcb9f", "#abd9ab"};
// joints.png: the forbidden band beyond a joint's range (red, 65 % transparent, so a transition
// band under it still shows) and the range's limit lines
constexpr const char* kLimitBandColour = "#a6d62728";
constexpr const char* kLimitLineColour = "#d62728";
// paths3d.png: travels, tool axes, the part's surface
constexpr const char* kTravelColour = "#a0a0a0";
constexpr const char* kToolAxisColour = "#303030";
constexpr const char* kPartColour = "#d0d3d8";
constexpr const char* kPartEdgeColour = "#b4b8be";
// colours cycled over print lines and planners
constexpr const char* kSeriesColours[8] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                           "#9467bd", "#8c564b", "#e377c2", "#17becf"};

// line widths (gnuplot units, 1 = 1 px at this terminal scale)
constexpr double kPlannedLineWidth = 2.0;
constexpr double kPathLineWidth = 3.0;  // planned print path under the simulated one
constexpr double kSimulatedLineWidth = 1.2;
constexpr double kThinLineWidth = 1.0;
constexpr double kSimulatedBandWidth = 6.0;  // simulated axis curves, under the planned ones

const char* series_colour(size_t index);

// `set terminal pngcairo ...` for an image of the given size
std::string terminal(int width_px, int height_px);
// every plot starts from this: reset, grid, border, key box, number formats
std::string common_settings();
// a title line in the title font
std::string title_font();
std::string mono_font();
// axis label with unit, e.g. axis_label("x", "mm") -> "x (mm)"
std::string axis_label(const std::string& name, const std::string& unit);

// grey rectangles spanning the full plot height over each interval (drawn behind the data),
// one `set object rect` per band, and the key entry naming them; empty for no bands
std::string transition_shading(const std::vector<TimeInterval>& bands);
// the key entry for the shading ("transition"), only when there are bands
std::string transition_key_entry(const std::vector<TimeInterval>& bands);
// remove the rectangles again before the next plot
std::string clear_shading();

// a plot element that draws nothing (a line below every zero-based y range): the frame,
// axes and shading of a panel without data
constexpr const char* kEmptyFrame = "-1e30 with lines lc rgb \"white\" notitle";

// the perceptually uniform colour map of thickness maps (viridis stops)
std::string thickness_palette();

// a string literal for gnuplot: single quotes, embedded quotes doubled (no escapes)
std::string quoted(const std::string& text);
// a string literal in double quotes, lines joined by gnuplot's "\n" (backslashes and quotes
// escaped): a label of several lines
std::string double_quoted_lines(const std::vector<std::string>& lines);

}  // namespace depotwin::plots::style
