#include "commands.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <stdexcept>
#include <string_view>

#include "assemble.hpp"
#include "numbers.hpp"
#include "output.hpp"
#include "registry.hpp"
#include "scene.hpp"
#include "varia/core/verification.hpp"
#include "verify.hpp"

namespace varia::host {

using nlohmann::json;

namespace {


// Loads a scene file, applies the --set settings, and assembles it; every InputError about the scene
// is prefixed with the file's name.
Prepared prepare(const std::string& scene_file, const CommonOptions& common, Registry& registry) {
  try {
    json document = read_json_file(scene_file);
    apply_settings(document, common.settings);
    return prepare_document(document, registry);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", scene_file, e.what()));
  }
}

// ---- plugins -------------------------------------------------------------------------------------

std::string plain(const json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

// "order=4, symmetric=true, group=SO(2)"
std::string properties_text(const json& properties) {
  std::vector<std::string> items;
  if (properties.is_object())
    for (const auto& [key, value] : properties.items()) items.push_back(key + "=" + plain(value));
  return fmt::format("{}", fmt::join(items, ", "));
}

// "mass (default 1), length (default 1)", from the parameter schema's "properties".
std::string parameters_text(const json& schema) {
  std::vector<std::string> items;
  if (schema.is_object() && schema.contains("properties") && schema["properties"].is_object())
    for (const auto& [key, value] : schema["properties"].items())
      items.push_back(value.is_object() && value.contains("default")
                          ? fmt::format("{} (default {})", key, plain(value["default"]))
                          : key);
  return items.empty() ? "-" : fmt::format("{}", fmt::join(items, ", "));
}

// One line for each kind and type that more than one file provides: a scene naming it is refused
// (Registry::find names the files).
std::vector<std::string> duplicates(const std::vector<PluginRecord>& records) {
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> files;
  for (const auto& r : records) files[{r.kind, r.type}].push_back(r.file.string());
  std::vector<std::string> lines;
  for (const auto& [name, provided_by] : files)
    if (provided_by.size() > 1)
      lines.push_back(fmt::format("{} '{}' is provided by {} files: {}; a scene naming it is refused (exit 3)",
                                  name.first, name.second, provided_by.size(), fmt::join(provided_by, ", ")));
  return lines;
}

// One line per plugin (kind, type, version, file), its parameters and properties indented below;
// then the types provided twice and the files refused.
void print_plugins_table(const std::vector<PluginRecord>& records, const std::vector<Refusal>& refused) {
  std::size_t kind_width = 4, type_width = 4, version_width = 7;
  for (const auto& r : records) {
    kind_width = std::max(kind_width, r.kind.size());
    type_width = std::max(type_width, r.type.size());
    version_width = std::max(version_width, r.version.size());
  }
  const auto line = [&](const std::string& kind, const std::string& type, const std::string& version,
                        const std::string& file) {
    fmt::print(results(), "{:<{}}  {:<{}}  {:<{}}  {}\n", kind, kind_width, type, type_width, version, version_width, file);
  };
  line("KIND", "TYPE", "VERSION", "FILE");
  const std::string indent(kind_width + 2, ' ');
  for (const auto& r : records) {
    line(r.kind, r.type, r.version, r.file.string());
    fmt::print(results(), "{}parameters: {}\n", indent, parameters_text(r.parameter_schema));
    if (const auto properties = properties_text(r.properties); !properties.empty())
      fmt::print(results(), "{}properties: {}\n", indent, properties);
  }
  if (const auto twice = duplicates(records); !twice.empty()) {
    fmt::print(results(), "\nduplicates:\n");
    for (const auto& line : twice) fmt::print(results(), "  {}\n", line);
  }
  if (refused.empty()) return;
  fmt::print(results(), "\nrefused:\n");
  for (const auto& r : refused) fmt::print(results(), "  {}: {}\n", r.file.string(), r.reason);
}


// ---- ld ------------------------------------------------------------------------------------------

Eigen::VectorXd parse_numbers(const std::string& text, int expected, const char* flag) {
  const std::optional<std::vector<double>> values = comma_separated_numbers(text);
  if (!values || static_cast<int>(values->size()) != expected)
    throw InputError(fmt::format("{}: expected {} comma-separated finite numbers; found '{}'", flag, expected, text));
  return Eigen::Map<const Eigen::VectorXd>(values->data(), expected);
}

// A point of the manifold, checked as the scene's initial point is (scene.cpp).
Eigen::VectorXd parse_point(const std::string& text, Manifold& manifold, const std::string& manifold_type,
                            const char* flag) {
  Eigen::VectorXd q = parse_numbers(text, manifold.point_size(), flag);
  char why[256] = {};
  if (!manifold.contains(q.data(), why, sizeof why))
    throw InputError(fmt::format("{}: expected a point of {}{}{}; found '{}'", flag, manifold_type, why[0] ? ": " : "",
                                 why, text));
  return q;
}

// --h of ld and tangent: one step of that size.
void check_one_step(double h) {
  if (!(h > 0.0) || !std::isfinite(h)) throw InputError(fmt::format("--h: expected a number > 0; found {}", h));
}

}  // namespace

nlohmann::ordered_json plugins_json(const std::vector<PluginRecord>& records) {
  auto array = nlohmann::ordered_json::array();
  for (const auto& r : records)
    array.push_back({{"kind", r.kind},
                     {"type", r.type},
                     {"version", r.version},
                     {"file", r.file.string()},
                     {"properties", r.properties},
                     {"parameter_schema", r.parameter_schema}});
  return array;
}

Registry make_registry(const CommonOptions& common) { return Registry(Registry::search_path(common.plugin_paths)); }

Prepared prepare_document(const json& document, Registry& registry) {
  try {
    Scene scene = parse_scene(document);
    validate_parameters(scene, registry);
    Assembly assembly = assemble(scene, registry);
    return Prepared{std::move(scene), std::move(assembly)};
  } catch (const std::invalid_argument& e) {  // a construction refusing the parts it was given
    throw InputError(fmt::format("/method: {}", e.what()));
  }
}

int with_registry(const CommonOptions& common, const std::function<int(Registry&)>& body) {
  Registry registry = make_registry(common);
  try {
    return body(registry);
  } catch (const PluginFault& e) {
    if (e.origin() == nullptr) throw;
    throw PluginFault(fmt::format("{}; from {}", e.what(), describe(Registry::record_of(e.origin()))));
  } catch (const NumericalFailure& e) {
    if (e.origin() == nullptr) throw;
    throw NumericalFailure(fmt::format("{}; from {}", e.what(), describe(Registry::record_of(e.origin()))),
                           e.residual());
  }
}

void check_step_flag(double h, double span, const std::string& span_name) {
  if (!(h > 0.0) || !std::isfinite(h)) throw InputError(fmt::format("--h: expected numbers > 0; found {}", h));
  if (h > span) throw InputError(fmt::format("--h: expected step sizes at most {}; found {}", span_name, h));
  if (span / h > kMaxFlagSteps)
    throw InputError(fmt::format("--h: expected at most {:g} steps to {}; h = {} gives {:g}", kMaxFlagSteps,
                                 span_name, h, span / h));
}

int command_plugins(const CommonOptions& common, bool as_json) {
  Registry registry = make_registry(common);
  std::vector<Refusal> refused;
  const auto records = registry.list(refused);
  if (!as_json) {
    print_plugins_table(records, refused);
    return 0;
  }
  fmt::print(results(), "{}\n", plugins_json(records).dump(2));
  // With --json, stdout holds the array alone; duplicates and refusals are diagnostics on stderr.
  for (const auto& line : duplicates(records)) fmt::print(stderr, "varia: duplicate: {}\n", line);
  for (const auto& r : refused) fmt::print(stderr, "varia: refused {}: {}\n", r.file.string(), r.reason);
  return 0;
}

int command_validate(const CommonOptions& common, const std::string& scene_file) {
  return with_registry(common, [&](Registry& registry) {
    const Prepared prepared = prepare(scene_file, common, registry);
    fmt::print(results(), "{}: valid ({} with {} on {}, {} steps of {})\n", scene_file, prepared.scene.construction->name(),
               prepared.scene.lagrangian.type, prepared.scene.manifold.type, prepared.scene.steps,
               prepared.scene.step);
    return 0;
  });
}

int command_run(const CommonOptions& common, const std::string& scene_file, const RunOptions& options) {
  std::vector<NamedFile> outputs;
  for (const auto& [flag, file] : {std::pair{"--out", options.out}, {"--summary", options.summary},
                                   {"--plot", options.plot}})
    if (file) outputs.push_back({flag, *file});
  check_distinct({{"scene", scene_file}}, outputs);
  return with_registry(common, [&](Registry& registry) {
    Prepared prepared = prepare(scene_file, common, registry);
    run_scene(prepared.scene, prepared.assembly, registry, options);
    return 0;
  });
}

nlohmann::ordered_json discrete_lagrangian(Prepared& prepared, const LdOptions& options) {
  Assembly& a = prepared.assembly;
  if (a.discrete_lagrangian == nullptr)
    throw InputError(fmt::format("/method/construction: construction '{}' has no discrete Lagrangian",
                                 prepared.scene.construction->name()));
  check_one_step(options.h);
  const Eigen::VectorXd q0 = parse_point(options.q0, *a.manifold, prepared.scene.manifold.type, "--q0");
  const Eigen::VectorXd q1 = parse_point(options.q1, *a.manifold, prepared.scene.manifold.type, "--q1");
  double ld = 0.0;
  Eigen::VectorXd d1(a.map->dim()), d2(a.map->dim());
  a.discrete_lagrangian->evaluate(q0.data(), q1.data(), options.h, &ld, d1.data(), d2.data());
  if (!std::isfinite(ld) || !d1.allFinite() || !d2.allFinite())  // as run does with a non-finite state
    throw NumericalFailure(fmt::format("a non-finite value of L_d or its derivatives at --q0 {} --q1 {} --h {} "
                                       "(Ld = {}, D1 = [{}], D2 = [{}])",
                                       options.q0, options.q1, options.h, ld, fmt::join(as_vector(d1), ", "),
                                       fmt::join(as_vector(d2), ", ")),
                           std::nan(""));
  return nlohmann::ordered_json{{"Ld", ld}, {"D1", as_vector(d1)}, {"D2", as_vector(d2)}};
}

namespace {

// ld and tangent: the scene prepared, `compute`'s result at the flags' point (an InputError about
// the point or the construction naming the scene file), printed as JSON with --json, else by `human`.
int point_command(const CommonOptions& common, const std::string& scene_file, bool as_json,
                  const std::function<nlohmann::ordered_json(Prepared&)>& compute,
                  const std::function<void(const nlohmann::ordered_json&)>& human) {
  return with_registry(common, [&](Registry& registry) {
    Prepared prepared = prepare(scene_file, common, registry);
    nlohmann::ordered_json result;
    try {
      result = compute(prepared);
    } catch (const InputError& e) {
      if (e.what()[0] != '/') throw;
      throw InputError(fmt::format("{}: {}", scene_file, e.what()));
    }
    if (as_json) fmt::print(results(), "{}\n", result.dump());
    else human(result);
    return 0;
  });
}

}  // namespace

int command_ld(const CommonOptions& common, const std::string& scene_file, const LdOptions& options) {
  return point_command(
      common, scene_file, options.json, [&](Prepared& prepared) { return discrete_lagrangian(prepared, options); },
      [](const nlohmann::ordered_json& result) {
        fmt::print(results(), "Ld = {}\nD1 = [{}]\nD2 = [{}]\n", result["Ld"].get<double>(),
                   fmt::join(result["D1"].get<std::vector<double>>(), ", "),
                   fmt::join(result["D2"].get<std::vector<double>>(), ", "));
      });
}

nlohmann::ordered_json tangent_map(Prepared& prepared, const TangentOptions& options) {
  Assembly& a = prepared.assembly;
  if (const std::string refusal = a.map->tangent_map_refusal(); !refusal.empty())
    throw InputError(fmt::format("/method/construction: expected a construction with a tangent map: {}", refusal));
  check_one_step(options.h);
  const Eigen::VectorXd q0 = parse_point(options.q0, *a.manifold, prepared.scene.manifold.type, "--q0");
  const Eigen::VectorXd p0 = parse_numbers(options.p0, a.map->dim(), "--p0");
  const int d = 2 * a.map->dim();
  Eigen::VectorXd q1(a.map->point_size()), p1(a.map->dim());
  const Eigen::MatrixXd directions = Eigen::MatrixXd::Identity(d, d);
  Eigen::MatrixXd jacobian(d, d);
  a.map->step_with_tangent(q0.data(), p0.data(), a.t0, options.h, q1.data(), p1.data(), d, directions.data(),
                           jacobian.data());
  if (!q1.allFinite() || !p1.allFinite() || !jacobian.allFinite())
    throw NumericalFailure(fmt::format("a non-finite step or tangent map from --q0 {} --p0 {} with --h {}", options.q0,
                                       options.p0, options.h),
                           std::nan(""));
  auto rows = nlohmann::ordered_json::array();
  for (int r = 0; r < d; ++r) rows.push_back(as_vector(jacobian.row(r).transpose()));
  return nlohmann::ordered_json{{"q1", as_vector(q1)}, {"p1", as_vector(p1)}, {"jacobian", rows}};
}

int command_tangent(const CommonOptions& common, const std::string& scene_file, const TangentOptions& options) {
  std::string not_canonical;  // why M^T J M - J is not the map's symplecticity defect, where it is not
  return point_command(
      common, scene_file, options.json,
      [&](Prepared& prepared) {
        if (!prepared.assembly.manifold->is_vector_space())  // the canonical form has a term in p there
          not_canonical = "on a Lie group the charts' coordinates are not canonical";
        else if (prepared.assembly.holonomic)
          not_canonical = "with constraints the map is read in the embedding, where it projects onto the "
                          "constraint's cotangent bundle, and a method's symplecticity is on that bundle";
        return tangent_map(prepared, options);
      },
      [&](const nlohmann::ordered_json& result) {
        fmt::print(results(), "q1 = [{}]\np1 = [{}]\nd(q1, p1)/d(q0, p0) =\n",
                   fmt::join(result["q1"].get<std::vector<double>>(), ", "),
                   fmt::join(result["p1"].get<std::vector<double>>(), ", "));
        const int d = static_cast<int>(result["jacobian"].size());
        Eigen::MatrixXd M(d, d);
        for (int r = 0; r < d; ++r) {
          const auto row = result["jacobian"][r].get<std::vector<double>>();
          fmt::print(results(), "  {:>24.16e}\n", fmt::join(row, " "));
          for (int c = 0; c < d; ++c) M(r, c) = row[c];
        }
        if (!not_canonical.empty())
          fmt::print(results(), "symplecticity defect: not measured here ({}: varia verify measures it)\n",
                     not_canonical);
        else
          fmt::print(results(), "symplecticity defect max |M^T J M - J| = {:.3e}\n", symplecticity_residual(M));
      });
}

int command_verify(const CommonOptions& common, const std::string& scene_file, const std::string& json_file,
                   const std::vector<double>& h, bool explain, bool quiet) {
  if (!json_file.empty()) check_distinct({{"scene", scene_file}}, {{"--json", json_file}});
  return with_registry(common, [&](Registry& registry) {
    Prepared prepared = prepare(scene_file, common, registry);
    check_fit_steps(prepared.scene, h);
    const auto checks = verify_scene(prepared.scene, prepared.assembly, registry, h, !quiet);
    fmt::print(results(), "{}", checks_table(checks, explain));
    if (!json_file.empty()) write_json_file(json_file, nlohmann::ordered_json(checks_json(checks)), "--json");
    std::vector<std::string> failed, unmeasured;
    for (const auto& c : checks) {
      if (c.failed()) failed.push_back(c.name);
      if (c.unmeasured()) unmeasured.push_back(c.name);
    }
    if (!failed.empty()) fmt::print(stderr, "varia: verify: predicted but not measured to hold: {}\n", fmt::join(failed, ", "));
    if (!unmeasured.empty())
      fmt::print(stderr, "varia: verify: predicted but could not be measured (the table says why): {}\n",
                 fmt::join(unmeasured, ", "));
    return failed.empty() && unmeasured.empty() ? 0 : 1;
  });
}

}  // namespace varia::host
