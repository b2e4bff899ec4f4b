// The plots of one run: path.png (Fig. 8), axes.png (Fig. 9), errors.png (Figs. 10, 12),
// thickness_profile.png and thickness.png here; joints.png, layers.png and paths3d.png (the
// conformal ones) in conformal_plots.cpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include "plots/plot_job.hpp"
#include "plots/plots.hpp"
#include "plots/style.hpp"

namespace depotwin::plots {

namespace {

constexpr const char* kAxisNames[3] = {"x", "y", "z"};

// [0, 1.08 * max] for quantities that start at zero (errors, thickness)
std::string zero_based_range(double max_value) {
  return format("[0:%.9g]", max_value > 0.0 ? 1.08 * max_value : 1.0);
}

// thickness_profile.png: at most this many key entries go under the plot (two rows of three)
constexpr size_t kProfileKeyEntriesBelow = 6;

// an axis moves when its position range exceeds 1 um
bool moves(const Curve& position) {
  Range r;
  r.add_y(position);
  return !r.empty() && r.hi - r.lo > 1e-3;
}

}  // namespace

std::string target_thickness_note(bool extrusion, double target_um, double speed_mm_s,
                                  double sigma_mm, double flow_mm3_s, double bead_width_mm,
                                  double layer_height_mm) {
  if (extrusion && !(flow_mm3_s > 0.0))
    return format(
        "target %.3g µm = w h / (σ √(2π)) = 1.60 h: a w × h = %.3g × %.3g mm bead as a "
        "Gaussian, σ = w/4",
        target_um, bead_width_mm, layer_height_mm);
  return format(
      "target %.3g µm: a straight line's centreline peak Q / (v σ √(2π)), Q = %.3g mm³/s, "
      "v = %.3g mm/s, σ = %.3g mm",
      target_um, flow_mm3_s, speed_mm_s, sigma_mm);
}

const char* file_name(RunPlot plot) {
  switch (plot) {
    case RunPlot::path:
      return "path.png";
    case RunPlot::axes:
      return "axes.png";
    case RunPlot::errors:
      return "errors.png";
    case RunPlot::thickness_profile:
      return "thickness_profile.png";
    case RunPlot::thickness:
      return "thickness.png";
    case RunPlot::joints:
      return "joints.png";
    case RunPlot::layers:
      return "layers.png";
    case RunPlot::paths3d:
      return "paths3d.png";
  }
  return "plot.png";
}

std::vector<RunPlot> available_plots(const RunPlotInput& input) {
  std::vector<RunPlot> plots = {RunPlot::path, RunPlot::axes, RunPlot::errors};
  if (!input.profiles.empty()) plots.push_back(RunPlot::thickness_profile);
  if (input.thickness != nullptr && input.thickness->nx > 0 && input.thickness->ny > 0)
    plots.push_back(RunPlot::thickness);
  if (input.joints != nullptr && !input.joints->names.empty()) plots.push_back(RunPlot::joints);
  if (std::any_of(input.layer_maps.begin(), input.layer_maps.end(), [](const HeightMap* map) {
        return map != nullptr && map->nx > 0 && map->ny > 0;
      }))
    plots.push_back(RunPlot::layers);
  if (input.toolpath != nullptr) {
    const auto& paths = input.toolpath->paths;
    const bool conformal = (input.part != nullptr && !input.part->empty()) ||
                           input.toolpath->layer_count() > 1 ||
                           std::any_of(paths.begin(), paths.end(),
                                       [](const PrintPath& path) { return !path.normals.empty(); });
    if (conformal) plots.push_back(RunPlot::paths3d);
  }
  return plots;
}

RunPlotData prepare_run_plot_data(const RunPlotInput& input, const PlotOptions& options) {
  require(input.toolpath != nullptr, "run plots need the toolpath");
  require(input.planned != nullptr && input.planned->size() > 0, "run plots need planned samples");
  const MotionSamples& planned = *input.planned;
  const bool simulated = input.simulated != nullptr && input.simulated->size() > 0;
  const size_t budget = options.max_points_per_curve;

  RunPlotData data;
  data.simulated = simulated;
  data.transitions = input.transitions ? *input.transitions : transition_intervals(planned);
  data.duration_s = planned.t_s.back();
  data.feature_size_mm =
      input.feature_size_mm > 0.0 ? input.feature_size_mm : feature_size_mm(*input.toolpath);

  // path.png
  data.planned_print_xy = xy_path_curve(planned, PathPart::printing, budget);
  data.planned_transition_xy = xy_path_curve(planned, PathPart::transition, budget);
  if (simulated) data.simulated_xy = xy_path_curve(*input.simulated, PathPart::all, budget);

  // axes.png: each axis's position and velocity, min/max decimated
  std::vector<double> values;
  auto axis_curves = [&](const MotionSamples& s, int axis, Curve& position, Curve& velocity) {
    values.resize(s.size());
    for (size_t k = 0; k < s.size(); ++k) values[k] = s.position_mm[k][axis];
    position = time_curve(s.t_s, values, budget);
    for (size_t k = 0; k < s.size(); ++k) values[k] = s.velocity_mm_s[k][axis];
    velocity = time_curve(s.t_s, values, budget);
  };
  for (int axis = 0; axis < 3; ++axis) {
    axis_curves(planned, axis, data.planned_position[axis], data.planned_velocity[axis]);
    if (simulated)
      axis_curves(*input.simulated, axis, data.simulated_position[axis],
                  data.simulated_velocity[axis]);
    data.axis_moves[axis] =
        moves(data.planned_position[axis]) || moves(data.simulated_position[axis]);
  }

  // errors.png: percent, gaps where nothing is deposited
  auto percent = [](std::vector<double> v) {
    for (double& e : v) e *= 100.0;
    return v;
  };
  data.planned_speed_error_pct =
      time_curve(planned.t_s, percent(speed_error_with_gaps(planned)), budget);
  data.planned_position_error_pct = time_curve(
      planned.t_s, percent(relative_position_error(planned, *input.toolpath, data.feature_size_mm)),
      budget);
  if (simulated) {
    const MotionSamples& s = *input.simulated;
    data.simulated_speed_error_pct = time_curve(s.t_s, percent(speed_error_with_gaps(s)), budget);
    data.simulated_position_error_pct = time_curve(
        s.t_s, percent(relative_position_error(s, *input.toolpath, data.feature_size_mm)), budget);
  }

  // thickness_profile.png
  for (const LineProfile& profile : input.profiles) {
    require(profile.arc_length_mm.size() == profile.thickness_um.size(),
            "a line profile's arc lengths and thicknesses differ in count");
    data.profiles.push_back(time_curve(profile.arc_length_mm, profile.thickness_um, budget));
  }

  // thickness.png
  if (input.thickness != nullptr && input.thickness->nx > 0 && input.thickness->ny > 0) {
    require(input.thickness->thickness_um.size() ==
                static_cast<size_t>(input.thickness->nx) * input.thickness->ny,
            "the height map's size does not match nx * ny");
    data.display_map = downsample_for_display(*input.thickness, options.max_map_cells_per_side);
  }

  // the conformal plots
  if (input.joints != nullptr) prepare_joint_panels(*input.joints, options, data);
  prepare_layer_panels(input, options, data);
  prepare_paths3d(input, options, data);
  return data;
}

namespace {

// path.png: the planned XY path, print and transition styles, simulated path, start and end
// (Thompson & Yoon Fig. 8)
void path_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
               const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  const Toolpath& toolpath = *input.toolpath;
  s += "set title " + style::quoted(input.title + ": XY path") + " font \"" + style::title_font() +
       "\"\n";
  s += "set xlabel " + style::quoted(style::axis_label("x", "mm")) + "\n";
  s += "set ylabel " + style::quoted(style::axis_label("y", "mm")) + "\n";
  s += "set size ratio -1\nset key outside right top vertical\n";
  s += "set style textbox opaque noborder margins 1,1\n";

