// The plugin tests load the real .so files the build writes to ${VARIA_BUILD_DIR}/lib/varia/plugins
// with the SDK's conformance loader (varia/sdk/conformance/loader.hpp), and check the SDK's
// conformance suites on them.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/loader.hpp"

namespace varia::test {

using sdk::conformance::LoadedPlugin;

// The manifold description a plugin is created with on R^n.
inline nlohmann::json rn(int n) { return {{"manifold", "Rn"}, {"point_size", n}, {"dim", n}}; }

inline std::filesystem::path plugin_directory() {
  return std::filesystem::path(VARIA_BUILD_DIR) / "lib" / "varia" / "plugins";
}

// The plugin files <kind>_*.so of the build, sorted by name.
inline std::vector<std::filesystem::path> plugin_files(const std::string& kind) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(plugin_directory())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kind + "_", 0) == 0 && entry.path().extension() == ".so") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The plugin <kind>_<type>.so of the build (type with '-' written '_').
inline LoadedPlugin load_plugin(const std::string& kind, const std::string& type) {
  return LoadedPlugin(plugin_directory() / (kind + "_" + type + ".so"));
}

// A conformance result as a doctest check, each failure on its own line.
inline void check_conforms(const sdk::conformance::Failures& failures) {
  std::string text;
  for (const auto& failure : failures.list()) text += "\n  " + failure;
  CHECK_MESSAGE(failures.empty(), text);
}

}  // namespace varia::test
