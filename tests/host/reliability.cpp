// Reliability and security of the host (docs/security.md): no code runs from data, no output is
// lost silently, interrupts and collisions leave whole files. Each case reproduces a defect of the
// probe that issue 20 reports.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>

#include <chrono>
#include <random>
#include <tuple>
#include <nlohmann/json.hpp>
#include <thread>

#include "host/support.hpp"
#include "json_schema.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

// A cheap scene: the harmonic oscillator (exact solution) for 2 time units.
json oscillator_scene() {
  return json::parse(R"({
    "system": {"manifold": {"type": "Rn", "dim": 1},
               "lagrangian": {"type": "harmonic-oscillator", "mass": 1, "stiffness": 1}},
    "method": {"construction": "galerkin", "degree": 1, "quadrature": {"type": "trapezoid"}},
    "initial": {"q": [1.0], "p": [0.0]}, "step": 0.1, "t_end": 2, "observe": ["energy"]})");
}

// Every line ends with a newline and has as many cells as the header.
void check_whole_rows(const std::string& csv) {
  REQUIRE_FALSE(csv.empty());
  CHECK(csv.back() == '\n');
  const auto lines = lines_of(csv);
  const auto cells = [](const std::string& line) { return std::count(line.begin(), line.end(), ',') + 1; };
  for (const auto& line : lines) {
    CAPTURE(line);
    REQUIRE(cells(line) == cells(lines.front()));
  }
}

// ---- 1: no code from data ------------------------------------------------------------------------

TEST_CASE("hostile scene names, scene file names and output names run no command through gnuplot") {
  struct Case {
    const char* what;
    std::string name;  // the scene's "name" ("": none)
    std::string file;  // the scene's file name
    std::string plot;  // run --plot FILE
  };
  const std::vector<Case> cases{
      {"backquotes in the name", "a`touch MARK`b", "s.json", "p.svg"},
      {"a newline and system() in the name", "x\"\nsystem('touch MARK')\n\"y", "s.json", "p.svg"},
      {"a quote, newline and system() in the name", "x'\nsystem(\"touch MARK\")\n'y", "s.json", "p.svg"},
      {"a macro in the name", "@x; system 'touch MARK'", "s.json", "p.svg"},
      {"backquotes in the file name", "", "x`touch MARK`.json", "p.svg"},
      {"backquotes in the plot's file name", "", "s.json", "p`touch MARK`.svg"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.what);
    TempDir dir;
    // The command names its target through the environment, so that no '/' enters a file name.
    const fs::path mark = dir / "MARK";
    const auto replace = [](std::string text) {
      for (std::size_t at = 0; (at = text.find("MARK", at)) != std::string::npos; at += 11)
        text.replace(at, 4, "$VARIA_MARK");
      return text;
    };
    const std::string environment = "VARIA_MARK=" + quoted(mark) + " ";
    json scene = oscillator_scene();
    if (!c.name.empty()) scene["name"] = replace(c.name);
    const fs::path file = dir / replace(c.file);
    write_file(file, scene.dump());
    const auto cost =
        run_shell(environment + varia() + " cost " + quoted(file) + " --h 0.1,0.05 --quiet --out " + quoted(dir / "cost"));
    CAPTURE(cost.err);
    CHECK(cost.code == 0);
    CHECK(cost.out.empty());
    CHECK(fs::file_size(dir / "cost" / "cost.svg") > 0);
    const fs::path plot = dir / replace(c.plot);
    const auto run = run_shell(environment + varia() + " run " + quoted(file) + " --quiet --plot " + quoted(plot));
    CAPTURE(run.err);
    CHECK(run.code == 0);
    CHECK(fs::file_size(plot) > 0);
    CHECK_FALSE(fs::exists(mark));
  }
}

// ---- 2: every write checked -----------------------------------------------------------------------

