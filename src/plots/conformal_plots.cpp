// The plots of a conformal run (a 6-DOF arm over a curved part, several layers): joints.png
// (each joint against time with its forbidden bands beyond the range), layers.png (each
// layer's thickness map, small multiples on one colour scale) and paths3d.png (the print
// paths in 3-D by layer, the travels, the tool axes, the part's surface).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "plots/plot_job.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"

namespace depotwin::plots {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// joints.png: the y range reaches this fraction of the joint's range beyond each limit (the
// forbidden bands' height)
constexpr double kLimitBandFraction = 0.08;
// ... and a joint that came within this fraction of its range of a limit is named in red
constexpr double kNearLimitFraction = 0.05;
// layers.png: the cells per side of a panel's map (a panel is at most ~350 px wide)
constexpr int kLayerMapCellsPerSide = 200;
// paths3d.png: points of all print paths together, and the tool-axis segments' length as a
// fraction of the print paths' horizontal extent
constexpr size_t kPath3dPointsFactor = 4;
constexpr double kToolAxisFraction = 0.08;

// a tic step of 1, 2, 2.5 or 5 times a power of ten giving at most max_tics intervals over span
double nice_step(double span, int max_tics) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / std::max(max_tics, 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * power >= raw) return m * power;
  return 10.0 * power;
}

// the number as text without trailing zeros ("45", "22.5")
std::string number_text(double v) {
  return format("%.4g", v);
}

}  // namespace

JointSeries joint_series(const RecordedRun& run, const std::vector<JointLimit>& limits,
                         const std::vector<bool>& revolute) {
  const size_t joints = static_cast<size_t>(std::max(run.joint_count, 0));
  require(limits.size() == joints && revolute.size() == joints,
          "joint limits or joint kinds do not match the recorded joints");
  require(run.joint_position.size() == run.size() * joints,
          "the recorded joint positions do not match the recorded steps");
  JointSeries series;
  series.t_s = run.t_s;
  for (size_t j = 0; j < joints; ++j) {
    series.names.push_back(j < run.joint_names.size() ? run.joint_names[j] : limits[j].name);
    series.units.push_back(revolute[j] ? "rad" : "mm");
    series.min.push_back(limits[j].min);
    series.max.push_back(limits[j].max);
    std::vector<double> position(run.size());
    for (size_t k = 0; k < run.size(); ++k)
      position[k] = run.joint(run.joint_position, k, static_cast<int>(j));
    series.position.push_back(std::move(position));
  }
  return series;
}

void prepare_joint_panels(const JointSeries& joints, const PlotOptions& options,
                          RunPlotData& data) {
  const size_t n = joints.names.size();
  require(joints.units.size() == n && joints.position.size() == n && joints.min.size() == n &&
              joints.max.size() == n,
          "a joint series' names, units, positions and ranges differ in count");
  for (const std::vector<double>& position : joints.position)
    require(position.size() == joints.t_s.size(), "a joint's positions and times differ in count");

  std::vector<double> values;
  for (size_t j = 0; j < n; ++j) {
    JointPanel panel;
    panel.name = joints.names[j];
    const bool radians = joints.units[j] == "rad";
    panel.unit = radians ? "deg" : joints.units[j];
    const double scale = radians ? 180.0 / kPi : 1.0;
    values = joints.position[j];
    for (double& v : values) v *= scale;
    panel.position = time_curve(joints.t_s, values, options.max_points_per_curve);

    Range y;
    for (double v : values) y.add(v);
    const double lo = joints.min[j] * scale, hi = joints.max[j] * scale;
    panel.limited = std::isfinite(lo) && std::isfinite(hi) && lo < hi;
    panel.closest_to_limit = kNaN;
    if (panel.limited) {
      panel.min = lo;
      panel.max = hi;
      const double span = hi - lo;
      // the bands beyond each limit, and any excursion past them with a little room
      panel.y_lo = lo - kLimitBandFraction * span;
      panel.y_hi = hi + kLimitBandFraction * span;
      if (!y.empty()) {
        panel.y_lo = std::min(panel.y_lo, y.lo - 0.02 * span);
        panel.y_hi = std::max(panel.y_hi, y.hi + 0.02 * span);
        for (double v : values)
          if (std::isfinite(v))
            panel.closest_to_limit = std::isnan(panel.closest_to_limit)
                                         ? std::min(v - lo, hi - v)
                                         : std::min({panel.closest_to_limit, v - lo, hi - v});
      }
    } else {
      // the data padded, at least 1 unit tall
      double a = y.empty() ? 0.0 : y.lo, b = y.empty() ? 1.0 : y.hi;
      if (b - a < 1.0) {
        const double mid = 0.5 * (a + b);
        a = mid - 0.5;
        b = mid + 0.5;
      }
      panel.y_lo = a - 0.06 * (b - a);
      panel.y_hi = b + 0.06 * (b - a);
    }
    data.joint_panels.push_back(std::move(panel));
  }
}

