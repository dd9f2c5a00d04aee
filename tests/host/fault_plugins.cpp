// Bad plugin files (spec: "Build layout", "Exit codes"): next to the bundled plugins, a directory
// holds the fault plugins of tests/fault_plugins, a text file named .so and a foreign library.
// `varia plugins` lists the good ones and refuses the bad with a reason; a scene that does not
// need them runs; one that does exits 3 (4 for a non-finite value) naming the plugin file.
// Plugins in files or directories that group or others can write are refused ("Trust").
#include <doctest/doctest.h>

#include <unistd.h>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "assemble.hpp"
#include "commands.hpp"
#include "host/support.hpp"
#include "registry.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

const fs::path kFaultPluginDir = VARIA_FAULT_PLUGIN_DIR;

// A plugin directory (owner-only) holding every fault plugin, a text file and a foreign library.
struct FaultDirectory {
  TempDir dir;
  FaultDirectory() {
    for (const auto& file : files_in(kFaultPluginDir, ".so")) fs::copy_file(file, dir / file.filename().string());
    write_file(dir / "not_a_library.so", "this is text, not a library\n");
  }
  std::string flag() const { return "--plugin-path '" + dir.path().string() + "'"; }
};

// The default scene with another Lagrangian, observing nothing (so that nothing evaluates the
// Lagrangian before the first step).
fs::path scene_with_lagrangian(const TempDir& dir, const std::string& type) {
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["system"]["lagrangian"] = {{"type", type}};
  scene.erase("observe");
  const auto file = dir / (type + ".json");
  write_file(file, scene.dump());
  return file;
}

struct Refused {
  const char* file;
  std::string reason;
};

TEST_CASE("plugins lists the good fault plugins and refuses each bad file with its reason") {
  const FaultDirectory faults;
  const Refused refused[] = {
      {"not_a_library.so", "not a shared library"},
      {"fault_foreign.so", "not a varia plugin (no varia_abi_version symbol)"},
      {"fault_wrong_abi.so", "ABI version " + std::to_string(kAbiVersion + 100) + ", this host speaks " +
                                 std::to_string(kAbiVersion)},
      {"fault_no_metadata.so", "missing metadata (no varia_info)"},
      {"fault_bad_schema.so", "unusable parameter_schema in varia_info: "},
      {"fault_bad_properties.so", "its properties declare \"symplectic\": \"yes\", expected true or false"},
      // Issue 43, item 9: listing it overflowed the stack (exit 139).
      {"fault_deep_schema.so", "malformed parameter_schema in varia_info: /not/not/not/not/not/not/not/not"},
      // Loaded lazily it was listed, and a run died at its first evaluation (exit 127).
      {"fault_undefined_symbol.so", "not a loadable shared library: "},
  };
  const auto table = run_varia("plugins " + faults.flag());
  CAPTURE(table.out);
  REQUIRE(table.code == 0);
  for (const char* good : {"fault-construct", "fault-evaluate", "fault-nan", "pendulum"}) CHECK(contains(table.out, good));
  const auto refusals = table.out.substr(table.out.find("\nrefused:\n"));
  for (const auto& r : refused) {
    CAPTURE(r.file);
    CHECK(contains(refusals, (faults.dir / r.file).string() + ": " + r.reason));
  }
}

struct SceneCase {
  const char* lagrangian;
  int code;
  const char* file;    // the plugin file the one error line names ("" for exit 0)
  const char* reason;  // and what went wrong
};

