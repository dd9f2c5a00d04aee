// A holonomic constraint g(q) = 0 of a mechanical system (spec: "Constrained systems"): m scalar
// functions of the configuration q (n numbers) with their sparse Jacobian G = dg/dq and the Hessian
// of sum_i lambda_i g_i for given multipliers lambda, which the constructions need for the exact
// Newton Jacobian of the constrained discrete Euler-Lagrange equations (docs/constraints.md).
// Model evaluations only: a construction decides where and with which multipliers g enters.
// ABI 16; quadratic() ABI 18; curvature_derivative() ABI 20.
#pragma once

#include <algorithm>

#include "varia/abi/plugin_object.hpp"

namespace varia {

class Constraint : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::constraint; }
  // Called once, before anything else: the configuration has n numbers; where they are the
  // positions of particles in space_dim dimensions (a particle system, Lagrangian::space_dim()),
  // particle i is q[i * space_dim + k], else space_dim is 0. Fails (a message naming the parameter at
  // fault) when the constraint does not apply to such a system.
  virtual Status bind(int n, int space_dim) noexcept = 0;
  // m, the number of scalar constraints g_i (after bind).
  virtual int size() const noexcept = 0;
  // The stored entries (i, j) of G_ij = dg_i/dq_j; fixed after bind, no entry twice.
  virtual int jacobian_pattern(const int** rows, const int** cols) const noexcept = 0;
  // The stored entries (j, k) of the n x n Hessian of sum_i lambda_i g_i (both triangles); fixed
  // after bind, no entry twice.
  virtual int hessian_pattern(const int** rows, const int** cols) const noexcept = 0;
  // g(q) (m numbers) and G's values in jacobian_pattern's order; either may be null.
  virtual Status evaluate(const double* q, double* g, double* jacobian) noexcept = 0;
  // The Hessian of sum_i lambda_i g_i at q, its values in hessian_pattern's order.
  virtual Status weighted_hessian(const double* q, const double* lambda, double* values) noexcept = 0;
  // Whether every g_i is a quadratic polynomial in q, so that the Hessian of sum_i lambda_i g_i does
  // not depend on q (the rod, S2's sphere). The shooting construction takes such constraints only:
  // it propagates the constrained field at second-order jets, where G and the Hessians at a jet
  // follow exactly from their values at one point (docs/constraints.md). The SDK's conformance
  // suite checks the declaration (the Hessian at random points).
  virtual bool quadratic() const noexcept { return false; }
  // The derivatives in q of c_i(q, v) = v^T H_i(q) v, H_i the Hessian of g_i (the term of
  // d^2/dt^2 g_i = G_i q'' + c_i that does not hold the acceleration), their values in
  // jacobian_pattern's order: c_i depends on q_j only where g_i does. The index-1 constrained field's
  // Jacobian needs them (an implicit one-step method's stage Newton, docs/constraints.md): they are
  // g's third derivatives along v twice. A quadratic constraint's are zero, which the default gives;
  // a constraint that is not quadratic gives them where gives_curvature_derivative() says so.
  virtual bool gives_curvature_derivative() const noexcept { return quadratic(); }
  virtual Status curvature_derivative(const double* /*q*/, const double* /*v*/, double* values) noexcept {
    const int *rows = nullptr, *cols = nullptr;
    std::fill_n(values, jacobian_pattern(&rows, &cols), 0.0);
    return quadratic() ? nullptr : "this constraint does not give the derivatives of v^T H_i(q) v in q";
  }
};

}  // namespace varia
