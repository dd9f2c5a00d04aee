// The Galerkin construction (paper, sec. 2): the degree-s Lagrange interpolant through s + 1
// control points at control times d_0 = 0 < ... < d_s = 1, the action by a quadrature rule, the
// internal control points extremized; on a Lie group in the natural chart at q0 (sec. 2,
// "Natural charts"). Core: varia/core/galerkin.hpp (vector spaces), galerkin_chart.hpp (groups).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "../json_schema.hpp"
#include "construction.hpp"
#include "parts.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/galerkin_sphere.hpp"

namespace varia::host {

namespace {

using nlohmann::json;

struct GalerkinOptions : MethodOptions {
  int degree = 0;
  // s + 1 of them; unless the scene gives them, Chebyshev-Gauss-Lobatto times (galerkin.hpp): the
  // polynomial space of the equispaced times the contract names, solved in a basis that keeps
  // round-off at high degree.
  std::vector<double> control_times;
  bool control_times_given = false;
  bool reduced = false;
  bool natural_chart = false;  // "chart": "natural" (S2 and products of S2)
};

// What a quadrature rule determines of the degree-s interpolant. Its velocity, a polynomial of
// degree s - 1, is seen at the r nodes with a weight; s nodes determine it, and the order is
// min(2s, the rule's order) (paper, sec. 2). With r < s the rule is too weak: the s - r velocities
// that vanish at every node are invisible to the kinetic energy and fixed, if at all, only through
// the potential's Hessian at the interior nodes. That hypothesis depends on the trajectory (the
// pendulum's Hessian cos q vanishes at q = pi/2; a projectile has none), so no run can promise it:
// s = 3 with 2 Gauss points at h = 0.2 leaves every sane range within 100 steps, and on SO(3) such
// compositions fail within a few steps. The composition is refused (r = 0 interior directions left
// fixed gives a singular or non-converging L_d in any case: s = 2 with the midpoint rule).
struct Determination {
  int nodes = 0;  // r: the nodes with a weight
  int order = 0;  // min(2s, the rule's order) where r >= s
  std::string how;
};

Determination determination(const Quadrature& rule, int s) {
  Determination d;
  for (int i = 0; i < rule.size(); ++i)
    if (rule.weights()[i] != 0.0) ++d.nodes;
  d.order = std::min(2 * s, quadrature_order(rule));
  d.how = fmt::format("order min(2s, quadrature order) = min({}, {}): {} nodes determine the degree-{} velocity",
                      2 * s, quadrature_order(rule), d.nodes, s - 1);
  return d;
}

// With constraints the control points carry them (core/galerkin.hpp): unless the scene gives control
// times, they are the rule's nodes where the rule has s + 1 nodes from 0 to 1 (a Lobatto rule), so
// that the equations are Jay's Lobatto IIIA-IIIB ones; otherwise the options' times.
std::vector<double> control_times(const GalerkinOptions& o, const Quadrature& rule, const Assembly& a) {
  const std::vector<double> nodes(rule.nodes(), rule.nodes() + rule.size());
  const bool fits = static_cast<int>(nodes.size()) == o.degree + 1 && nodes.front() == 0.0 && nodes.back() == 1.0;
  return a.holonomic && !o.control_times_given && fits ? nodes : o.control_times;
}

// Jay's theorem (SIAM J. Numer. Anal. 33, 1996: the s-stage Lobatto IIIA-IIIB pair for constrained
// mechanical systems, constraints and multipliers at every stage, has order 2s - 2 in q and p) for
// degree s: control times at the nodes of a rule of s + 1 nodes from 0 to 1 exact to degree 2s - 1
// (the Lobatto rule of s + 1 points, the only one), order 2s.
bool lobatto_constrained(const GalerkinOptions& o, const Quadrature& rule, const Assembly& a) {
  const std::vector<double> times = control_times(o, rule, a);
  return rule.size() == o.degree + 1 && rule.degree() >= 2 * o.degree - 1 &&
         std::equal(times.begin(), times.end(), rule.nodes());
}

class Galerkin final : public Construction {
 public:
  const char* name() const override { return "galerkin"; }
  bool takes_forces() const override { return true; }
  bool takes_constraints(ManifoldStructure structure) const override {
    return structure == ManifoldStructure::vector_space;
  }

