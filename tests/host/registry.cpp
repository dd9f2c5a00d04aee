// The plugin registry (spec: "Build layout"): bundled plugins found without flags, unknown types
// listing the valid ones, duplicates naming both files, bad candidates refused with a reason.
#include "registry.hpp"

#include <dlfcn.h>
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <map>

#include "host/support.hpp"
#include "varia/abi/manifold.hpp"

namespace varia::host {
namespace {

using test::contains;
using test::kPluginDir;
using test::TempDir;
namespace fs = std::filesystem;

template <class Error, class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(nothing thrown)";
}

// A shared library that is not a varia plugin: the C library this test is linked against.
fs::path foreign_library() {
  Dl_info info{};
  REQUIRE(::dladdr(reinterpret_cast<void*>(&std::printf), &info) != 0);
  return info.dli_fname;
}

TEST_CASE("the registry finds the bundled plugins without any flag") {
  Registry registry(Registry::search_path({}));
  const PluginRecord& record = registry.find("lagrangian", "pendulum");
  CHECK(record.file.filename() == "lagrangian_pendulum.so");
  CHECK(record.kind == "lagrangian");
  CHECK(record.type == "pendulum");
  CHECK(record.parameter_schema.is_object());
  registry.find("quadrature", "gauss-lobatto");  // a '-' in the type is '_' in the marker
  CHECK(registry.loaded() == std::vector<std::string>{"pendulum", "gauss-lobatto"});
}

TEST_CASE("an unknown type is an input error that lists the valid types of its kind, sorted") {
  Registry registry(Registry::search_path({}));
  const std::string message = error_of<InputError>([&] { registry.find("lagrangian", "pendulm"); });
  CAPTURE(message);
  CHECK(contains(message, "unknown lagrangian type 'pendulm'; valid lagrangian types are: "));
  CHECK(contains(message, "kepler, morse-chain, pendulum"));
  CHECK_FALSE(contains(message, "gauss-lobatto"));
}

TEST_CASE("the search path is bundled, then --plugin-path, then VARIA_PLUGIN_PATH without empty entries") {
  ::setenv("VARIA_PLUGIN_PATH", ":/env/a::/env/b:", 1);
  const auto path = Registry::search_path({"/flag/c"});
  ::unsetenv("VARIA_PLUGIN_PATH");
  REQUIRE(path.size() == 4);
  CHECK(fs::equivalent(path[0], kPluginDir));
  CHECK(path[1] == "/flag/c");
  CHECK(path[2] == "/env/a");
  CHECK(path[3] == "/env/b");
}

TEST_CASE("a missing plugin directory is skipped silently") {
  Registry registry({"/nonexistent/varia/plugins"});
  std::vector<Refusal> refused;
  CHECK(registry.list(refused).empty());
  CHECK(refused.empty());
}

TEST_CASE("a type provided by two files is an error naming both files") {
  TempDir a, b;
  fs::copy_file(kPluginDir / "lagrangian_pendulum.so", a / "pendulum.so");
  fs::copy_file(kPluginDir / "lagrangian_pendulum.so", b / "another.so");
  Registry registry({a.path(), b.path()});
  const std::string message = error_of<PluginLoadError>([&] { registry.find("lagrangian", "pendulum"); });
  CAPTURE(message);
  CHECK(contains(message, (a / "pendulum.so").string()));
  CHECK(contains(message, (b / "another.so").string()));
}

TEST_CASE("a directory named twice does not make its plugins duplicates") {
  Registry registry({kPluginDir, kPluginDir});
  CHECK(registry.find("lagrangian", "pendulum").type == "pendulum");
}

TEST_CASE("list() refuses files that are not varia plugins, with one-line reasons, and lists the rest") {
  TempDir dir;
  fs::copy_file(kPluginDir / "manifold_Rn.so", dir / "Rn.so");
  test::write_file(dir / "x.so", "this is text, not a library\n");
  test::write_file(dir / "junk.so", std::string("\x7f" "ELF\x02\x01\x01 truncated", 20));
  fs::copy_file(foreign_library(), dir / "foreign.so");
  test::write_file(dir / "notes.txt", "not a candidate: no .so suffix\n");

  Registry registry({dir.path()});
  std::vector<Refusal> refused;
  const auto records = registry.list(refused);
  REQUIRE(records.size() == 1);
  CHECK(records[0].type == "Rn");

  std::map<std::string, std::string> reasons;
  for (const auto& r : refused) reasons[r.file.filename().string()] = r.reason;
  CAPTURE(reasons.size());
  REQUIRE(reasons.size() == 3);
  CHECK(contains(reasons["x.so"], "not a shared library"));
  CHECK(contains(reasons["junk.so"], "not a shared library"));
  CHECK(contains(reasons["foreign.so"], "no varia_abi_version"));
  for (const auto& [file, reason] : reasons) CHECK(reason.find('\n') == std::string::npos);
  // The good plugin still works next to the refused files.
  CHECK(registry.find("manifold", "Rn").type == "Rn");
}

TEST_CASE("an object a plugin made outlives the registry (it holds its library)") {
  std::shared_ptr<Manifold> manifold;
  {
    Registry registry(Registry::search_path({}));
    manifold = registry.create_as<Manifold>("manifold", "Rn", {{"dim", 3}}, sdk::Context{"Rn", 0, 0});
  }
  CHECK(manifold->point_size() == 3);
  CHECK(manifold->dim() == 3);
}

TEST_CASE("a plugin that refuses a parameter value is bad input naming the plugin, its type and why") {
  Registry registry(Registry::search_path({}));
  const std::string message = error_of<InputError>(
      [&] { registry.create("manifold", "Rn", {{"dim", "three"}}, sdk::Context{"Rn", 0, 0}); });
  CAPTURE(message);
  CHECK(message == "Rn: 'dim' must be an integer >= 1, got \"three\" (the Rn plugin manifold_Rn.so)");
}

}  // namespace
}  // namespace varia::host
