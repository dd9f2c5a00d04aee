// The Lie group velocity Verlet (LGVI) for Lagrangians of rigid-body form on SO(3) (paper, sec. 2
// example), with the Cayley or the exponential solver. Core: varia/core/lie_verlet.hpp.
#include "construction.hpp"
#include "parts.hpp"
#include "varia/core/lie_verlet.hpp"

namespace varia::host {

namespace {

using nlohmann::json;

struct LieVerletOptions : MethodOptions {
  LieVerletSolver solver = LieVerletSolver::cayley;
};

class LieVerlet final : public Construction {
 public:
  const char* name() const override { return "lie-verlet"; }

  json schema() const override {
    return method_schema("lie-verlet",
                         {{"solver",
                           {{"description", "how the implicit attitude equation is solved: \"cayley\" (default) or "
                                            "\"exp\""},
                            {"enum", {"cayley", "exp"}}}}},
                         {});
  }

  std::shared_ptr<const MethodOptions> read(const json& method) const override {
    auto options = std::make_shared<LieVerletOptions>();
    if (method.value("solver", "cayley") == "exp") options->solver = LieVerletSolver::exp;
    return options;
  }

  void build(const Scene& scene, Registry&, Assembly& a) const override {
    try {
      auto map = std::make_unique<LieGroupVelocityVerlet>(*a.manifold, *a.lagrangian, options(scene).solver,
                                                          scene.solver);
      a.discrete_lagrangian = map.get();
      a.map = std::move(map);
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("/method/construction: ") + e.what());
    }
  }

  // Order 2, symplectic, G-invariant (its L_d is the trapezoid-rule L_d of the exponential chart).
  Predictions predict(const Scene&, const Assembly& a) const override {
    Predictions p;
    p.ld_order = p.global_order = 2;
    p.self_adjoint = p.symplectic = p.energy_bounded = true;
    p.reason = "Lie group velocity Verlet (sec. 2 example): order 2, symplectic, G-invariant";
    apply_shared_theorems(a, true, p);
    return p;
  }

  std::string describe(const Scene& scene) const override {
    return options(scene).solver == LieVerletSolver::exp ? "lie-verlet (exp solver)" : "lie-verlet (cayley solver)";
  }

 private:
  static const LieVerletOptions& options(const Scene& scene) {
    return static_cast<const LieVerletOptions&>(*scene.method_options);
  }
};

}  // namespace

const Construction& lie_verlet_construction() {
  static const LieVerlet construction;
  return construction;
}

}  // namespace varia::host
