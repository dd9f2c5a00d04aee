#include "scene.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>

#include "json_reader.hpp"
#include "json_schema.hpp"
#include "output.hpp"
#include "registry.hpp"
#include "scene_schema.hpp"

namespace varia::host {

using nlohmann::json;

namespace {

const SchemaValidator& scene_validator() {
  static const SchemaValidator validator(json::parse(kSceneSchema));
  return validator;
}

PluginSpec plugin_spec(const json& object, std::string pointer, std::string kind) {
  PluginSpec spec{std::move(pointer), std::move(kind), object.at("type").get<std::string>(), object};
  spec.parameters.erase("type");
  return spec;
}

std::optional<PluginSpec> optional_plugin(const json& method, const char* key, const char* kind) {
  if (!method.contains(key)) return std::nullopt;
  return plugin_spec(method[key], std::string("/method/") + key, kind);
}

// Spec: "step is h; exactly one of t_end or steps". t_end must be a whole number of steps.
long steps_of(const json& document, double t0, double step) {
  if (document.contains("steps")) return document["steps"].get<long>();
  const double t_end = document["t_end"].get<double>();
  if (!(t_end > t0))
    throw InputError(fmt::format("/t_end: expected a final time after the start time /initial/t = {}; found {}", t0,
                                 t_end));
  const double ratio = (t_end - t0) / step;
  constexpr double kMaxSteps = 1e12;
  if (ratio > kMaxSteps)
    throw InputError(fmt::format("/t_end: expected at most {:g} steps; t_end / step is {:g}", kMaxSteps, ratio));
  const long steps = std::lround(ratio);
  if (steps < 1 || std::abs(steps * step - (t_end - t0)) > 1e-9 * std::max(1.0, std::abs(t_end)))
    throw InputError(fmt::format(
        "/t_end: expected a whole number of steps of {} (t_end / step = {:.17g}); found {}", step, ratio, t_end));
  return steps;
}

// The times of a run, t0 + k h, are told apart to a thousandth of a step: near the largest of
// them, doubles are at most kTimeResolution h apart. Beyond that the written times are uneven, and
// once doubles are h apart they repeat (initial.t = 1e16 with h = 0.1).
constexpr double kTimeResolution = 1e-3;

void check_time_resolution(double t0, double step, long steps) {
  const double t = std::max(std::abs(t0), std::abs(t0 + static_cast<double>(steps) * step));
  const double spacing = std::nextafter(t, std::numeric_limits<double>::infinity()) - t;
  if (!(spacing <= kTimeResolution * step))  // also a run whose last time overflows
    throw InputError(fmt::format("/initial/t: expected a start time at which the times t0 + k h of the run stay "
                                 "apart: near t = {:g} doubles are {:g} apart, and the step is {:g} (at most {:g} "
                                 "of a step is taken); found {:g}",
                                 t, spacing, step, kTimeResolution, t0));
}

// The construction checks and reads its own keys; the generic parts (quadrature, one-step method,
// solver options) are read here.
void read_method(const json& method, Scene& scene) {
  scene.construction = &construction_named(method["construction"].get<std::string>());
  static std::map<const Construction*, SchemaValidator> validators;
  auto validator = validators.find(scene.construction);
  if (validator == validators.end())
    validator = validators.emplace(scene.construction, SchemaValidator(scene.construction->schema())).first;
  validator->second.validate(method, "/method");
  scene.method_options = scene.construction->read(method);
  scene.quadrature = optional_plugin(method, "quadrature", "quadrature");
  scene.one_step = optional_plugin(method, "one_step", "one_step");
  if (!method.contains("solver") || !method["solver"].is_object()) return;
  const json& solver = method["solver"];
  scene.solver.tolerance = solver.value("tolerance", scene.solver.tolerance);
  scene.solver.max_iterations = solver.value("max_iterations", scene.solver.max_iterations);
}

void read_observe(const json& document, Scene& scene) {
  for (const auto& name : document.value("observe", json::array())) {
    if (name == "energy") scene.observe.energy = true;
    if (name == "momentum") scene.observe.momentum = true;
    if (name == "orthogonality") scene.observe.orthogonality = true;
    if (name == "constraint") scene.observe.constraint = true;
    if (name == "constraint_velocity") scene.observe.constraint_velocity = true;
    if (name == "megno") scene.observe.megno = true;
    if (name == "lyapunov") scene.observe.lyapunov = true;
  }
}

void check_size(const std::vector<double>& values, int expected, const std::string& pointer,
                const std::string& what) {
  if (static_cast<int>(values.size()) != expected)
    throw InputError(fmt::format("{}: expected {} number{} ({}); found {}", pointer, expected,
                                 expected == 1 ? "" : "s", what, values.size()));
}

}  // namespace

std::vector<PluginSpec*> Scene::plugins() {
  std::vector<PluginSpec*> all{&manifold, &lagrangian};
  for (auto& force : forces) all.push_back(&force);
  for (auto& constraint : constraints) all.push_back(&constraint);
  if (quadrature) all.push_back(&*quadrature);
  if (one_step) all.push_back(&*one_step);
  return all;
}

Scene parse_scene(const json& document) {
  scene_validator().validate(document, "");
  Scene scene;
  scene.text = document.dump();
  const json& system = document["system"];
  scene.manifold = plugin_spec(system["manifold"], "/system/manifold", "manifold");
  scene.lagrangian = plugin_spec(system["lagrangian"], "/system/lagrangian", "lagrangian");
  const json forces = system.value("forces", json::array());
  for (std::size_t i = 0; i < forces.size(); ++i)
    scene.forces.push_back(plugin_spec(forces[i], fmt::format("/system/forces/{}", i), "force"));
  const json constraints = system.value("constraints", json::array());
  for (std::size_t i = 0; i < constraints.size(); ++i)
    scene.constraints.push_back(plugin_spec(constraints[i], fmt::format("/system/constraints/{}", i), "constraint"));
  read_method(document["method"], scene);
  scene.step = document["step"].get<double>();
  const json& initial = document["initial"];
  scene.t0 = initial.value("t", 0.0);
  scene.steps = steps_of(document, scene.t0, scene.step);
  check_time_resolution(scene.t0, scene.step, scene.steps);
  read_observe(document, scene);
  if (document.contains("output")) scene.output_every = document["output"].value("every", 1);
  scene.departure_warning = document.value("departure_warning", scene.departure_warning);
  scene.q = initial["q"].get<std::vector<double>>();
  if (initial.contains("p")) scene.p = initial["p"].get<std::vector<double>>();
  if (initial.contains("v")) scene.v = initial["v"].get<std::vector<double>>();
  return scene;
}

namespace {

// A plugin object where a part of `role` must be one: an object with a string "type".
PluginSpec part_spec(const json& object, const std::string& pointer, const PartRole& role) {
  if (!object.is_object() || !object.contains("type") || !object["type"].is_string())
    throw InputError(fmt::format("{}: expected a {} plugin object, with a \"type\"; found {}", pointer, role.kind,
                                 brief(object)));
  PluginSpec spec = plugin_spec(object, pointer, role.kind);
  spec.role = role.role;
  return spec;
}

// The parts of spec's plugin among its parameters (a role's value is one plugin object or an array
// of them), each checked as spec is.
void validate_spec(PluginSpec& spec, Registry& registry) {
  const PluginRecord* record = nullptr;
  try {
    record = &registry.find(spec.kind, spec.type);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}/type: {}", spec.pointer, e.what()));
  }
  std::optional<SchemaValidator> validator;
  try {
    validator.emplace(record->parameter_schema);
  } catch (const std::invalid_argument& e) {
    throw PluginLoadError(fmt::format("{}: parameter_schema: {}", record->file.string(), e.what()));
  }
  validator->validate(spec.parameters, spec.pointer);
  spec.parts.clear();
  for (const PartRole& role : record->part_roles) {
    if (!spec.parameters.contains(role.role)) continue;
    const json& value = spec.parameters[role.role];
    const std::string pointer = spec.pointer + "/" + role.role;
    if (!value.is_array()) spec.parts.push_back(part_spec(value, pointer, role));
    for (std::size_t i = 0; value.is_array() && i < value.size(); ++i)
      spec.parts.push_back(part_spec(value[i], fmt::format("{}/{}", pointer, i), role));
  }
  for (PluginSpec& part : spec.parts) validate_spec(part, registry);
}

}  // namespace

