// The Galerkin discrete Lagrangian (paper, sec. 2): the action of the degree-s Lagrange
// interpolant through control points q^0 = q0, q^1, ..., q^s = q1 at control times
// 0 = d_0 < ... < d_s = 1, approximated by a quadrature rule and extremized over the internal
// control points:
//   L_d(q0, q1) = ext_{q^1..q^{s-1}} h sum_i b_i L(q(c_i h), qdot(c_i h)).
// Its discrete Hamiltonian map solves the IDEL equations p0 = -D1 L_d, p1 = D2 L_d together with
// the internal stationarity conditions by Newton's method with the exact Jacobian.
#pragma once

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/core/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/quadrature.hpp"

namespace varia {

// Lagrange basis through the control times, evaluated at the quadrature nodes:
// phi(i, nu) = l_nu(c_i), dphi(i, nu) = l'_nu(c_i) (derivative in tau in [0, 1]).
struct LagrangeBasis {
  LagrangeBasis(const std::vector<double>& control_times, const Quadrature& quadrature);
  Eigen::MatrixXd phi, dphi;
  // l_nu(tau) for one tau, e.g. to extrapolate the previous step's curve as a warm start.
  Eigen::VectorXd at(double tau) const;
  std::vector<double> control_times;
};

// Equispaced control times d_nu = nu / s.
std::vector<double> equispaced_control_times(int degree);

class GalerkinDiscreteLagrangian : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // The manifold must be a vector space (is_vector_space()); Lie groups use their natural chart
  // through the same interface once the manifold provides it.
  GalerkinDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
                             std::vector<double> control_times, SolverOptions options);
  int degree() const { return static_cast<int>(basis_.control_times.size()) - 1; }

  // L_d, D1 L_d, D2 L_d with the internal control points extremized (any output may be null).
  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return n_; }
  int dim() const override { return n_; }
  void step(const double* q0, const double* p0, double h, double* q1, double* p1) override;
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }
  // Residual norms of the last Newton solve, one per iteration (to show quadratic convergence).
  const std::vector<double>& last_residuals() const { return residuals_; }

 private:
  enum class Order { value, gradient, hessian };
  // The discrete action S(q^0..q^s) = h sum_i b_i L(q(c_i h), qdot(c_i h)) of the control points
  // in points_, with its gradient dS/dq^nu in gradient_ and Hessian in hessian_ up to `order`.
  double action(double h, Order order);
  // Newton's method on the control points [first_unknown, first_unknown + blocks) for the
  // equations dS/dq^nu = 0, nu in [first_equation, first_equation + blocks), where p0 (if not
  // null) is added to the equation nu = 0 (IDEL: p0 + D1 L_d = 0).
  void newton(double h, int first_unknown, int first_equation, int blocks, const double* p0);
  void warm_start(const double* q0, const double* p0, double h);
  // Degree 1 with nodes only at 0 and 1 and a constant mass matrix M: the IDEL equations are
  // explicit (Stormer-Verlet for the trapezoid rule), solved without Newton.
  bool explicit_form_applies(Quadrature& quadrature);
  void explicit_step(const double* q0, const double* p0, double h, double* q1, double* p1);

  LagrangianEvaluator lagrangian_;
  LagrangeBasis basis_;
  Eigen::VectorXd weights_;
  Eigen::MatrixXd extrapolation_;  // l_mu(1 + d_nu): the last step's curve continued
  SolverOptions options_;
  SolverStatistics statistics_;
  int n_, s_;
  // Workspace, sized once: a step allocates nothing.
  Eigen::MatrixXd points_;    // n x (s+1), control points as columns
  Eigen::MatrixXd previous_;  // the last step's control points
  double previous_h_ = 0.0;
  bool has_previous_ = false;
  Eigen::VectorXd q_, v_, grad_, gradient_, residual_, update_, velocity_;
  Eigen::MatrixXd hess_, hessian_, jacobian_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  std::vector<double> residuals_;
  // The explicit form: endpoint weights, the factorized mass matrix, and dL/dq at the last q1
  // (reused as dL/dq at the next q0: one gradient evaluation per step).
  bool explicit_ = false;
  double b0_ = 0.0, b1_ = 0.0;
  Eigen::MatrixXd mass_matrix_;
  Eigen::LLT<Eigen::MatrixXd> mass_;
  Eigen::VectorXd force_, last_q_;
  bool has_force_ = false;
};

}  // namespace varia