  // ranges over everything drawn, with a margin
  Range x, y;
  x.add_x(data.planned_print_xy), y.add_y(data.planned_print_xy);
  x.add_x(data.planned_transition_xy), y.add_y(data.planned_transition_xy);
  x.add_x(data.simulated_xy), y.add_y(data.simulated_xy);
  x.add(toolpath.start_mm.x()), y.add(toolpath.start_mm.y());
  x.add(toolpath.end_mm.x()), y.add(toolpath.end_mm.y());
  const PlanRanges frame = plan_ranges(x, y, 0.05, 0.5);
  s += format("set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\n", frame.x_lo, frame.x_hi,
              frame.y_lo, frame.y_hi);

  // print paths numbered in print order at their middle (as in the paper's Fig. 7), 0-based
  // as in trajectory.csv and metrics.json; numbers that would cover one another (a part's
  // layers) share one label, "0–2"
  const double merge_within_mm =
      kLabelMergeShare * std::max(frame.x_hi - frame.x_lo, frame.y_hi - frame.y_lo);
  const std::vector<DrawnLabel> labels =
      drawn_path_labels(halfway_path_labels(toolpath), merge_within_mm, kMaxPathLabels);
  for (size_t i = 0; i < labels.size(); ++i)
    s += format("set label %zu \"%s\" at %.9g,%.9g offset 0.7,0.7 tc rgb \"#404040\" boxed front\n",
                i + 1, labels[i].text.c_str(), labels[i].x_mm, labels[i].y_mm);

