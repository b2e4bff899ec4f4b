// comparison.png: one column per run with its thickness map (shared colour scale) and a zoom
// on the thickest spot, or, comparing print orders, its print paths and travels; its speed
// error against time (shared axes) and its key metrics.
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
  return fraction ? format("%.2f", 100.0 * *fraction) : "n/a";
}

// the vertical layout of the sheet (screen fractions, bottom = 0)
constexpr double kColourBarY = 0.93, kColourBarHeight = 0.014;
constexpr double kMapBottom = 0.585, kMapHeight = 0.29;
constexpr double kZoomBottom = 0.335, kZoomHeight = 0.215;
constexpr double kSpeedBottom = 0.165, kSpeedTop = 0.295;
constexpr double kMetricsTop = 0.115, kMetricsLine = 0.017;
// an orders comparison: the travel panel takes the map's and the zoom's place on a shorter sheet
// (kOrdersHeight_px: a travel panel about as tall as its column is wide, no blank bands above
// and below it), the panels under it as many pixels up as on the full sheet
constexpr int kOrdersHeight_px = 1000;
constexpr double kTravelBottom = 0.43, kTravelHeight = 0.53;
// at most this many points per x-y curve
constexpr size_t kMaxPathPoints = 1200;
// the zoom window: this fraction of the largest map extent a side, at least this many cells
constexpr double kZoomFraction = 0.125;
constexpr int kZoomMinCells = 24;
constexpr int kZoomMaxCellsPerSide = 200;
// the footer caption: the width a character takes at most on average (px, the 11 pt font),
// the room kept at either side and the height of each further line
constexpr double kCaptionCharWidth_px = 7.6;
constexpr int kCaptionSideMargin_px = 8, kCaptionLine_px = 17;

// the window's outline on a map (object 800), removed by `unset object 800`
std::string window_outline(const ZoomWindow& w) {
  return format(
      "set object 800 rect from %.9g,%.9g to %.9g,%.9g front fillstyle empty border lc rgb "
      "\"white\" lw 1.5\n",
      w.x_lo, w.y_lo, w.x_hi, w.y_hi);
}

// the print paths (dark), the travels (the column's colour) and the path numbers (those
// within merge_within_mm of one another share a label)
std::string travel_elements(PlotJob& job, const ComparisonColumn& column, size_t c,
                            double merge_within_mm) {
  std::string s;
  const std::vector<DrawnLabel> labels =
      drawn_path_labels(column.path_labels, merge_within_mm, kMaxPathLabels);
  for (size_t i = 0; i < labels.size(); ++i)
    s += format(
        "set label %zu \"%s\" at %.9g,%.9g offset 0.5,0.5 tc rgb \"#404040\" font \",9\" front\n",
        1000 + i, labels[i].text.c_str(), labels[i].x_mm, labels[i].y_mm);
  std::vector<std::string> elements;
  if (column.print_xy.point_count() > 0)
    elements.push_back(job.data_file(format("prints_%zu.dat", c), format_curve(column.print_xy)) +
                       " " + line_style("#303030", style::kPathLineWidth) + " notitle");
  if (column.travel_xy.point_count() > 0)
    elements.push_back(job.data_file(format("travels_%zu.dat", c), format_curve(column.travel_xy)) +
                       " " + line_style(style::series_colour(c), style::kThinLineWidth + 0.3) +
                       " notitle");
  if (elements.empty()) elements.push_back(style::kEmptyFrame);
  return s + plot_command(elements);
}

// the x-y extent of every column's print and travel curves (shared by the travel panels)
struct TravelExtent {
  Range x, y;

  explicit TravelExtent(const std::vector<ComparisonColumn>& columns) {
    for (const ComparisonColumn& c : columns) {
      x.add_x(c.print_xy), y.add_y(c.print_xy);
      x.add_x(c.travel_xy), y.add_y(c.travel_xy);
    }
  }
  std::string gnuplot_ranges() const {
    return "set xrange " + x.gnuplot(0.03, 0.5) + "\nset yrange " + y.gnuplot(0.03, 0.5) + "\n";
  }
  // path numbers closer than kLabelMergeShare of the larger side share a label
  double label_merge_mm() const {
    return x.empty() ? 0.0 : kLabelMergeShare * std::max(x.hi - x.lo, y.hi - y.lo);
  }
};

}  // namespace

void set_speed_error(ComparisonColumn& column, const MotionSamples& samples) {
  column.t_s = samples.t_s;
  column.speed_error_rel = speed_error_with_gaps(samples);
}

