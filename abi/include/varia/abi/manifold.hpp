// Configuration manifold Q with a natural chart (paper, sec. 2 "Natural charts"):
// psi_{q0}^{-1}(xi) = q0 exp(xi) (retract) and psi_{q0}(q) = log(q0^{-1} q) (local).
// A point is point_size() numbers (n on R^n; 9 on SO(3), a row-major rotation matrix; 12 on
// SE(3), R then x); tangent vectors, velocities and momenta are dim() numbers, left-trivialized
// on a Lie group.
//
// A manifold declares its structure (structure()): a vector space (the chart is affine), a Lie
// group whose natural chart it gives to second order (chart, local_derivatives), a homogeneous
// space of a Lie group (such as S2 = SO(3)/SO(2), a point moved by the group's action), or a
// product of manifolds (a product of Lie groups is itself a Lie group, and declares lie_group). The
// derivatives cross the boundary as plain arrays sized by the caller, so no capacity of the
// interface limits the group's dimension. A plugin author writes the group's operations once,
// templated on the scalar, and the SDK's adapter (varia/sdk/lie_group.hpp) derives these.
#pragma once

#include "varia/abi/constraint.hpp"
#include "varia/abi/jet.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia {

// What a manifold is, beyond its charts: the constructions choose their equations by it (in the
// coordinates of a vector space, with the Lagrangian's sparsity; in a Lie group's natural chart).
// New kinds are appended; a construction refuses a structure it does not serve when it is built.
enum class ManifoldStructure { vector_space, lie_group, homogeneous_space, product };

inline const char* structure_name(ManifoldStructure structure) {
  switch (structure) {
    case ManifoldStructure::vector_space: return "vector space";
    case ManifoldStructure::lie_group: return "Lie group";
    case ManifoldStructure::homogeneous_space: return "homogeneous space";
    case ManifoldStructure::product: return "product";
  }
  return "unknown";
}

// A quantity of k components and its first and second derivatives in V variables, in buffers the
// caller sizes: value k numbers, gradient k x V, hessian k x V x V, component-major (the gradient
// of component c starts at c V, its symmetric Hessian at c V^2). A null buffer is not written.
struct Derivatives {
  double* value = nullptr;
  double* gradient = nullptr;
  double* hessian = nullptr;
};

class Manifold : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::manifold; }
  virtual int point_size() const noexcept = 0;
  virtual int dim() const noexcept = 0;
  virtual ManifoldStructure structure() const noexcept = 0;  // ABI 15 (was is_vector_space())
  // True when the natural chart is affine, q = q0 + xi (a vector space): the constructions then
  // assemble their equations directly in the coordinates, with the Lagrangian's sparsity.
  bool is_vector_space() const noexcept { return structure() == ManifoldStructure::vector_space; }
  virtual Status retract(const double* q0, const double* xi, double* q) noexcept = 0;
  virtual Status local(const double* q0, const double* q, double* xi) noexcept = 0;
  // Checks that q is a point of the manifold (to a tolerance); fills `why` when it is not.
  virtual bool contains(const double* q, char* why, int why_size) noexcept = 0;
  // How far q lies off the manifold in its embedding, for the run's drift observables:
  // ||I - R^T R||_F on SO(3) and SE(3) (the paper's orthogonality error); 0 where every point is
  // valid (has_constraint() false).
  virtual double constraint_error(const double* /*q*/) const noexcept { return 0.0; }
  virtual bool has_constraint() const noexcept { return false; }
  // A manifold embedded in R^point_size() as the zero set of equations g(q) = 0 (S2: |q|^2 = 1)
  // may give them as a holonomic constraint (abi/constraint.hpp), the manifold's own object: the
  // host binds it to point_size() coordinates, and the constructions then serve the manifold in
  // its embedding, as R^point_size() with the equations' multipliers (the constrained discrete
  // Euler-Lagrange equations, docs/constraints.md); velocities and momenta are then point_size()
  // numbers, a momentum given as the covector orthogonal to the normals G(q)^T. Null (the
  // default) where the manifold is served in its natural chart. ABI 17.
  virtual Constraint* defining_constraint() noexcept { return nullptr; }
  // The natural chart to second order, for the Galerkin construction on a Lie group (paper,
  // sec. 2, "Natural charts"): with n = dim(),
  //   point:    q0 exp(eta) exp(xi) at eta = 0, point_size() components in the 2n variables
  //             (eta, xi);
  //   velocity: the left-trivialized velocity dexp_{-xi}(xi_dot) of the curve q0 exp(xi(t)) with
  //             xi' = xi_dot, n components in the 2n variables (xi, xi_dot).
  // On R^n: q0 + eta + xi and xi_dot.
  virtual Status chart(const double* /*q0*/, const double* /*xi*/, const double* /*xi_dot*/,
                       Derivatives /*point*/, Derivatives /*velocity*/) noexcept {
    return "this manifold does not provide its natural chart to second order";
  }
  // The chart's inverse to second order, for the shooting construction's boundary condition
  // (paper, sec. 3 with sec. 2 "Natural charts"): xi = local(q0, q) = log(q0^{-1} q), dim()
  // components in the point_size() variables q. On R^n: q - q0.
  virtual Status local_derivatives(const double* /*q0*/, const double* /*q*/, Derivatives /*xi*/) noexcept {
    return "this manifold does not provide its natural chart's inverse to second order";
  }
  // The step's increment of the point, q0 exp(xi) - q0 in the embedding, for the compensated
  // update of the Lie group Galerkin construction (g1 = g0 + (g1 - g0) summed by Kahan's method,
  // compensated.hpp). Formed as an increment, its rounding error is of the increment's size, not
  // the point's; but an error of relative size eps that repeats from step to step (the same xi
  // along a steady motion) still adds up over a long run, and what it carries off the group
  // shows in every quantity that assumes the embedding's constraint: the orthogonality of R, and
  // through it a momentum map evaluated at the point (docs/lie-groups.md, "Long runs"). A group
  // that forms the increment to more than working precision declares has_increment() and gives
  // it as dq + dq_low (point_size() numbers each): dq rounded to double, dq_low the rest, which
  // the compensated sum takes in too (a rounding of the increment to double at every step would
  // still walk randomly, eps/2 |xi| a step). Otherwise the construction integrates the chart's
  // derivative by a quadrature, to working precision.
  virtual bool has_increment() const noexcept { return false; }
  virtual Status increment(const double* /*q0*/, const double* /*xi*/, double* /*dq*/, double* /*dq_low*/) noexcept {
    return "this manifold does not provide its increment q0 exp(xi) - q0";
  }
  // The group's action on its points at second-order jets (jet.hpp), for the Lie group one-step
  // methods and the shooting construction, which propagate (q, xi) with their derivatives
  // (paper, sec. 3 with sec. 2's Lie group methods): with n = dim(), m = point_size(),
  //   translate:  q exp(xi), m jets, from q (m jets, a point) and xi (n jets);
  //   generators: the tangent vectors q e_a of the curves q exp(t e_a) at t = 0, a = 1..n, as the
  //               m x n matrix D(q) (component-major: D[k n + a]), at jets of q. The Euler-Poincare
  //               field moves q with velocity D(q) xi and takes the left-trivialized derivative
  //               of a function f of the point as D(q)^T df/dq.
  virtual Status translate(const Jet2* /*q*/, const Jet2* /*xi*/, Jet2* /*moved*/) noexcept {
    return "this manifold does not provide its group's translation at jets";
  }
  virtual Status generators(const Jet2* /*q*/, Jet2* /*D*/) noexcept {
    return "this manifold does not provide its group's generators at jets";
  }
};

}  // namespace varia