  s += format("$start << EOD\n%.9g %.9g\nEOD\n$end << EOD\n%.9g %.9g\nEOD\n", toolpath.start_mm.x(),
              toolpath.start_mm.y(), toolpath.end_mm.x(), toolpath.end_mm.y());
  std::vector<std::string> elements;
  if (data.planned_print_xy.point_count() > 0)
    elements.push_back(job.data_file("path_print.dat", format_curve(data.planned_print_xy)) + " " +
                       line_style(style::kPlannedColour, style::kPathLineWidth) +
                       " title 'planned: printing'");
  if (data.planned_transition_xy.point_count() > 0)
    elements.push_back(
        job.data_file("path_transition.dat", format_curve(data.planned_transition_xy)) + " " +
        line_style(style::kTransitionPathColour, style::kPlannedLineWidth, 2) +
        " title 'planned: transition'");
  if (data.simulated_xy.point_count() > 0)
    elements.push_back(job.data_file("path_simulated.dat", format_curve(data.simulated_xy)) + " " +
                       line_style(style::kSimulatedPathColour, style::kThinLineWidth) +
                       " title 'simulated'");
  // the end, then the start as a ring over it: both show where they coincide
  elements.push_back(
      format("$end with points pt 5 ps 1.6 lc rgb \"%s\" title 'end'", style::kEndColour));
  elements.push_back(format("$start with points pt 6 ps 2.4 lw 2 lc rgb \"%s\" title 'start'",
                            style::kStartColour));
  s += plot_command(elements);
  job.end_png();
}

// the screen margins shared by stacked time panels, so their time axes line up
struct Panel {
  double bottom, top;
};
constexpr double kPanelLeft = 0.095, kPanelRight = 0.79;

void begin_panel(std::string& s, const Panel& panel, double left = kPanelLeft) {
  s += format(
      "set lmargin at screen %.4f\nset rmargin at screen %.4f\n"
      "set bmargin at screen %.4f\nset tmargin at screen %.4f\n",
      left, kPanelRight, panel.bottom, panel.top);
}

// axes.png: per-axis position and velocity against time, transitions shaded (Fig. 9)
void axes_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
               const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  s += "set multiplot title " + style::quoted(input.title + ": axis position and velocity") +
       " font \"" + style::title_font() + "\"\n";
  s += "set key outside right top vertical\n";
  s += format("set xrange [0:%.9g]\n", std::max(data.duration_s, 1e-6));
  s += style::transition_shading(data.transitions);

