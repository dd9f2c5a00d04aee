#include "parts.hpp"

namespace varia::host {

std::string refusal_pointer(const PluginSpec& spec, std::string& message) {
  const std::size_t colon = message.find(": ");
  const std::string path = message.substr(0, colon);
  const std::string parameter = path.substr(0, path.find('/'));
  if (colon == std::string::npos || parameter.empty() || !spec.parameters.is_object() ||
      !spec.parameters.contains(parameter) || path.find(' ') != std::string::npos)
    return spec.pointer;
  message.erase(0, colon + 2);
  return spec.pointer + "/" + path;
}

void apply_shared_theorems(const Assembly& a, std::optional<bool> ld_invariant, Predictions& p) {
  if (declares_symmetry(*a.lagrangian)) {
    p.g_invariant = ld_invariant;
    if (ld_invariant.value_or(false)) p.momentum_conserved = true;
  }
  // An embedded manifold's own equations hold wherever its symmetry's action takes a point of it
  // (the action maps the manifold to itself): only the scene's constraints void the prediction.
  if (!a.constraints.empty() && (p.g_invariant || p.momentum_conserved)) {
    p.g_invariant.reset();
    p.momentum_conserved.reset();
    p.reason += "; with constraints a symmetry of L need not be one of g: G-invariance and momentum not predicted";
  }
  if (!a.forces.empty()) {
    p.symplectic.reset();
    p.energy_bounded.reset();
    p.momentum_conserved.reset();
    p.reason += "; with forces the conservation theorems do not apply";
  }
}

void make_one_step(const Scene& scene, Registry& registry, Assembly& a) {
  a.one_step = make_part<OneStepMethod>(registry, *scene.one_step, scene, *a.manifold);
  a.one_step->set_solver(scene.solver.tolerance, scene.solver.max_iterations);
  a.one_step_symplectic = registry.find(scene.one_step->kind, scene.one_step->type).declared.symplectic;
}

DeclaredMethod declared(const Assembly& a) {
  const std::string equivariance = a.one_step->equivariance();
  return DeclaredMethod{a.one_step->order(), a.one_step->self_adjoint(), a.one_step_symplectic,
                        equivariance == "affine" || equivariance == "left",
                        a.manifold->is_vector_space() || equivariance == "left"};
}

nlohmann::json plugin_schema(const char* description) {
  return {{"description", description},
          {"type", "object"},
          {"required", {"type"}},
          {"properties", {{"type", {{"description", "the plugin's type name"}, {"type", "string"}}}}}};
}

nlohmann::json method_schema(const char* construction, nlohmann::json keys, std::vector<std::string> required) {
  nlohmann::json properties = {
      {"construction", {{"description", "the construction"}, {"const", construction}}},
      {"solver",
       {{"description", "{\"tolerance\": number > 0, \"max_iterations\": integer >= 1}: the nonlinear solver's options"},
        {"type", "object"},
        {"additionalProperties", false},
        {"properties",
         {{"tolerance",
           {{"description",
             "the Newton stopping rule's tolerance: a solve ends when the residual is within tolerance (1 + the size "
             "of its terms), the update within tolerance (1 + the size of the unknowns), or the residual stagnates "
             "at round-off (docs/architecture.md)"},
            {"type", "number"},
            {"exclusiveMinimum", 0}}},
          {"max_iterations",
           {{"description", "the most Newton updates a solve may take before it is a numerical failure (exit 4)"},
            {"type", "integer"},
            {"minimum", 1},
            {"maximum", 1000000}}}}}}}};
  properties.update(keys);
  required.insert(required.begin(), "construction");
  return {{"description", std::string("the method of construction '") + construction + "'"},
          {"type", "object"},
          {"required", required},
          {"additionalProperties", false},
          {"properties", properties}};
}

std::string describe_parts(const Scene& scene, std::string words) {
  if (scene.one_step) words += " with " + scene.one_step->type;
  if (scene.quadrature) words += ", quadrature " + scene.quadrature->type + " " + scene.quadrature->parameters.dump();
  return words;
}

}  // namespace varia::host