  json schema() const override {
    return method_schema(
        "galerkin",
        {{"quadrature", plugin_schema("the quadrature plugin, e.g. {\"type\": \"gauss-lobatto\", \"points\": 3}")},
         {"degree",
          {{"description", "the polynomial degree s of the interpolant"},
           {"type", "integer"},
           {"minimum", 1},
           {"maximum", 32}}},
         {"control_times",
          {{"description", "s+1 increasing control times from 0 to 1 (default: Chebyshev-Gauss-Lobatto times (1 - cos(pi k/s))/2, the same interpolant space as equispaced times, better conditioned at high degree)"},
           {"type", "array"},
           {"minItems", 2},
           {"items", {{"description", "a control time"}, {"type", "number"}, {"minimum", 0}, {"maximum", 1}}}}},
         {"reduced",
          {{"description",
            "on a Lie group: solve the reduced (higher-order discrete Euler-Poincare) equations; needs a "
            "Lagrangian invariant under the whole group, for which the step takes them whether asked or not "
            "(the same equations, without position jets)"},
           {"type", "boolean"}}},
         {"chart",
          {{"description",
            "on S2 and products of S2: 'natural' interpolates each factor in the sphere's natural chart at q0, "
            "q(t) = Exp_q0(w(t)) with w(t) in the tangent plane (the curves stay on the sphere, no multipliers; "
            "2 N s <= 12 unknowns a step for N spheres at degree s); 'embedding' (the default) interpolates in R^3 "
            "with the multipliers of the sphere's equation (docs/constraints.md)"},
           {"enum", {"embedding", "natural"}}}}},
        {"quadrature", "degree"});
  }

  std::shared_ptr<const MethodOptions> read(const json& method) const override {
    auto options = std::make_shared<GalerkinOptions>();
    options->degree = method["degree"].get<int>();
    options->reduced = method.value("reduced", false);
    options->natural_chart = method.value("chart", std::string("embedding")) == "natural";
    options->control_times_given = method.contains("control_times");
    options->control_times = method.contains("control_times")
                                 ? method["control_times"].get<std::vector<double>>()
                                 : chebyshev_lobatto_control_times(options->degree);
    check_control_times(options->control_times, options->degree);
    return options;
  }

  void build(const Scene& scene, Registry& registry, Assembly& a) const override {
    const auto& o = options(scene);
    a.quadrature = make_part<Quadrature>(registry, *scene.quadrature, scene, *a.manifold);
    if (const Determination d = determination(*a.quadrature, o.degree); d.nodes < o.degree)
      throw InputError(fmt::format(
          "{}: the rule is too weak for degree {}: its {} weighted nodes see {} of the {} coefficients of the "
          "degree-{} velocity, and the rest are fixed, if at all, only through the potential's Hessian along the "
          "trajectory (no theorem, and the steps then have roots that leave every sane range); use a rule with at "
          "least {} weighted nodes, e.g. {{\"type\": \"gauss-legendre\", \"points\": {}}}",
          scene.quadrature->pointer, o.degree, d.nodes, d.nodes, o.degree, o.degree - 1, o.degree, o.degree));
    if (o.natural_chart) return build_in_sphere_chart(scene, o, a);
    if (!a.manifold->is_vector_space()) return build_on_group(scene, o, a);
    if (o.reduced)
      throw InputError("/method/reduced: the reduced (Euler-Poincare) form is for Lie groups; " + scene.manifold.type +
                       " is a vector space");
    auto map = std::make_unique<GalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                            control_times(o, *a.quadrature, a), scene.solver,
                                                            forces_of(a), a.holonomic.get());
    a.discrete_lagrangian = map.get();
    a.map = std::move(map);
  }