void prepare_layer_panels(const RunPlotInput& input, const PlotOptions& options,
                          RunPlotData& data) {
  const int n = static_cast<int>(input.layer_maps.size());
  data.layer_count = n;
  if (n == 0) return;
  // every layer, or max_layer_panels of them evenly chosen (the first and the last among them)
  std::vector<int> shown;
  const int panels = std::max(options.max_layer_panels, 2);
  if (n <= panels) {
    for (int k = 0; k < n; ++k) shown.push_back(k);
  } else {
    for (int i = 0; i < panels; ++i)
      shown.push_back(
          static_cast<int>(std::lround(static_cast<double>(i) * (n - 1) / (panels - 1))));
  }

  const int cells = std::min(options.max_map_cells_per_side, kLayerMapCellsPerSide);
  Range x, y;
  std::vector<const HeightMap*> shown_maps;
  for (int k : shown) {
    LayerPanel panel;
    panel.layer = k;
    const double angle = k < static_cast<int>(input.layer_angles_deg.size())
                             ? input.layer_angles_deg[static_cast<size_t>(k)]
                             : kNaN;
    panel.title = std::isfinite(angle) ? format("layer %d (%s°)", k, number_text(angle).c_str())
                                       : format("layer %d", k);
    const HeightMap* map = input.layer_maps[static_cast<size_t>(k)];
    if (map != nullptr && map->nx > 0 && map->ny > 0) {
      require(map->thickness_um.size() == static_cast<size_t>(map->nx) * map->ny,
              "a layer's height map size does not match nx * ny");
      panel.map = downsample_for_display(*map, cells);
      shown_maps.push_back(map);
      const HeightMap& m = panel.map;
      x.add(m.x_lo_mm());
      x.add(m.x_hi_mm());
      y.add(m.y_lo_mm());
      y.add(m.y_hi_mm());
    }
    if (input.toolpath != nullptr)
      for (const PrintPath& path : input.toolpath->paths) {
        if (path.layer != k) continue;
        for (const Vec3& p : path.points) {
          panel.paths.add(p.x(), p.y());
          x.add(p.x());
          y.add(p.y());
        }
        panel.paths.add_break();
      }
    data.layer_panels.push_back(std::move(panel));
  }
  // one colour scale, topped near the beads' height when a blob (where the layers start)
  // stands far above them; a layer of nothing still gets a scale
  data.layer_scale = capped_thickness_scale(shown_maps);
  if (!(data.layer_scale.peak_um > 0.0)) data.layer_scale.top_um = 1e-3;
  // every panel shows the same extent: all shown maps and paths (at least 1 mm)
  auto span = [](const Range& r, double& lo, double& hi) {
    lo = r.empty() ? 0.0 : r.lo;
    hi = r.empty() ? 1.0 : r.hi;
    if (hi - lo < 1.0) {
      const double mid = 0.5 * (lo + hi);
      lo = mid - 0.5;
      hi = mid + 0.5;
    }
  };
  span(x, data.layers_x_lo, data.layers_x_hi);
  span(y, data.layers_y_lo, data.layers_y_hi);
}