void set_travels(ComparisonColumn& column, const MotionSamples& planned) {
  column.print_xy = xy_path_curve(planned, PathPart::printing, kMaxPathPoints);
  column.travel_xy = xy_path_curve(planned, PathPart::transition, kMaxPathPoints);
  // each printed run's path number at its middle sample
  column.path_labels.clear();
  size_t k = 0;
  while (k < planned.size()) {
    const int path = planned.path_index[k];
    if (!planned.depositing[k] || path < 0) {
      ++k;
      continue;
    }
    const size_t first = k;
    while (k < planned.size() && planned.depositing[k] && planned.path_index[k] == path) ++k;
    const Vec3& middle = planned.position_mm[(first + k - 1) / 2];
    column.path_labels.push_back({middle.x(), middle.y(), path});
  }
}

bool is_orders_comparison(const std::vector<ComparisonColumn>& columns) {
  for (const ComparisonColumn& c : columns)
    if (c.order != columns.front().order) return true;
  return false;
}

ZoomWindow thickest_spot_window(const std::vector<const HeightMap*>& maps) {
  ZoomWindow w;
  Range x, y;
  double cell_mm = 0.0;
  for (const HeightMap* map : maps) {
    if (!has_map(map)) continue;
    x.add(map->x_lo_mm());
    x.add(map->x_hi_mm());
    y.add(map->y_lo_mm());
    y.add(map->y_hi_mm());
    cell_mm = std::max(cell_mm, map->cell_mm);
    // the first thickest cell, row by row
    for (int iy = 0; iy < map->ny; ++iy)
      for (int ix = 0; ix < map->nx; ++ix)
        if (map->at(ix, iy) > w.peak_um) {
          w.peak_um = map->at(ix, iy);
          w.centre_x_mm = map->origin_x_mm + ix * map->cell_mm;
          w.centre_y_mm = map->origin_y_mm + iy * map->cell_mm;
          w.found = true;
        }
  }
  if (!w.found) return w;
  // a square an eighth of the extent a side (at least kZoomMinCells cells), kept inside it
  const double side = std::min(
      std::max(kZoomFraction * std::max(x.hi - x.lo, y.hi - y.lo), kZoomMinCells * cell_mm),
      std::min(x.hi - x.lo, y.hi - y.lo));
  const auto place = [&](double centre, double lo, double hi, double& a, double& b) {
    a = std::clamp(centre - 0.5 * side, lo, std::max(lo, hi - side));
    b = a + side;
  };
  place(w.centre_x_mm, x.lo, x.hi, w.x_lo, w.x_hi);
  place(w.centre_y_mm, y.lo, y.hi, w.y_lo, w.y_hi);
  return w;
}

HeightMap crop_map(const HeightMap& map, const ZoomWindow& window) {
  HeightMap out;
  if (!has_map(&map)) return out;
  // the cells whose centres lie inside [lo, hi] on each axis
  const auto cells = [&](double origin, int n, double lo, double hi, int& first, int& count) {
    first = std::max(0, static_cast<int>(std::ceil((lo - origin) / map.cell_mm - 1e-9)));
    const int last =
        std::min(n - 1, static_cast<int>(std::floor((hi - origin) / map.cell_mm + 1e-9)));
    count = std::max(0, last - first + 1);
  };
  int x0 = 0, y0 = 0;
  cells(map.origin_x_mm, map.nx, window.x_lo, window.x_hi, x0, out.nx);
  cells(map.origin_y_mm, map.ny, window.y_lo, window.y_hi, y0, out.ny);
  if (out.nx == 0 || out.ny == 0) return HeightMap{};
  out.cell_mm = map.cell_mm;
  out.origin_x_mm = map.origin_x_mm + x0 * map.cell_mm;
  out.origin_y_mm = map.origin_y_mm + y0 * map.cell_mm;
  out.thickness_um.reserve(static_cast<size_t>(out.nx) * out.ny);
  for (int iy = 0; iy < out.ny; ++iy)
    for (int ix = 0; ix < out.nx; ++ix) out.thickness_um.push_back(map.at(x0 + ix, y0 + iy));
  return out;
}

