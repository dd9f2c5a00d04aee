// End-to-end tests of the varia program (spec: "Commands", "Exit codes", "Outputs"): every
// example scene runs and writes the spec's CSV header and run record (the bad scenes are in
// bad_scenes.cpp, the bad plugins in fault_plugins.cpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "host/support.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

// Spec "Outputs": t, q0.., p0.., then energy; momentum0..; orthogonality; constraint;
// constraint_velocity; megno; lyapunov as asked.
std::vector<std::string> expected_header(const json& scene, int momentum_columns) {
  std::vector<std::string> columns{"t"};
  const auto& initial = scene["initial"];
  for (std::size_t i = 0; i < initial["q"].size(); ++i) columns.push_back("q" + std::to_string(i));
  const auto& p = initial.contains("p") ? initial["p"] : initial["v"];
  for (std::size_t i = 0; i < p.size(); ++i) columns.push_back("p" + std::to_string(i));
  const auto observe = scene.value("observe", json::array());
  const auto asked = [&](const char* name) { return std::find(observe.begin(), observe.end(), name) != observe.end(); };
  if (asked("energy")) columns.emplace_back("energy");
  for (int i = 0; i < momentum_columns; ++i) columns.push_back("momentum" + std::to_string(i));
  for (const char* name : {"orthogonality", "constraint", "constraint_velocity", "megno", "lyapunov"})
    if (asked(name)) columns.emplace_back(name);
  return columns;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  return cells;
}

int count_momentum_columns(const std::vector<std::string>& header) {
  return static_cast<int>(std::count_if(header.begin(), header.end(),
                                        [](const std::string& c) { return c.rfind("momentum", 0) == 0; }));
}

long rows_expected(long steps, long every) { return steps / every + 1 + (steps % every != 0 ? 1 : 0); }

void check_run_record(const json& scene, const json& record, long rows) {
  const double step = scene["step"];
  const long steps = scene.contains("steps") ? scene["steps"].get<long>()
                                             : std::lround(scene["t_end"].get<double>() / step);
  CHECK(record["steps"] == steps);
  CHECK(record["final"]["t"].get<double>() == doctest::Approx(steps * step));
  for (const char* key : {"wall_seconds", "newton_iterations", "evaluations", "final", "plugins_loaded"})
    CHECK_MESSAGE(record.contains(key), key);
  const auto observe = scene.value("observe", json::array());
  const bool energy = std::find(observe.begin(), observe.end(), "energy") != observe.end();
  CHECK(record.contains("energy_error_max") == energy);
  for (const char* name : {"constraint", "constraint_velocity"}) {
    const bool asked = std::find(observe.begin(), observe.end(), name) != observe.end();
    CHECK(record.contains(std::string(name) + "_error_max") == asked);
  }
  for (const char* name : {"megno", "lyapunov"}) {
    const bool asked = std::find(observe.begin(), observe.end(), name) != observe.end();
    CHECK(record.contains(std::string(name) + "_final") == asked);
  }
  CHECK_FALSE(record.contains("failure"));
  const auto& loaded = record["plugins_loaded"];
  CHECK(std::find(loaded.begin(), loaded.end(), scene["system"]["lagrangian"]["type"]) != loaded.end());
  const long every = scene.contains("output") ? scene["output"].value("every", 1L) : 1L;
  CHECK(rows == rows_expected(steps, every));
}

TEST_CASE("every example scene runs, writing the spec's CSV header and run record") {
  for (const auto& file : files_in(kSourceDir / "scenes", ".json")) {
    CAPTURE(file);
    TempDir dir;
    const auto outcome = run_varia("run '" + file.string() + "' --quiet --out '" + (dir / "t.csv").string() +
                                   "' --summary '" + (dir / "r.json").string() + "'");
    CAPTURE(outcome.err);
    REQUIRE(outcome.code == 0);
    CHECK(outcome.err.empty());
    const json scene = json::parse(read_file(file));
    const auto lines = lines_of(read_file(dir / "t.csv"));
    REQUIRE(lines.size() >= 2);
    const auto header = split(lines[0]);
    CHECK(header == expected_header(scene, count_momentum_columns(header)));
    CHECK(split(lines.back()).size() == header.size());
    check_run_record(scene, json::parse(read_file(dir / "r.json")), static_cast<long>(lines.size()) - 1);
  }
}

