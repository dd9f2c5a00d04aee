// The constrained one-step map on R^n (docs/constraints.md), for holonomic constraints g(q) = 0
// and a Lagrangian with a constant mass matrix M, which the one-step construction steps and the
// shooting construction's shot propagates:
//   - the field: the constrained Euler-Lagrange equations in their index-1 form (Hairer, Lubich &
//     Wanner, "Geometric Numerical Integration", sec. VII.1), q' = v, v' = a - M^-1 G^T lambda,
//     a = M^-1 L_q the free acceleration and lambda from d^2/dt^2 g(q) = 0:
//       (G M^-1 G^T) lambda = G a + c,   c_i = v^T H_i v,   H_i the Hessian of g_i;
//   - the projection after each step (HLW sec. IV.4, the standard projection method): q^ onto
//     g(q) = 0 along M^-1 G(q^)^T, q = q^ - M^-1 G(q^)^T mu by Newton's method in mu, then v onto the
//     hidden constraint G(q) v = 0 (M-orthogonally). Both move the step by O(h^(p+1)) for a method
//     of order p, so the projected method keeps order p; it is not symplectic.
// Both at doubles and, for quadratic constraints (Constraint::quadratic: G and the Hessians at a
// jet follow exactly from their values at the jet's value, g(q + d) = g + G d + d^T H d / 2), at
// second-order jets: there the projection's Newton iteration runs two iterations past the values'
// convergence, which make the first and then the second derivatives exact. One template serves
// both. The field's Jacobian (an implicit method's stage Newton) needs c's derivative in q, g's
// third derivatives along v twice (Constraint::curvature_derivative: zero for quadratic
// constraints); where a constraint does not give it, the constructions take explicit Runge-Kutta
// methods only.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>

#include "varia/core/constraints.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/core/solve/newton.hpp"

namespace varia {

class ConstrainedField final : public EulerLagrangeField {
 public:
  // Throws std::invalid_argument unless the Lagrangian declares a constant mass matrix.
  ConstrainedField(LagrangianEvaluator& lagrangian, HolonomicConstraints& constraints);
  int size() const noexcept override { return 2 * n_; }
  Status eval(const double* y, double* f) noexcept override;
  // Quadratic constraints only (else the Status says so).
  Status eval(const Jet2* y, Jet2* f) noexcept override;
  // Constraints that give c's derivative only (else the Status says so).
  Status jacobian(const double* y, double* f, double* df) noexcept override;
  // Whether the field has its Jacobian (Constraint::curvature_derivative): implicit methods may integrate it.
  bool has_jacobian() const { return has_jacobian_; }
  // q onto g(q) = 0 (to `options.tolerance`, at most `options.max_iterations` Newton steps; throws
  // NumericalFailure otherwise), then v onto G(q) v = 0. At jets for quadratic constraints only.
  void project(double* q, double* v, const SolverOptions& options);
  void project(Jet2* q, Jet2* v, const SolverOptions& options);
  // Whether the field and the projection evaluate at jets (quadratic constraints).
  bool evaluates_at_jets() const { return quadratic_; }
  // v onto G(q) v = 0 alone, at a point q on the constraint.
  void project_velocity(const double* q, double* v);

 private:
  // The constraint at a point q (g, G^T, and with a velocity c), W = M^-1 G^T and S = G W, the
  // multipliers' systems: one workspace per scalar type, sized once.
  template <class T>
  struct Workspace {
    using Vector = Eigen::Matrix<T, Eigen::Dynamic, 1>;
    using Matrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
    Vector g, curvature, gradient, free, rhs, multiplier, step, offset, start;
    Matrix GT, W, S, W_start;
  };
  template <class T>
  Workspace<T>& workspace();
  template <class T>
  Status evaluate(const T* y, T* f) noexcept;
  // g(q), G(q)^T and, for a velocity v, c_i = v^T H_i v into the workspace.
  template <class T>
  void linearize(const T* q, const T* v, Workspace<T>& w);
  // W = M^-1 G^T and S = G W from the workspace's G^T.
  template <class T>
  void factor(Workspace<T>& w);
  // x = A^-1 b for the m x m matrix A (LU at doubles, JetLinearSolve at jets).
  template <class T>
  void solve(const typename Workspace<T>::Matrix& A, const typename Workspace<T>::Vector& b,
             typename Workspace<T>::Vector& x);
  template <class T>
  void project_point(T* q, const SolverOptions& options);
  template <class T>
  void project_onto_hidden(T* v, Workspace<T>& w);
  void require_quadratic() const;

  HolonomicConstraints& constraints_;
  int m_;
  bool quadratic_, has_jacobian_;
  Workspace<double> doubles_;
  Workspace<Jet2> jets_;
  Eigen::VectorXd point_, values_, unit_;  // a point's values, g there (at jets), e_i
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  JetLinearSolve jet_solve_;
  // The Jacobian's workspace: L's Hessian, du/dz = M^-1 L_qz (n x 2n), R = d(S lambda)'s part (m x 2n),
  // K = M^-1 H_lambda, r = W lambda, H_i d's products.
  Eigen::MatrixXd lagrangian_hessian_, free_jacobian_, R_, K_;
  Eigen::VectorXd weighted_, product_, scratch_;
};

}  // namespace varia