TEST_CASE("a scene needing a bad plugin exits 3 (4 for a non-finite value) naming the file, others run") {
  const FaultDirectory faults;
  const SceneCase cases[] = {
      {"pendulum", 0, "", ""},
      {"fault-construct", 3, "fault_throws_on_construction.so", "fault-construct: deliberate failure in the constructor"},
      {"fault-evaluate", 3, "fault_throws_on_evaluation.so", "deliberate failure in evaluate"},
      {"fault-nan", 4, "fault_returns_nan.so", "is not finite"},
      {"fault-abi", 3, "fault_wrong_abi.so", "ABI version"},
      {"fault-no-info", 3, "fault_no_metadata.so", "missing metadata (no varia_info)"},
      {"fault-bad-schema", 3, "fault_bad_schema.so", "unusable parameter_schema"},
      // Issue 43, item 10: the pattern was written through, and varia died of SIGSEGV (exit 139).
      {"fault-undefined", 3, "fault_undefined_symbol.so", "undefined symbol: varia_fault_symbol_that_no_library_defines"},
      {"fault-bad-pattern", 3, "fault_bad_hessian_pattern.so",
       "sparse Hessian pattern names entry 3 at (row 268435456, column 268435456), outside its 2 x 2 Hessian"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.lagrangian);
    const auto scene = scene_with_lagrangian(faults.dir, c.lagrangian);
    const auto outcome = run_varia("run '" + scene.string() + "' --quiet " + faults.flag());
    CAPTURE(outcome.err);
    CHECK(outcome.code == c.code);
    if (c.code == 0) {
      CHECK(outcome.err.empty());
      continue;
    }
    check_one_error_line(outcome, (faults.dir / c.file).string());
    CHECK(contains(outcome.err, c.reason));
  }
}

// Issue 43, item 10: the composite read its coordinates through the pattern unchecked.
TEST_CASE("an effect whose Hessian pattern lies outside its coordinates is a plugin fault naming its file, exit 3") {
  const FaultDirectory faults;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["system"]["lagrangian"] = {{"type", "composite"},
                                   {"space_dim", 1},
                                   {"masses", {1.0}},
                                   {"terms", {{{"type", "fault-bad-effect-pattern"}}}}};
  scene.erase("observe");
  const auto file = faults.dir / "bad_effect.json";
  write_file(file, scene.dump());
  const auto outcome = run_varia("validate '" + file.string() + "' " + faults.flag());
  CAPTURE(outcome.err);
  CHECK(outcome.code == 3);
  check_one_error_line(outcome, (faults.dir / "fault_bad_effect_pattern.so").string());
  CHECK(contains(outcome.err, "terms/0: the effect's Hessian pattern names entry 1 at (row 268435456, column 0), "
                              "outside its 1 coordinates"));
}

TEST_CASE("a plugin fault in the middle of a run leaves a run record that notes it") {
  const FaultDirectory faults;
  const auto scene = scene_with_lagrangian(faults.dir, "fault-evaluate");
  const auto record_file = faults.dir / "r.json";
  const auto outcome = run_varia("run '" + scene.string() + "' --quiet --summary '" + record_file.string() + "' " +
                                 faults.flag());
  CHECK(outcome.code == 3);
  REQUIRE(fs::exists(record_file));
  const json record = json::parse(read_file(record_file));
  REQUIRE(record.contains("failure"));
  CHECK(contains(record["failure"]["plugin_fault"].get<std::string>(), "deliberate failure in evaluate"));
  CHECK(record["failure"]["step"] == 1);
}

struct TrustCase {
  const char* name;
  fs::perms directory, file;
  const char* reason;
};

