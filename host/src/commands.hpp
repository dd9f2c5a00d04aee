// The subcommands of the varia program (spec: "Commands"), independent of the command line
// parser: each takes its parsed options and returns an exit code, or throws one of the errors
// that cli.cpp maps to exit codes.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "registry.hpp"
#include "run.hpp"

namespace varia::host {

// A scene document checked and assembled (InputError at its JSON pointer, as validate reports it).
struct Prepared {
  Scene scene;
  Assembly assembly;
};
Prepared prepare_document(const nlohmann::json& document, Registry& registry);

// The plugins as `plugins --json` lists them.
nlohmann::ordered_json plugins_json(const std::vector<PluginRecord>& records);

struct CommonOptions {
  std::vector<std::string> plugin_paths{};  // --plugin-path, repeatable
  std::vector<std::string> settings{};      // --set POINTER=JSON, repeatable (scene.hpp, apply_settings)
};

// The registry of the bundled plugins and the --plugin-path directories.
Registry make_registry(const CommonOptions& common);

// Runs a command's body with a registry of its own. A plugin fault, or a non-finite value that a
// plugin returned, is re-thrown naming the plugin (kind, type, file) of the object that failed: the
// object carries its plugin record (PluginObject::origin, set by Registry::create) into the fault.
int with_registry(const CommonOptions& common, const std::function<int(Registry&)>& body);

// The most steps a run that `cost --h` or `verify --h` asks for may take: those commands repeat
// their runs and time them, and a step costs microseconds.
inline constexpr double kMaxFlagSteps = 1e8;
// A step size given with --h for runs over `span` (named by `span_name` in messages): InputError
// unless it is a number > 0, at most the span, taking at most kMaxFlagSteps steps over it.
void check_step_flag(double h, double span, const std::string& span_name);

int command_plugins(const CommonOptions& common, bool json);
int command_validate(const CommonOptions& common, const std::string& scene_file);
int command_run(const CommonOptions& common, const std::string& scene_file, const RunOptions& options);

struct LdOptions {
  std::string q0, q1;  // comma-separated numbers
  double h = 0.0;
  bool json = false;
};
int command_ld(const CommonOptions& common, const std::string& scene_file, const LdOptions& options);
// {"Ld", "D1", "D2"} at the points and step of `options` (InputError at --q0, --q1, --h or
// /method/construction; NumericalFailure for a non-finite value).
nlohmann::ordered_json discrete_lagrangian(Prepared& prepared, const LdOptions& options);
struct TangentOptions {
  std::string q0, p0;  // comma-separated numbers
  double h = 0.0;
  bool json = false;
};
int command_tangent(const CommonOptions& common, const std::string& scene_file, const TangentOptions& options);
// {"q1", "p1", "jacobian"} (rows: q1 then p1) of one step from the point of `options` (InputError at
// --q0, --p0, --h or /method/construction; NumericalFailure where the step fails).
nlohmann::ordered_json tangent_map(Prepared& prepared, const TangentOptions& options);
// Prints the table of checks (and writes them as JSON when json_file is not empty); 1 when a
// property the theorems predict was measured not to hold.
int command_verify(const CommonOptions& common, const std::string& scene_file, const std::string& json_file,
                   const std::vector<double>& h, bool explain, bool quiet);

}  // namespace varia::host
