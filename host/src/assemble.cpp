#include "assemble.hpp"

#include <fmt/format.h>

#include <functional>
#include <map>

#include "registry.hpp"
#include "varia/core/galerkin.hpp"
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

void galerkin(const Scene& scene, Registry& registry, Assembly& a) {
  a.quadrature = make<Quadrature>(registry, *scene.quadrature, context_of(scene, *a.manifold));
  auto times = scene.control_times ? *scene.control_times : equispaced_control_times(scene.degree);
  auto map = std::make_unique<GalerkinDiscreteLagrangian>(*a.manifold, *a.lagrangian, *a.quadrature,
                                                          std::move(times), scene.solver);
  a.discrete_lagrangian = map.get();
  a.map = std::move(map);
}

const std::map<std::string, Construction>& constructions() {
  static const std::map<std::string, Construction> table{{"galerkin", galerkin}};
  return table;
}

void build_map(const Scene& scene, Registry& registry, Assembly& a) {
  if (!scene.forces.empty())
    throw InputError(fmt::format("/system/forces: forces are not available yet with construction '{}'",
                                 scene.construction));
  const auto it = constructions().find(scene.construction);
  if (it == constructions().end())
    throw InputError(
        fmt::format("/method/construction: construction '{}' is not available yet", scene.construction));
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

// Spec "observe": momentum needs a declared symmetry; orthogonality is for SO3 only.
void check_observables(const Scene& scene, Lagrangian& lagrangian, const Manifold& manifold) {
  if (scene.observe.momentum && lagrangian.momentum_size() <= 0)
    throw InputError(fmt::format("/observe: expected no \"momentum\": the {} Lagrangian declares no symmetry",
                                 scene.lagrangian.type));
  const bool rotations = manifold.point_size() == 9 && manifold.dim() == 3 && !manifold.is_vector_space();
  if (scene.observe.orthogonality && !rotations)
    throw InputError(fmt::format(
        "/observe: expected no \"orthogonality\": it is defined on SO3 only, and the manifold is {}",
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

}  // namespace

Assembly assemble(const Scene& scene, Registry& registry) {
  Assembly a;
  // The manifold first: its sizes go into the context of the others (Rn reads its "dim").
  a.manifold = make<Manifold>(registry, scene.manifold, sdk::Context{scene.manifold.type, 0, 0});
  check_initial_state(scene, *a.manifold, scene.manifold.type);
  a.lagrangian = make<Lagrangian>(registry, scene.lagrangian, context_of(scene, *a.manifold));
  check_lagrangian_fits(scene, *a.lagrangian, *a.manifold);
  check_observables(scene, *a.lagrangian, *a.manifold);
  build_map(scene, registry, a);
  initial_state(scene, a);
  return a;
}

}  // namespace varia::host
