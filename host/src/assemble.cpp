#include "assemble.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <map>

#include "registry.hpp"
#include "varia/core/composite.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/lie_verlet.hpp"
#include "varia/core/one_step_map.hpp"
#include "varia/core/shooting.hpp"
#include "varia/core/mechanics.hpp"

namespace varia::host {

namespace {

sdk::Context context_of(const Scene& scene, const Manifold& manifold) {
  return sdk::Context{scene.manifold.type, manifold.point_size(), manifold.dim()};
}

template <class T>
std::shared_ptr<T> make(Registry& registry, const PluginSpec& spec, const sdk::Context& context) {
  return registry.create_as<T>(spec.kind, spec.type, spec.parameters, context);
}

// ---- constructions: one function each, chosen by method.construction -------------------------

using Construction = std::function<void(const Scene&, Registry&, Assembly&)>;

// Control times symmetric about 1/2: d_nu + d_{s-nu} = 1 (paper, sec. 3: self-adjointness).
bool symmetric_times(const std::vector<double>& d) {
  for (std::size_t nu = 0; nu < d.size(); ++nu)
    if (std::abs(d[nu] + d[d.size() - 1 - nu] - 1.0) > 1e-14) return false;
  return true;
}

void describe_quadrature(const Quadrature& quadrature, Composition& composition) {
  composition.quadrature_order = quadrature.degree() + 1;
  composition.quadrature_symmetric = quadrature.symmetric();
}

// On a Lie group the interpolant lives in the natural chart at q0 (core/galerkin_chart.hpp).
void lie_group_galerkin(const Scene& scene, std::vector<double> times, Assembly& a) {
  if (!a.forces.empty())
    throw InputError("/system/forces: the galerkin construction takes forces on vector spaces only, not on " +
                     scene.manifold.type);
  a.composition.natural_chart = true;
  try {
    auto map = std::make_unique<LieGroupGalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                                    std::move(times), scene.solver, scene.reduced);
    a.discrete_lagrangian = map.get();
    a.map = std::move(map);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string(scene.reduced ? "/method/reduced: " : "/method: ") + e.what());
  }
}

void galerkin(const Scene& scene, Registry& registry, Assembly& a) {
  a.quadrature = make<Quadrature>(registry, *scene.quadrature, context_of(scene, *a.manifold));
  auto times = scene.control_times ? *scene.control_times : equispaced_control_times(scene.degree);
  a.composition.construction = Composition::Construction::galerkin;
  a.composition.degree = scene.degree;
  a.composition.control_times_symmetric = symmetric_times(times);
  describe_quadrature(*a.quadrature, a.composition);
  if (!a.manifold->is_vector_space()) return lie_group_galerkin(scene, std::move(times), a);
  if (scene.reduced)
    throw InputError("/method/reduced: the reduced (Euler-Poincare) form is for Lie groups; " + scene.manifold.type +
                     " is a vector space");
  std::vector<Force*> forces;
  for (const auto& force : a.forces) forces.push_back(force.get());
  auto map = std::make_unique<GalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                          std::move(times), scene.solver, std::move(forces));
  a.discrete_lagrangian = map.get();
  a.map = std::move(map);
}

// The one-step method and what it declares: order, self-adjointness, symplecticity (from its
// metadata), equivariance under the Lagrangian's symmetry: "affine" (Runge-Kutta) commutes with
// every linear group action on R^n, e.g. rotations, and on SO(3) with left multiplication, linear
// in the embedding R^9 x R^3 that it integrates in; "left" (Lie group methods) with left
// multiplication on the group, and with affine maps where the group is R^n.
void one_step_method(const Scene& scene, Registry& registry, Assembly& a) {
  a.one_step = make<OneStepMethod>(registry, *scene.one_step, context_of(scene, *a.manifold));
  a.one_step->set_solver(scene.solver.tolerance, scene.solver.max_iterations);
  Composition& c = a.composition;
  c.method_order = a.one_step->order();
  c.method_self_adjoint = a.one_step->self_adjoint();
  c.method_symplectic =
      registry.find(scene.one_step->kind, scene.one_step->type).properties.value("symplectic", false);
  const std::string equivariance = a.one_step->equivariance();
  c.method_equivariant = equivariance == "affine" || equivariance == "left";
}

void shooting(const Scene& scene, Registry& registry, Assembly& a) {
  a.quadrature = make<Quadrature>(registry, *scene.quadrature, context_of(scene, *a.manifold));
  one_step_method(scene, registry, a);
  a.composition.construction = Composition::Construction::shooting;
  describe_quadrature(*a.quadrature, a.composition);
  std::vector<Force*> forces;
  for (const auto& force : a.forces) forces.push_back(force.get());
  auto map = std::make_unique<ShootingDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature, *a.one_step,
                                                          shooting_form(scene.form), scene.solver, std::move(forces));
  a.discrete_lagrangian = map.get();
  a.map = std::move(map);
}

void one_step(const Scene& scene, Registry& registry, Assembly& a) {
  one_step_method(scene, registry, a);
  a.composition.construction = Composition::Construction::one_step;
  a.map = std::make_unique<OneStepHamiltonianMap>(*a.manifold, *a.lagrangian, *a.one_step, scene.solver);
}

void lie_verlet(const Scene& scene, Registry&, Assembly& a) {
  a.composition.construction = Composition::Construction::lie_verlet;
  const auto solver = scene.group_solver == "exp" ? LieVerletSolver::exp : LieVerletSolver::cayley;
  auto map = std::make_unique<LieGroupVelocityVerlet>(*a.manifold, *a.lagrangian, solver, scene.solver);
  a.discrete_lagrangian = map.get();
  a.map = std::move(map);
}

