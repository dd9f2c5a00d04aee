// The one-step methods with holonomic constraints g(q) = 0 on R^n (docs/constraints.md), for a
// Lagrangian with a constant mass matrix M:
//   - the field: the constrained Euler-Lagrange equations in their index-1 form (Hairer, Lubich &
//     Wanner, "Geometric Numerical Integration", sec. VII.1), q' = v, v' = a - M^-1 G^T lambda,
//     a = M^-1 L_q the free acceleration and lambda from d^2/dt^2 g(q) = 0:
//       (G M^-1 G^T) lambda = G a + c,   c_i = v^T H_i v,   H_i the Hessian of g_i;
//   - the projection after each step (HLW sec. IV.4, the standard projection method): q onto
//     g(q) = 0 along M^-1 G^T by Newton's method, then v onto the hidden constraint G(q) v = 0
//     (M-orthogonally). Both move the step by O(h^(p+1)) for a method of order p, so the projected
//     method keeps order p; it is not symplectic.
// The field has no Jacobian (its lambda's derivatives would need g's third derivatives, which the
// constraint interface does not give) and no jets: the one-step construction takes explicit
// Runge-Kutta methods only with constraints, and gives no tangent map there.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "varia/core/constraints.hpp"
#include "varia/core/mechanical_field.hpp"

namespace varia {

class ConstrainedField final : public EulerLagrangeField {
 public:
  // Throws std::invalid_argument unless the Lagrangian declares a constant mass matrix.
  ConstrainedField(LagrangianEvaluator& lagrangian, HolonomicConstraints& constraints);
  int size() const noexcept override { return 2 * n_; }
  Status eval(const double* y, double* f) noexcept override;
  Status eval(const Jet2* /*y*/, Jet2* /*f*/) noexcept override {
    return "the constrained field (index 1) is not evaluated at jets";
  }
  Status jacobian(const double* /*y*/, double* /*f*/, double* /*df*/) noexcept override {
    return "the constrained field (index 1) has no Jacobian: its multiplier's derivatives need the constraints' "
           "third derivatives";
  }
  // q onto g(q) = 0 (to `options.tolerance`, at most `options.max_iterations` Newton steps; throws
  // NumericalFailure otherwise), then v onto G(q) v = 0.
  void project(double* q, double* v, const SolverOptions& options);

 private:
  // G(q), W = M^-1 G^T and the Cholesky factor of S = G W.
  void factor(const double* q);

  HolonomicConstraints& constraints_;
  int m_;
  Eigen::MatrixXd W_, S_;
  Eigen::LLT<Eigen::MatrixXd> S_factor_;
  Eigen::VectorXd gradient_, lambda_, rhs_, unit_, g_, curvature_;  // curvature_: H_i v
};

}  // namespace varia
