// varia-conformance PLUGIN.so [PLUGIN.so ...]: runs the conformance suite of each plugin's kind on
// it (varia/sdk/conformance/plugin.hpp) and prints what failed. Installed with varia, so that a
// plugin author checks a plugin before dropping it in. Exit codes: 0 every plugin conforms, 1 a
// check failed, 3 a file is not a loadable varia plugin of this ABI version.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include "varia/sdk/conformance/plugin.hpp"

namespace conformance = varia::sdk::conformance;

namespace {

// The exit code for one file, after printing its result.
int check_file(const char* file) {
  try {
    const conformance::LoadedPlugin plugin(file);
    std::string checked;
    const auto failures = conformance::check_plugin(plugin, checked);
    const auto& info = plugin.info();
    if (failures.empty()) {
      std::printf("%s: %s '%s' conforms (%s)\n", file, info.kind, info.type, checked.c_str());
      return 0;
    }
    std::printf("%s: %s '%s' does not conform, %zu failure(s):\n", file, info.kind, info.type,
                failures.list().size());
    for (const auto& failure : failures.list()) std::printf("  %s\n", failure.c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "varia-conformance: error: %s\n", e.what());
    return 3;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::printf("usage: varia-conformance PLUGIN.so [PLUGIN.so ...]\n"
                "Runs the conformance suite of each plugin's kind on it.\n"
                "Exit codes: 0 all conform, 1 a check failed, 3 a file is not a loadable varia plugin.\n");
    return argc < 2 ? 2 : 0;
  }
  int worst = 0;
  for (int i = 1; i < argc; ++i) worst = std::max(worst, check_file(argv[i]));
  return worst;
}