TEST_CASE("a failed write ends the command with one message and exit 2, for every output") {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"run scenes/default.json --quiet --out /dev/full", "--out /dev/full"},
      {"run scenes/default.json --quiet --summary /dev/full", "--summary /dev/full"},
      {"run scenes/default.json --quiet --plot /dev/full", "/dev/full"},
      {"run scenes/default.json --quiet --out - > /dev/full", "--out"},
      {"run scenes/default.json > /dev/full", "stdout"},
      {"plugins --json > /dev/full", "stdout"},
      {"ld scenes/default.json --q0 1 --q1 1.1 --h 0.1 --json > /dev/full", "stdout"},
      {"validate scenes/default.json > /dev/full", "stdout"},
  };
  for (const auto& [arguments, named] : cases) {
    CAPTURE(arguments);
    const auto outcome = run_shell(varia() + " " + arguments);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, named);
  }
}

TEST_CASE("on a full disk the trajectory ends with a whole row and the run fails with exit 2") {
  // A file size limit (ulimit -f, SIGXFSZ ignored) makes the file system refuse writes past it,
  // as a full disk does: the limit falls inside a row.
  for (const char* blocks : {"8", "19"}) {
    CAPTURE(blocks);
    TempDir dir;
    const auto outcome = run_shell(std::string("trap '' XFSZ; ulimit -f ") + blocks + "; " + varia() +
                                   " run scenes/default.json --quiet --out " + quoted(dir / "t.csv") + " --summary " +
                                   quoted(dir / "r.json"));
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, "t.csv");
    check_whole_rows(read_file(dir / "t.csv"));
    CHECK_FALSE(fs::exists(dir / "r.json"));  // no record claiming every step
  }
}

// ---- 11: closed or full stderr ---------------------------------------------------------------------

TEST_CASE("a closed or full stderr (or stdout) keeps the exit code") {
  const std::vector<std::pair<std::string, int>> cases{
      {"run /nonexistent.json 2>&-", 2},
      {"run /nonexistent.json 2>/dev/full", 2},
      {"run scenes/bad/mass-zero.json 2>&-", 2},
      {"run scenes/default.json --quiet --out - >&-", 2},
      {"run scenes/default.json 2>&- >&-", 2},
  };
  for (const auto& [arguments, code] : cases) {
    CAPTURE(arguments);
    CHECK(run_shell(varia() + " " + arguments).code == code);
  }
}

// ---- 7: interrupts -----------------------------------------------------------------------------------

