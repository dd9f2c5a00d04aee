#include "plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "errors.hpp"
#include "output.hpp"

extern char** environ;

namespace varia::host {

namespace {

// Text shown in a plot (titles, labels, legends: they may come from scene names and file names)
// reduced to a safe alphabet and single-quoted: gnuplot expands backquotes and macros in double
// quotes and ends a command at a newline, but in single quotes only the quote itself is special,
// and that is not in the alphabet. Anything else becomes '_'; "noenhanced" (by the caller) keeps
// '_' and '^' from being read as sub- and superscripts (docs/security.md, "No code from data").
std::string label(const std::string& text) {
  constexpr std::size_t kMaxLength = 80;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMaxLength; ++i) {
    const char c = text[i];
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::strchr(" .,:;()+-=*/^_[]|", c) != nullptr;
    out += safe && c != '\0' ? c : '_';
  }
  return out + "'";
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

// Markers only where they can be told apart: a curve of many points is a line (10^4 markers are a
// solid block).
constexpr std::size_t kMarkedPoints = 60;
const char* style(const Series& series) {
  if (series.dashed) return "lines dashtype 2 lw 1.5";
  return series.x.size() <= kMarkedPoints ? "linespoints pt 7 ps 0.5 lw 1.5" : "lines lw 1.2";
}

std::string panel_commands(const Panel& panel, std::size_t index) {
  std::string script = fmt::format("set title {} noenhanced\nset xlabel {} noenhanced\nset ylabel {} noenhanced\n",
                                   label(panel.title), label(panel.xlabel), label(panel.ylabel));
  script += panel.logx ? "set logscale x\nset format x \"10^{%L}\"\n" : "unset logscale x\nset format x \"% h\"\n";
  script += panel.logy ? "set logscale y\nset format y \"10^{%L}\"\n" : "unset logscale y\nset format y \"% h\"\n";
  script += "plot ";
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    const Series& series = panel.series[s];
    script += fmt::format("{}$d{}_{} using 1:2 with {} title {} noenhanced", s ? ", " : "", index, s, style(series),
                          label(series.title));
  }
  return script + "\n";
}

// An anonymous temporary file, closed on destruction.
struct TempFile {
  std::FILE* file = std::tmpfile();
  ~TempFile() {
    if (file != nullptr) std::fclose(file);
  }
  int fd() const { return ::fileno(file); }
  std::string text() const {
    std::string all;
    std::rewind(file);
    char chunk[1 << 16];
    for (std::size_t n; (n = std::fread(chunk, 1, sizeof chunk, file)) > 0;) all.append(chunk, n);
    return all;
  }
};

// Runs gnuplot (no shell, no init files: -d) on `script`; returns what it wrote to stdout (the
// SVG). Its diagnostics are kept apart: they reach the message when it fails, never stdout.
std::string run_gnuplot(const std::string& script) {
  TempFile input, output, diagnostics;
  if (input.file == nullptr || output.file == nullptr || diagnostics.file == nullptr ||
      std::fwrite(script.data(), 1, script.size(), input.file) != script.size() || std::fflush(input.file) != 0 ||
      ::lseek(input.fd(), 0, SEEK_SET) != 0)
    throw OutputError(fmt::format("the plot's temporary files cannot be written: {}", std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, input.fd(), STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, output.fd(), STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, diagnostics.fd(), STDERR_FILENO);
  char name[] = "gnuplot", defaults[] = "-d";
  char* argv[] = {name, defaults, nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, name, &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0)
    throw OutputError(fmt::format("the plot: cannot start gnuplot: {} (is the gnuplot-nox package installed?)",
                                         std::strerror(spawned)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  std::string svg = output.text();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || svg.empty()) {
    std::string why = diagnostics.text();
    for (char& c : why)
      if (c == '\n' || c == '\r') c = ' ';
    throw OutputError(fmt::format("the plot: gnuplot failed: {}", why.substr(0, 300)));
  }
  return svg;
}

}  // namespace

void write_svg(const std::filesystem::path& file, const std::vector<Panel>& panels) {
  std::string script = data_blocks(panels);
  script += fmt::format(
      "set terminal svg size {},{} dynamic enhanced font 'sans,11' background rgb 'white'\n"
      "set grid\nset key below box\nset multiplot layout 1,{}\n",
      520 * panels.size(), 460, panels.size());
  for (std::size_t p = 0; p < panels.size(); ++p) script += panel_commands(panels[p], p);
  script += "unset multiplot\n";
  write_output(file, run_gnuplot(script), "the plot");
}

void write_map_svg(const std::filesystem::path& file, const GridMap& map) {
  std::string script = "$map << EOD\n";
  for (std::size_t i = 0; i < map.x.size(); ++i) {
    for (std::size_t j = 0; j < map.y.size(); ++j) {
      const double z = map.z[i * map.y.size() + j];
      script += std::isfinite(z) ? fmt::format("{:.17g} {:.17g} {:.17g}\n", map.x[i], map.y[j], z)
                                 : fmt::format("{:.17g} {:.17g} NaN\n", map.x[i], map.y[j]);
    }
    script += "\n";
  }
  script += "EOD\n";
  script += fmt::format(
      "set terminal svg size 640,560 dynamic enhanced font 'sans,11' background rgb 'white'\n"
      "set datafile missing 'NaN'\nset title {} noenhanced\nset xlabel {} noenhanced\nset ylabel {} noenhanced\n"
      "set cblabel {} noenhanced\nset cbrange [{:.17g}:{:.17g}]\nset palette rgbformulae 30,31,32\n"
      "set size ratio -1\nset autoscale fix\nplot $map using 1:2:3 with image notitle\n",
      label(map.title), label(map.xlabel), label(map.ylabel), label(map.zlabel), map.z_low, map.z_high);
  write_output(file, run_gnuplot(script), "the plot");
}

}  // namespace varia::host