TEST_CASE("plugins in files or directories writable by group or others are refused with the reason") {
  using P = fs::perms;
  const TrustCase cases[] = {
      {"directory writable by others", P::owner_all | P::others_all, P::owner_all, "its directory"},
      {"directory writable by group", P::owner_all | P::group_all, P::owner_all, "its directory"},
      {"file writable by others", P::owner_all, P::owner_all | P::others_write, "mode 0702"},
      {"file writable by group", P::owner_all, P::owner_all | P::group_write, "mode 0720"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    TempDir dir, scenes;
    const auto plugin = dir / "fault_returns_nan.so";
    fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", plugin);
    fs::permissions(plugin, c.file);
    fs::permissions(dir.path(), c.directory);
    const std::string flag = " --plugin-path '" + dir.path().string() + "'";
    const auto listing = run_varia("plugins" + flag);
    CHECK(listing.code == 0);
    CHECK(contains(listing.out, plugin.string() + ": not trusted: "));
    CHECK(contains(listing.out, c.reason));
    CHECK_FALSE(contains(listing.out, "fault-nan"));
    // A scene that needs it: exit 3 naming the file and why; one that does not: it runs.
    const auto needing = run_varia("run '" + scene_with_lagrangian(scenes, "fault-nan").string() + "' --quiet" + flag);
    CHECK(needing.code == 3);
    check_one_error_line(needing, plugin.string() + ": lagrangian type 'fault-nan' is in this file, which was refused: "
                                                    "not trusted: ");
    CHECK(run_varia("run scenes/default.json --quiet" + flag).code == 0);
  }
}

// Issue 43, item 15: on a cluster, a project's directories are often writable by its group and setgid.
TEST_CASE("plugins under a group-writable setgid directory are loaded when VARIA_TRUSTED_PLUGIN_DIRS names it") {
  using P = fs::perms;
  TempDir top;
  const fs::path project = top / "project", plugins = project / "plugins", plugin = plugins / "fault_returns_nan.so";
  fs::create_directories(plugins);
  fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", plugin);
  fs::permissions(plugin, P::owner_all | P::group_all);
  for (const fs::path& d : {project, plugins}) fs::permissions(d, P::owner_all | P::group_all | P::set_gid);
  const std::string listing = varia() + " plugins --plugin-path " + quoted(plugins);
  const std::string trusting = "VARIA_TRUSTED_PLUGIN_DIRS=" + quoted(project) + " ";
  auto outcome = run_shell(listing);
  CHECK(outcome.code == 0);
  CHECK(contains(outcome.out, plugin.string() + ": not trusted: writable by group or others (mode 0770)"));
  CHECK(contains(outcome.out, "VARIA_TRUSTED_PLUGIN_DIRS"));  // the refusal says how to trust it
  CHECK_FALSE(contains(outcome.out, "fault-nan"));
  // Named (the project: everything under it), the plugin is trusted; the directories above it are
  // still checked, and are the test's own.
  outcome = run_shell(trusting + listing);
  CHECK(outcome.code == 0);
  CHECK(contains(outcome.out, "fault-nan"));
  CHECK_FALSE(contains(outcome.out, "not trusted"));
  // Writable by others stays refused, named or not.
  fs::permissions(plugins, P::owner_all | P::group_all | P::others_all | P::set_gid);
  outcome = run_shell(trusting + listing);
  CHECK(contains(outcome.out, plugin.string() + ": not trusted: its directory " + plugins.string() +
                                  " is writable by group or others (mode 2777)"));
  CHECK_FALSE(contains(outcome.out, "fault-nan"));
  // An entry that is not an absolute path of a directory is bad input.
  for (const std::string& entry : {std::string("project"), (top / "missing").string(), plugin.string()}) {
    CAPTURE(entry);
    outcome = run_shell("VARIA_TRUSTED_PLUGIN_DIRS=" + quoted(fs::path(entry)) + " " + listing);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, "VARIA_TRUSTED_PLUGIN_DIRS: '" + entry +
                                      "': expected absolute paths of directories, separated by ':'");
  }
}

