// The shooting construction (paper, sec. 3): L_d = h sum_i b_i L(q^i, v^i) along a one-step
// method's propagation from q0 to q1, in the Lagrangian, Hamiltonian (Type I) or Type II form;
// on a Lie group in the natural charts. Core: varia/core/shooting.hpp.
#include <fmt/format.h>

#include "construction.hpp"
#include "parts.hpp"
#include "varia/core/shooting.hpp"

namespace varia::host {

namespace {

using nlohmann::json;

struct ShootingOptions : MethodOptions {
  std::string form = "lagrangian";
};

class Shooting final : public Construction {
 public:
  const char* name() const override { return "shooting"; }
  bool takes_forces() const override { return true; }
  // With quadratic constraints on a vector space (docs/constraints.md): the shot is the constrained
  // one-step map, the construction runs in charts of the constraint manifold (core/shooting.hpp).
  bool takes_constraints(ManifoldStructure structure) const override {
    return structure == ManifoldStructure::vector_space;
  }

  json schema() const override {
    return method_schema(
        "shooting",
        {{"quadrature", plugin_schema("the quadrature plugin; its nodes may include 0 and 1")},
         {"one_step", plugin_schema("the one-step method that propagates, e.g. {\"type\": \"rk4\"}")},
         {"form",
          {{"description", "the shooting form: the method integrates the Euler-Lagrange equations (lagrangian), "
                           "Hamilton's equations (hamiltonian), or the discrete Hamiltonian H_d^+ (type-2)"},
           {"enum", {"lagrangian", "hamiltonian", "type-2"}}}}},
        {"quadrature", "one_step"});
  }

  std::shared_ptr<const MethodOptions> read(const json& method) const override {
    auto options = std::make_shared<ShootingOptions>();
    options->form = method.value("form", options->form);
    return options;
  }

  void build(const Scene& scene, Registry& registry, Assembly& a) const override {
    a.quadrature = make_part<Quadrature>(registry, *scene.quadrature, scene, *a.manifold);
    make_one_step(scene, registry, a);
    try {
      auto map = std::make_unique<ShootingDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                              *a.one_step, shooting_form(options(scene).form),
                                                              scene.solver, forces_of(a), kMaxJetVariables,
                                                              a.holonomic.get());
      a.discrete_lagrangian = map.get();
      a.map = std::move(map);
    } catch (const ConstraintsRefused& e) {
      throw InputError(fmt::format("{}: {}", constraints_pointer(scene), e.what()));
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("/method: {}", e.what()));
    }
  }

  // The paper's theorem (sec. 3): order min(p, quadrature order); self-adjoint for a self-adjoint
  // method and a symmetric rule (the proposition is for the Type I form: nothing for type-2);
  // G-invariant for a G-equivariant method; symplectic and, with an invariant L_d,
  // momentum-conserving as a variational integrator on Q x Q, which needs a propagation that stays
  // on Q (on a Lie group: a Lie group method).
  Predictions predict(const Scene& scene, const Assembly& a) const override {
    const DeclaredMethod method = declared(a);
    const bool type_2 = options(scene).form == "type-2";
    Predictions p;
    p.ld_order = p.global_order = std::min(method.order, quadrature_order(*a.quadrature));
    p.orders_are_bounds = true;
    if (!type_2) p.self_adjoint = method.self_adjoint && a.quadrature->symmetric();
    p.symplectic = p.energy_bounded = true;
    p.reason = "shooting (sec. 3 theorem): order min(p, q); self-adjoint for a self-adjoint method and a symmetric "
               "rule (Type I form; no prediction for type-2); G-invariant for a G-equivariant method";
    if (a.holonomic) {  // L_d's own order is not measured: verify's sampled pairs leave Q (docs/constraints.md)
      p.self_adjoint.reset();
      p.ld_order.reset();
      p.reason += "; with constraints the shot is the method's index-1 steps each projected onto the constraint "
                  "(Hairer, Lubich & Wanner, sec. IV.4), of order p, not self-adjoint: the theorem on the "
                  "constraint manifold Q, L_d a function on Q x Q (symplectic on Q), no self-adjointness predicted";
    }
    apply_shared_theorems(a, method.equivariant, p);
    if (!method.stays_on_group) {
      p.symplectic.reset();
      p.energy_bounded.reset();
      p.momentum_conserved.reset();
      p.reason += "; the method's propagation leaves the group: L_d is not a function on G x G, no conservation "
                  "theorem applies";
    }
    return p;
  }

  std::string describe(const Scene& scene) const override {
    const std::string& form = options(scene).form;
    return describe_parts(scene, form == "lagrangian" ? "shooting" : "shooting (" + form + " form)");
  }

 private:
  static const ShootingOptions& options(const Scene& scene) {
    return static_cast<const ShootingOptions&>(*scene.method_options);
  }
};

}  // namespace

const Construction& shooting_construction() {
  static const Shooting construction;
  return construction;
}

}  // namespace varia::host