void prepare_paths3d(const RunPlotInput& input, const PlotOptions& options, RunPlotData& data) {
  const Toolpath& toolpath = *input.toolpath;
  const int layers = toolpath.layer_count();

  // print paths per layer, the point budget shared by the layers
  const size_t budget =
      std::max<size_t>(300, kPath3dPointsFactor * options.max_points_per_curve / layers);
  data.layer_paths.assign(static_cast<size_t>(layers), Curve3{});
  for (int k = 0; k < layers; ++k) {
    std::vector<const std::vector<Vec3>*> lines;
    for (const PrintPath& path : toolpath.paths)
      if (path.layer == k) lines.push_back(&path.points);
    data.layer_paths[static_cast<size_t>(k)] = polylines_3d(lines, budget);
  }
  data.travels = path_curve_3d(*input.planned, PathPart::transition, options.max_points_per_curve);

  // tool axes: one segment per cell of an x-y lattice over the print paths (the first path
  // point to reach a cell, in print order), so that they stand evenly over the part whatever
  // the hatch; the lattice is coarsened until there are at most max_tool_axes
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  size_t point_count = 0;
  for (const PrintPath& path : toolpath.paths)
    for (const Vec3& p : path.points) {
      lo = lo.cwiseMin(p.head<2>());
      hi = hi.cwiseMax(p.head<2>());
      ++point_count;
    }
  if (point_count > 0) {
    const Eigen::Vector2d extent = hi - lo;
    data.tool_axis_length_mm = std::max(kToolAxisFraction * extent.maxCoeff(), 0.1);
    const size_t wanted = std::max<size_t>(options.max_tool_axes, 1);
    double cell_mm = std::max(
        {std::sqrt(std::max(extent.x(), data.tool_axis_length_mm) *
                   std::max(extent.y(), data.tool_axis_length_mm) / static_cast<double>(wanted)),
         1e-6});
    for (int attempt = 0; attempt < 60; ++attempt, cell_mm *= 1.1) {
      std::map<std::pair<long, long>, bool> used;
      Curve3 axes;
      for (const PrintPath& path : toolpath.paths)
        for (size_t i = 0; i < path.points.size(); ++i) {
          const Vec3& p = path.points[i];
          const std::pair<long, long> cell(
              static_cast<long>(std::floor((p.x() - lo.x()) / cell_mm)),
              static_cast<long>(std::floor((p.y() - lo.y()) / cell_mm)));
          if (!used.emplace(cell, true).second) continue;
          axes.add(p);
          axes.add(p + data.tool_axis_length_mm * path.tool_axis(i));
          axes.add_break();
        }
      data.tool_axes = std::move(axes);
      if (used.size() <= wanted) break;
    }
  }
  if (input.part != nullptr && !input.part->empty())
    data.part_surface = display_surface(*input.part, options.max_part_triangles);
}

// ---- drawing ----

namespace {

// paths3d.png: the plot's share of the width (the key right of it), and gnuplot's projection:
// with `set view equal xyz` the larger of the x and y ranges spans [-1, 1], z at the same
// scale; one unit is about kViewUnit_px at view scale 1 on a 500 px tall canvas (measured)
constexpr double kPlotLeftFraction = 0.05, kPlotWidthFraction = 0.70;
constexpr double kViewUnit_px = 121.0;
constexpr double kViewFit_px[2] = {430.0, 360.0};  // the room for the box (w, h), labels aside

// the view scale at which the box of `extent` fills the room: normalised to the larger
// horizontal range (a, b, c = the ranges / that, so the box is [-a, a] x [-b, b] x [-c, c])
// and rotated by rot_z about z, then by rot_x about the screen's x axis, its projection is
// 2 (a |cos z| + b |sin z|) wide and 2 ((a |sin z| + b |cos z|) |cos x| + c |sin x|) tall
double view_scale(const Vec3& extent, double rot_x_deg, double rot_z_deg) {
  const double d = std::max({extent.x(), extent.y(), 1e-9});
  const double a = extent.x() / d, b = extent.y() / d, c = extent.z() / d;
  const double rx = rot_x_deg * kPi / 180.0, rz = rot_z_deg * kPi / 180.0;
  const double w = a * std::abs(std::cos(rz)) + b * std::abs(std::sin(rz));
  const double h =
      (a * std::abs(std::sin(rz)) + b * std::abs(std::cos(rz))) * std::abs(std::cos(rx)) +
      c * std::abs(std::sin(rx));
  // the box spans 2 w by 2 h units
  const double scale =
      std::min(kViewFit_px[0] / (2 * w * kViewUnit_px), kViewFit_px[1] / (2 * h * kViewUnit_px));
  return std::clamp(scale, 0.5, 3.0);
}

}  // namespace

