// Building the integrator a scene describes: its plugin objects, the construction named by
// method.construction, and the initial state (spec: "Scene files (JSON)").
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "scene.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/constraint.hpp"
#include "varia/abi/force.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/constraints.hpp"
#include "varia/core/verification.hpp"

namespace varia::host {

class Registry;

// The assembled integrator. Members are declared so that the map, which refers to the plugin
// objects, is destroyed before them.
struct Assembly {
  // The manifold the constructions serve: the scene's, or R^point_size where the scene's is served
  // in its embedding (Manifold::defining_constraint; then `embedded` holds the scene's).
  std::shared_ptr<Manifold> manifold;
  std::shared_ptr<Manifold> embedded;
  std::shared_ptr<Lagrangian> lagrangian;
  std::shared_ptr<Quadrature> quadrature;  // when the construction uses one
  std::shared_ptr<OneStepMethod> one_step;  // when the construction uses one
  std::vector<std::shared_ptr<Force>> forces;  // system.forces
  std::vector<std::shared_ptr<Constraint>> constraints;  // system.constraints, bound to the system
  std::unique_ptr<HolonomicConstraints> holonomic;  // them as one g (null without constraints)
  // On an embedded manifold a momentum is read and written as the covector orthogonal to the
  // normals G(q)^T (S2: q . p = 0), which the constructions hold as M v (G M^-1 p = 0): this
  // projection (CotangentProjection with M = I) forms the written one; null elsewhere.
  std::unique_ptr<CotangentProjection> orthogonal_momentum;
  std::unique_ptr<DiscreteHamiltonianMap> map;
  DiscreteLagrangian* discrete_lagrangian = nullptr;  // when the construction has one (in `map`)
  bool one_step_symplectic = false;  // what the one-step plugin declares (its "symplectic" property)
  Eigen::VectorXd q0, p0;  // the initial state, at time t0 (initial.t)
  double t0 = 0.0;
  Eigen::VectorXd v0;  // set when the scene gives v or observes energy or momentum
};

// The momentum p at q as written (Assembly::orthogonal_momentum): p itself, or into `out`.
const Eigen::VectorXd& written_momentum(Assembly& a, const Eigen::VectorXd& q, const Eigen::VectorXd& p,
                                        Eigen::VectorXd& out);

// Whether the whole system, Lagrangian and forces, has a closed-form solution: only then do
// `verify` and `cost` measure against it; otherwise against a reference run of the same system.
bool has_exact_solution(const Assembly& assembly);

// Where a refusal of the system's constraints points (spec "Constrained systems"): at
// /system/constraints, or at /system/manifold where the only ones are an embedded manifold's own
// equations (S2).
std::string constraints_pointer(const Scene& scene);

// A Lagrangian's momentum map has at most dim (dim + 2) numbers, the dimension of the largest Lie
// group that acts effectively on a manifold of dimension dim (the projective group on RP^dim): a
// plugin declaring more is at fault (PluginFault from the Lagrangian, naming its plugin), rather
// than a scene asking for more memory than the machine has. Called by assemble().
void check_momentum_size(const Lagrangian& lagrangian, int dim);

// Sizes no scene can cause: a manifold of dimension < 1 or above its point size (it is embedded in
// R^point_size), a Lagrangian of fewer than one position or velocity number. PluginFault naming
// the plugin; a size that merely differs from the scene's or the manifold's is the scene's
// mismatch (InputError: Rn's dim comes from the scene). Called by assemble().
void check_declared_sizes(const Manifold& manifold);
void check_declared_sizes(const Lagrangian& lagrangian);

// A sparse Hessian pattern (Lagrangian::hessian_pattern) indexes the Hessian over (q, v) that the
// evaluator and the constructions write through it: every row and column must lie within it, else
// PluginFault from the Lagrangian, naming its plugin. Called by assemble().
void check_hessian_pattern(const Lagrangian& lagrangian);

// Creates the plugin objects and the construction; InputError for a construction that is not
// available, a Lagrangian that does not fit the manifold, a bad initial state or an observable the
// system does not define.
Assembly assemble(const Scene& scene, Registry& registry);

}  // namespace varia::host