// As sshd's StrictModes: the file a link leads to, every directory above it, and the owners.
TEST_CASE("plugins behind a link, under a writable parent or owned by another user are refused") {
  struct Layout {
    const char* name;
    const char* reason;
    bool needs_root;  // to give a file to another user
    void (*make)(const TempDir& top, const fs::path& plugin_dir);
  };
  const Layout layouts[] = {
      {"a link to a file in a directory writable by all", "/open is writable by group or others", false,
       [](const TempDir& top, const fs::path& plugin_dir) {
         fs::create_directory(top / "open");
         fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", top / "open" / "real.so");
         fs::permissions(top / "open", fs::perms::all);
         fs::create_symlink(top / "open" / "real.so", plugin_dir / "fault_returns_nan.so");
       }},
      {"an owner-only directory under a parent writable by all", "writable by group or others", false,
       [](const TempDir& top, const fs::path& plugin_dir) {
         fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", plugin_dir / "fault_returns_nan.so");
         fs::permissions(top.path(), fs::perms::all);
       }},
      // Issue #43 item 10: on 5a2c708 the link was trusted by where it led, and loaded by its name.
      {"a link in a directory writable by all to a plugin in a trusted one", "plugins is writable by group or others",
       false,
       [](const TempDir& top, const fs::path& plugin_dir) {
         fs::create_directory(top / "safe");
         fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", top / "safe" / "real.so");
         fs::create_symlink(top / "safe" / "real.so", plugin_dir / "fault_returns_nan.so");
         fs::permissions(plugin_dir, fs::perms::all);
       }},
      {"a file owned by another user", "owned by another user", true,
       [](const TempDir&, const fs::path& plugin_dir) {
         fs::copy_file(kFaultPluginDir / "fault_returns_nan.so", plugin_dir / "fault_returns_nan.so");
         REQUIRE(::chown((plugin_dir / "fault_returns_nan.so").c_str(), 65534, -1) == 0);
       }},
  };
  for (const auto& layout : layouts) {
    CAPTURE(layout.name);
    if (layout.needs_root && ::geteuid() != 0) continue;
    TempDir top;
    const fs::path plugin_dir = top / "plugins";
    fs::create_directory(plugin_dir);
    fs::permissions(plugin_dir, fs::perms::owner_all);
    layout.make(top, plugin_dir);
    const auto listing = run_varia("plugins --plugin-path '" + plugin_dir.string() + "'");
    fs::permissions(top.path(), fs::perms::owner_all);
    CHECK(listing.code == 0);
    CHECK(contains(listing.out, (plugin_dir / "fault_returns_nan.so").string() + ": not trusted: "));
    CHECK(contains(listing.out, layout.reason));
    CHECK_FALSE(contains(listing.out, "fault-nan"));
  }
}

// The ELF header's section header table removed (e_shoff, e_shnum, e_shstrndx zeroed): the
// dynamic loader needs none, so the file still loads, but no symbol can be read from it.
void remove_section_headers(const fs::path& file) {
  std::fstream elf(file, std::ios::in | std::ios::out | std::ios::binary);
  const char zeros[8] = {};
  elf.seekp(40);  // e_shoff
  elf.write(zeros, 8);
  elf.seekp(60);  // e_shnum, e_shstrndx
  elf.write(zeros, 4);
  REQUIRE(elf.good());
}

// Issue #43 item 10: on 5a2c708 the file without section headers was loaded (its constructors run,
// here abort) by every run, whatever the scene named.
TEST_CASE("a plugin whose type no scene names is never loaded: stripped, or without section headers") {
  for (const char* form : {"as built", "stripped", "without section headers"}) {
    CAPTURE(form);
    TempDir dir;
    const auto plugin = dir / "fault_aborts_on_load.so";
    fs::copy_file(fs::path(VARIA_ABORTING_PLUGIN_DIR) / "fault_aborts_on_load.so", plugin);
    if (std::string(form) == "stripped")
      REQUIRE(std::system(("strip --strip-all '" + plugin.string() + "'").c_str()) == 0);
    if (std::string(form) == "without section headers") remove_section_headers(plugin);
    const auto outcome = run_varia("run scenes/default.json --quiet --plugin-path '" + dir.path().string() + "'");
    CAPTURE(outcome.err);
    CHECK(outcome.code == 0);
  }
  TempDir dir;  // varia plugins names it, unloaded
  fs::copy_file(fs::path(VARIA_ABORTING_PLUGIN_DIR) / "fault_aborts_on_load.so", dir / "fault_aborts_on_load.so");
  remove_section_headers(dir / "fault_aborts_on_load.so");
  const auto listing = run_varia("plugins --plugin-path '" + dir.path().string() + "'");
  CAPTURE(listing.err);
  CHECK(listing.code == 0);
  CHECK(contains(listing.out, "no section headers"));
}