void joints_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                 const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  const size_t n = data.joint_panels.size();
  s += "set multiplot title " + style::quoted(input.title + ": joint positions") + " font \"" +
       style::title_font() + "\"\n";
  // the plan's duration, or the joints' own clock when it runs longer (settling)
  double duration_s = data.duration_s;
  for (const JointPanel& panel : data.joint_panels)
    for (double t : panel.position.x)
      if (std::isfinite(t)) duration_s = std::max(duration_s, t);
  s += format("set xrange [0:%.9g]\n", std::max(duration_s, 1e-6));
  s += style::transition_shading(data.transitions);

  // one column up to three joints, two beyond; the key in one line under the title
  const size_t columns = n <= 3 ? 1 : 2;
  const size_t rows = (n + columns - 1) / columns;
  constexpr double kTop = 0.83, kBottom = 0.10, kRowGap = 0.065;
  const double row_height = (kTop - kBottom - (rows - 1) * kRowGap) / rows;
  const double column_lefts[2] = {0.09, 0.595};
  const double column_width = columns == 1 ? 0.88 : 0.385;
  s += "unset key\n";

  for (size_t j = 0; j < n; ++j) {
    const JointPanel& panel = data.joint_panels[j];
    const size_t row = j / columns, column = j % columns;
    const double top = kTop - row * (row_height + kRowGap);
    const bool bottom_row = row + 1 == rows || (j + columns >= n);
    s += format(
        "set lmargin at screen %.4f\nset rmargin at screen %.4f\n"
        "set bmargin at screen %.4f\nset tmargin at screen %.4f\n",
        column_lefts[column], column_lefts[column] + column_width, top - row_height, top);
    s += bottom_row ? "set format x '%g'\nset xlabel " +
                          style::quoted(style::axis_label("time", "s")) + " offset 0,0.3\n"
                    : std::string("set format x ''\nunset xlabel\n");
    s += "set ylabel " + style::quoted(style::axis_label(panel.name, panel.unit)) + "\n";
    s += format("set yrange [%.9g:%.9g]\n", panel.y_lo, panel.y_hi);
    s += format("set ytics %.9g\n", nice_step(panel.y_hi - panel.y_lo, 5));
    // how close it came: the panel's title, right-aligned over it
    std::string closest;
    if (panel.limited && std::isfinite(panel.closest_to_limit)) {
      const std::string unit = panel.unit == "deg" ? "°" : " " + panel.unit;
      closest = panel.closest_to_limit >= 0.0
                    ? format("closest to a limit: %.3g%s", panel.closest_to_limit, unit.c_str())
                    : format("beyond a limit by %.3g%s", -panel.closest_to_limit, unit.c_str());
    }
    // red when it came within kNearLimitFraction of the range of a limit, or beyond
    const bool near_limit =
        panel.limited && panel.closest_to_limit < kNearLimitFraction * (panel.max - panel.min);
    s += "set label 1 " + style::quoted(closest) +
         format(" at graph 1, graph 1 right offset 0,0.55 tc rgb \"%s\"\n",
                near_limit ? style::kLimitLineColour : "#404040");
    // the forbidden bands, exactly from each limit outwards
    if (panel.limited) {
      s += format(
          "set object 900001 rect from graph 0, first %.9g to graph 1, first %.9g behind "
          "fc rgb \"%s\" fs solid 1.0 noborder\n",
          panel.y_lo, panel.min, style::kLimitBandColour);
      s += format(
          "set object 900002 rect from graph 0, first %.9g to graph 1, first %.9g behind "
          "fc rgb \"%s\" fs solid 1.0 noborder\n",
          panel.max, panel.y_hi, style::kLimitBandColour);
    } else {
      s += "unset object 900001\nunset object 900002\n";
    }
    std::vector<std::string> elements;
    if (panel.position.point_count() > 0)
      elements.push_back(job.data_file(format("joint_%zu.dat", j), format_curve(panel.position)) +
                         " " + line_style(style::series_colour(j), style::kPlannedLineWidth) +
                         " notitle");
    else
      elements.push_back(style::kEmptyFrame);
    s += plot_command(elements);
  }
  // the key in one line under the title: a plot of its entries alone across the width (the
  // panels are too narrow for a horizontal key)
  s += style::clear_shading();
  s += "unset label 1\nunset border\nunset tics\nunset grid\nunset xlabel\nunset ylabel\n";
  s += "set lmargin at screen 0.02\nset rmargin at screen 0.98\n"
       "set bmargin at screen 0.87\nset tmargin at screen 0.93\nset yrange [0:1]\n";
  s += "set key at screen 0.5, 0.90 center center horizontal samplen 2 width 1\n";
  s += plot_command(
      {style::kEmptyFrame,
       format("keyentry with boxes fs solid 1.0 noborder fc rgb \"%s\" title \"beyond the "
              "joint's range\"",
              style::kLimitBandColour),
       style::transition_key_entry(data.transitions)});
  job.end_png();
}

