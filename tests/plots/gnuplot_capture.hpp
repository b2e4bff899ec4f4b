// What gnuplot was asked to draw: a stand-in for gnuplot (a shell script, given to the plots
// as PlotOptions::gnuplot, or found first on PATH as `gnuplot`) copies the plot job's folder,
// the script plots.gp and every data file it reads, to a folder of the test's, then runs the
// real gnuplot on the original. The tests then read the script's plot commands and the data
// behind each curve, not just the pixels.
#pragma once

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "plots/gnuplot.hpp"

namespace depotwin::testing_support {

struct GnuplotCapture {
  std::string program;  // the stand-in (an absolute path)
  std::string folder;   // where each run's job folder is copied (replaced on every run)

  std::string script() const {
    std::ifstream in(folder + "/plots.gp", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
};

// A stand-in written into `directory` as `name` (named `gnuplot` it can go first on PATH),
// copying to directory/captured.
inline GnuplotCapture capturing_gnuplot(const std::string& directory,
                                        const std::string& name = "gnuplot") {
  namespace fs = std::filesystem;
  GnuplotCapture capture;
  capture.program = (fs::absolute(directory) / name).string();
  capture.folder = (fs::absolute(directory) / "captured").string();
  const std::string real = plots::find_gnuplot("gnuplot");
  // gnuplot is started as `gnuplot -d <job folder>/plots.gp`, with a minimal environment
  std::ofstream(capture.program) << "#!/bin/sh\n"
                                 << "/bin/rm -rf '" << capture.folder << "'\n"
                                 << "/bin/cp -r \"${2%/*}\" '" << capture.folder << "' || exit 1\n"
                                 << "exec '" << real << "' \"$@\"\n";
  fs::permissions(capture.program, fs::perms::owner_all | fs::perms::group_read |
                                       fs::perms::group_exec | fs::perms::others_read |
                                       fs::perms::others_exec);
  return capture;
}

// The script's part that draws the PNG whose final path ends in `png_name` (PlotJob starts
// each with a comment naming it), up to the next PNG's.
inline std::string png_section(const std::string& script, const std::string& png_name) {
  std::istringstream in(script);
  std::string line, section;
  bool inside = false;
  while (std::getline(in, line)) {
    const bool header = line.rfind("# ", 0) == 0 && line.size() > 4 &&
                        line.compare(line.size() - 4, 4, ".png") == 0;
    if (header) {
      if (inside) break;
      inside =
          line.size() >= png_name.size() + 1 &&
          line.compare(line.size() - png_name.size() - 1, png_name.size() + 1, "/" + png_name) == 0;
      continue;
    }
    if (inside) section += line + "\n";
  }
  return section;
}

// The elements of every plot (or splot) command of a section, in order: PlotJob joins them
// with ", \" line continuations.
inline std::vector<std::string> plot_elements(const std::string& section) {
  std::vector<std::string> elements;
  std::istringstream in(section);
  std::string line;
  bool continued = false;
  while (std::getline(in, line)) {
    std::string element;
    if (continued) {
      element = line.substr(line.find_first_not_of(' '));
    } else if (line.rfind("plot ", 0) == 0) {
      element = line.substr(5);
    } else if (line.rfind("splot ", 0) == 0) {
      element = line.substr(6);
    } else {
      continue;
    }
    continued = element.size() >= 3 && element.compare(element.size() - 3, 3, ", \\") == 0;
    if (continued) element.resize(element.size() - 3);
    elements.push_back(element);
  }
  return elements;
}

// an element's key entry: the text of `title '...'`, "" for notitle (or none)
inline std::string key_title(const std::string& element) {
  std::smatch match;
  if (std::regex_search(element, match, std::regex("title '([^']*)'"))) return match[1];
  if (std::regex_search(element, match, std::regex("title \"([^\"]*)\""))) return match[1];
  return "";
}

// an element's line colour (`lc rgb "#rrggbb"`), "" when it names none
inline std::string line_colour(const std::string& element) {
  std::smatch match;
  if (std::regex_search(element, match, std::regex("lc rgb \"([^\"]*)\""))) return match[1];
  return "";
}

// the data file an element plots, as a file name (its folder dropped), "" for none
inline std::string data_file_name(const std::string& element) {
  std::smatch match;
  if (!std::regex_search(element, match, std::regex("^'([^']*)'"))) return "";
  return std::filesystem::path(match[1].str()).filename().string();
}

// the numbers of a data file, one row per non-empty line
inline std::vector<std::vector<double>> read_rows(const std::string& path) {
  std::vector<std::vector<double>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::vector<double> row;
    double value = 0.0;
    while (fields >> value) row.push_back(value);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

}  // namespace depotwin::testing_support