// The lines of stderr that varia wrote (a shell that ran it may add its own, e.g. "Aborted").
std::vector<std::string> varia_lines(const std::string& err) {
  std::vector<std::string> lines;
  for (auto& line : lines_of(err))
    if (line.rfind("varia:", 0) == 0) lines.push_back(std::move(line));
  return lines;
}

TEST_CASE("a plugin that crashes varia while it is loaded is named on stderr, exit 3") {
  TempDir dir;
  fs::copy_file(fs::path(VARIA_ABORTING_PLUGIN_DIR) / "fault_aborts_on_load.so", dir / "fault_aborts_on_load.so");
  const auto outcome = run_varia("plugins --plugin-path '" + dir.path().string() + "'");
  CAPTURE(outcome.err);
  CHECK(outcome.code == 3);
  const auto lines = varia_lines(outcome.err);
  REQUIRE(lines.size() == 1);
  CHECK(contains(lines[0], "varia: error: plugin fault: fatal signal SIGABRT (abort) in a call to the plugin " +
                               (dir / "fault_aborts_on_load.so").string() + "; varia ends with exit code 3"));
  CHECK(outcome.out.empty());
}

// The default scene over 4,000 steps (6 evaluations each) with a fault plugin of tests/fault_plugins as its Lagrangian,
// faulting at its evaluation number `after`.
fs::path scene_faulting_after(const TempDir& dir, const std::string& type, long after) {
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["system"]["lagrangian"] = {{"type", type}, {"after", after}};
  scene.erase("t_end");
  scene["steps"] = 4000;
  const auto file = dir / (type + "-" + std::to_string(after) + ".json");
  write_file(file, scene.dump());
  return file;
}

struct CrashCase {
  const char* type;
  const char* file;
  const char* what;  // in the one line that names the file
};

// Spec "Exit codes": 3 for a plugin fault, the file named; the trajectory written so far whole. A
// fatal signal or an exit cannot be recovered from: the process ends with code 3 (crash.hpp).
TEST_CASE("a plugin that crashes, overflows its stack or exits mid-run is named, exit 3, output whole rows") {
  const FaultDirectory faults;
  const CrashCase cases[] = {
      {"fault-segfault", "fault_segfaults.so", "fatal signal SIGSEGV"},
      {"fault-abort", "fault_aborts.so", "fatal signal SIGABRT (abort)"},
      {"fault-stack-overflow", "fault_overflows_stack.so", "fatal signal SIGSEGV"},
      {"fault-exit", "fault_exits.so", "called exit or quick_exit during the command"},
      {"fault-quick-exit", "fault_quick_exits.so", "called exit or quick_exit during the command"},
  };
  // What the same oscillator writes when it does not fault: the rows a faulting run must begin with.
  const auto whole = run_varia("run '" + scene_faulting_after(faults.dir, "fault-exit", 1L << 40).string() +
                               "' --out - --quiet " + faults.flag());
  REQUIRE(whole.code == 0);
  const auto whole_rows = lines_of(whole.out);
  REQUIRE(whole_rows.size() == 4002);
  for (const auto& c : cases) {
    // Early (every row still in the writer's buffer) and late (after chunks reached the file).
    for (const long after : {300L, 18000L}) {
      for (const std::string& out : {std::string("-"), (faults.dir / "t.csv").string()}) {
        CAPTURE(c.type);
        CAPTURE(after);
        CAPTURE(out);
        const auto summary = faults.dir / "run.json";
        fs::remove(summary);
        const auto outcome = run_varia("run '" + scene_faulting_after(faults.dir, c.type, after).string() +
                                       "' --out '" + out + "' --summary '" + summary.string() + "' --quiet " +
                                       faults.flag());
        CAPTURE(outcome.err);
        CHECK(outcome.code == 3);
        const auto lines = varia_lines(outcome.err);
        REQUIRE(lines.size() == 1);
        CHECK(contains(lines[0], "varia: error: plugin fault: "));
        CHECK(contains(lines[0], c.what));
        CHECK(contains(lines[0], (faults.dir / c.file).string()));
        const std::string csv = out == "-" ? outcome.out : read_file(out);
        if (out != "-") CHECK(outcome.out.empty());
        // Whole rows, the same as the run without the fault, as many as were computed: the rows the
        // writer still held are written too.
        REQUIRE(!csv.empty());
        CHECK(csv.back() == '\n');
        const auto rows = lines_of(csv);
        CHECK(rows.size() >= 2);
        CHECK(rows.size() < whole_rows.size());
        for (std::size_t i = 0; i < rows.size() && i < whole_rows.size(); ++i) REQUIRE(rows[i] == whole_rows[i]);
        CHECK_FALSE(fs::exists(summary));
      }
    }
  }
}