  // The order from what the rule determines (determination()); self-adjoint for a symmetric rule on
  // a vector space, whatever the control times: L_d extremizes over the polynomials of degree s,
  // which the control times only parametrize (the chart at q0 of a Lie group is not symmetric in q0
  // and q1: no prediction there); G-invariant L_d from the equivariant interpolant.
  Predictions predict(const Scene& scene, const Assembly& a) const override {
    const Determination d = determination(*a.quadrature, options(scene).degree);
    Predictions p;
    p.ld_order = p.global_order = d.order;
    p.orders_are_bounds = true;
    if (options(scene).natural_chart) return predict_in_sphere_chart(a, d, p);
    if (a.manifold->is_vector_space()) p.self_adjoint = a.quadrature->symmetric();
    p.symplectic = p.energy_bounded = true;
    p.reason = "Galerkin (sec. 2): " + d.how +
               "; self-adjoint for a symmetric rule on a vector space (L_d depends on the polynomial space, not on "
               "the control times; the natural chart at q0 of a Lie group is not symmetric); G-invariant L_d from an "
               "equivariant interpolant";
    if (a.holonomic) predict_constrained(scene, a, p);
    apply_shared_theorems(a, true, p);
    return p;
  }

  // With constraints at the control points (docs/constraints.md): the constrained discrete
  // Euler-Lagrange equations are symplectic on the constraint's cotangent bundle (Marsden & West
  // 2001, sec. 3.5), and so keep the energy bounded; the order is Jay's where the equations are the
  // Lobatto IIIA-IIIB pair's, otherwise no theorem gives one; L_d's own order is not predicted.
  static void predict_constrained(const Scene& scene, const Assembly& a, Predictions& p) {
    const auto& o = options(scene);
    p.ld_order.reset();
    p.global_order.reset();
    const std::vector<double> t = control_times(o, *a.quadrature, a);
    bool symmetric_times = true;
    for (std::size_t k = 0; k < t.size(); ++k) symmetric_times = symmetric_times && std::abs(t[k] + t[t.size() - 1 - k] - 1.0) <= 1e-14;
    if (p.self_adjoint) p.self_adjoint = *p.self_adjoint && symmetric_times;
    if (lobatto_constrained(o, *a.quadrature, a)) {
      p.global_order = 2 * o.degree;
      p.reason = fmt::format("constrained Galerkin with control points at the {} Lobatto nodes: Jay's Lobatto IIIA-IIIB "
                             "equations, order 2s = {} (Jay 1996); symplectic on the constraint's cotangent bundle "
                             "(Marsden & West 2001, sec. 3.5)",
                             o.degree + 1, 2 * o.degree);
    } else {
      p.reason = "constrained Galerkin with control points not at the nodes of a Lobatto rule of s + 1 points: no "
                 "theorem gives its order (not predicted); symplectic on the constraint's cotangent bundle (Marsden & "
                 "West 2001, sec. 3.5)";
    }
    p.reason += "; self-adjoint for a symmetric rule with symmetric control times; L_d's order not predicted";
  }

  std::string describe(const Scene& scene) const override {
    return describe_parts(scene, fmt::format("galerkin degree {}{}", options(scene).degree,
                                             options(scene).natural_chart ? " in the natural chart of S2" : ""));
  }

 private:
  static const GalerkinOptions& options(const Scene& scene) {
    return static_cast<const GalerkinOptions&>(*scene.method_options);
  }

  // Spec: s+1 control points at times 0 = d_0 < ... < d_s = 1.
  static void check_control_times(const std::vector<double>& times, int degree) {
    bool ok = static_cast<int>(times.size()) == degree + 1 && times.front() == 0.0 && times.back() == 1.0;
    for (std::size_t i = 1; ok && i < times.size(); ++i) ok = times[i - 1] < times[i];
    if (!ok)
      throw InputError(fmt::format(
          "/method/control_times: expected degree + 1 = {} increasing numbers from 0 to 1; found {}", degree + 1,
          brief(json(times))));
  }