TEST_CASE("every example scene validates, in scenes/ and its directories (scenes/bad/ is refused by design)") {
  std::vector<fs::path> scenes = files_in(kSourceDir / "scenes", ".json");
  for (const auto& entry : fs::directory_iterator(kSourceDir / "scenes"))
    if (entry.is_directory() && entry.path().filename() != "bad")
      for (const auto& file : files_in(entry.path(), ".json")) scenes.push_back(file);
  CHECK(scenes.size() > 40);
  for (const auto& file : scenes) {
    CAPTURE(file);
    const auto outcome = run_varia("validate '" + file.string() + "'");
    CAPTURE(outcome.err);
    CHECK(outcome.code == 0);
  }
}

struct CommandCase {
  const char* arguments;
  int code;
  const char* output;  // expected in stdout (code 0) or in the one stderr line
};

TEST_CASE("command line: help and version exit 0, bad flags and bad arguments exit 2") {
  const CommandCase cases[] = {
      {"--help", 0, "Subcommands:"},
      {"run --help", 0, "--summary"},
      {"ld --help", 0, "--q0"},
      {"--version", 0, "0."},
      {"", 2, "A subcommand is required"},
      {"run", 2, "SCENE is required"},
      {"run scenes/default.json --bogus", 2, "--bogus"},
      {"frobnicate", 2, "unknown command 'frobnicate'; the commands are: plugins, run"},
      {"run no/such/scene.json", 2, "no/such/scene.json: cannot be read"},
      {"ld scenes/default.json --q0 1.3,2 --q1 1.2 --h 0.1", 2, "--q0: expected 1 comma-separated"},
      {"ld scenes/default.json --q0 1.3 --q1 abc --h 0.1", 2, "--q1: expected 1"},
      {"ld scenes/default.json --q0 1.3 --q1 1.2 --h -1", 2, "--h: expected a number > 0"},
  };
  for (const auto& c : cases) {
    const std::string arguments = c.arguments;
    CAPTURE(arguments);
    const auto outcome = run_varia(c.arguments);
    CAPTURE(outcome.err);
    CHECK(outcome.code == c.code);
    if (c.code == 0)
      CHECK(contains(outcome.out, c.output));
    else
      check_one_error_line(outcome, c.output);
  }
}

TEST_CASE("ld --json prints exactly Ld, D1 and D2") {
  const auto outcome = run_varia("ld scenes/kepler-galerkin.json --q0 0.5,0 --q1 0.5,0.017 --h 0.01 --json");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const json result = json::parse(outcome.out);
  CHECK(result.size() == 3);
  CHECK(result["Ld"].is_number());
  CHECK(result["D1"].size() == 2);
  CHECK(result["D2"].size() == 2);
}

TEST_CASE("plugins --json lists the bundled plugins, a junk file in --plugin-path is refused, the rest works") {
  TempDir dir;
  write_file(dir / "junk.so", "not a library\n");
  const auto listing = run_varia("plugins --json --plugin-path '" + dir.path().string() + "'");
  REQUIRE(listing.code == 0);
  const json plugins = json::parse(listing.out);
  const bool has_pendulum = std::any_of(plugins.begin(), plugins.end(), [](const json& p) {
    return p["kind"] == "lagrangian" && p["type"] == "pendulum";
  });
  CHECK(has_pendulum);
  CHECK(contains(listing.err, "junk.so"));
  const auto table = run_varia("plugins --plugin-path '" + dir.path().string() + "'");
  CHECK(table.code == 0);
  CHECK(contains(table.out, "refused:"));
  CHECK(run_varia("run scenes/default.json --quiet --plugin-path '" + dir.path().string() + "'").code == 0);
}

TEST_CASE("plugins flags a type that two files provide, naming both, in the table and on stderr with --json") {
  TempDir dir;
  fs::copy_file(kPluginDir / "lagrangian_pendulum.so", dir / "another-pendulum.so");
  const std::string flag = " --plugin-path '" + dir.path().string() + "'";
  // The bundled file (the directory of the program under test), then the copy.
  const std::string named = "lagrangian 'pendulum' is provided by 2 files: ";
  const std::string files = "/lagrangian_pendulum.so, " + (dir / "another-pendulum.so").string() +
                            "; a scene naming it is refused (exit 3)\n";
  const auto table = run_varia("plugins" + flag);
  CHECK(table.code == 0);
  CHECK(contains(table.out, "\nduplicates:\n  " + named));
  CHECK(contains(table.out, files));
  const auto listing = run_varia("plugins --json" + flag);
  CHECK(listing.code == 0);
  CHECK(contains(listing.err, "varia: duplicate: " + named));
  CHECK(contains(listing.err, files));
  CHECK(json::parse(listing.out).is_array());
  CHECK(run_varia("run scenes/default.json --quiet" + flag).code == 3);
}