// Starts varia with `arguments` (no shell), stdout and stderr to files in `dir`.
pid_t start_varia(const std::vector<std::string>& arguments, const TempDir& dir) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open((dir / "stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const int err = ::open((dir / "stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(out, 1);
    ::dup2(err, 2);
    if (::chdir(kSourceDir.c_str()) != 0) ::_exit(127);
    std::vector<char*> argv;
    std::string program = varia_program().string();
    argv.push_back(program.data());
    std::vector<std::string> copies = arguments;
    for (auto& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

TEST_CASE("SIGINT, SIGTERM and SIGHUP end a run with whole rows, a run record noting it, exit 130, 143 and 129") {
  for (const auto& [signal, code, name] :
       {std::tuple{SIGINT, 130, "SIGINT"}, std::tuple{SIGTERM, 143, "SIGTERM"}, std::tuple{SIGHUP, 129, "SIGHUP"}}) {
    CAPTURE(signal);
    TempDir dir;
    json scene = oscillator_scene();
    scene["t_end"] = 1e6;  // ten million steps: far longer than the test waits
    write_file(dir / "long.json", scene.dump());
    const pid_t pid = start_varia({"run", (dir / "long.json").string(), "--quiet", "--out",
                                   (dir / "t.csv").string(), "--summary", (dir / "r.json").string()},
                                  dir);
    REQUIRE(pid > 0);
    const auto written = [&] {  // bytes of the trajectory so far (0 before the file exists)
      std::error_code ec;
      const auto size = fs::file_size(dir / "t.csv", ec);
      return ec ? 0 : size;
    };
    for (int i = 0; i < 2000 && written() < (1 << 18); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == code);
    const auto csv = read_file(dir / "t.csv");
    check_whole_rows(csv);
    REQUIRE(fs::exists(dir / "r.json"));
    const json record = json::parse(read_file(dir / "r.json"));
    REQUIRE(record.contains("interrupted"));
    CHECK(record["interrupted"]["signal"] == name);
    CHECK(record["steps"].get<long>() + 2 == static_cast<long>(lines_of(csv).size()));  // header, step 0
    CHECK(contains(read_file(dir / "stderr"), "interrupted"));
  }
}

// Issue 43, item 11: verify looked at the flag only when it had finished, so `timeout N varia verify`
// ran to the end of every measurement.
TEST_CASE("SIGTERM ends verify between its measurements, exit 143, no --json written") {
  TempDir dir;
  // A verify of many seconds, each of its measurements far shorter.
  const pid_t pid =
      start_varia({"verify", "scenes/multibody/rod-chain-100.json", "--json", (dir / "v.json").string()}, dir);
  REQUIRE(pid > 0);
  std::this_thread::sleep_for(std::chrono::seconds(2));  // loaded and measuring
  const auto signalled = std::chrono::steady_clock::now();
  ::kill(pid, SIGTERM);
  int status = 0;
  pid_t ended = 0;
  while ((ended = ::waitpid(pid, &status, WNOHANG)) == 0 &&
         std::chrono::steady_clock::now() - signalled < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (ended == 0) {  // still measuring: end it, and fail
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  REQUIRE(ended == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 143);
  check_one_error_line(Outcome{143, "", read_file(dir / "stderr")}, "interrupted by SIGTERM before verify's ");
  CHECK_FALSE(fs::exists(dir / "v.json"));
}

// ---- 12: collisions and atomic records -----------------------------------------------------------

TEST_CASE("an output that is an input or another output is refused, and the files are untouched") {
  TempDir dir;
  const fs::path scene = dir / "s.json", other = dir / "x";
  write_file(scene, oscillator_scene().dump());
  write_file(other, "keep");
  fs::create_symlink(other, dir / "link");
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--out " + quoted(other) + " --summary " + quoted(other), "--summary"},
      {"--out " + quoted(scene), "scene"},
      {"--summary " + quoted(scene), "scene"},
      {"--plot " + quoted(other) + " --summary " + quoted(dir / "link"), "--plot"},
      {"--out - --summary -", "--summary"},
  };
  for (const auto& [flags, named] : cases) {
    CAPTURE(flags);
    const auto outcome = run_varia("run " + quoted(scene) + " --quiet " + flags);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, named);
    CHECK(read_file(other) == "keep");
    CHECK(json::parse(read_file(scene)) == oscillator_scene());
  }
  const auto outcome = run_varia("run " + quoted(scene) + " --quiet --out /dev/null --summary /dev/null");
  CHECK(outcome.code == 0);  // a device may take more than one output
}

TEST_CASE("a trajectory that another run is writing is refused before it is touched") {
  TempDir dir;
  write_file(dir / "t.csv", "another run's rows\n");
  const int fd = ::open((dir / "t.csv").c_str(), O_WRONLY);
  REQUIRE(::flock(fd, LOCK_EX) == 0);
  const auto outcome = run_varia("run scenes/default.json --quiet --out " + quoted(dir / "t.csv"));
  ::close(fd);
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "another run");
  CHECK(read_file(dir / "t.csv") == "another run's rows\n");
}

TEST_CASE("the run record replaces the file by a rename: a second name of the old file keeps it") {
  TempDir dir;
  write_file(dir / "r.json", "old");
  fs::create_hard_link(dir / "r.json", dir / "second-name");
  const auto outcome = run_varia("run scenes/default.json --quiet --summary " + quoted(dir / "r.json"));
  CHECK(outcome.code == 0);
  CHECK(read_file(dir / "second-name") == "old");
  CHECK(json::parse(read_file(dir / "r.json")).contains("steps"));
  CHECK(files_in(dir.path(), ".json").size() == 1);  // no temporary file left
}

TEST_CASE("the run record is written under a 255-byte file name, and through a link to a file not there yet") {
  TempDir dir;
  const fs::path longest = dir / (std::string(250, 'r') + ".json");
  auto outcome = run_varia("run scenes/default.json --quiet --summary " + quoted(longest));
  CAPTURE(outcome.err);
  CHECK(outcome.code == 0);
  CHECK(json::parse(read_file(longest)).contains("steps"));
  CHECK(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()) == 1);  // no temporary file left

  fs::create_symlink("made-by-the-run.json", dir / "link.json");  // dangling
  outcome = run_varia("run scenes/default.json --quiet --summary " + quoted(dir / "link.json"));
  CAPTURE(outcome.err);
  CHECK(outcome.code == 0);
  CHECK(fs::is_symlink(dir / "link.json"));
  CHECK(fs::read_symlink(dir / "link.json") == "made-by-the-run.json");
  REQUIRE(fs::exists(dir / "made-by-the-run.json"));
  CHECK(json::parse(read_file(dir / "made-by-the-run.json")).contains("steps"));
}

// ---- 3: validation bounded by the scene's size ----------------------------------------------------

TEST_CASE("a scene of many repeated observables is refused at the first repeat, in bounded time") {
  TempDir dir;
  json scene = oscillator_scene();
  scene["observe"] = json::array();
  for (int i = 0; i < 20000; ++i) scene["observe"].push_back("energy");
  write_file(dir / "s.json", scene.dump());
  const auto start = std::chrono::steady_clock::now();
  const auto outcome = run_varia("validate " + quoted(dir / "s.json"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "/observe/1: a repeated item");
  CHECK(seconds < 5.0);  // was 6.4 s and 2.6 GB for 5,000 repeats
}

// Issue 43, item 9: valijson compared every pair of distinct items (16,000 took 5-9 s).
TEST_CASE("distinct observe items are refused without comparing every pair") {
  TempDir dir;
  json scene = oscillator_scene();
  scene["observe"] = json::array();
  for (int i = 0; i < 20000; ++i) scene["observe"].push_back("x" + std::to_string(i));
  write_file(dir / "s.json", scene.dump());
  const auto start = std::chrono::steady_clock::now();
  const auto outcome = run_varia("validate " + quoted(dir / "s.json"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "/observe/0: expected one of");
  CHECK(seconds < 2.0);
}

// ---- 6: plugin parameter schemas -----------------------------------------------------------------

TEST_CASE("a parameter schema with what the host does not give valijson is refused, not run") {
  const char* refused[] = {
      R"({"type": 5})",
      R"({"$ref": "#"})",
      R"({"$ref": "http://example.com/schema.json"})",
      R"({"type": "object", "properties": {"name": {"type": "string", "pattern": "^(a+)+$"}}})",
      R"({"type": "object", "patternProperties": {"^x": {"type": "number"}}})",
      R"({"type": "object", "properties": {"a": {"allOf": [{"$ref": "#/properties/a"}]}}})",
      R"({"type": "array", "items": [{"type": "string", "format": "email"}]})",
      R"({"type": "object", "properties": {"a": {"allOf": [{"type": "array", "uniqueItems": true}]}}})",
      R"([1, 2])",
  };
  for (const char* text : refused) {
    CAPTURE(text);
    const json schema = json::parse(text);
    CHECK_THROWS_AS((host::check_parameter_schema(schema), host::SchemaValidator{schema}), std::invalid_argument);
  }
  // A parameter may be named like a keyword: only the keywords themselves are refused.
  const json named_pattern = json::parse(R"({"type": "object", "properties": {"pattern": {"type": "number"}}})");
  CHECK_NOTHROW(host::check_parameter_schema(named_pattern));
}

// ---- 9: every command checks its inputs ------------------------------------------------------------

TEST_CASE("ld, cost and the scene reader refuse inputs that gave wrong numbers with exit 0") {
  TempDir dir;
  json subnormal = oscillator_scene();
  subnormal["system"]["lagrangian"]["mass"] = 5e-324;
  write_file(dir / "subnormal.json", subnormal.dump());
  write_file(dir / "s.json", oscillator_scene().dump());
  const std::vector<std::tuple<std::string, int, std::string>> cases{
      {"ld scenes/default.json --q0 1e300 --q1 -1e300 --h 0.1 --json", 4, "non-finite"},
      {"ld scenes/paper/rigid-body-galerkin-s2.json --q0 1,2,3,4,5,6,7,8,9 --q1 1,0,0,0,1,0,0,0,1 --h 0.1", 2,
       "--q0: expected a point of SO3"},
      {"cost " + quoted(dir / "s.json") + " --h 1e-300 --out " + quoted(dir / "c"), 2, "--h"},
      {"cost " + quoted(dir / "s.json") + " --h 1e-9 --out " + quoted(dir / "c"), 2, "--h"},
      {"cost " + quoted(dir / "s.json") + " --h 5 --out " + quoted(dir / "c"), 2, "--h"},
      {"run " + quoted(dir / "subnormal.json"), 2, "/system/lagrangian/mass"},
  };
  for (const auto& [arguments, code, named] : cases) {
    CAPTURE(arguments);
    const auto outcome = run_varia(arguments);
    CHECK(outcome.code == code);
    check_one_error_line(outcome, named);
  }
}

TEST_CASE("verify --h refuses repeated, non-positive, too few and too small step sizes with exit 2 naming --h") {
  TempDir dir;
  write_file(dir / "s.json", oscillator_scene().dump());
  const std::vector<std::pair<std::string, std::string>> cases{
      {"0.1,0.1,0.05,0.025", "--h: expected distinct step sizes; 0.1 and 0.1 both take 20 steps to T = 2"},
      {"0.1,0.05,0.025,0.0125,0.05", "--h: expected distinct step sizes; 0.05 and 0.05 both take 40 steps"},
      {"0.1,0.05,0.025,0.0250000001", "--h: expected distinct step sizes; 0.025 and 0.0250000001 both take 80"},
      {"0.1,0.05,0.025,0", "--h: expected numbers > 0; found 0"},
      {"0.1,0.05,0.025,-0.0125", "--h: expected numbers > 0; found -0.0125"},
      {"0.1,0.05,0.025", "--h: expected at least 4 distinct step sizes"},
      {"0.1,0.05,0.025,1e-300", "--h: expected at most 1e+08 steps to T = 2"},
      {"0.1,0.05,0.025,1e-9", "--h: expected at most 1e+08 steps to T = 2"},
  };
  for (const auto& [h, named] : cases) {
    CAPTURE(h);
    const auto outcome = run_varia("verify " + quoted(dir / "s.json") + " --h " + h);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, named);
  }
}

// ---- 10: exit codes --------------------------------------------------------------------------------

TEST_CASE("cost --out naming a file is bad input (exit 2)") {
  TempDir dir;
  write_file(dir / "file", "");
  write_file(dir / "s.json", oscillator_scene().dump());
  const auto outcome = run_varia("cost " + quoted(dir / "s.json") + " --h 0.1 --out " + quoted(dir / "file"));
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "--out");
}

// ---- 13: hygiene -------------------------------------------------------------------------------------

TEST_CASE("the scene reader refuses repeated keys, NUL bytes and subnormal numbers, 1.0 is an integer") {
  const std::vector<std::tuple<std::string, int, std::string>> cases{
      {R"({"step": 0.1, "step": 0.2})", 2, "/step: a repeated key"},
      {std::string(R"({"a": 1})") + '\0' + "garbage", 2, "NUL"},
      {R"({"x": 1e-310})", 2, "/x: expected 0 or a number of magnitude"},
  };
  for (const auto& [text, code, named] : cases) {
    CAPTURE(text);
    TempDir dir;
    write_file(dir / "s.json", text);
    const auto outcome = run_varia("validate " + quoted(dir / "s.json"));
    CHECK(outcome.code == code);
    check_one_error_line(outcome, named);
  }
  TempDir dir;
  json scene = oscillator_scene();
  scene["system"]["manifold"]["dim"] = 1.0;
  scene.erase("t_end");
  scene["steps"] = 20.0;
  write_file(dir / "s.json", scene.dump());
  CHECK(run_varia("validate " + quoted(dir / "s.json")).code == 0);
}

TEST_CASE("a NUL in a plugin type name is shown as \\x00, and the message goes on to list the valid types") {
  TempDir dir;
  json scene = oscillator_scene();
  scene["system"]["lagrangian"]["type"] = std::string("harmonic\0oscillator", 19);
  write_file(dir / "s.json", scene.dump());
  const auto outcome = run_varia("validate " + quoted(dir / "s.json"));
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "/system/lagrangian/type: unknown lagrangian type 'harmonic\\x00oscillator'; "
                                "valid lagrangian types are: ");
  CHECK(contains(outcome.err, "harmonic-oscillator, "));
}