  // On S2 and products of S2 with "chart": "natural", each factor's interpolant lives in the
  // sphere's natural chart at q0 (core/galerkin_sphere.hpp); the spheres' equations stay in
  // a.holonomic for the observables, the initial state's check and verify's bundle, not in the steps.
  static void build_in_sphere_chart(const Scene& scene, const GalerkinOptions& o, Assembly& a) {
    const bool spheres = a.embedded && a.holonomic && a.holonomic->size() * 3 == a.manifold->dim();
    if (!spheres || !scene.constraints.empty())
      throw InputError(fmt::format("/method/chart: 'natural' is the natural chart of S2 and of products of S2, "
                                   "without the scene's own constraints; the {} manifold{} takes 'embedding' "
                                   "(Lie groups always interpolate in their natural chart)",
                                   scene.manifold.type, scene.constraints.empty() ? "" : " with constraints"));
    if (!a.forces.empty())
      throw InputError("/system/forces: the galerkin construction in the natural chart of S2 takes no forces");
    if (o.reduced) throw InputError("/method/reduced: the reduced (Euler-Poincare) form is for Lie groups");
    const int spheres_count = a.holonomic->size();
    if (const int unknowns = SphereGalerkinMap::unknowns(spheres_count, o.degree); unknowns > kMaxJetVariables)
      throw InputError(fmt::format("/method/degree: in the natural chart of S2 a step has 2 N s unknowns, at most {} "
                                   "(the variables of the jets that give its Newton Jacobian); {} sphere(s) at degree "
                                   "{} have {}: take degree <= {}, or 'embedding'",
                                   kMaxJetVariables, spheres_count, o.degree, unknowns,
                                   kMaxJetVariables / (2 * spheres_count)));
    if (a.quadrature->derivative_terms() > 0)
      throw InputError("/method/quadrature: the natural chart of S2 takes rules without derivative terms");
    auto map = std::make_unique<SphereGalerkinMap>(*a.lagrangian, *a.quadrature, o.control_times, scene.solver,
                                                   *a.holonomic);
    a.discrete_lagrangian = map.get();
    a.map = std::move(map);
  }

  // Galerkin's order theorem (sec. 2) holds in any smooth chart: L_d is the chart's pulled-back
  // Lagrangian's Galerkin L_d; no multiplier enters, so the order is the unconstrained one, and the
  // map is variational on T*S2 (symplectic, energy bounded). The chart at q0 is not symmetric in q0
  // and q1 (no self-adjointness predicted), and SO(3)-equivariant: Exp_{R q0}(R w) = R Exp_{q0}(w),
  // so L_d is invariant under every rotation that leaves L invariant.
  static Predictions predict_in_sphere_chart(const Assembly& a, const Determination& d, Predictions& p) {
    p.ld_order.reset();
    p.symplectic = p.energy_bounded = true;
    p.reason = "Galerkin (sec. 2) in the natural chart of S2 at q0: " + d.how +
               "; variational on T*S2 without multipliers (symplectic, energy bounded); the chart at q0 is not "
               "symmetric in q0 and q1 (self-adjointness not predicted); G-invariant L_d from the SO(3)-equivariant "
               "chart; L_d's order not predicted (its local error is the global order's, h^(r+1), only where the "
               "chart's exact discrete Lagrangian is compared, which the measurement does not do)";
    apply_shared_theorems(a, true, p);
    return p;
  }

  // On a Lie group the interpolant lives in the natural chart at q0 (core/galerkin_chart.hpp).
  static void build_on_group(const Scene& scene, const GalerkinOptions& o, Assembly& a) {
    if (!a.forces.empty())
      throw InputError("/system/forces: the galerkin construction takes forces on vector spaces only, not on " +
                       scene.manifold.type);
    try {
      auto map = std::make_unique<LieGroupGalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                                      o.control_times, scene.solver, o.reduced);
      a.discrete_lagrangian = map.get();
      a.map = std::move(map);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string(o.reduced ? "/method/reduced: " : "/method: ") + e.what());
    }
  }
};

}  // namespace

const Construction& galerkin_construction() {
  static const Galerkin construction;
  return construction;
}

Scene galerkin_reference(const Scene& scene, const Assembly& a, int degree, int points) {
  Scene reference = scene;
  // With constraints (the scene's, or an embedded manifold's equations): Lobatto's rule of
  // degree + 1 points, the control points at its nodes (Jay's Lobatto IIIA-IIIB equations, order
  // 2 degree), as no theorem gives Gauss's order there.
  const bool constrained = a.holonomic != nullptr;
  const std::string rule = constrained ? "gauss-lobatto" : "gauss-legendre";
  if (constrained) points = degree + 1;
  const json quadrature{{"type", rule}, {"points", points}};
  reference.construction = &galerkin_construction();
  reference.method_options =
      reference.construction->read({{"construction", "galerkin"}, {"degree", degree}, {"quadrature", quadrature}});
  reference.quadrature = PluginSpec{"/method/quadrature", "quadrature", rule, {{"points", points}}};
  reference.one_step.reset();
  return reference;
}

}  // namespace varia::host