SharedThicknessScale capped_thickness_scale(const std::vector<const HeightMap*>& all_maps) {
  SharedThicknessScale scale;
  std::vector<const HeightMap*> maps;
  for (const HeightMap* map : all_maps)
    if (has_map(map)) {
      maps.push_back(map);
      scale.peak_um = std::max(scale.peak_um, static_cast<double>(map->max_value()));
    }
  if (!(scale.peak_um > 0.0)) return scale;
  // each map's deposit cells' 95th percentile (the cells above a 10^4th of its peak: a bead
  // beside a blob a hundred times thicker still counts, a Gaussian's far tails hardly do)
  constexpr double kDepositFloor = 1e-4, kQuantile = 0.95;
  std::vector<double> quantiles_um;
  std::vector<float> deposit;
  for (const HeightMap* map : maps) {
    const double floor_um = kDepositFloor * map->max_value();
    deposit.clear();
    for (const float value : map->thickness_um)
      if (value > floor_um) deposit.push_back(value);
    if (deposit.empty()) continue;
    const size_t rank =
        static_cast<size_t>(std::ceil(kQuantile * static_cast<double>(deposit.size())));
    const auto at = deposit.begin() + static_cast<std::ptrdiff_t>(std::max<size_t>(rank, 1) - 1);
    std::nth_element(deposit.begin(), at, deposit.end());
    quantiles_um.push_back(*at);
  }
  // the median run's (the lower of the middle two)
  std::sort(quantiles_um.begin(), quantiles_um.end());
  const double median_um = quantiles_um[(quantiles_um.size() - 1) / 2];
  scale.top_um = std::min(scale.peak_um, kSharedScaleCap * median_um);
  scale.capped = scale.top_um < scale.peak_um;
  return scale;
}

SharedThicknessScale shared_thickness_scale(const ComparisonInput& input) {
  std::vector<const HeightMap*> maps;
  for (const ComparisonColumn& column : input.columns) maps.push_back(column.thickness);
  return capped_thickness_scale(maps);
}

std::string capped_scale_note(const SharedThicknessScale& scale, const std::string& map_noun) {
  if (!scale.capped) return "";
  // one map ("") has its own percentile; several, the median one's
  const std::string whose = map_noun.empty() ? "the" : "the median " + map_noun + "'s";
  return format("topped at %g × %s 95th percentile (thicker: the top colour); peak %s µm",
                kSharedScaleCap, whose.c_str(), fixed_text(scale.peak_um, scale.peak_um).c_str());
}

