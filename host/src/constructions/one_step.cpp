// The one-step construction: no discrete Lagrangian; a one-step method integrates the
// Euler-Lagrange equations directly (the comparison methods of the paper's Figure 1). Core:
// varia/core/one_step_map.hpp.
#include "construction.hpp"
#include "parts.hpp"
#include "varia/core/one_step_map.hpp"

namespace varia::host {

namespace {

using nlohmann::json;

class OneStep final : public Construction {
 public:
  const char* name() const override { return "one-step"; }

  json schema() const override {
    return method_schema(
        "one-step", {{"one_step", plugin_schema("the one-step method, e.g. {\"type\": \"implicit-midpoint\"}")}},
        {"one_step"});
  }

  std::shared_ptr<const MethodOptions> read(const json&) const override { return std::make_shared<MethodOptions>(); }

  // With constraints (docs/constraints.md): the index-1 equations and the projection after each step,
  // for explicit Runge-Kutta methods, and implicit ones with quadratic constraints (core/constrained_field.hpp).
  bool takes_constraints(ManifoldStructure structure) const override {
    return structure == ManifoldStructure::vector_space;
  }

  void build(const Scene& scene, Registry& registry, Assembly& a) const override {
    make_one_step(scene, registry, a);
    try {
      a.map = std::make_unique<OneStepHamiltonianMap>(*a.manifold, *a.lagrangian, *a.one_step, scene.solver,
                                                      a.holonomic.get());
    } catch (const ConstraintsRefused& e) {
      throw InputError(constraints_pointer(scene) + ": " + e.what());
    } catch (const std::invalid_argument& e) {
      if (!a.holonomic) throw;
      throw InputError(std::string("/method/one_step: ") + e.what());
    }
  }

  // What the method declares: its order, self-adjointness and symplecticity; a symplectic method
  // that commutes with the symmetry conserves its momentum map (no L_d, no G-invariance claim).
  // A Runge-Kutta method's symplecticity is for canonical coordinates: on a Lie group it integrates
  // (q, velocity) in the embedding, which are not, so it is predicted not symplectic there.
  Predictions predict(const Scene&, const Assembly& a) const override {
    const DeclaredMethod method = declared(a);
    const bool symplectic = method.symplectic && method.stays_on_group;
    Predictions p;
    p.global_order = method.order;
    p.self_adjoint = method.self_adjoint;
    p.symplectic = symplectic;
    if (symplectic) p.energy_bounded = true;
    if (declares_symmetry(*a.lagrangian) && symplectic && method.equivariant) p.momentum_conserved = true;
    p.reason = "one-step method: its declared order, self-adjointness and symplecticity (no L_d)";
    if (a.holonomic) {
      p.symplectic = false;
      p.energy_bounded.reset();
      p.momentum_conserved.reset();
      p.reason += "; with constraints the method integrates their index-1 form and each step is projected onto the "
                  "constraint and its hidden constraint (Hairer, Lubich & Wanner, sec. IV.4, standard projection): "
                  "the order is kept, the map is not symplectic, and no conservation is predicted";
    }
    if (method.symplectic && !symplectic)
      p.reason += "; its symplecticity is for canonical coordinates, and on a Lie group it integrates in the "
                  "embedding: predicted not symplectic";
    apply_shared_theorems(a, std::nullopt, p);
    return p;
  }

  std::string describe(const Scene& scene) const override { return describe_parts(scene, "one-step"); }
};

}  // namespace

const Construction& one_step_construction() {
  static const OneStep construction;
  return construction;
}

}  // namespace varia::host
