#include "plot.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace varia::host {

namespace {

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// One inline data block per series ($d<panel>_<series>), so no temporary files are needed.
std::string data_blocks(const std::vector<Panel>& panels) {
  std::string script;
  for (std::size_t p = 0; p < panels.size(); ++p)
    for (std::size_t s = 0; s < panels[p].series.size(); ++s) {
      const Series& series = panels[p].series[s];
      script += fmt::format("$d{}_{} << EOD\n", p, s);
      for (std::size_t i = 0; i < series.x.size() && i < series.y.size(); ++i) {
        const bool drawable = std::isfinite(series.x[i]) && std::isfinite(series.y[i]) &&
                              (!panels[p].logx || series.x[i] > 0) &&
                              (!panels[p].logy || series.y[i] > 0);
        if (drawable) script += fmt::format("{:.17g} {:.17g}\n", series.x[i], series.y[i]);
      }
      script += "EOD\n";
    }
  return script;
}

std::string panel_commands(const Panel& panel, std::size_t index) {
  std::string script = fmt::format("set title {}\nset xlabel {}\nset ylabel {}\n",
                                   quoted(panel.title), quoted(panel.xlabel), quoted(panel.ylabel));
  script += panel.logx ? "set logscale x\nset format x \"10^{%L}\"\n" : "unset logscale x\nset format x \"% h\"\n";
  script += panel.logy ? "set logscale y\nset format y \"10^{%L}\"\n" : "unset logscale y\nset format y \"% h\"\n";
  script += "plot ";
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    const Series& series = panel.series[s];
    script += fmt::format("{}$d{}_{} using 1:2 with {} title {}", s ? ", " : "", index, s,
                          series.dashed ? "lines dashtype 2 lw 1.5" : "linespoints pt 7 ps 0.5 lw 1.5",
                          quoted(series.title));
  }
  return script + "\n";
}

}  // namespace

void write_svg(const std::filesystem::path& file, const std::vector<Panel>& panels) {
  std::string script = data_blocks(panels);
  script += fmt::format(
      "set terminal svg size {},{} dynamic enhanced font 'sans,11' background rgb 'white'\n"
      "set output {}\nset grid\nset key top right box opaque\nset multiplot layout 1,{}\n",
      520 * panels.size(), 420, quoted(file.string()), panels.size());
  for (std::size_t p = 0; p < panels.size(); ++p) script += panel_commands(panels[p], p);
  script += "unset multiplot\nset output\n";
  FILE* gnuplot = popen("gnuplot 2>&1", "w");
  if (gnuplot == nullptr) throw std::runtime_error("cannot start gnuplot");
  std::fwrite(script.data(), 1, script.size(), gnuplot);
  if (pclose(gnuplot) != 0)
    throw std::runtime_error("gnuplot failed to write " + file.string() +
                             " (is the gnuplot-nox package installed?)");
}

}  // namespace varia::host