TEST_CASE("what a plugin prints goes to stderr: stdout holds the results alone") {
  const FaultDirectory faults;
  const auto scene = scene_with_lagrangian(faults.dir, "fault-printf");
  const auto run = run_varia("run '" + scene.string() + "' --out - --quiet " + faults.flag());
  CAPTURE(run.err);
  CHECK(run.code == 0);
  CHECK(contains(run.err, "prints plugin: printf in the first evaluation"));
  CHECK(contains(run.err, "prints plugin: write(1)"));
  const auto rows = lines_of(run.out);
  REQUIRE(rows.size() == 202);
  CHECK(rows[0] == "t,q0,p0");
  for (const auto& row : rows) CHECK(std::count(row.begin(), row.end(), ',') == 2);

  const auto ld = run_varia("ld '" + scene.string() + "' --q0 0.1 --q1 0.2 --h 0.1 --json " + faults.flag());
  CHECK(ld.code == 0);
  CHECK(contains(ld.err, "prints plugin: std::cout in the constructor"));
  CHECK(json::parse(ld.out).contains("Ld"));

  const auto listing = run_varia("plugins --json " + faults.flag());
  CHECK(listing.code == 0);
  CHECK(contains(listing.err, "prints plugin: puts"));
  CHECK(json::parse(listing.out).is_array());
}

// A Lagrangian of one degree of freedom declaring a momentum map of 2^31 - 1 numbers, made here
// rather than built as a plugin file; its origin is the record a registry would give it.
class HugeMomentum final : public Lagrangian {
 public:
  int position_size() const noexcept override { return 1; }
  int velocity_size() const noexcept override { return 1; }
  Status evaluate(const double*, const double*, double*, double*, double*) noexcept override { return nullptr; }
  int momentum_size() const noexcept override { return std::numeric_limits<int>::max(); }
};

TEST_CASE("a Lagrangian declaring a momentum map larger than any group acting on its manifold is a plugin fault "
          "naming its file") {
  const host::PluginRecord record{"/plugins/lagrangian_huge_momentum.so", "lagrangian", "huge-momentum", "0.0.1",
                                  {}, {}, {}};
  HugeMomentum lagrangian;
  lagrangian.set_origin(&record);
  std::string message = "(nothing thrown)";
  try {
    // As every command checks it when it assembles the scene, inside the registry's naming of faults.
    host::with_registry({}, [&](host::Registry&) {
      host::check_momentum_size(lagrangian, 1);
      return 0;
    });
  } catch (const PluginFault& e) {
    message = e.what();
  }
  CHECK(message == "the Lagrangian declares a momentum map of 2147483647 numbers; a symmetry group acting on a "
                   "manifold of dimension 1 has at most 3 generators (dim (dim + 2)); from lagrangian "
                   "'huge-momentum' (/plugins/lagrangian_huge_momentum.so)");
}