// The points gnuplot drew (each a use of the point symbol of `pt 7`, the legend's samples included).
// The vertices (M and L commands) of each curve gnuplot drew (a stroked path of 10 or more), in
// the order drawn; each path starts with its legend's sample line (2 vertices).
std::vector<long> curve_vertices(const std::string& svg) {
  std::vector<long> curves;
  const std::string start = "<path stroke='rgb";
  for (auto at = svg.find(start); at != std::string::npos; at = svg.find(start, at + 1)) {
    const auto d = svg.find("d='", at), end = svg.find('\'', d + 3);
    const std::string path = svg.substr(d + 3, end - d - 3);
    const long vertices = std::count(path.begin(), path.end(), 'M') + std::count(path.begin(), path.end(), 'L');
    if (vertices >= 10) curves.push_back(vertices);
  }
  return curves;
}

// Issue #43 item 14: on 5a2c708 the plot had two panels (q(t), E - E0 on a linear scale), a marker
// at every point (1000s of them: a solid block) and the legend inside the data.
TEST_CASE("run --plot draws q(t), the phase portrait and |E - E0| on a log scale, each curve bounded whatever the "
          "number of rows") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "oscillator-galerkin.json"));
  scene.erase("t_end");
  scene["step"] = 0.001;
  scene["steps"] = 100000;  // 100001 rows, about 16 periods
  scene.erase("output");
  write_file(dir / "s.json", scene.dump());
  const auto outcome =
      run_varia("run '" + (dir / "s.json").string() + "' --quiet --plot '" + (dir / "p.svg").string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  // q0 and |E - E0| each in at most 1000 stretches (of 101 rows) drawn as their two extremes (or
  // one where they are the same row; q0 moves in every stretch), the phase portrait every 26th row
  // (at most 4000), lines without markers, the legend below the panels.
  const std::string svg = read_file(dir / "p.svg");
  const auto curves = curve_vertices(svg);
  REQUIRE(curves.size() == 3);
  CHECK(curves[0] >= 1000 + 2);
  CHECK(curves[0] <= 2 * 1000 + 2 + 2);
  CHECK(curves[1] >= 3000);
  CHECK(curves[1] <= 4000 + 2 + 2);
  CHECK(curves[2] <= 2 * 1000 + 2 + 2);
  for (const char* title : {"<title>q0</title>", "<title>(q0, p0)</title>", "<title>|E - E0|</title>",
                            "phase portrait"})
    CHECK(contains(svg, title));
  CHECK_FALSE(contains(svg, "'#gpPt6'"));  // no markers on a long curve
}

TEST_CASE("run --plot on a Lie group draws the natural-chart coordinates of the start, not matrix entries") {
  TempDir dir;
  const auto outcome = run_varia("run '" + (kSourceDir / "scenes" / "paper" / "rigid-body-lgvi.json").string() +
                                 "' --quiet --plot '" + (dir / "p.svg").string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const std::string svg = read_file(dir / "p.svg");
  for (const char* title : {"<title>xi0</title>", "<title>xi2</title>", "<title>(xi1, p1)</title>"})
    CHECK(contains(svg, title));
  CHECK_FALSE(contains(svg, "<title>q0</title>"));
}

TEST_CASE("a solve that does not converge exits 4, the rows written stay whole, the record names the failure") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["method"]["solver"] = {{"tolerance", 1e-300}, {"max_iterations", 1}};
  write_file(dir / "scene.json", scene.dump());
  const auto outcome = run_varia("run '" + (dir / "scene.json").string() + "' --out '" + (dir / "t.csv").string() +
                                 "' --summary '" + (dir / "r.json").string() + "'");
  CHECK(outcome.code == 4);
  check_one_error_line(outcome, "step 1 (from t = 0) failed");
  CHECK(contains(outcome.err, "residual"));
  const auto lines = lines_of(read_file(dir / "t.csv"));
  REQUIRE(lines.size() >= 2);
  for (const auto& line : lines) CHECK(split(line).size() == 4);
  const json record = json::parse(read_file(dir / "r.json"));
  CHECK(record["failure"]["step"] == 1);
  CHECK(record["failure"].contains("residual"));
}