void layers_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                 const std::string& png) {
  const int width_px = style::kRunPlotWidth_px, height_px = style::kRunPlotHeight_px;
  job.begin_png(png, width_px, height_px);
  std::string& s = job.script();
  const size_t n = data.layer_panels.size();
  std::string title = input.title + ": thickness per layer";
  if (static_cast<int>(n) < data.layer_count)
    title += format(" (%zu of %d layers, evenly chosen)", n, data.layer_count);
  s += "set multiplot title " + style::quoted(title) + " font \"" + style::title_font() + "\"\n";
  s += style::thickness_palette();
  s += format("set cbrange [0:%.9g]\n", data.layer_scale.top_um);
  s += "set cblabel " + style::quoted(style::axis_label("thickness", "µm")) + " offset 0.5,0\n";
  s += "unset grid\nset tics front\nunset key\n";

  // The panels' region (px from the left and the top) and the room kept for tic labels (y
  // left of the first column, x under the last panel of each column), panel titles and gaps;
  // the grid of rows x columns that draws the maps largest, centred in the region.
  const double ex = data.layers_x_hi - data.layers_x_lo, ey = data.layers_y_hi - data.layers_y_lo;
  constexpr double kRegionLeft = 30, kRegionRight = 690, kRegionTop = 44;
  // (a topped scale's note takes a line under the x label: the grid ends higher for it)
  const double region_bottom = data.layer_scale.capped ? 444 : 470;
  constexpr double kTicsLeft = 50, kTicsBottom = 22, kTitleTop = 22, kGap = 24, kRowGap = 4;
  size_t columns = 1;
  double scale = 0.0;  // px per mm
  for (size_t c = 1; c <= n; ++c) {
    const size_t r = (n + c - 1) / c;
    const double map_w = ((kRegionRight - kRegionLeft) - kTicsLeft - (c - 1) * kGap) / c;
    const double map_h =
        ((region_bottom - kRegionTop) - kTicsBottom - r * kTitleTop - (r - 1) * kRowGap) / r;
    const double fit = std::min(map_w / ex, map_h / ey);
    if (fit > scale * 1.0001) scale = fit, columns = c;
  }
  const size_t rows = (n + columns - 1) / columns;
  const double map_w = scale * ex, map_h = scale * ey;
  const double grid_w = kTicsLeft + columns * map_w + (columns - 1) * kGap;
  const double grid_h = rows * (kTitleTop + map_h) + (rows - 1) * kRowGap + kTicsBottom;
  const double left0 = kRegionLeft + 0.5 * ((kRegionRight - kRegionLeft) - grid_w);
  const double top0 = kRegionTop + 0.5 * ((region_bottom - kRegionTop) - grid_h);
  const double x_step = nice_step(ex, std::max(3, static_cast<int>(map_w / 60))),
               y_step = nice_step(ey, std::max(3, static_cast<int>(map_h / 30)));
  s += format("set xtics %.9g\nset ytics %.9g\n", x_step, y_step);
  s += format("set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\n", data.layers_x_lo,
              data.layers_x_hi, data.layers_y_lo, data.layers_y_hi);
  // the colour bar right of the grid, as tall as its maps; the axis labels beside it
  const double grid_right = left0 + grid_w;
  const double maps_top = top0 + kTitleTop, maps_bottom = top0 + grid_h - kTicsBottom;
  s += format("set colorbox vertical user origin screen %.4f, %.4f size screen %.4f, %.4f\n",
              (grid_right + 16) / width_px, 1.0 - maps_bottom / height_px, 16.0 / width_px,
              (maps_bottom - maps_top) / height_px);
  s += format("set label 901 %s at screen %.4f, %.4f center\n",
              style::quoted(style::axis_label("x", "mm")).c_str(),
              (left0 + kTicsLeft + 0.5 * (grid_w - kTicsLeft)) / width_px,
              1.0 - (maps_bottom + kTicsBottom + 14) / height_px);
  s += format("set label 902 %s at screen %.4f, %.4f center rotate by 90\n",
              style::quoted(style::axis_label("y", "mm")).c_str(), (left0 + 4) / width_px,
              1.0 - 0.5 * (maps_top + maps_bottom) / height_px);
  // a topped scale says so under the x label (the colour bar is too short for the sentence)
  if (data.layer_scale.capped)
    s += format(
        "set label 904 %s at screen 0.5, %.4f center tc rgb \"#404040\"\n",
        style::quoted("colour scale " + capped_scale_note(data.layer_scale, "layer")).c_str(),
        1.0 - (maps_bottom + kTicsBottom + 40) / height_px);
  // the map's zero colour behind each panel, so that the extent a layer's grid does not
  // cover reads as "nothing there" like its empty cells
  s += "set object 1 rect from graph 0, graph 0 to graph 1, graph 1 behind fc rgb \"#440154\" "
       "fs solid 1.0 noborder\n";

  bool colour_bar_drawn = false;
  for (size_t i = 0; i < n; ++i) {
    const LayerPanel& panel = data.layer_panels[i];
    const size_t row = i / columns, column = i % columns;
    const double left_px = left0 + kTicsLeft + column * (map_w + kGap);
    const double top_px = top0 + kTitleTop + row * (kTitleTop + map_h + kRowGap);
    // tic labels on the outer panels only: x under each column's last, y left of the first
    s += i + columns >= n ? "set format x '%g'\n" : "set format x ''\n";
    s += column == 0 ? "set format y '%g'\n" : "set format y ''\n";
    s += format(
        "set lmargin at screen %.5f\nset rmargin at screen %.5f\n"
        "set tmargin at screen %.5f\nset bmargin at screen %.5f\n",
        left_px / width_px, (left_px + map_w) / width_px, 1.0 - top_px / height_px,
        1.0 - (top_px + map_h) / height_px);
    s += "set title " + style::quoted(panel.title) + " offset 0,-0.9\n";
    std::vector<std::string> elements;
    if (panel.map.nx > 0 && panel.map.ny > 0) {
      // the colour bar with the first map
      s += colour_bar_drawn ? "unset colorbox\n" : "";
      colour_bar_drawn = true;
      const HeightMap& map = panel.map;
      elements.push_back(
          job.data_file(format("layer_%d.bin", panel.layer), format_binary_map(map)) +
          format(" binary array=(%d,%d) dx=%.9g dy=%.9g origin=(%.9g,%.9g) "
                 "format='%%float32' endian=default with image notitle",
                 map.nx, map.ny, map.cell_mm, map.cell_mm, map.origin_x_mm, map.origin_y_mm));
      s += "unset label 903\n";
    } else {
      s += "set label 903 'nothing deposited' at graph 0.5, graph 0.5 center front tc rgb "
           "\"white\"\n";
    }
    if (panel.paths.point_count() > 0)
      elements.push_back(
          job.data_file(format("layer_%d_paths.dat", panel.layer), format_curve(panel.paths)) +
          " " + line_style(style::kPathOverlayColour, style::kPathOverlayLineWidth) + " notitle");
    if (elements.empty()) elements.push_back(style::kEmptyFrame);
    s += plot_command(elements);
    s += "unset label 901\nunset label 902\nunset label 904\n";
  }
  job.end_png();
}

