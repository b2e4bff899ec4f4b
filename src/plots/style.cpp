#include "plots/style.hpp"

namespace depotwin::plots::style {

const char* series_colour(size_t index) {
  return kSeriesColours[index % (sizeof kSeriesColours / sizeof kSeriesColours[0])];
}

std::string terminal(int width_px, int height_px) {
  // noenhanced: names like lspb_mtt print as written, not with subscripts
  return format("set terminal pngcairo size %d,%d noenhanced font \"%s,%d\" linewidth 1 rounded\n",
                width_px, height_px, kFont, kFontSize_pt);
}

std::string common_settings() {
  std::string s = "reset\n";
  s += "set border 3 lw 1 lc rgb \"#404040\"\n";
  s += "set tics nomirror out scale 0.6 textcolor rgb \"#202020\"\n";
  s += "set grid xtics ytics back lw 1 lc rgb \"#e6e6e6\" dt 1\n";
  s += "set key box lc rgb \"#b0b0b0\" opaque samplen 2.5 spacing 1.1 width 1\n";
  s += "set format x \"%g\"\nset format y \"%g\"\n";
  s += "set datafile separator whitespace\n";
  return s;
}

std::string title_font() {
  return format("%s,%d", kFont, kTitleFontSize_pt);
}
std::string mono_font() {
  return format("%s,%d", kMonoFont, kFontSize_pt);
}

std::string axis_label(const std::string& name, const std::string& unit) {
  return name + " (" + unit + ")";
}

std::string transition_shading(const std::vector<TimeInterval>& bands) {
  std::string s;
  int tag = 1000;  // object tags reserved for the shading
  for (const TimeInterval& band : bands) {
    s += format(
        "set object %d rect from first %.9g, graph 0 to first %.9g, graph 1 behind "
        "fc rgb \"%s\" fs solid 1.0 noborder\n",
        tag++, band.begin_s, band.end_s, kShadingColour);
  }
  return s;
}

std::string transition_key_entry(const std::vector<TimeInterval>& bands) {
  if (bands.empty()) return "";
  return format("keyentry with boxes fs solid 1.0 noborder fc rgb \"%s\" title \"transition\"",
                kShadingColour);
}

std::string clear_shading() {
  return "unset object\n";
}

std::string thickness_palette() {
  return "set palette defined (0 \"#440154\", 0.125 \"#472d7b\", 0.25 \"#3b528b\", "
         "0.375 \"#2c728e\", 0.5 \"#21918c\", 0.625 \"#28ae80\", 0.75 \"#5ec962\", "
         "0.875 \"#addc30\", 1 \"#fde725\")\nset palette maxcolors 0\n";
}

std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') out += '\'';
    if (c == '\n') {
      out += ' ';
      continue;
    }
    out += c;
  }
  out += '\'';
  return out;
}

std::string double_quoted_lines(const std::vector<std::string>& lines) {
  std::string out = "\"";
  for (size_t i = 0; i < lines.size(); ++i) {
    if (i > 0) out += "\\n";
    for (char c : lines[i]) {
      if (c == '\\' || c == '"') out += '\\';
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace depotwin::plots::style