// A manifold and a Lagrangian declaring sizes no scene can cause (a dimension above the point size,
// no velocity numbers), made here, their origin a registry's record.
class WiderThanItsPoints final : public Manifold {
 public:
  int point_size() const noexcept override { return 2; }
  int dim() const noexcept override { return 3; }
  ManifoldStructure structure() const noexcept override { return ManifoldStructure::vector_space; }
  Status retract(const double*, const double*, double*) noexcept override { return nullptr; }
  Status local(const double*, const double*, double*) noexcept override { return nullptr; }
  bool contains(const double*, char*, int) noexcept override { return true; }
};
class NoVelocities final : public Lagrangian {
 public:
  int position_size() const noexcept override { return 1; }
  int velocity_size() const noexcept override { return -4; }
  Status evaluate(const double*, const double*, double*, double*, double*) noexcept override { return nullptr; }
};

// The message the check gives inside the registry's naming of faults, as every command's assembly does.
template <class F>
std::string fault_of(F&& check) {
  try {
    host::with_registry({}, [&](host::Registry&) {
      check();
      return 0;
    });
  } catch (const PluginFault& e) {
    return e.what();
  }
  return "(nothing thrown)";
}

TEST_CASE("a manifold or a Lagrangian declaring sizes no scene can cause is a plugin fault naming its file (issue "
          "#43: they were reported as the scene's mismatch, exit 2)") {
  const host::PluginRecord manifold_record{"/plugins/manifold_wide.so", "manifold", "wide", "0.0.1", {}, {}, {}};
  const host::PluginRecord lagrangian_record{"/plugins/lagrangian_still.so", "lagrangian", "still", "0.0.1", {}, {}, {}};
  WiderThanItsPoints manifold;
  manifold.set_origin(&manifold_record);
  NoVelocities lagrangian;
  lagrangian.set_origin(&lagrangian_record);
  CHECK(fault_of([&] { host::check_declared_sizes(manifold); }) ==
        "the manifold declares point size 2 and dimension 3; a manifold embedded in R^(point size) has a dimension "
        "from 1 to its point size; from manifold 'wide' (/plugins/manifold_wide.so)");
  CHECK(fault_of([&] { host::check_declared_sizes(lagrangian); }) ==
        "the Lagrangian declares 1 position and -4 velocity numbers; each is at least 1; from lagrangian 'still' "
        "(/plugins/lagrangian_still.so)");
}

// A manifold whose structure no construction serves (a homogeneous space that gives neither a
// group's chart nor its equations: tests/fault_plugins/unserved_sphere.cpp) is refused once, at /system/manifold, by validate and
// for every construction, before anything else is made of it; it is not taken for a Lie group.
TEST_CASE("a manifold of a structure no construction serves is refused at /system/manifold, exit 2") {
  const FaultDirectory faults;
  const json methods[] = {
      {{"construction", "galerkin"}, {"degree", 1}, {"quadrature", {{"type", "trapezoid"}}}},
      {{"construction", "shooting"}, {"one_step", {{"type", "rk4"}}}, {"quadrature", {{"type", "simpson"}}}},
  };
  for (const json& method : methods) {
    json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
    scene["system"]["manifold"] = {{"type", "unserved-sphere"}};
    scene["method"] = method;
    scene["initial"] = {{"q", {0.0, 0.0, 1.0}}, {"p", {0.0, 0.0}}};
    scene.erase("observe");
    const auto file = faults.dir / "sphere.json";
    write_file(file, scene.dump());
    for (const char* command : {"validate", "run"}) {
      CAPTURE(method.dump());
      CAPTURE(command);
      const std::string quiet = std::string(command) == "run" ? " --quiet " : " ";
      const auto outcome = run_varia(std::string(command) + " '" + file.string() + "'" + quiet + faults.flag());
      CAPTURE(outcome.err);
      CHECK(outcome.code == 2);
      CHECK(contains(outcome.err, "/system/manifold: the unserved-sphere manifold is a homogeneous space, and the "
                                  "constructions serve vector spaces, Lie groups and manifolds given by their equations"));
    }
  }
}

}  // namespace
}  // namespace varia::test
