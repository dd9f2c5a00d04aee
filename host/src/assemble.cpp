#include "assemble.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "constructions/parts.hpp"
#include "registry.hpp"
#include "varia/core/mechanics.hpp"

namespace varia::host {

std::string constraints_pointer(const Scene& scene) {
  return scene.constraints.empty() ? "/system/manifold" : "/system/constraints";
}

namespace {

// Spec "Composed systems": forces enter through the discrete Lagrange-d'Alembert principle, which
// the constructions that take forces implement (Construction::takes_forces).
void create_forces(const Scene& scene, Registry& registry, Assembly& a) {
  if (scene.forces.empty()) return;
  if (!scene.construction->takes_forces())
    throw InputError(fmt::format("/system/forces: forces are taken by constructions {} only (the discrete "
                                 "Lagrange-d'Alembert principle), not '{}'",
                                 constructions_taking_forces(), scene.construction->name()));
  for (const auto& spec : scene.forces) a.forces.push_back(make_part<Force>(registry, spec, scene, *a.manifold));
}

// A constant mass matrix, declared: constant_mass_matrix for a dense Lagrangian, has_constant_mass_matrix
// for a sparse one.
bool has_constant_mass_matrix(Lagrangian& lagrangian) {
  const int *rows = nullptr, *cols = nullptr;
  if (lagrangian.hessian_pattern(&rows, &cols) >= 0) return lagrangian.has_constant_mass_matrix();
  std::vector<double> mass(static_cast<std::size_t>(lagrangian.velocity_size()) * lagrangian.velocity_size());
  return lagrangian.constant_mass_matrix(mass.data());
}

// Spec "Constrained systems": the constraints, bound to the system (its coordinates, and its particles'
// space where the Lagrangian is a particle system), as one g, after an embedded manifold's own
// equations. A construction that does not take them on this manifold, or a Lagrangian without a
// constant mass matrix (the hidden constraint's projection, docs/constraints.md), is refused at
// /system/constraints (at /system/manifold for the manifold's equations).
void create_constraints(const Scene& scene, Registry& registry, Assembly& a) {
  if (scene.constraints.empty() && !a.embedded) return;
  const std::string pointer = constraints_pointer(scene);
  const std::string what = scene.constraints.empty()
                               ? fmt::format("the {} manifold is served in its embedding, with its equations' "
                                             "multipliers, as constraints are",
                                             scene.manifold.type)
                               : "constraints are";
  if (!scene.construction->takes_constraints(a.manifold->structure()))
    throw InputError(fmt::format("{}: {} taken by the galerkin, one-step and shooting constructions on vector spaces "
                                 "(docs/constraints.md), not by '{}' on the {} manifold",
                                 pointer, what, scene.construction->name(), scene.manifold.type));
  if (!has_constant_mass_matrix(*a.lagrangian))
    throw InputError(fmt::format("{}: constraints need a Lagrangian with a constant mass matrix (the momenta's "
                                 "projection onto the constraint), and the {} Lagrangian declares none",
                                 pointer, scene.lagrangian.type));
  std::vector<Constraint*> bound;
  const int n = a.manifold->dim();
  if (a.embedded) {
    Constraint* equations = a.embedded->defining_constraint();
    equations->set_origin(a.embedded->origin());
    check(*equations, equations->bind(n, 0), "the manifold's equations");
    bound.push_back(equations);
  }
  for (const auto& spec : scene.constraints) {
    auto constraint = make_part<Constraint>(registry, spec, scene, *a.manifold);
    if (const Status refused = constraint->bind(n, a.lagrangian->space_dim()); refused != nullptr)
      throw InputError(fmt::format("{}: {}", spec.pointer, refused));
    bound.push_back(constraint.get());
    a.constraints.push_back(std::move(constraint));
  }
  a.holonomic = std::make_unique<HolonomicConstraints>(bound, n);
  if (!a.embedded) return;
  std::vector<Eigen::Triplet<double>> identity;
  for (int i = 0; i < n; ++i) identity.emplace_back(i, i, 1.0);
  a.orthogonal_momentum = std::make_unique<CotangentProjection>(*a.holonomic, identity);
}

// A manifold served in its embedding (Manifold::defining_constraint): the constructions take it
// as R^point_size, through the bundled Rn, and its equations as constraints (create_constraints).
void serve_in_embedding(Registry& registry, Assembly& a) {
  if (a.manifold->defining_constraint() == nullptr) return;
  a.embedded = a.manifold;
  a.manifold = registry.create_as<Manifold>("manifold", "Rn", nlohmann::json{{"dim", a.embedded->point_size()}},
                                            sdk::Context{"Rn", 0, 0});
}

// Spec: initial.q satisfies every constraint within kInitialConstraintTolerance (the rod's g is
// relative to its length), and the initial velocity (v, or M^{-1} p) is tangent to them within
// the same tolerance times the largest speed (1 at rest).
constexpr double kInitialConstraintTolerance = 1e-10;
void check_initial_constraints(const Scene& scene, Assembly& a) {
  if (!a.holonomic) return;
  if (const double g = a.holonomic->residual(a.q0.data()); !(g <= kInitialConstraintTolerance))
    throw InputError(fmt::format("/initial/q: expected a point on the constraints (max |g_i(q)| <= {:g}); found "
                                 "max |g_i(q)| = {:.3g}",
                                 kInitialConstraintTolerance, g));
  Eigen::VectorXd v = a.v0;
  if (v.size() != a.p0.size()) {
    v = Eigen::VectorXd::Zero(a.p0.size());
    LagrangianEvaluator(*a.lagrangian).inverse_legendre(a.q0.data(), a.p0.data(), v.data(), scene.solver);
  }
  const double tolerance = kInitialConstraintTolerance * std::max(1.0, v.lpNorm<Eigen::Infinity>());
  if (const double Gv = a.holonomic->velocity_residual(a.q0.data(), v.data()); !(Gv <= tolerance))
    throw InputError(fmt::format("/initial/{}: expected a velocity tangent to the constraints (max |(G(q) v)_i| <= "
                                 "{:.3g}); found {:.3g}",
                                 scene.v ? "v" : "p", tolerance, Gv));
}

// The constructions serve vector spaces and Lie groups (a product of Lie groups is one), and a
// manifold that gives its equations in its embedding (S2); a manifold of another structure is
// refused here, once, for every construction.
void check_structure_served(const Scene& scene, Manifold& manifold) {
  const ManifoldStructure structure = manifold.structure();
  if (structure == ManifoldStructure::vector_space || structure == ManifoldStructure::lie_group ||
      manifold.defining_constraint() != nullptr)
    return;
  throw InputError(fmt::format(
      "/system/manifold: the {} manifold is a {}, and the constructions serve vector spaces, Lie groups and "
      "manifolds given by their equations in R^n (S2, and products of those with vector spaces)",
      scene.manifold.type, structure_name(structure)));
}

void check_lagrangian_fits(const Scene& scene, const Lagrangian& lagrangian, const Manifold& manifold) {
  if (lagrangian.position_size() == manifold.point_size() && lagrangian.velocity_size() == manifold.dim())
    return;
  throw InputError(fmt::format(
      "/system/lagrangian: the {} Lagrangian takes {} position and {} velocity numbers, but the {} manifold "
      "has point size {} and dimension {}",
      scene.lagrangian.type, lagrangian.position_size(), lagrangian.velocity_size(), scene.manifold.type,
      manifold.point_size(), manifold.dim()));
}

// A Lagrangian without a Hessian pattern is dense: the evaluator holds its (m + n)^2 Hessian and
// the constructions' Newton matrices grow as the square of the unknowns, so its size is bounded
// (docs/writing-plugins.md, "What still limits the size"). A large system is written as a sum of
// terms (sdk::TermwiseLagrangian) or as a composite, whose Hessians are sparse.
constexpr long kMaxDenseNumbers = 4096;

void check_dense_size(const Scene& scene, const Lagrangian& lagrangian) {
  const int *rows = nullptr, *cols = nullptr;
  const long k = static_cast<long>(lagrangian.position_size()) + lagrangian.velocity_size();
  if (k <= kMaxDenseNumbers || lagrangian.hessian_pattern(&rows, &cols) >= 0) return;
  throw InputError(fmt::format(
      "{}: the {} Lagrangian has a dense Hessian over its {} position and velocity numbers, and at most {} are "
      "taken (the Hessian and the Newton matrices grow as the square: {:.0f} MB for this Hessian alone); write "
      "it as a sum of terms (sdk::TermwiseLagrangian) or as a composite system, whose Hessians are sparse",
      scene.lagrangian.pointer, scene.lagrangian.type, k, kMaxDenseNumbers, 8e-6 * static_cast<double>(k * k)));
}

// Spec "observe": momentum needs a declared symmetry; orthogonality a manifold embedded with a
// constraint (the rotation matrix of SO3 and SE3: Manifold::has_constraint).
void check_observables(const Scene& scene, Lagrangian& lagrangian, Manifold& manifold) {
  if (scene.observe.momentum && lagrangian.momentum_size() <= 0)
    throw InputError(fmt::format("/observe: expected no \"momentum\": the {} Lagrangian declares no symmetry",
                                 scene.lagrangian.type));
  if ((scene.observe.constraint || scene.observe.constraint_velocity) && scene.constraints.empty() &&
      manifold.defining_constraint() == nullptr)
    throw InputError(fmt::format("/observe: expected no \"{}\": the system has no constraints",
                                 scene.observe.constraint ? "constraint" : "constraint_velocity"));
  if (scene.observe.orthogonality && !manifold.has_constraint())
    throw InputError(fmt::format(
        "/observe: expected no \"orthogonality\": it is defined on SO3 and SE3 only, and the manifold is {}",
        scene.manifold.type));
}

// Spec "Tangent maps and ensembles": megno and lyapunov propagate a deviation by the map's tangent map.
void check_tangent_map(const Scene& scene, const DiscreteHamiltonianMap& map) {
  if (!scene.observe.chaos()) return;
  if (const std::string refusal = map.tangent_map_refusal(); !refusal.empty())
    throw InputError(fmt::format("/observe: expected no \"{}\": it propagates a deviation by the step's tangent map, "
                                 "and {}",
                                 scene.observe.megno ? "megno" : "lyapunov", refusal));
}

// initial.p on an embedded manifold: orthogonal to the normals, else exit 2 at /initial/p; then
// held as M v with G v = 0 (CotangentProjection with the mass matrix).
void held_momentum(Assembly& a, LagrangianEvaluator& evaluator) {
  a.holonomic->evaluate_jacobian(a.q0.data());
  const Eigen::VectorXd normal = a.holonomic->jacobian() * a.p0;
  const double tolerance = kInitialConstraintTolerance * std::max(1.0, a.p0.lpNorm<Eigen::Infinity>());
  if (const double Gp = normal.lpNorm<Eigen::Infinity>(); !(Gp <= tolerance))
    throw InputError(fmt::format("/initial/p: expected a momentum orthogonal to the manifold's normals (max |(G(q) "
                                 "p)_i| <= {:.3g}, q . p = 0 on S2); found {:.3g}",
                                 tolerance, Gp));
  CotangentProjection held(*a.holonomic, constant_mass_entries(evaluator, a.q0.data()));
  Eigen::VectorXd correction(a.p0.size());
  held.correction(a.q0.data(), a.p0.data(), correction.data());
  a.p0 += correction;
}

Eigen::VectorXd to_vector(const std::vector<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

// Spec "initial": p, or v converted by the Legendre transform p = dL/dv. On an embedded manifold
// p is given orthogonal to the normals (S2: q . p = 0, within the constraints' tolerance relative
// to |p|) and held as the constructions hold it, p - G^T mu with G M^-1 p = 0 (Assembly::
// orthogonal_momentum).
void initial_state(const Scene& scene, Assembly& a) {
  LagrangianEvaluator evaluator(*a.lagrangian);
  a.q0 = to_vector(scene.q);
  a.t0 = scene.t0;
  if (scene.v) {
    a.v0 = to_vector(*scene.v);
    a.p0.resize(a.v0.size());
    evaluator.legendre(a.q0.data(), a.v0.data(), a.p0.data());
    return;
  }
  a.p0 = to_vector(*scene.p);
  if (a.orthogonal_momentum) held_momentum(a, evaluator);
  if (!scene.observe.energy && !scene.observe.momentum) return;
  a.v0 = Eigen::VectorXd::Zero(a.p0.size());
  evaluator.inverse_legendre(a.q0.data(), a.p0.data(), a.v0.data(), scene.solver);
}

}  // namespace

void check_momentum_size(const Lagrangian& lagrangian, int dim) {
  const long largest = static_cast<long>(dim) * (dim + 2);
  if (lagrangian.momentum_size() > largest)
    throw PluginFault(fmt::format("the Lagrangian declares a momentum map of {} numbers; a symmetry group acting on "
                                  "a manifold of dimension {} has at most {} generators (dim (dim + 2))",
                                  lagrangian.momentum_size(), dim, largest),
                      lagrangian.origin());
}

void check_declared_sizes(const Manifold& manifold) {
  const int m = manifold.point_size(), n = manifold.dim();
  if (n >= 1 && n <= m) return;
  throw PluginFault(fmt::format("the manifold declares point size {} and dimension {}; a manifold embedded in "
                                "R^(point size) has a dimension from 1 to its point size",
                                m, n),
                    manifold.origin());
}

void check_declared_sizes(const Lagrangian& lagrangian) {
  const int m = lagrangian.position_size(), n = lagrangian.velocity_size();
  if (m >= 1 && n >= 1) return;
  throw PluginFault(fmt::format("the Lagrangian declares {} position and {} velocity numbers; each is at least 1", m, n),
                    lagrangian.origin());
}

void check_hessian_pattern(const Lagrangian& lagrangian) {
  const int *rows = nullptr, *cols = nullptr;
  const int entries = lagrangian.hessian_pattern(&rows, &cols);
  if (entries <= 0) return;
  const int size = lagrangian.position_size() + lagrangian.velocity_size();
  if (rows == nullptr || cols == nullptr)
    throw PluginFault(fmt::format("the Lagrangian declares a sparse Hessian of {} entries without their rows and "
                                  "columns",
                                  entries),
                      lagrangian.origin());
  for (int e = 0; e < entries; ++e)
    if (rows[e] < 0 || rows[e] >= size || cols[e] < 0 || cols[e] >= size)
      throw PluginFault(fmt::format("the Lagrangian's sparse Hessian pattern names entry {} at (row {}, column {}), "
                                    "outside its {} x {} Hessian over (q, v)",
                                    e, rows[e], cols[e], size, size),
                        lagrangian.origin());
}

const Eigen::VectorXd& written_momentum(Assembly& a, const Eigen::VectorXd& q, const Eigen::VectorXd& p,
                                        Eigen::VectorXd& out) {
  if (!a.orthogonal_momentum) return p;
  out.resize(p.size());
  a.orthogonal_momentum->correction(q.data(), p.data(), out.data());
  out += p;
  return out;
}

bool has_exact_solution(const Assembly& a) { return a.forces.empty() && a.lagrangian->has_exact_solution(); }

Assembly assemble(const Scene& scene, Registry& registry) {
  Assembly a;
  // The manifold first: its sizes go into the context of the others (Rn reads its "dim").
  a.manifold = make_part<Manifold>(registry, scene.manifold, sdk::Context{manifold_name(scene.manifold), 0, 0});
  check_declared_sizes(*a.manifold);
  check_structure_served(scene, *a.manifold);
  check_initial_state(scene, *a.manifold, scene.manifold.type);
  a.lagrangian = make_part<Lagrangian>(registry, scene.lagrangian, scene, *a.manifold);
  serve_in_embedding(registry, a);
  check_declared_sizes(*a.lagrangian);
  check_lagrangian_fits(scene, *a.lagrangian, *a.manifold);
  check_momentum_size(*a.lagrangian, a.manifold->dim());
  check_hessian_pattern(*a.lagrangian);
  check_dense_size(scene, *a.lagrangian);
  check_observables(scene, *a.lagrangian, a.embedded ? *a.embedded : *a.manifold);
  create_forces(scene, registry, a);
  create_constraints(scene, registry, a);
  scene.construction->build(scene, registry, a);
  check_tangent_map(scene, *a.map);
  initial_state(scene, a);
  check_initial_constraints(scene, a);
  return a;
}

}  // namespace varia::host