const std::map<std::string, Construction>& constructions() {
  static const std::map<std::string, Construction> table{
      {"galerkin", galerkin}, {"shooting", shooting}, {"one-step", one_step}, {"lie-verlet", lie_verlet}};
  return table;
}

// Spec "Composed systems": forces enter through the discrete Lagrange-d'Alembert principle, which
// the galerkin and shooting constructions implement (core/galerkin.hpp, core/shooting.hpp).
void create_forces(const Scene& scene, Registry& registry, Assembly& a) {
  if (scene.forces.empty()) return;
  a.composition.forced = true;
  if (scene.construction != "galerkin" && scene.construction != "shooting")
    throw InputError(fmt::format("/system/forces: forces are taken by constructions 'galerkin' and 'shooting' "
                                 "only (the discrete Lagrange-d'Alembert principle), not '{}'",
                                 scene.construction));
  for (const auto& spec : scene.forces) a.forces.push_back(make<Force>(registry, spec, context_of(scene, *a.manifold)));
}

void build_map(const Scene& scene, Registry& registry, Assembly& a) {
  const auto it = constructions().find(scene.construction);
  if (it == constructions().end())
    throw InputError(
        fmt::format("/method/construction: construction '{}' is not available yet", scene.construction));
  create_forces(scene, registry, a);
  it->second(scene, registry, a);
}

// -----------------------------------------------------------------------------------------------

void check_lagrangian_fits(const Scene& scene, const Lagrangian& lagrangian, const Manifold& manifold) {
  if (lagrangian.position_size() == manifold.point_size() && lagrangian.velocity_size() == manifold.dim())
    return;
  throw InputError(fmt::format(
      "/system/lagrangian: the {} Lagrangian takes {} position and {} velocity numbers, but the {} manifold "
      "has point size {} and dimension {}",
      scene.lagrangian.type, lagrangian.position_size(), lagrangian.velocity_size(), scene.manifold.type,
      manifold.point_size(), manifold.dim()));
}

// Spec "observe": momentum needs a declared symmetry; orthogonality a manifold embedded with a
// constraint (the rotation matrix of SO3 and SE3: Manifold::has_constraint).
void check_observables(const Scene& scene, Lagrangian& lagrangian, const Manifold& manifold) {
  if (scene.observe.momentum && lagrangian.momentum_size() <= 0)
    throw InputError(fmt::format("/observe: expected no \"momentum\": the {} Lagrangian declares no symmetry",
                                 scene.lagrangian.type));
  if (scene.observe.orthogonality && !manifold.has_constraint())
    throw InputError(fmt::format(
        "/observe: expected no \"orthogonality\": it is defined on SO3 and SE3 only, and the manifold is {}",
        scene.manifold.type));
}

Eigen::VectorXd to_vector(const std::vector<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

// Spec "initial": p, or v converted by the Legendre transform p = dL/dv.
void initial_state(const Scene& scene, Assembly& a) {
  LagrangianEvaluator evaluator(*a.lagrangian);
  a.q0 = to_vector(scene.q);
  if (scene.v) {
    a.v0 = to_vector(*scene.v);
    a.p0.resize(a.v0.size());
    evaluator.legendre(a.q0.data(), a.v0.data(), a.p0.data());
    return;
  }
  a.p0 = to_vector(*scene.p);
  if (!scene.observe.energy && !scene.observe.momentum) return;
  a.v0 = Eigen::VectorXd::Zero(a.p0.size());
  evaluator.inverse_legendre(a.q0.data(), a.p0.data(), a.v0.data(), scene.solver);
}

// Spec "Composed systems": the host creates the effect plugin of each term and builds the composite
// in core (varia/core/composite.hpp), so that no plugin calls another; the composite plugin itself
// carries the type's metadata and schema (docs/effects.md).
std::shared_ptr<Lagrangian> composite(const Scene& scene, Registry& registry, const sdk::Context& context) {
  registry.find(scene.lagrangian.kind, scene.lagrangian.type);
  std::vector<std::shared_ptr<Effect>> effects;
  for (const auto& spec : scene.effects) effects.push_back(make<Effect>(registry, spec, context));
  const auto& parameters = scene.lagrangian.parameters;
  try {
    return std::make_shared<CompositeLagrangian>(parameters.value("space_dim", 1),
                                                 parameters.value("masses", std::vector<double>{1.0}),
                                                 std::move(effects));
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}/{}", scene.lagrangian.pointer, e.what()));
  }
}

std::shared_ptr<Lagrangian> lagrangian(const Scene& scene, Registry& registry, const Manifold& manifold) {
  const sdk::Context context = context_of(scene, manifold);
  if (scene.lagrangian.type == "composite") return composite(scene, registry, context);
  return make<Lagrangian>(registry, scene.lagrangian, context);
}

}  // namespace

Assembly assemble(const Scene& scene, Registry& registry) {
  Assembly a;
  // The manifold first: its sizes go into the context of the others (Rn reads its "dim").
  a.manifold = make<Manifold>(registry, scene.manifold, sdk::Context{scene.manifold.type, 0, 0});
  check_initial_state(scene, *a.manifold, scene.manifold.type);
  a.lagrangian = lagrangian(scene, registry, *a.manifold);
  check_lagrangian_fits(scene, *a.lagrangian, *a.manifold);
  check_observables(scene, *a.lagrangian, *a.manifold);
  a.composition.lagrangian_invariant = std::string(a.lagrangian->symmetry_group()) != "none";
  build_map(scene, registry, a);
  initial_state(scene, a);
  return a;
}

}  // namespace varia::host