TEST_CASE("messages show control characters escaped and long input cut") {
  TempDir dir;
  const std::string long_key(1 << 20, 'k');
  json scene = oscillator_scene();
  scene["\x1b[31mred\x1b[0m\x07"] = 1;
  write_file(dir / "escape.json", scene.dump());
  scene = oscillator_scene();
  scene[long_key] = 1;
  write_file(dir / "long.json", scene.dump());
  for (const char* file : {"escape.json", "long.json"}) {
    CAPTURE(file);
    const auto outcome = run_varia("validate " + quoted(dir / file));
    CHECK(outcome.code == 2);
    REQUIRE(lines_of(outcome.err).size() == 1);
    CHECK(outcome.err.size() < 4096);
    CHECK(std::none_of(outcome.err.begin(), outcome.err.end() - 1,
                       [](char c) { return static_cast<unsigned char>(c) < 0x20; }));
  }
}

// Issue #43's must-show: 300 runs ended by a signal of the handled set at a random time (a fixed
// seed; 0 to 300 ms after the trajectory file appears), each with exit 128 + the signal, whole
// rows and a whole run record noting it. In
// TEST_SUITE("long"): about two minutes.
TEST_SUITE("long") {
  TEST_CASE("300 runs ended by random signals at random times all end cleanly") {
    const std::pair<int, const char*> signals[] = {{SIGINT, "SIGINT"},   {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"},
                                                   {SIGALRM, "SIGALRM"}, {SIGUSR1, "SIGUSR1"}, {SIGUSR2, "SIGUSR2"}};
    std::mt19937 random(43);
    std::uniform_int_distribution<int> which(0, 5), delay_ms(0, 300);
    json scene = oscillator_scene();
    scene["t_end"] = 1e6;
    int clean = 0;
    for (int run = 0; run < 300; ++run) {
      const auto [signal, name] = signals[which(random)];
      const int delay = delay_ms(random);
      CAPTURE(run);
      CAPTURE(name);
      CAPTURE(delay);
      TempDir dir;
      write_file(dir / "long.json", scene.dump());
      const pid_t pid = start_varia({"run", (dir / "long.json").string(), "--quiet", "--out",
                                     (dir / "t.csv").string(), "--summary", (dir / "r.json").string()},
                                    dir);
      REQUIRE(pid > 0);
      // From the trajectory's creation (the handlers are in place long before: a signal before
      // main, while the loader maps the program, has its default action, as for any program).
      for (int i = 0; i < 1000 && !fs::exists(dir / "t.csv"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      std::this_thread::sleep_for(std::chrono::milliseconds(delay));
      ::kill(pid, signal);
      int status = 0;
      ::waitpid(pid, &status, 0);
      REQUIRE(WIFEXITED(status));
      CHECK(WEXITSTATUS(status) == 128 + signal);
      if (fs::exists(dir / "t.csv")) check_whole_rows(read_file(dir / "t.csv"));
      if (fs::exists(dir / "r.json")) {
        const json record = json::parse(read_file(dir / "r.json"));
        CHECK(record["interrupted"]["signal"] == name);
      }
      clean += WIFEXITED(status) && WEXITSTATUS(status) == 128 + signal;
    }
    MESSAGE(clean, " of 300 runs ended cleanly by their signal");
    CHECK(clean == 300);
  }
}

}  // namespace
}  // namespace varia::test