  // axes that stay put are left out; with none moving, x and y are shown
  std::vector<int> axes;
  for (int axis = 0; axis < 3; ++axis)
    if (data.axis_moves[axis]) axes.push_back(axis);
  if (axes.empty()) axes = {0, 1};

  auto panel = [&](const Curve* planned, const Curve* simulated, const char* quantity,
                   const char* unit, const std::string& file_stem, bool with_shading_key) {
    Range y;
    for (int axis : axes) y.add_y(planned[axis]), y.add_y(simulated[axis]);
    s += "set ylabel " + style::quoted(style::axis_label(quantity, unit)) + "\n";
    s += "set yrange " + y.gnuplot(0.06, 0.5) + "\n";
    std::vector<std::string> elements;
    // the simulated curves as wide light bands, then the planned ones as lines on top: both
    // stay visible where they coincide (which they mostly do), and no band hides a line
    for (int axis : axes)
      if (simulated[axis].point_count() > 0)
        elements.push_back(
            job.data_file(file_stem + "_simulated_" + kAxisNames[axis] + std::string(".dat"),
                          format_curve(simulated[axis])) +
            " " + line_style(style::kAxisBandColours[axis], style::kSimulatedBandWidth) +
            " title '" + kAxisNames[axis] + " simulated'");
    for (int axis : axes)
      if (planned[axis].point_count() > 0)
        elements.push_back(
            job.data_file(file_stem + "_planned_" + kAxisNames[axis] + std::string(".dat"),
                          format_curve(planned[axis])) +
            " " + line_style(style::kAxisColours[axis], style::kThinLineWidth + 0.5) + " title '" +
            kAxisNames[axis] + " planned'");
    if (with_shading_key) elements.push_back(style::transition_key_entry(data.transitions));
    s += plot_command(elements);
  };

  begin_panel(s, {0.55, 0.90});
  s += "set format x ''\nunset xlabel\n";
  panel(data.planned_position, data.simulated_position, "position", "mm", "position", true);
  begin_panel(s, {0.11, 0.51});
  s += "set format x '%g'\nset xlabel " + style::quoted(style::axis_label("time", "s")) + "\n";
  panel(data.planned_velocity, data.simulated_velocity, "velocity", "mm/s", "velocity", false);
  job.end_png();
}

// errors.png: the room left of a panel (px) for its y label (two lines) and tick labels of
// `chars` characters, from the image's edge to the axis
double error_panel_left_px(size_t chars) {
  constexpr double kEdge_px = 6, kLabelLines_px = 2 * 17, kGap_px = 8, kChar_px = 7.5, kTick_px = 8;
  return kEdge_px + kLabelLines_px + kGap_px + chars * kChar_px + kTick_px;
}