TEST_CASE("output.every writes every k-th step, step 0 and the last step") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene.erase("t_end");
  scene["steps"] = 10;
  scene["output"] = {{"every", 4}};
  write_file(dir / "scene.json", scene.dump());
  const auto outcome = run_varia("run '" + (dir / "scene.json").string() + "' --quiet --out '" +
                                 (dir / "t.csv").string() + "'");
  REQUIRE(outcome.code == 0);
  const auto lines = lines_of(read_file(dir / "t.csv"));
  std::vector<std::string> times;
  for (std::size_t i = 1; i < lines.size(); ++i) times.push_back(split(lines[i])[0]);
  CHECK(times == std::vector<std::string>{"0", "0.4", "0.8", "1"});
}

// A step too large for the motion: the pendulum of default.json at h = 0.5 departs from its energy by
// several percent, and says so; with departure_warning 0.5 (or 0) it does not.
TEST_CASE("a run whose energy departs from its start by more than departure_warning warns on stderr and in the record") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "pendulum-galerkin-s1.json"));
  scene["step"] = 0.8;
  write_file(dir / "coarse.json", scene.dump());
  const auto outcome = run_varia("run '" + (dir / "coarse.json").string() + "' --quiet --summary '" +
                                 (dir / "r.json").string() + "'");
  CAPTURE(outcome.err);
  CHECK(outcome.code == 0);
  CHECK(contains(outcome.err, "varia: warning: the energy departed from its start"));
  const json record = json::parse(read_file(dir / "r.json"));
  REQUIRE(record.contains("warnings"));
  CHECK(record["warnings"].size() == 1);
  for (const double fraction : {0.5, 0.0}) {
    scene["departure_warning"] = fraction;
    write_file(dir / "tolerant.json", scene.dump());
    const auto quiet = run_varia("run '" + (dir / "tolerant.json").string() + "' --quiet");
    CHECK(quiet.code == 0);
    CHECK(quiet.err.empty());
  }
  const auto fine = run_varia("run scenes/pendulum-galerkin-s1.json --quiet");
  CHECK(fine.err.empty());
}

// Issue #42 item 3: --set POINTER=JSON on every command that reads a scene, applied before the
// scene is checked.
TEST_CASE("--set replaces values at JSON pointers before the scene is checked, and a bad one exits 2 naming --set") {
  TempDir dir;
  const auto run = run_varia("run scenes/default.json --quiet --set /step=0.05 --set '/initial/q=[0.5]' --out '" +
                             (dir / "t.csv").string() + "'");
  REQUIRE(run.code == 0);
  const auto lines = lines_of(read_file(dir / "t.csv"));
  CHECK(lines.size() == 402);  // t_end 20 at h = 0.05: 400 steps, 401 rows and the header
  CHECK(lines[1].rfind("0,0.5,", 0) == 0);
  CHECK(run_varia("validate scenes/default.json --set /step=-1").err.find("/step: expected a number > 0") !=
        std::string::npos);
  for (const char* bad : {"--set step=1", "--set /step=abc", "--set '/a~2=1'"}) {
    CAPTURE(bad);
    const auto refused = run_varia(std::string("validate scenes/default.json ") + bad);
    CHECK(refused.code == 2);
    CHECK(contains(refused.err, "--set"));
  }
  CHECK(run_varia("verify scenes/default.json --set /step=0.2 --h 0.4,0.2,0.1,0.05").code == 0);
  CHECK(run_varia("cost scenes/default.json --set /step=0.2 --quiet --h 0.2,0.1,0.05,0.025 --out '" + dir.path().string() + "'").code == 0);
}


TEST_CASE("on a terminal verify shows its runs' progress, with the time left, and --quiet silences it, off a "
          "terminal there is no progress line") {
  // script(1) gives the command a terminal and copies what it shows to stdout.
  const std::string verify = varia() + " verify scenes/multibody/spherical-pendulum-rod-rk4.json";
  const auto shown = run_shell("script -qec \"" + verify + "\" /dev/null");
  REQUIRE(shown.code == 0);
  CHECK(contains(shown.out, "varia: the energy and momentum run at h = 0.01: step "));
  CHECK(contains(shown.out, "of 4000"));
  CHECK(contains(shown.out, "s left"));
  CHECK(contains(shown.out, "varia: an order run at h = "));
  const auto quiet = run_shell("script -qec \"" + verify + " --quiet\" /dev/null");
  REQUIRE(quiet.code == 0);
  CHECK(!contains(quiet.out, "s left"));
  CHECK(contains(quiet.out, "energy_bounded"));  // the table is still printed
  const auto piped = run_varia("verify scenes/multibody/spherical-pendulum-rod-rk4.json");
  REQUIRE(piped.code == 0);
  CHECK(!contains(piped.err, "s left"));
}

}  // namespace
}  // namespace varia::test
