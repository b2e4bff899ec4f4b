// comparison.png: one column per planner with its thickness map (shared colour scale), its
// speed error against time (shared axes) and its key metrics.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "plots/plot_job.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"

namespace depotwin::plots {

namespace {

bool has_map(const HeightMap* map) {
  return map != nullptr && map->nx > 0 && map->ny > 0;
}

std::string percent_or_na(const std::optional<double>& fraction) {
  return fraction ? format("%.2f %%", 100.0 * *fraction) : "n/a";
}

// the vertical layout of the sheet (screen fractions, bottom = 0)
constexpr double kColourBarY = 0.905, kColourBarHeight = 0.02;
constexpr double kMapBottom = 0.46, kMapHeight = 0.40;
constexpr double kSpeedBottom = 0.225, kSpeedTop = 0.415;
constexpr double kMetricsTop = 0.135, kMetricsLine = 0.024;

}  // namespace

void set_speed_error(ComparisonColumn& column, const MotionSamples& samples) {
  column.t_s = samples.t_s;
  column.speed_error_rel = speed_error_with_gaps(samples);
}

double shared_thickness_max_um(const ComparisonInput& input) {
  double peak_um = 0.0;
  for (const ComparisonColumn& column : input.columns)
    if (has_map(column.thickness))
      peak_um = std::max(peak_um, static_cast<double>(column.thickness->max_value()));
  return peak_um > 0.0 ? peak_um : 1.0;
}

PlotResult render_comparison(const ComparisonInput& input, const std::string& png_path,
                             const PlotOptions& options) {
  if (input.columns.empty()) throw InternalError("plots: a comparison needs at least one planner");
  const std::string directory = std::filesystem::path(png_path).parent_path().string();
  PlotJob job(directory.empty() ? "." : directory, options);

  const size_t columns = input.columns.size();
  const int width_px = static_cast<int>(columns) * style::kComparisonColumnWidth_px;
  job.begin_png(png_path, width_px, style::kComparisonHeight_px);
  std::string& s = job.script();

  // shared scales: colour range, map extent, time and error axes
  std::vector<HeightMap> display_maps(columns);
  std::vector<const HeightMap*> maps;
  double duration_s = 0.0, error_max_pct = 0.0;
  std::vector<Curve> speed_curves(columns);
  for (size_t c = 0; c < columns; ++c) {
    const ComparisonColumn& column = input.columns[c];
    if (column.t_s.size() != column.speed_error_rel.size())
      throw InternalError("plots: speed error and time differ in count for " + column.planner);
    if (has_map(column.thickness)) {
      display_maps[c] = downsample_for_display(*column.thickness, options.max_map_cells_per_side);
      maps.push_back(&display_maps[c]);
    }
    std::vector<double> percent = column.speed_error_rel;
    for (double& e : percent) e *= 100.0;
    speed_curves[c] = time_curve(column.t_s, percent, options.max_points_per_curve);
    for (double e : speed_curves[c].y)
      if (std::isfinite(e)) error_max_pct = std::max(error_max_pct, e);
    if (!column.t_s.empty()) duration_s = std::max(duration_s, column.t_s.back());
    if (column.total_time_s) duration_s = std::max(duration_s, *column.total_time_s);
  }
  const double cb_max_um = shared_thickness_max_um(input);

  s += "set multiplot title " + style::quoted(input.title + ": planner comparison") + " font \"" +
       style::title_font() + "\"\n";
  s += style::thickness_palette();
  s += format("set cbrange [0:%.9g]\n", cb_max_um);
  s += "set cblabel " +
       style::quoted(style::axis_label("thickness, one colour scale for all planners", "µm")) +
       " offset 0,0.4\n";
  s += format("set colorbox horizontal user origin screen 0.2,%.4f size screen 0.6,%.4f\n",
              kColourBarY, kColourBarHeight);
  s += format(
      "set label 900 'grey bands: transitions (nothing deposited)' at screen 0.5,%.4f "
      "center tc rgb \"#606060\"\n",
      0.018);
  const std::string shared_map_ranges = maps.empty() ? "" : map_ranges(maps, input.toolpath);
  bool colour_bar_drawn = false;

  for (size_t c = 0; c < columns; ++c) {
    const ComparisonColumn& column = input.columns[c];
    const double left = static_cast<double>(c) / columns, width = 1.0 / columns;

    // thickness map, the colour bar drawn once with the first map
    if (has_map(column.thickness)) {
      s += "set margins -1,-1,-1,-1\nset origin " + format("%.4f,%.4f\n", left, kMapBottom);
      s += format("set size ratio -1 %.4f,%.4f\n", width, kMapHeight);
      s += "unset grid\nset tics front\nunset key\n" + shared_map_ranges;
      s += "set title " + style::quoted(column.planner) + " font \"" + style::title_font() + "\"\n";
      s += "set xlabel " + style::quoted(style::axis_label("x", "mm")) + "\n";
      s += "set ylabel " + style::quoted(style::axis_label("y", "mm")) + "\n";
      s += colour_bar_drawn ? "unset colorbox\n" : "";
      s +=
          thickness_map_elements(job, display_maps[c], input.toolpath, format("map_%zu", c), false);
      colour_bar_drawn = true;
      s += "unset title\nunset label 900\n";
    } else {
      // named over the empty map area, drawn with the speed panel below
      s += format("set label 901 %s at screen %.4f,%.4f center font \"%s\"\n",
                  style::quoted(column.planner).c_str(), left + 0.5 * width,
                  kMapBottom + kMapHeight - 0.025, style::title_font().c_str());
      s += format("set label 902 'no thickness map (plan only)' at screen %.4f,%.4f center\n",
                  left + 0.5 * width, kMapBottom + 0.5 * kMapHeight);
    }

    // speed error against time on the shared axes, transitions shaded
    s += "set size noratio 1,1\nset origin 0,0\nunset key\nset grid xtics ytics\n";
    s += format(
        "set lmargin at screen %.4f\nset rmargin at screen %.4f\n"
        "set bmargin at screen %.4f\nset tmargin at screen %.4f\n",
        left + 0.16 * width, left + 0.95 * width, kSpeedBottom, kSpeedTop);
    s += format("set xrange [0:%.9g]\n", std::max(duration_s, 1e-6));
    s += format("set yrange [0:%.9g]\n", error_max_pct > 0.0 ? 1.08 * error_max_pct : 1.0);
    s += "set xlabel " + style::quoted(style::axis_label("time", "s")) + "\n";
    s += "set ylabel " + style::quoted(style::axis_label("speed error", "%")) + "\n";
    s += style::transition_shading(column.transitions);

    // key metrics under the panel
    const std::string lines[5] = {
        "max speed error  " + percent_or_na(column.max_speed_error_rel),
        "RMS speed error  " + percent_or_na(column.rms_speed_error_rel),
        "thickness CV     " + (column.thickness_cv ? format("%.4f", *column.thickness_cv) : "n/a"),
        "waste fraction   " + percent_or_na(column.waste_fraction),
        "total time       " +
            (column.total_time_s ? format("%.2f s", *column.total_time_s) : "n/a")};
    for (int i = 0; i < 5; ++i)
      s += format("set label %d %s at screen %.4f,%.4f left font \"%s\"\n", 910 + i,
                  style::quoted(lines[i]).c_str(), left + 0.16 * width,
                  kMetricsTop - i * kMetricsLine, style::mono_font().c_str());

    const Curve& curve = speed_curves[c];
    if (curve.point_count() > 0)
      s += "plot " + job.data_file(format("speed_error_%zu.dat", c), format_curve(curve)) +
           format(" with lines lw %.2f lc rgb \"%s\" notitle\n", style::kPlannedLineWidth,
                  style::series_colour(c));
    else
      s += std::string("plot ") + style::kEmptyFrame + "\n";
    s += style::clear_shading();
    s += "unset label\nunset lmargin\nunset rmargin\nunset bmargin\nunset tmargin\n";
  }
  job.end_png();
  return job.finish();
}

}  // namespace depotwin::plots