// errors.png: relative speed error and relative position error against time, transitions
// shaded (Figs. 10 and 12)
void errors_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                 const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  // each panel's y range [0, 1.08 max] and its tick step (about five intervals), so that the
  // left margin can be made as wide as the widest tick label needs (tiny errors print as
  // "0.025" or "4e-05"); one margin for both, so the time axes line up
  const auto y_top = [](const Curve& planned, const Curve& simulated) {
    Range y;
    y.add_y(planned), y.add_y(simulated);
    return !y.empty() && y.hi > 0.0 ? 1.08 * y.hi : 1.0;
  };
  const double speed_top = y_top(data.planned_speed_error_pct, data.simulated_speed_error_pct);
  const double position_top =
      y_top(data.planned_position_error_pct, data.simulated_position_error_pct);
  const double speed_step = round_step_up(speed_top / 5.0);
  const double position_step = round_step_up(position_top / 5.0);
  const size_t widest = std::max(widest_tick_label(0.0, speed_top, speed_step),
                                 widest_tick_label(0.0, position_top, position_step));
  const double left = std::max(kPanelLeft, error_panel_left_px(widest) / style::kRunPlotWidth_px);
  s += "set multiplot title " + style::quoted(input.title + ": speed and position error") +
       " font \"" + style::title_font() + "\"\n";
  s += "set key outside right top vertical\n";
  s += format("set xrange [0:%.9g]\n", std::max(data.duration_s, 1e-6));
  s += style::transition_shading(data.transitions);

  auto panel = [&](const Curve& planned, const Curve& simulated,
                   const std::vector<std::string>& label, double top, double step,
                   const std::string& stem, bool with_shading_key) {
    s += "set ylabel " + style::double_quoted_lines(label) + "\n";
    s += format("set yrange [0:%.9g]\nset ytics %.9g\n", top, step);
    std::vector<std::string> elements;
    if (planned.point_count() > 0)
      elements.push_back(job.data_file(stem + "_planned.dat", format_curve(planned)) + " " +
                         line_style(style::kPlannedColour, style::kPlannedLineWidth) +
                         " title 'planned'");
    if (simulated.point_count() > 0)
      elements.push_back(job.data_file(stem + "_simulated.dat", format_curve(simulated)) + " " +
                         line_style(style::kSimulatedColour, style::kSimulatedLineWidth) +
                         " title 'simulated'");
    // nothing deposited at all: an empty frame (a key entry alone is not a plot), no key box
    // unless the shading needs one
    const bool no_curves = elements.empty();
    if (no_curves) elements.push_back(style::kEmptyFrame);
    if (with_shading_key) elements.push_back(style::transition_key_entry(data.transitions));
    const bool keyed = !no_curves || (with_shading_key && !data.transitions.empty());
    s += keyed ? "set key outside right top vertical\n" : "unset key\n";
    s += plot_command(elements);
  };

  begin_panel(s, {0.55, 0.90}, left);
  s += "set format x ''\nunset xlabel\n";
  panel(data.planned_speed_error_pct, data.simulated_speed_error_pct, {"(a) speed error (%)"},
        speed_top, speed_step, "speed_error", true);
  begin_panel(s, {0.11, 0.51}, left);
  s += "set format x '%g'\nset xlabel " + style::quoted(style::axis_label("time", "s")) + "\n";
  // (two lines: one would be taller than the panel)
  panel(data.planned_position_error_pct, data.simulated_position_error_pct,
        {"(b) position error", format("(%% of %.3g mm)", data.feature_size_mm)}, position_top,
        position_step, "position_error", false);
  job.end_png();
}

// the mean of the centreline profiles, each sample weighted by the arc length it stands for
double centreline_mean_um(const std::vector<LineProfile>& profiles) {
  double sum = 0.0, length = 0.0;
  for (const LineProfile& p : profiles)
    for (size_t k = 0; k + 1 < p.arc_length_mm.size(); ++k) {
      const double ds = p.arc_length_mm[k + 1] - p.arc_length_mm[k];
      sum += 0.5 * (p.thickness_um[k] + p.thickness_um[k + 1]) * ds;
      length += ds;
    }
  return length > 0.0 ? sum / length : 0.0;
}