std::string manifold_name(const PluginSpec& manifold) {
  if (manifold.parts.empty()) return manifold.type;
  std::string name = manifold.type + "(";
  for (std::size_t i = 0; i < manifold.parts.size(); ++i)
    name += (i > 0 ? "," : "") + manifold_name(manifold.parts[i]);
  return name + ")";
}

void validate_parameters(Scene& scene, Registry& registry) {
  for (PluginSpec* spec : scene.plugins()) validate_spec(*spec, registry);
}

void apply_settings(json& document, const std::vector<std::string>& settings) {
  for (const std::string& setting : settings) {
    const auto equals = setting.find('=');
    if (equals == std::string::npos || equals == 0 || setting[0] != '/')
      throw InputError(fmt::format("--set: expected POINTER=JSON (a JSON pointer such as /step, then '=', then a JSON "
                                   "value); found '{}'",
                                   printable(setting)));
    json value;
    try {
      value = parse_json_text(setting.substr(equals + 1));
    } catch (const InputError& e) {
      throw InputError(fmt::format("--set {}: the value is not JSON: {}", printable(setting.substr(0, equals)), e.what()));
    }
    try {
      document[json::json_pointer(setting.substr(0, equals))] = std::move(value);
    } catch (const json::exception& e) {
      throw InputError(fmt::format("--set {}: not a place in the scene: {}", printable(setting.substr(0, equals)), e.what()));
    }
  }
}

Scene load_scene(const std::filesystem::path& file, Registry& registry, const std::vector<std::string>& settings) {
  json document = read_json_file(file);
  apply_settings(document, settings);
  Scene scene = parse_scene(document);
  validate_parameters(scene, registry);
  return scene;
}

void check_initial_state(const Scene& scene, Manifold& manifold, const std::string& manifold_type) {
  // A manifold served in its embedding takes velocities and momenta in the embedding's numbers.
  const int point_size = manifold.point_size(),
            dim = manifold.defining_constraint() != nullptr ? point_size : manifold.dim();
  check_size(scene.q, point_size, "/initial/q", fmt::format("the point size of {}", manifold_type));
  const std::string numbers = manifold.defining_constraint() != nullptr
                                  ? fmt::format("{} in its embedding, as its points", manifold_type)
                                  : fmt::format("the dimension of {}", manifold_type);
  if (scene.p) check_size(*scene.p, dim, "/initial/p", numbers);
  if (scene.v) check_size(*scene.v, dim, "/initial/v", numbers);
  char why[256] = {};
  if (!manifold.contains(scene.q.data(), why, sizeof why))
    throw InputError(fmt::format("/initial/q: expected a point of {}{}{}; found {}", manifold_type,
                                 why[0] ? ": " : "", why, brief(json(scene.q))));
}

}  // namespace varia::host
