// One gnuplot run (internal to the module): data files and PNGs go to a private temporary
// directory beside the outputs, the script is assembled piece by piece, gnuplot runs once
// and the PNGs are renamed into place only when it succeeded.
#pragma once

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

// the thickness map as an image (colours by the current cbrange) with the print paths
// overlaid as dashed lines: a plot command; shared by thickness.png and the comparison sheet
std::string thickness_map_elements(PlotJob& job, const HeightMap& map, const Toolpath* toolpath,
                                   const std::string& stem, bool path_key);
// `set xrange/yrange` covering the maps' cells (to their edges) and the print paths
std::string map_ranges(const std::vector<const HeightMap*>& maps, const Toolpath* toolpath);

}  // namespace depotwin::plots