// thickness_profile.png: thickness along each print line's centreline, the target and the
// centreline mean; the key and the notes (where the target comes from, what
// thickness.mean_um is) under the plot, clear of the data
void profile_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                  const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  s += "set title " + style::quoted(input.title + ": thickness along the print lines") +
       " font \"" + style::title_font() + "\"\n";
  s += "set xlabel " + style::quoted(style::axis_label("arc length along the line", "mm")) + "\n";
  // (several layers: each line on its own layer's deposit, centreline_profiles)
  s += "set ylabel " +
       style::quoted(style::axis_label(
           input.layer_count > 1 ? "centreline thickness, own layer" : "centreline thickness",
           "µm")) +
       "\n";
  const double centreline_um = centreline_mean_um(input.profiles);

  // one colour and key entry per line when few; one shared colour and entry when many, on the
  // first line drawn, naming the paths' range
  int first_path = std::numeric_limits<int>::max(), last_path = std::numeric_limits<int>::min();
  size_t drawn = 0;
  for (size_t i = 0; i < data.profiles.size(); ++i) {
    if (data.profiles[i].point_count() == 0) continue;
    ++drawn;
    first_path = std::min(first_path, input.profiles[i].path_index);
    last_path = std::max(last_path, input.profiles[i].path_index);
  }
  const bool few = drawn <= 8;

  // the key under the plot, above the notes, while its entries fill at most two rows of three;
  // more (up to eight lines and the two references) would reach down over the notes, so they
  // go in one column right of the plot
  const size_t key_entries = (input.target_thickness_um > 0.0 ? 1 : 0) +
                             (centreline_um > 0.0 ? 1 : 0) +
                             (few ? drawn : std::min<size_t>(drawn, 1));
  if (key_entries <= kProfileKeyEntriesBelow) {
    s += "set lmargin at screen 0.095\nset rmargin at screen 0.97\n";
    s += "set tmargin at screen 0.90\nset bmargin at screen 0.36\n";
    s += "set key at screen 0.5,0.235 center top horizontal maxrows 3 width 1 samplen 3\n";
  } else {
    s += "set lmargin at screen 0.095\nset rmargin at screen 0.63\n";
    s += "set tmargin at screen 0.90\nset bmargin at screen 0.25\n";
    s += "set key at screen 0.985,0.90 right top vertical width 1 samplen 3\n";
  }
  Range x, y;
  for (const Curve& c : data.profiles) x.add_x(c), y.add_y(c);
  y.add(input.target_thickness_um), y.add(centreline_um);
  s += format("set xrange [0:%.9g]\n", x.empty() || x.hi <= 0.0 ? 1.0 : x.hi);
  s += "set yrange " + zero_based_range(y.empty() ? 0.0 : y.hi) + "\n";

  // the notes: where the target comes from, and the other mean metrics.json gives
  std::vector<std::string> notes;
  if (input.target_thickness_um > 0.0)
    notes.push_back(!input.target_note.empty()
                        ? input.target_note
                        : "target: the centreline peak of a straight line at its print speed "
                          "(Gaussian cross-section)");
  if (input.mean_thickness_um > 0.0)
    notes.push_back(input.layer_count > 1
                        ? format("metrics.json thickness.mean_um = %.3g µm: all %d layers "
                                 "stacked, over the lines' whole width",
                                 input.mean_thickness_um, input.layer_count)
                        : format("metrics.json thickness.mean_um = %.3g µm is the mean over "
                                 "the lines' whole width, not the centreline",
                                 input.mean_thickness_um));
  for (size_t i = 0; i < notes.size(); ++i)
    s += format("set label %zu %s at screen 0.5,%.4f center font \",10\" tc rgb \"#404040\"\n",
                950 + i, style::quoted(notes[i]).c_str(), 0.075 - 0.04 * i);

  bool shared_entry_given = false;
  std::vector<std::string> elements;
  // the reference lines first, so the profiles are drawn over them
  if (input.target_thickness_um > 0.0)
    elements.push_back(format("%.9g with lines lw 2 dt 2 lc rgb \"%s\" title 'target %.3g µm'",
                              input.target_thickness_um, style::kTargetColour,
                              input.target_thickness_um));
  if (centreline_um > 0.0)
    elements.push_back(
        format("%.9g with lines lw 2 dt 3 lc rgb \"%s\" title 'centreline mean %.3g µm'",
               centreline_um, style::kMeanColour, centreline_um));
  for (size_t i = 0; i < data.profiles.size(); ++i) {
    if (data.profiles[i].point_count() == 0) continue;
    const int path = input.profiles[i].path_index;
    std::string title = few                   ? format("title 'path %d'", path)
                        : !shared_entry_given ? format("title 'paths %d-%d'", first_path, last_path)
                                              : std::string("notitle");
    shared_entry_given = true;
    elements.push_back(
        job.data_file(format("profile_%zu.dat", i), format_curve(data.profiles[i])) + " " +
        line_style(few ? style::series_colour(i) : style::kPlannedColour, 1.5) + " " + title);
  }
  if (elements.empty()) elements.push_back(style::kEmptyFrame);
  s += plot_command(elements);
  s += "unset label\n";
  job.end_png();
}

}  // namespace

