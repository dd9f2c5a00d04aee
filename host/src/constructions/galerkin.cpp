// The Galerkin construction (paper, sec. 2): the degree-s Lagrange interpolant through s + 1
// control points at control times d_0 = 0 < ... < d_s = 1, the action by a quadrature rule, the
// internal control points extremized; on a Lie group in the natural chart at q0 (sec. 2,
// "Natural charts"). Core: varia/core/galerkin.hpp (vector spaces), galerkin_chart.hpp (groups).
#include <fmt/format.h>

#include <cmath>

#include "../json_schema.hpp"
#include "construction.hpp"
#include "parts.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"

namespace varia::host {

namespace {

using nlohmann::json;

struct GalerkinOptions : MethodOptions {
  int degree = 0;
  std::vector<double> control_times;  // s + 1 of them, equispaced unless the scene gives them
  bool reduced = false;
};

// Control times symmetric about 1/2: d_nu + d_{s-nu} = 1 (paper, sec. 3: self-adjointness).
bool symmetric(const std::vector<double>& d) {
  for (std::size_t nu = 0; nu < d.size(); ++nu)
    if (std::abs(d[nu] + d[d.size() - 1 - nu] - 1.0) > 1e-14) return false;
  return true;
}

class Galerkin final : public Construction {
 public:
  const char* name() const override { return "galerkin"; }
  bool takes_forces() const override { return true; }

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
          {{"description", "s+1 increasing control times from 0 to 1 (default: equispaced)"},
           {"type", "array"},
           {"minItems", 2},
           {"items", {{"description", "a control time"}, {"type", "number"}, {"minimum", 0}, {"maximum", 1}}}}},
         {"reduced",
          {{"description",
            "on a Lie group: solve the reduced (higher-order discrete Euler-Poincare) equations; needs a "
            "Lagrangian invariant under the whole group"},
           {"type", "boolean"}}}},
        {"quadrature", "degree"});
  }

  std::shared_ptr<const MethodOptions> read(const json& method) const override {
    auto options = std::make_shared<GalerkinOptions>();
    options->degree = method["degree"].get<int>();
    options->reduced = method.value("reduced", false);
    options->control_times = method.contains("control_times")
                                 ? method["control_times"].get<std::vector<double>>()
                                 : equispaced_control_times(options->degree);
    check_control_times(options->control_times, options->degree);
    return options;
  }

  void build(const Scene& scene, Registry& registry, Assembly& a) const override {
    const auto& o = options(scene);
    a.quadrature = make_part<Quadrature>(registry, *scene.quadrature, scene, *a.manifold);
    if (!a.manifold->is_vector_space()) return build_on_group(scene, o, a);
    if (o.reduced)
      throw InputError("/method/reduced: the reduced (Euler-Poincare) form is for Lie groups; " + scene.manifold.type +
                       " is a vector space");
    auto map = std::make_unique<GalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                            o.control_times, scene.solver, forces_of(a));
    a.discrete_lagrangian = map.get();
    a.map = std::move(map);
  }

  // Order min(2s, quadrature order); self-adjoint for a symmetric rule and symmetric control
  // times on a vector space (the chart at q0 of a Lie group is not symmetric in q0 and q1: no
  // prediction there); G-invariant L_d from the equivariant interpolant.
  Predictions predict(const Scene& scene, const Assembly& a) const override {
    const auto& o = options(scene);
    Predictions p;
    p.ld_order = p.global_order = std::min(2 * o.degree, quadrature_order(*a.quadrature));
    if (a.manifold->is_vector_space()) p.self_adjoint = a.quadrature->symmetric() && symmetric(o.control_times);
    p.symplectic = p.energy_bounded = true;
    p.reason = "Galerkin (sec. 2): order min(2s, quadrature order); self-adjoint for a symmetric rule and control "
               "times (on a vector space: the natural chart at q0 of a Lie group is not symmetric); G-invariant L_d "
               "from an equivariant interpolant";
    apply_shared_theorems(a, true, p);
    return p;
  }

  std::string describe(const Scene& scene) const override {
    return describe_parts(scene, fmt::format("galerkin degree {}", options(scene).degree));
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

Scene galerkin_reference(const Scene& scene, int degree, int points) {
  Scene reference = scene;
  const json quadrature{{"type", "gauss-legendre"}, {"points", points}};
  reference.construction = &galerkin_construction();
  reference.method_options =
      reference.construction->read({{"construction", "galerkin"}, {"degree", degree}, {"quadrature", quadrature}});
  reference.quadrature = PluginSpec{"/method/quadrature", "quadrature", "gauss-legendre", {{"points", points}}};
  reference.one_step.reset();
  return reference;
}

}  // namespace varia::host
