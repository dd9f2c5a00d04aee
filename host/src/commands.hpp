// The subcommands of the varia program (spec: "Commands"), independent of the command line
// parser: each takes its parsed options and returns an exit code, or throws one of the errors
// that cli.cpp maps to exit codes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "run.hpp"

namespace varia::host {

struct CommonOptions {
  std::vector<std::string> plugin_paths;  // --plugin-path, repeatable
};

int command_plugins(const CommonOptions& common, bool json);
int command_validate(const CommonOptions& common, const std::string& scene_file);
int command_run(const CommonOptions& common, const std::string& scene_file, const RunOptions& options);

struct LdOptions {
  std::string q0, q1;  // comma-separated numbers
  double h = 0.0;
  bool json = false;
};
int command_ld(const CommonOptions& common, const std::string& scene_file, const LdOptions& options);
// Prints the table of checks (and writes them as JSON when json_file is not empty); 1 when a
// property the theorems predict was measured not to hold.
int command_verify(const CommonOptions& common, const std::string& scene_file, const std::string& json_file,
                   const std::vector<double>& h);

}  // namespace varia::host