std::string thickness_map_elements(PlotJob& job, const HeightMap& map, const Toolpath* toolpath,
                                   const std::string& stem, bool path_key) {
  std::vector<std::string> elements;
  elements.push_back(job.data_file(stem + ".bin", format_binary_map(map)) +
                     format(" binary array=(%d,%d) dx=%.9g dy=%.9g origin=(%.9g,%.9g) "
                            "format='%%float32' endian=default with image notitle",
                            map.nx, map.ny, map.cell_mm, map.cell_mm, map.origin_x_mm,
                            map.origin_y_mm));
  if (toolpath != nullptr && !toolpath->paths.empty()) {
    if (paths_crowd_map(*toolpath, map)) {
      // (not over a map they would hide, as a slicer's infill would: the key says so)
      if (path_key)
        elements.push_back(
            "keyentry with lines lc rgb \"#FF000000\" title 'print paths: too dense to draw over "
            "the map'");
    } else {
      Curve paths;
      for (const PrintPath& path : toolpath->paths) {
        for (const Vec3& p : path.points) paths.add(p.x(), p.y());
        paths.add_break();
      }
      elements.push_back(job.data_file(stem + "_paths.dat", format_curve(paths)) + " " +
                         line_style(style::kPathOverlayColour, style::kPathOverlayLineWidth, 2) +
                         (path_key ? " title 'print path'" : " notitle"));
    }
  }
  return plot_command(elements);
}

bool paths_crowd_map(const Toolpath& toolpath, const HeightMap& map) {
  return paths_crowd_window(toolpath, map.x_lo_mm(), map.x_hi_mm(), map.y_lo_mm(), map.y_hi_mm());
}

std::string map_ranges(const std::vector<const HeightMap*>& maps, const Toolpath* toolpath) {
  Range x, y;
  for (const HeightMap* map : maps) {
    if (map == nullptr || map->nx <= 0 || map->ny <= 0) continue;
    x.add(map->x_lo_mm());
    x.add(map->x_hi_mm());
    y.add(map->y_lo_mm());
    y.add(map->y_hi_mm());
  }
  if (toolpath != nullptr)
    for (const PrintPath& path : toolpath->paths)
      for (const Vec3& p : path.points) x.add(p.x()), y.add(p.y());
  // one tic step on both axes (the map is drawn at 1:1), about four over the longer side, so a
  // tall narrow map does not crowd its x axis with the step its own width would get; an axis
  // that step leaves with fewer than three ticks gets a finer one of its own
  const auto [x_lo, x_hi, y_lo, y_hi] = plan_ranges(x, y, 0.0, 0.05);
  const double shared_step = round_step_up(std::max(x_hi - x_lo, y_hi - y_lo) / 4.0);
  return format("set xrange [%.9g:%.9g]\nset yrange [%.9g:%.9g]\n", x_lo, x_hi, y_lo, y_hi) +
         format("set xtics %.9g\nset ytics %.9g\n", axis_tick_step(x_lo, x_hi, shared_step),
                axis_tick_step(y_lo, y_hi, shared_step));
}