void paths3d_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                  const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  s += "set title " + style::quoted(input.title + ": print paths in 3-D") + " font \"" +
       style::title_font() + "\"\n";

  // the extent of everything drawn
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  auto add_curve = [&](const Curve3& c) {
    for (size_t k = 0; k < c.size(); ++k)
      if (!std::isnan(c.x[k])) {
        const Vec3 p(c.x[k], c.y[k], c.z[k]);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
  };
  for (const Curve3& c : data.layer_paths) add_curve(c);
  add_curve(data.travels);
  add_curve(data.tool_axes);
  for (const Vec3& p : data.part_surface.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Toolpath& toolpath = *input.toolpath;
  lo = lo.cwiseMin(toolpath.start_mm).cwiseMin(toolpath.end_mm);
  hi = hi.cwiseMax(toolpath.start_mm).cwiseMax(toolpath.end_mm);
  const Vec3 pad = (0.03 * (hi - lo)).cwiseMax(0.5);
  lo -= pad;
  hi += pad;

  // equal scales on x, y and z; looked at from the front, a little above, the longer
  // horizontal side across the picture; the plot left of the key
  const Vec3 extent = hi - lo;
  const double rot_x = 62.0, rot_z = extent.x() >= extent.y() ? 22.0 : 68.0;
  s += format("set view %.1f, %.1f, %.4f\nset view equal xyz\n", rot_x, rot_z,
              view_scale(extent, rot_x, rot_z));
  s += format("set size %.3f, 1\nset origin %.3f, 0\n", kPlotWidthFraction, kPlotLeftFraction);
  s += "set xyplane relative 0\nset border 4095 lw 1 lc rgb \"#c0c0c0\"\nunset grid\n";
  s += format("set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\nset zrange [%.9g:%.9g]\n", lo.x(),
              hi.x(), lo.y(), hi.y(), lo.z(), hi.z());
  const double horizontal = std::max(extent.x(), extent.y());
  // one step on x and y, finer on a short horizontal axis it would leave with under 3 ticks
  const double step = nice_step(horizontal, 6);
  s += format("set xtics %.9g offset 0,-0.3\nset ytics %.9g offset 0.5,-0.3\nset ztics %.9g\n",
              axis_tick_step(lo.x(), hi.x(), step), axis_tick_step(lo.y(), hi.y(), step),
              nice_step(extent.z(), 3));
  s += "set xlabel " + style::quoted(style::axis_label("x", "mm")) + " offset 0,-0.8\n";
  s += "set ylabel " + style::quoted(style::axis_label("y", "mm")) + " offset -2,-0.5\n";
  s += "set zlabel " + style::quoted(style::axis_label("z", "mm")) + " rotate by 90\n";
  s += "set key at screen 0.985, 0.87 right top vertical\n";

  // the part's facets: filled, their edges drawn a little darker (the wireframe)
  s += format("set style fill solid 1.0 border lc rgb \"%s\"\n", style::kPartEdgeColour);

  std::vector<std::string> elements;
  if (!data.part_surface.empty())
    elements.push_back(job.data_file("part.dat", format_triangles(data.part_surface)) +
                       format(" with polygons fc rgb \"%s\" notitle, keyentry with boxes lc rgb "
                              "\"%s\" fs solid 1.0 title 'part'",
                              style::kPartColour, style::kPartColour));
  if (data.travels.point_count() > 0)
    elements.push_back(job.data_file("travels.dat", format_curve3(data.travels)) + " " +
                       line_style(style::kTravelColour, style::kThinLineWidth, 2) +
                       " title 'travel'");
  const size_t layers = data.layer_paths.size();
  const bool by_palette = layers > 8;  // many layers: one colour scale, not a key entry each
  if (by_palette) {
    s += style::thickness_palette();
    s += format("set cbrange [0:%zu]\nset cbtics %.9g\nset cblabel 'layer'\n", layers - 1,
                std::max(1.0, nice_step(static_cast<double>(layers - 1), 5)));
    s += "set colorbox vertical user origin screen 0.80, 0.22 size screen 0.022, 0.36\n";
  }
  for (size_t k = 0; k < layers; ++k) {
    const Curve3& c = data.layer_paths[k];
    if (c.point_count() == 0) continue;
    const std::string file = job.data_file(format("paths3d_layer_%zu.dat", k), format_curve3(c));
    if (by_palette)
      elements.push_back(file + format(" using 1:2:3:(%zu) with lines lw %.2f lc palette notitle",
                                       k, style::kPlannedLineWidth - 0.5));
    else
      elements.push_back(file + " " +
                         line_style(style::series_colour(k), style::kPlannedLineWidth - 0.5) +
                         format(" title 'layer %zu'", k));
  }
  if (data.tool_axes.point_count() > 0)
    elements.push_back(job.data_file("tool_axes.dat", format_curve3(data.tool_axes)) + " " +
                       line_style(style::kToolAxisColour, style::kThinLineWidth) +
                       format(" title 'tool axis, %.3g mm'", data.tool_axis_length_mm));
  s += format("$start3 << EOD\n%.9g %.9g %.9g\nEOD\n$end3 << EOD\n%.9g %.9g %.9g\nEOD\n",
              toolpath.start_mm.x(), toolpath.start_mm.y(), toolpath.start_mm.z(),
              toolpath.end_mm.x(), toolpath.end_mm.y(), toolpath.end_mm.z());
  // the end, then the start as a ring over it: both show where they coincide (a job that
  // returns to where it began)
  elements.push_back(
      format("$end3 with points pt 5 ps 1.3 lc rgb \"%s\" title 'end'", style::kEndColour));
  elements.push_back(format("$start3 with points pt 6 ps 2.2 lw 2 lc rgb \"%s\" title 'start'",
                            style::kStartColour));
  s += plot_command(elements, "splot");
  job.end_png();
}

}  // namespace depotwin::plots
