// Plots rendered by gnuplot (a Debian package) into SVG: panels side by side, each with labelled
// axes, a legend and optional log scales. Used by `run --plot` and `cost`.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace varia::host {

struct Series {
  std::string title;
  std::vector<double> x, y;
  bool dashed = false;  // reference lines (e.g. a predicted slope)
};

struct Panel {
  std::string title, xlabel, ylabel;
  bool logx = false, logy = false;
  std::vector<Series> series;
};

// Writes `file` (SVG; "-": stdout) through write_output; throws OutputError when gnuplot is missing
// or fails. No text of a panel reaches gnuplot's command language unfiltered (docs/security.md).
void write_svg(const std::filesystem::path& file, const std::vector<Panel>& panels);

}  // namespace varia::host
