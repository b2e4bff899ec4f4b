#include "plots/plot_job.hpp"

#include <algorithm>
#include <tuple>

#include "plots/style.hpp"

namespace depotwin::plots {

PlanRanges plan_ranges(const Range& x, const Range& y, double pad_fraction, double min_half_width) {
  PlanRanges r;
  std::tie(r.x_lo, r.x_hi) = x.padded(pad_fraction, min_half_width);
  std::tie(r.y_lo, r.y_hi) = y.padded(pad_fraction, min_half_width);
  const auto widen = [](double& lo, double& hi, double least) {
    const double grow = 0.5 * std::max(0.0, least - (hi - lo));
    lo -= grow;
    hi += grow;
  };
  widen(r.x_lo, r.x_hi, kMinPlanAspect * (r.y_hi - r.y_lo));
  widen(r.y_lo, r.y_hi, kMinPlanAspect * (r.x_hi - r.x_lo));
  return r;
}

std::string plot_command(const std::vector<std::string>& elements, const char* verb) {
  std::string command;
  for (const std::string& e : elements) {
    if (e.empty()) continue;
    command += command.empty() ? std::string(verb) + " " : ", \\\n     ";
    command += e;
  }
  return command.empty() ? "" : command + "\n";
}

std::string line_style(const char* colour, double width, int dash) {
  return format("with lines lw %.2f dt %d lc rgb \"%s\"", width, dash, colour);
}

void require(bool condition, const char* what) {
  if (!condition) throw InternalError(std::string("plots: ") + what);
}

PlotJob::PlotJob(const std::string& output_directory, const PlotOptions& options)
    : gnuplot_(find_gnuplot(options.gnuplot)), temporary_(output_directory) {}

std::string PlotJob::data_file(const std::string& name, const std::string& content) {
  const std::string path = temporary_.file(name);
  write_text_file(path, content);
  return style::quoted(path);
}

void PlotJob::begin_png(const std::string& final_path, int width_px, int height_px) {
  const std::string temporary = temporary_.file("png-" + std::to_string(pngs_.size()) + ".png");
  pngs_.push_back({temporary, final_path});
  script_ += "\n# " + final_path + "\n";
  script_ += style::terminal(width_px, height_px);
  script_ += "set output " + style::quoted(temporary) + "\n";
  script_ += style::common_settings();
}

void PlotJob::end_png() {
  script_ += "unset multiplot\nunset output\n";
}

PlotResult PlotJob::finish() {
  const std::string script_path = temporary_.file("plots.gp");
  write_text_file(script_path, script_);
  PlotResult result;
  result.warnings = run_gnuplot(gnuplot_, script_path, temporary_.file("gnuplot.stderr"));
  for (const auto& [temporary, final_path] : pngs_) {
    move_into_place(temporary, final_path);
    result.files.push_back(final_path);
  }
  return result;
}

}  // namespace depotwin::plots