namespace {

// a map this many times as wide as high or more is a wide one (thickness_plot)
constexpr double kWideMapAspect = 1.5;

// thickness.png: top-down heat map with colour bar, mm axes, print paths overlaid
void thickness_plot(PlotJob& job, const RunPlotInput& input, const RunPlotData& data,
                    const std::string& png) {
  job.begin_png(png, style::kRunPlotWidth_px, style::kRunPlotHeight_px);
  std::string& s = job.script();
  const HeightMap& map = data.display_map;
  s += "set title " + style::quoted(input.title + ": deposited thickness") + " font \"" +
       style::title_font() + "\"\n";
  s += "set xlabel " + style::quoted(style::axis_label("x", "mm")) + "\n";
  s += "set ylabel " + style::quoted(style::axis_label("y", "mm")) + "\n";
  s += "set size ratio -1\nunset grid\nset tics front\n";
  // the key under the x label, right-aligned with the map, dark so the white sample shows
  s += format(
      "set bmargin 5\nset key at graph 1, screen 0.012 right bottom horizontal opaque "
      "fc rgb \"%s\" textcolor rgb \"white\"\n",
      style::kMapKeyColour);
  s += style::thickness_palette();
  // topped like the comparison's and layers.png's scale, so that a blob (a start, layers
  // stacked there) does not wash the beads out; the note under the title says so
  const SharedThicknessScale scale = capped_thickness_scale({input.thickness});
  s += format("set cbrange [0:%.9g]\n",
              std::max(scale.capped ? scale.top_um : static_cast<double>(map.max_value()), 1e-3));
  if (scale.capped)  // (just over the map, under the title, which moves up for it)
    s += "set title offset 0, 0.8\n" +
         format(
             "set label 905 %s at graph 0.5, graph 1 center offset 0, 0.8 font \",9\" tc rgb "
             "\"#404040\"\n",
             style::quoted("colour scale " + capped_scale_note(scale, "")).c_str());
  s += "set cblabel " + style::quoted(style::axis_label("thickness", "µm")) + " offset 1.5,0\n";
  s += "set colorbox\n";
  // a wide map (half as wide again as high) keeps room at its right for the colour bar, its
  // tick labels and its label, which it ran past the image's edge (a narrower one is centred
  // by its height and has that room)
  if (map.nx >= kWideMapAspect * map.ny) s += "set rmargin 13\n";
  s += map_ranges({&map}, input.toolpath);
  s += thickness_map_elements(job, map, input.toolpath, "thickness_map", true);
  job.end_png();
}

}  // namespace

PlotResult render_run_plots(const RunPlotInput& input, const std::string& directory,
                            const std::vector<RunPlot>& plots, const PlotOptions& options) {
  const std::vector<RunPlot> wanted = plots.empty() ? available_plots(input) : plots;
  PlotJob job(directory, options);  // GnuplotNotFound before any work
  const RunPlotData data = prepare_run_plot_data(input, options);
  for (RunPlot plot : wanted) {
    const std::string png = directory + "/" + file_name(plot);
    switch (plot) {
      case RunPlot::path:
        path_plot(job, input, data, png);
        break;
      case RunPlot::axes:
        axes_plot(job, input, data, png);
        break;
      case RunPlot::errors:
        errors_plot(job, input, data, png);
        break;
      case RunPlot::thickness_profile:
        require(!data.profiles.empty(), "thickness_profile.png needs line profiles");
        profile_plot(job, input, data, png);
        break;
      case RunPlot::thickness:
        require(data.display_map.nx > 0 && data.display_map.ny > 0,
                "thickness.png needs a thickness map");
        thickness_plot(job, input, data, png);
        break;
      case RunPlot::joints:
        require(!data.joint_panels.empty(), "joints.png needs joint positions");
        joints_plot(job, input, data, png);
        break;
      case RunPlot::layers:
        require(!data.layer_panels.empty(), "layers.png needs layer thickness maps");
        layers_plot(job, input, data, png);
        break;
      case RunPlot::paths3d:
        paths3d_plot(job, input, data, png);
        break;
    }
  }
  return job.finish();
}

}  // namespace depotwin::plots
