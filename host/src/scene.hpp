// Scenes (spec: "Scene files (JSON)"): reading, validation against schemas/scene.schema.json
// (embedded in the program) and against each plugin's parameter schema, and the parsed content.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "constructions/construction.hpp"
#include "json_reader.hpp"  // read_json_file
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/manifold.hpp"

namespace varia::host {

class Registry;

// A JSON object with a "type" key: a plugin of the kind its place in the scene asks for.
struct PluginSpec {
  std::string pointer;        // where it is in the scene, e.g. "/system/lagrangian"
  std::string kind;           // registry kind, e.g. "lagrangian"
  std::string type;           // e.g. "pendulum"
  nlohmann::json parameters;  // the object's keys minus "type"
  // The plugin objects among its parameters that its plugin takes as parts (a product's factors,
  // a composite's terms; registry.hpp, PartRole), found by validate_parameters, each with its role.
  std::vector<PluginSpec> parts{};
  std::string role{};  // the parameter this spec is a part of, or empty
};

// The manifold's name as the plugins' Context gives it: its type, with its parts' names in
// parentheses ("product(SO3,SO3)").
std::string manifold_name(const PluginSpec& manifold);

struct Observe {
  bool energy = false, momentum = false, orthogonality = false, constraint = false, constraint_velocity = false;
  bool megno = false, lyapunov = false;  // from the tangent map along the run
  bool chaos() const { return megno || lyapunov; }
  static Observe energy_only() {
    Observe o;
    o.energy = true;
    return o;
  }
};

struct Scene {
  std::string text;  // the scene's JSON (as parsed, compact), for outputs that carry it
  const Construction* construction = nullptr;  // method.construction, from the table
  std::shared_ptr<const MethodOptions> method_options;  // its own keys of "method", read by it
  PluginSpec manifold, lagrangian;
  std::vector<PluginSpec> forces;
  std::vector<PluginSpec> constraints;  // system.constraints
  std::optional<PluginSpec> quadrature, one_step;  // the parts a construction names in "method"
  SolverOptions solver;
  double t0 = 0.0;  // initial.t: the start time
  double step = 0.0;
  long steps = 0;  // given, or round((t_end - t0) / step)
  Observe observe;
  int output_every = 1;
  // departure_warning: the fraction of its scale by which an observed conserved quantity may depart
  // from its start before the run warns (0: never).
  double departure_warning = 0.01;
  std::vector<double> q;
  std::optional<std::vector<double>> p, v;  // exactly one is set

  // Every plugin object of the scene outside other plugins' parameters, in the order they are
  // created (each after its parts).
  std::vector<PluginSpec*> plugins();
};

// Checks a scene document against the scene schema and returns its content (InputError).
Scene parse_scene(const nlohmann::json& document);
// Checks each plugin object's parameters against its plugin's parameter schema, and finds the
// parts among them (PluginSpec::parts), checked the same way; an unknown type is an InputError
// naming the object's "type" pointer.
void validate_parameters(Scene& scene, Registry& registry);
// Spec "--set POINTER=JSON": replaces (or adds) the value at each JSON pointer of the document, in
// order, before the scene is checked; InputError at "--set" for a setting that is not POINTER=JSON.
void apply_settings(nlohmann::json& document, const std::vector<std::string>& settings);
// read_json_file + apply_settings + parse_scene + validate_parameters.
Scene load_scene(const std::filesystem::path& file, Registry& registry, const std::vector<std::string>& settings = {});
// Checks initial.q/p/v against the manifold (sizes, contains); InputError naming /initial/...
void check_initial_state(const Scene& scene, Manifold& manifold, const std::string& manifold_type);

}  // namespace varia::host
