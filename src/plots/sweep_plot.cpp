// summary.png of a parameter study (plots/sweep_plot.hpp).
#include "plots/sweep_plot.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "plots/plot_job.hpp"
#include "plots/style.hpp"

namespace depotwin::plots {

namespace {

// panel sizes (px): a metric's row, the Pareto panel's row, the title band
constexpr int kPanelWidth_px = 460;
constexpr int kPanelHeight_px = 280;
constexpr int kParetoHeight_px = 380;
constexpr int kParetoMaxWidth_px = 920;
constexpr int kTitleBand_px = 70;
// the most tasks drawn as dots (cairo draws each; thousands more add time, not information)
constexpr std::size_t kMaxDots = 2500;

// a value in a data file: "?" for none (`set datafile missing`)
std::string value_text(double value) {
  return std::isfinite(value) ? format("%.10g", value) : std::string("?");
}

// the series colour, 70 % transparent (ARGB): the faint points behind the means
std::string faint(std::size_t curve) {
  return std::string("#b0") + (style::series_colour(curve) + 1);
}

}  // namespace

std::vector<std::size_t> pareto_front(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < x.size() && i < y.size(); ++i)
    if (std::isfinite(x[i]) && std::isfinite(y[i])) order.push_back(i);
  // by x, then y: a point is on the front when its y is below every y before it (ties in
  // both kept)
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return x[a] != x[b] ? x[a] < x[b] : (y[a] != y[b] ? y[a] < y[b] : a < b);
  });
  std::vector<std::size_t> front;
  double best_y = INFINITY;
  for (const std::size_t i : order) {
    const bool same_as_last = !front.empty() && x[front.back()] == x[i] && y[front.back()] == y[i];
    if (y[i] < best_y || same_as_last) {
      front.push_back(i);
      best_y = std::min(best_y, y[i]);
    }
  }
  return front;
}

