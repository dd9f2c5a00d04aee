// What the construction files share: creating a part named in the scene, the forces as the core
// takes them, and the theorems that hold whatever the construction (discrete Noether, forces).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "../assemble.hpp"
#include "../registry.hpp"
#include "../scene.hpp"
#include "varia/abi/force.hpp"
#include "varia/core/verification.hpp"

namespace varia::host {

inline sdk::Context context_of(const Scene& scene, const Manifold& manifold) {
  return sdk::Context{manifold_name(scene.manifold), manifold.point_size(), manifold.dim()};
}

// The JSON pointer a plugin's refusal names: the spec's, joined with the parameter path the
// refusal starts with when it names one of the object's parameters ("terms/1: ..." from a
// composite, CompositeLagrangian's convention), so that the message points at the value at fault.
std::string refusal_pointer(const PluginSpec& spec, std::string& message);

// The plugin object a scene's plugin spec names, made after its parts (PluginSpec::parts), which
// it keeps; a parameter value the plugin refuses is bad input at the spec's JSON pointer.
template <class T>
std::shared_ptr<T> make_part(Registry& registry, const PluginSpec& spec, const sdk::Context& context) {
  std::vector<MadePart> parts;
  for (const PluginSpec& part : spec.parts)
    parts.push_back(MadePart{part.role, make_part<PluginObject>(registry, part, context)});
  try {
    return registry.create_as<T>(spec.kind, spec.type, spec.parameters, context, std::move(parts));
  } catch (const InputError& e) {
    std::string message = e.what();
    const std::string pointer = refusal_pointer(spec, message);
    throw InputError(pointer + ": " + message);
  }
}
template <class T>
std::shared_ptr<T> make_part(Registry& registry, const PluginSpec& spec, const Scene& scene, const Manifold& manifold) {
  return make_part<T>(registry, spec, context_of(scene, manifold));
}

inline std::vector<Force*> forces_of(const Assembly& a) {
  std::vector<Force*> forces;
  for (const auto& force : a.forces) forces.push_back(force.get());
  return forces;
}

// Whether the Lagrangian declares a symmetry group (Noether: a momentum map to conserve).
inline bool declares_symmetry(const Lagrangian& lagrangian) {
  return std::string(lagrangian.symmetry_group()) != "none";
}

// The declared order of a quadrature rule as the theorems use it: its degree of exactness + 1.
inline int quadrature_order(const Quadrature& rule) { return rule.degree() + 1; }

// The scene's one-step method, with the solver options of its stages, into a.one_step; and what it
// declares, as the theorems use it.
struct DeclaredMethod {
  int order = 0;
  bool self_adjoint = false, symplectic = false;
  // Commutes with the Lagrangian's symmetry: "affine" (Runge-Kutta methods) with every linear group
  // action on R^n, e.g. rotations, and on a matrix group with left multiplication, linear in the
  // embedding it integrates in; "left" (Lie group methods) with left multiplication on the group,
  // and with affine maps where the group is R^n.
  bool equivariant = false;
  // Its propagation stays on the manifold: every method on a vector space; on a Lie group only a
  // Lie group method ("left"), not a Runge-Kutta method integrating in the embedding, whose stages
  // leave the group (and whose coordinates there are not canonical).
  bool stays_on_group = true;
};
void make_one_step(const Scene& scene, Registry& registry, Assembly& a);
DeclaredMethod declared(const Assembly& a);

// The theorems every construction shares, applied to its own predictions:
// - discrete Noether (paper, sec. 1): a G-invariant L_d conserves the discrete momentum map;
//   `ld_invariant` is whether the construction's L_d is G-invariant for a G-invariant L (null
//   where it has no L_d);
// - forces (discrete Lagrange-d'Alembert) keep the order but none of the conservation theorems.
void apply_shared_theorems(const Assembly& a, std::optional<bool> ld_invariant, Predictions& p);

// The schema of a "method" object naming `construction`: its own `keys` (JSON schema properties),
// the `required` ones among them, and the keys every construction takes (construction, solver:
// the nonlinear solver's options) unless `keys` overrides them; no other key is allowed.
nlohmann::json method_schema(const char* construction, nlohmann::json keys, std::vector<std::string> required);
// The schema of a plugin object (a JSON object with a "type") in a method, e.g. its quadrature.
nlohmann::json plugin_schema(const char* description);

// `scene`'s method described for summaries: the construction's words, then its one-step method
// and quadrature if it has them.
std::string describe_parts(const Scene& scene, std::string words);

}  // namespace varia::host