PlotResult render_comparison(const ComparisonInput& input, const std::string& png_path,
                             const PlotOptions& options) {
  if (input.columns.empty()) throw InternalError("plots: a comparison needs at least one planner");
  const std::string directory = std::filesystem::path(png_path).parent_path().string();
  PlotJob job(directory.empty() ? "." : directory, options);

  const size_t columns = input.columns.size();
  const int width_px = static_cast<int>(columns) * style::kComparisonColumnWidth_px;
  const bool orders = is_orders_comparison(input.columns);
  // every run's map padded with zero cells to the extent of all of them, so that each fills
  // the shared axes (map and zoom) instead of leaving a white strip where its grid ends
  Range map_x, map_y;
  for (const ComparisonColumn& column : input.columns)
    if (has_map(column.thickness)) {
      const HeightMap& m = *column.thickness;
      map_x.add(m.x_lo_mm());
      map_x.add(m.x_hi_mm());
      map_y.add(m.y_lo_mm());
      map_y.add(m.y_hi_mm());
    }
  std::vector<HeightMap> padded_maps(columns);
  for (size_t c = 0; c < columns; ++c)
    if (has_map(input.columns[c].thickness))
      padded_maps[c] =
          pad_to_extent(*input.columns[c].thickness, map_x.lo, map_x.hi, map_y.lo, map_y.hi);

  // shared scales: colour range, map extent, zoom window, time and error axes
  std::vector<HeightMap> display_maps(columns), zoom_maps(columns);
  std::vector<const HeightMap*> maps, full_maps;
  double duration_s = 0.0, error_max_pct = 0.0;
  std::vector<Curve> speed_curves(columns);
  for (size_t c = 0; c < columns; ++c) {
    const ComparisonColumn& column = input.columns[c];
    if (column.t_s.size() != column.speed_error_rel.size())
      throw InternalError("plots: speed error and time differ in count for " + column.planner);
    if (has_map(column.thickness)) {
      display_maps[c] = downsample_for_display(padded_maps[c], options.max_map_cells_per_side);
      maps.push_back(&display_maps[c]);
      full_maps.push_back(&padded_maps[c]);
    }
    std::vector<double> percent = column.speed_error_rel;
    for (double& e : percent) e *= 100.0;
    speed_curves[c] = time_curve(column.t_s, percent, options.max_points_per_curve);
    for (double e : speed_curves[c].y)
      if (std::isfinite(e)) error_max_pct = std::max(error_max_pct, e);
    if (!column.t_s.empty()) duration_s = std::max(duration_s, column.t_s.back());
    if (column.total_time_s) duration_s = std::max(duration_s, *column.total_time_s);
  }
  const SharedThicknessScale scale = shared_thickness_scale(input);
  const ZoomWindow zoom = orders ? ZoomWindow{} : thickest_spot_window(full_maps);
  if (zoom.found)
    for (size_t c = 0; c < columns; ++c)
      if (has_map(input.columns[c].thickness))
        zoom_maps[c] = downsample_for_display(crop_map(padded_maps[c], zoom), kZoomMaxCellsPerSide);
  // the zooms' peaks in one fixed format, set by the largest of them
  double largest_zoom_peak_um = 0.0;
  for (const HeightMap& zoom_map : zoom_maps)
    if (has_map(&zoom_map))
      largest_zoom_peak_um =
          std::max(largest_zoom_peak_um, static_cast<double>(zoom_map.max_value()));

  // where the print paths are drawn (thickness_map_elements leaves them off a map they would
  // hide: a slicer's infill), for the caption
  const auto crowded = [&](const HeightMap& map) {
    return input.toolpath != nullptr && has_map(&map) && paths_crowd_map(*input.toolpath, map);
  };
  const bool maps_crowded = !maps.empty() && crowded(*maps.front());
  const bool zooms_crowded =
      std::any_of(zoom_maps.begin(), zoom_maps.end(), crowded) || !zoom.found;
  const std::string paths_note =
      !maps_crowded    ? "dashed: the print paths"
      : !zooms_crowded ? "dashed: the print paths, on the zooms (over the whole maps they would "
                         "hide the deposit)"
                       : "print paths not drawn (denser than the maps show)";
  // the footer caption, wrapped to the sheet's width (a one-run sheet is too narrow for one
  // line); each line past the first makes the sheet that much taller
  const std::vector<std::string> caption = wrap_text(
      orders ? "top: print paths (dark, numbered in print order from 0) and travels; grey bands: "
               "transitions"
             : paths_note +
                   "; grey bands: transitions (nothing deposited); white box: the zoom "
                   "below each map, on the thickest spot of all runs",
      static_cast<size_t>((width_px - 2 * kCaptionSideMargin_px) / kCaptionCharWidth_px));
  const int caption_extra_px = static_cast<int>(caption.size() - 1) * kCaptionLine_px;
  const int height_px =
      (orders ? kOrdersHeight_px : style::kComparisonHeight_px) + caption_extra_px;
  job.begin_png(png_path, width_px, height_px);
  std::string& s = job.script();
  // the panels under the maps (speed error, metrics, the footnote) keep their pixels from the
  // sheet's bottom (raised by the caption's extra lines): their screen fractions grow as the
  // sheet gets shorter
  const double bottom_scale = static_cast<double>(style::kComparisonHeight_px) / height_px;
  const double lift = static_cast<double>(caption_extra_px) / height_px;
  const double speed_bottom = kSpeedBottom * bottom_scale + lift,
               speed_top = kSpeedTop * bottom_scale + lift;
  const double metrics_top = kMetricsTop * bottom_scale + lift,
               metrics_line = kMetricsLine * bottom_scale;

  s += "set multiplot title " +
       style::quoted(input.title + (orders ? ": print order comparison" : ": planner comparison")) +
       " font \"" + style::title_font() + "\"\n";
  s += style::thickness_palette();
  s += format("set cbrange [0:%.9g]\n", scale.top_um);
  // (capped: a second line says so; gnuplot's double quotes take the \n)
  const std::string scale_text =
      style::axis_label("thickness, one colour scale for all runs", "µm") +
      (scale.capped ? "\\n" + capped_scale_note(scale, "run") : std::string());
  s += "set cblabel \"" + scale_text + "\" offset 0,0.4\n";
  s += format("set colorbox horizontal user origin screen 0.2,%.4f size screen 0.6,%.4f\n",
              kColourBarY, kColourBarHeight);
  // (the label's position is its first line's; the others follow below)
  s += format("set label 900 %s at screen 0.5,%.4f center tc rgb \"#606060\"\n",
              style::double_quoted_lines(caption).c_str(), 0.012 * bottom_scale + lift);
  const std::string shared_map_ranges = maps.empty() ? "" : map_ranges(maps, input.toolpath);
  const TravelExtent travel_extent(input.columns);
  bool colour_bar_drawn = false;

  for (size_t c = 0; c < columns; ++c) {
    const ComparisonColumn& column = input.columns[c];
    const double left = static_cast<double>(c) / columns, width = 1.0 / columns;
    const std::string title =
        "set title " + style::quoted(column.planner) + " font \"" + style::title_font() + "\"\n";
    const std::string xy_labels = "set xlabel " + style::quoted(style::axis_label("x", "mm")) +
                                  "\nset ylabel " + style::quoted(style::axis_label("y", "mm")) +
                                  "\n";

    if (orders) {
      // the print paths numbered in print order, and the travels between them
      s += "set margins -1,-1,-1,-1\nset origin " + format("%.4f,%.4f\n", left, kTravelBottom);
      s += format("set size ratio -1 %.4f,%.4f\n", width, kTravelHeight);
      s += "unset colorbox\nset grid\nunset key\n" + travel_extent.gnuplot_ranges() + title +
           xy_labels;
      s += travel_elements(job, column, c, travel_extent.label_merge_mm());
      s += "unset title\nunset label\n";
    } else if (has_map(column.thickness)) {
      // thickness map, the colour bar drawn once with the first map, the zoom window outlined
      s += "set margins -1,-1,-1,-1\nset origin " + format("%.4f,%.4f\n", left, kMapBottom);
      s += format("set size ratio -1 %.4f,%.4f\n", width, kMapHeight);
      s += "unset grid\nset tics front\nunset key\n" + shared_map_ranges + title + xy_labels;
      s += colour_bar_drawn ? "unset colorbox\n" : "";
      if (zoom.found) s += window_outline(zoom);
      s +=
          thickness_map_elements(job, display_maps[c], input.toolpath, format("map_%zu", c), false);
      colour_bar_drawn = true;
      s += "unset title\nunset label 900\nunset object 800\nunset colorbox\n"
           "set xtics autofreq\nset ytics autofreq\n";
      // the zoom: the same window in every column, at full resolution
      if (zoom.found && has_map(&zoom_maps[c])) {
        s += "set origin " + format("%.4f,%.4f\n", left, kZoomBottom);
        s += format("set size ratio -1 %.4f,%.4f\n", width, kZoomHeight);
        s += format("set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\n", zoom.x_lo, zoom.x_hi,
                    zoom.y_lo, zoom.y_hi);
        // the window is centred on the thickest spot of all runs; the title gives this run's
        // own peak inside it
        const double column_peak_um = zoom_maps[c].max_value();
        s += "set title " +
             style::quoted(format("zoom at (%.2f, %.2f) mm: peak %s µm", zoom.centre_x_mm,
                                  zoom.centre_y_mm,
                                  fixed_text(column_peak_um, largest_zoom_peak_um).c_str())) +
             "\n" + xy_labels;
        // about four intervals over the (square) window, at least three ticks on each axis
        const double tic_mm = round_step_up((zoom.x_hi - zoom.x_lo) / 4.0);
        s +=
            format("set xtics %.9g\nset ytics %.9g\n", axis_tick_step(zoom.x_lo, zoom.x_hi, tic_mm),
                   axis_tick_step(zoom.y_lo, zoom.y_hi, tic_mm));
        s +=
            thickness_map_elements(job, zoom_maps[c], input.toolpath, format("zoom_%zu", c), false);
        s += "unset title\nset xtics autofreq\nset ytics autofreq\n";
      }
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
        left + 0.16 * width, left + 0.95 * width, speed_bottom, speed_top);
    s += format("set xrange [0:%.9g]\n", std::max(duration_s, 1e-6));
    s += format("set yrange [0:%.9g]\n", error_max_pct > 0.0 ? 1.08 * error_max_pct : 1.0);
    s += "set xlabel " + style::quoted(style::axis_label("time", "s")) + "\n";
    s += "set ylabel " + style::quoted(style::axis_label("speed error", "%")) + "\n";
    s += style::transition_shading(column.transitions);

    // key metrics under the panel, named as in the summary tables (comparison.csv)
    const std::string lines[6] = {
        "sim_vel_err_max_pct         " + percent_or_na(column.max_speed_error_rel),
        "sim_vel_err_steady_max_pct  " + percent_or_na(column.steady_speed_error_rel),
        "sim_vel_err_rms_pct         " + percent_or_na(column.rms_speed_error_rel),
        "thickness_cv                " +
            (column.thickness_cv ? format("%.4f", *column.thickness_cv) : "n/a"),
        "waste_pct                   " + percent_or_na(column.waste_fraction),
        "time_s                      " +
            (column.total_time_s ? format("%.3f", *column.total_time_s) : "n/a")};
    for (int i = 0; i < 6; ++i)
      s += format("set label %d %s at screen %.4f,%.4f left font \"%s\"\n", 910 + i,
                  style::quoted(lines[i]).c_str(), left + 0.10 * width,
                  metrics_top - i * metrics_line, style::mono_font().c_str());

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
