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

// A map of z over a grid (a stability map): z[i * y.size() + j] at (x[i], y[j]), drawn as an image
// with a colour bar clipped to [z_low, z_high]; points whose z is not finite are left blank.
struct GridMap {
  std::string title, xlabel, ylabel, zlabel;
  std::vector<double> x, y, z;
  double z_low = 0.0, z_high = 1.0;
};
void write_map_svg(const std::filesystem::path& file, const GridMap& map);

// Writes `file` (SVG; "-": stdout) through write_output; throws OutputError when gnuplot is missing
// or fails. No text of a panel reaches gnuplot's command language unfiltered (docs/security.md).
void write_svg(const std::filesystem::path& file, const std::vector<Panel>& panels);

}  // namespace varia::host