std::vector<std::pair<double, double>> curve_means(const std::vector<double>& x,
                                                   const std::vector<double>& y,
                                                   const std::vector<std::size_t>& curve,
                                                   std::size_t which) {
  std::map<double, std::pair<double, int>> sums;  // x -> (sum, count)
  for (std::size_t i = 0; i < x.size() && i < y.size() && i < curve.size(); ++i) {
    if (curve[i] != which || !std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    auto& [sum, count] = sums[x[i]];
    sum += y[i];
    ++count;
  }
  std::vector<std::pair<double, double>> means;
  for (const auto& [at, sum_count] : sums)
    means.emplace_back(at, sum_count.first / sum_count.second);
  return means;
}

PlotResult render_sweep_summary(const SweepPlotInput& input, const std::string& png_path,
                                const PlotOptions& options) {
  const std::size_t points = input.curve.size();
  require(input.x.size() == input.parameters.size(), "sweep plot: one x list per parameter");
  require(input.y.size() == input.metrics.size(), "sweep plot: one y list per metric");
  for (const auto& values : input.x) require(values.size() == points, "sweep plot: x count");
  for (const auto& values : input.y) require(values.size() == points, "sweep plot: y count");
  require(!input.parameters.empty() && !input.metrics.empty(), "sweep plot: nothing to draw");
  const std::size_t curves = std::max<std::size_t>(1, input.curves.size());
  const std::size_t columns = input.parameters.size();
  const std::size_t rows = input.metrics.size();
  const bool pareto = input.pareto_x >= 0 && input.pareto_y >= 0;

  const std::string directory =
      png_path.find('/') == std::string::npos ? "." : png_path.substr(0, png_path.rfind('/'));
  PlotJob job(directory, options);

  // the points drawn as dots, evenly thinned to at most kMaxDots (the means and the front use
  // every point): its curve, its x per parameter, its y per metric
  std::vector<std::size_t> dots;
  for (std::size_t k = 0; k < std::min(points, kMaxDots); ++k)
    dots.push_back(points <= kMaxDots ? k : k * points / kMaxDots);
  std::string text;
  for (const std::size_t i : dots) {
    text += std::to_string(input.curve[i]);
    for (const auto& values : input.x) text += " " + value_text(values[i]);
    for (const auto& values : input.y) text += " " + value_text(values[i]);
    text += "\n";
  }
  const std::string points_file = job.data_file("points.dat", text);
  const auto x_column = [](std::size_t p) { return 2 + p; };
  const auto y_column = [&](std::size_t m) { return 2 + columns + m; };

  // per parameter, each curve's means in its own block (index = curve)
  std::vector<std::string> means_files;
  std::vector<std::vector<bool>> has_means(columns, std::vector<bool>(curves, false));
  for (std::size_t p = 0; p < columns; ++p) {
    std::string block_text;
    for (std::size_t c = 0; c < curves; ++c) {
      std::map<double, std::vector<double>> rows_at;  // x -> mean per metric
      for (std::size_t m = 0; m < rows; ++m)
        for (const auto& [at, mean] : curve_means(input.x[p], input.y[m], input.curve, c)) {
          std::vector<double>& row = rows_at[at];
          row.resize(rows, NAN);
          row[m] = mean;
        }
      has_means[p][c] = !rows_at.empty();
      if (rows_at.empty()) block_text += "? ?\n";  // keeps the block's index
      for (const auto& [at, means] : rows_at) {
        block_text += value_text(at);
        for (const double mean : means) block_text += " " + value_text(mean);
        block_text += "\n";
      }
      block_text += "\n\n";
    }
    means_files.push_back(job.data_file("means_" + std::to_string(p) + ".dat", block_text));
  }

  // the sheet: a row per metric, a column per parameter (one parameter: the metrics in two
  // columns), the Pareto panel below
  const std::size_t panel_columns = columns == 1 ? 2 : columns;
  const std::size_t panel_rows = (rows * columns + panel_columns - 1) / panel_columns;
  const int width_px = static_cast<int>(panel_columns) * kPanelWidth_px;
  const int height_px = kTitleBand_px + static_cast<int>(panel_rows) * kPanelHeight_px +
                        (pareto ? kParetoHeight_px : 0);
  job.begin_png(png_path, width_px, height_px);
  std::string& s = job.script();
  s += "set datafile missing \"?\"\n";
  const std::string title =
      input.title + (dots.size() < points ? format(" (dots: %zu of %zu tasks)", dots.size(), points)
                                          : std::string());
  s += "set multiplot title " + style::quoted(title) + " font \"" + style::title_font() + "\"\n";
  const double panel_w = 1.0 / static_cast<double>(panel_columns);
  const double panel_h = static_cast<double>(kPanelHeight_px) / height_px;
  const double top = 1.0 - static_cast<double>(kTitleBand_px) / height_px;
  // the key once, across the top under the title: a coloured dot and name per curve
  bool key_drawn = false;
  const auto key = [&]() -> std::string {
    if (input.curves.size() < 2 || key_drawn) return "unset key\n";
    key_drawn = true;
    std::string labels = "unset key\n";
    const double spacing = 210.0 / width_px;
    const double first = 0.5 - 0.5 * spacing * static_cast<double>(input.curves.size() - 1);
    for (std::size_t c = 0; c < input.curves.size(); ++c)
      labels += format("set label %zu %s at screen %.4f,%.4f center tc rgb \"%s\"\n", 990 + c,
                       style::quoted("● " + input.curves[c]).c_str(), first + spacing * c,
                       1.0 - 0.62 * kTitleBand_px / height_px, style::series_colour(c));
    return labels;
  };
  const auto curve_title = [&](std::size_t c) {
    return input.curves.empty() ? std::string("notitle")
                                : "title " + style::quoted(input.curves[c]);
  };

  for (std::size_t m = 0; m < rows; ++m) {
    const SweepPlotInput::Metric& metric = input.metrics[m];
    for (std::size_t p = 0; p < columns; ++p) {
      const SweepPlotInput::Parameter& parameter = input.parameters[p];
      const std::size_t panel = m * columns + p;
      const std::size_t row = panel / panel_columns, column = panel % panel_columns;
      s += format("set origin %.5f,%.5f\nset size %.5f,%.5f\n", column * panel_w,
                  top - (row + 1) * panel_h, panel_w, panel_h);
      s += "set xlabel " + style::quoted(parameter.key) + " offset 0,0.3\n";
      s += "set ylabel " + style::quoted(metric.label) + "\n";
      s += "set autoscale y\nset offsets 0, 0, graph 0.05, graph 0.05\n";
      if (parameter.categories.empty()) {
        s += "set autoscale x\nset xtics autofreq\nset offsets graph 0.03, graph 0.03, graph "
             "0.05, graph 0.05\n";
      } else {
        // words: their positions, labelled
        std::string tics;
        for (std::size_t k = 0; k < parameter.categories.size(); ++k)
          tics += (k == 0 ? "" : ", ") + style::quoted(parameter.categories[k]) + " " +
                  std::to_string(k);
        s += format("set xrange [-0.5:%.1f]\n", parameter.categories.size() - 0.5);
        s += "set xtics (" + tics + ")" +
             (parameter.categories.size() > 3 ? " rotate by 20 right" : "") + "\n";
      }
      s += key();
      std::vector<std::string> elements;
      const std::string scale = format("%.10g", metric.scale);
      for (std::size_t c = 0; c < curves; ++c)
        elements.push_back(
            points_file +
            format(" using (column(%zu)):(column(1) == %zu ? column(%zu) * %s : NaN)", x_column(p),
                   c, y_column(m), scale.c_str()) +
            " with points pt 7 ps 0.45 lc rgb \"" + faint(c) + "\" notitle");
      for (std::size_t c = 0; c < curves; ++c) {
        if (!has_means[p][c]) continue;
        elements.push_back(
            means_files[p] +
            format(" index %zu using 1:(column(%zu) * %s)", c, 2 + m, scale.c_str()) +
            " with linespoints lw 2 pt 7 ps 0.8 lc rgb \"" + style::series_colour(c) + "\" " +
            curve_title(c));
      }
      s += plot_command(elements);
      s += "set xtics autofreq norotate\nunset label\n";
    }
  }

  // time against line CV: every task, and the front no other task beats in both
  if (pareto) {
    const auto px = static_cast<std::size_t>(input.pareto_x);
    const auto py = static_cast<std::size_t>(input.pareto_y);
    const std::vector<std::size_t> front = pareto_front(input.y[px], input.y[py]);
    std::string front_text;
    for (const std::size_t i : front)
      front_text += value_text(input.y[px][i] * input.metrics[px].scale) + " " +
                    value_text(input.y[py][i] * input.metrics[py].scale) + "\n";
    const std::string front_file =
        job.data_file("front.dat", front_text.empty() ? "? ?\n" : front_text);
    const double pareto_w = std::min(1.0, static_cast<double>(kParetoMaxWidth_px) / width_px);
    s += format("set origin %.5f,0\nset size %.5f,%.5f\n", 0.5 * (1.0 - pareto_w), pareto_w,
                static_cast<double>(kParetoHeight_px) / height_px - 0.005);
    s += "set autoscale xy\nset xtics autofreq\nset offsets graph 0.03, graph 0.03, graph 0.05, "
         "graph 0.05\n";
    s += "set xlabel " + style::quoted(input.metrics[px].label) + " offset 0,0.3\n";
    s += "set ylabel " + style::quoted(input.metrics[py].label) + "\n";
    s += "set title " +
         style::quoted(format("%s against %s: %zu tasks on the Pareto front (circled)",
                              input.metrics[py].label.c_str(), input.metrics[px].label.c_str(),
                              front.size())) +
         "\n";
    s += "set key default\nset key inside top right opaque box\n";
    std::vector<std::string> elements;
    for (std::size_t c = 0; c < curves; ++c)
      elements.push_back(
          points_file +
          format(" using (column(%zu) * %.10g):(column(1) == %zu ? column(%zu) * %.10g : NaN)",
                 y_column(px), input.metrics[px].scale, c, y_column(py), input.metrics[py].scale) +
          " with points pt 7 ps 0.9 lc rgb \"" + style::series_colour(c) + "\" notitle");
    elements.push_back(front_file + " using 1:2 with steps lw 1.5 dt 2 lc rgb \"#303030\" notitle");
    elements.push_back(front_file +
                       " using 1:2 with points pt 6 ps 1.6 lw 1.5 lc rgb \"#000000\" title "
                       "\"Pareto front\"");
    s += plot_command(elements);
    s += "unset title\n";
  }
  job.end_png();
  return job.finish();
}

}  // namespace depotwin::plots
