// The Galerkin discrete Lagrangian on a Lie group, in the natural chart (paper, sec. 2, "Natural
// charts"): the degree-s Lagrange interpolant in the Lie algebra through the control points
// xi^0 = 0, xi^1, ..., xi^s in the chart at g0, mapped to the group as g(t) = g0 exp(xi(t)), whose
// left-trivialized velocity is dexp_{-xi}(xi') (so3.hpp on the sign):
//   L_d(g0, g1) = ext_{xi^1..xi^{s-1}} h sum_i b_i L(g0 exp(xi(c_i h)), dexp_{-xi(c_i h)} xi'(c_i h)),
//   xi^s = log(g0^{-1} g1).
// The interpolant is G-equivariant (the paper's Proposition in "Natural charts"), so L_d is
// G-invariant when L is, and the discrete Noether momentum is conserved.
//
// Left-trivialized derivatives. With S(eta, xi^1..xi^s) the action of the curve
// g0 exp(eta) exp(xi(t)) (the chart based at g0 exp(eta)), sigma = dS/dxi^s and tau = dS/deta at
// eta = 0, and the internal control points held fixed (envelope theorem: dS/dxi^nu = 0):
//   D2 L_d = dexp_{-xi^s}^{-T} sigma   (g1 exp(e) = g0 exp(xi^s + dexp_{-xi^s}^{-1} e)),
//   D1 L_d = tau - dexp_{xi^s}^{-T} sigma   (g1 fixed while g0 -> g0 exp(eta) moves xi^s by
//                                           -dexp_{xi^s}^{-1} eta).
// The discrete Hamiltonian map solves p0 = -D1 L_d with the internal conditions for xi^1..xi^s by
// Newton's method with the exact Jacobian: the manifold gives its chart at second-order jets
// (Manifold::chart), the Lagrangian its dense Hessian, and the chain rule their product.
//
// Reduced form (sec. 2, "Higher-order discrete Euler-Poincare equations"), for a Lagrangian
// invariant under the whole group (momentum_size() == dim()): L(g, Omega) = l(Omega), so tau = 0
// and the action depends on the velocities alone. The step solves the higher-order discrete
// Euler-Poincare equations dexp_{xi^s}^{-T} sigma = p0 (the right-trivialized l_d'(f) = p0,
// f = exp(xi^s)) with the internal conditions, evaluating l(Omega) = L(g0, Omega) and no position
// derivative, then reconstructs g1 = g0 f and p1 = dexp_{-xi^s}^{-T} sigma = Ad*_f p0.
// These are the step's equations above with tau = 0 and L(g0 exp(xi), Omega) = L(g0, Omega), so
// the map takes the reduced form's evaluation for every such Lagrangian: the position jets would
// add exact zeros at a large part of a step's cost. `reduced` asks for it and throws where
// it does not apply. Its Jacobian needs only d2l/dOmega2, which is M for a Lagrangian declaring a
// constant mass matrix (L = 1/2 v^T M v - V(q)): its nodes then evaluate L's gradient only.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/solve/newton.hpp"

namespace varia {

class LieGroupGalerkinDiscreteLagrangian : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // Throws std::invalid_argument when the reduced form is asked of a Lagrangian not invariant under the whole group.
  LieGroupGalerkinDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian,
                                     Quadrature& quadrature, std::vector<double> control_times,
                                     SolverOptions options, bool reduced = false);
  int degree() const { return s_; }

  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return m_; }
  int dim() const override { return n_; }
 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  // The step, then its tangent map by the implicit function theorem on the step's equations
  // (galerkin_chart_tangent.cpp), the directions and images in the natural charts at g0 and g1.
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 public:
  // Empty: every form has its tangent map.
  std::string tangent_map_refusal() const override;
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }
  // Residual norms of the last Newton solve, one per iteration (to show quadratic convergence).
  const std::vector<double>& last_residuals() const { return solver_.residuals(); }

 private:
  // S (also kept in action_) and, in gradient_ and (with_hessian) hessian_, its derivatives in (eta, xi^1, ..., xi^s)
  // (blocks of n numbers; block 0 is eta) for the control points in xi_ and the base point q0.
  // Without `with_value` S is not wanted (a step's equations need only its derivatives), and for
  // a constant mass matrix in the reduced form the nodes then ask the plugin for nothing:
  // dl/dOmega = M Omega.
  double action(const double* q0, double h, bool with_hessian = true, bool with_value = true);
  // The kernels below are templates on the group's dimension N and point size M, fixed for the
  // groups listed in choose_kernels() (SO(3), SE(3)) and Eigen::Dynamic for any other: one piece
  // of code, instantiated once per size and chosen once, at construction.
  void choose_kernels();
  // Adds quadrature node i: L at the chart curve and the chain rule through the chart's jets
  // (chain_to_node), weighted into the action's derivatives (add_to_action).
  template <int N, int M>
  double add_node(const double* q0, int i, double h, bool with_hessian, bool with_value);
  template <int N, int M>
  void chain_to_node(bool with_hessian);
  template <int N>
  void add_to_action(int i, double h, bool with_hessian);
  // dexp_{sign w} (= d velocity / d xi_dot at xi = -sign w) into dexp_, its inverse transpose,
  // and (with_derivatives) its derivatives in (sign w)_l (one n x n matrix each), from the
  // manifold's chart at jets.
  template <int N>
  void dexp_with_derivatives(const double* q0, const double* w, double sign, bool with_derivatives);
  // The residual of the step's equations [p0 + D1 L_d; dS/dxi^1..s-1] (evaluate: internal only)
  // and its Jacobian in the unknowns.
  template <int N>
  void step_equations(const double* p0, bool with_jacobian = true);
  double (LieGroupGalerkinDiscreteLagrangian::*add_node_)(const double*, int, double, bool, bool) = nullptr;
  void (LieGroupGalerkinDiscreteLagrangian::*dexp_with_derivatives_)(const double*, const double*, double, bool) = nullptr;
  void (LieGroupGalerkinDiscreteLagrangian::*step_equations_)(const double*, bool) = nullptr;
  struct Equations;  // those equations as a NewtonSolver system
  // simplified: Newton's method with the Jacobian at the first iterate (Equations), falling back
  // to the exact Jacobian when that does not contract.
  void newton(const double* q0, const double* p0, double h, bool simplified);
  // The compensated final update (see step()): dexp's slopes at 0, and g0 exp(xi) - g0.
  void dexp_slopes(const double* q0);
  bool point_increment(const double* q0, const Eigen::Ref<const Eigen::VectorXd>& xi);
  struct GaussRule {
    Eigen::VectorXd nodes, weights;  // on [0, 1]
    double bound;                    // the error constant E_k
  };
  static GaussRule gauss_legendre(int k);
  // True when the guess continues the last steps' curve (see the .cpp).
  bool warm_start(const double* q0, const double* p0, double h);
  auto previous() { return history_.rightCols(s_ + 1); }  // the last step's control points
  void check(Status status) const;
  void size_workspace();  // once, at construction

  Manifold& manifold_;
  LagrangianEvaluator lagrangian_;
  LagrangeBasis basis_;
  Eigen::VectorXd weights_;
  // The warm start's extrapolations to the times 1 + d_nu: of the last step's curve (l_mu(1 + d_nu),
  // (s+1) x (s+1)), and of the polynomial through the last two steps' control points
  // ((2s+1) x (s+1): the step before's d_mu - 1, mu < s, then the last's d_mu).
  Eigen::MatrixXd extrapolation_, extrapolation_two_;
  SolverOptions options_;
  NewtonSolver solver_;
  SolverStatistics statistics_;
  bool reduced_;
  bool constant_mass_ = false;  // reduced, and L = 1/2 v^T M v - V(q) declared: hess_'s velocity block is M
  int m_, n_, s_;
  // Workspace, sized once: a step allocates nothing.
  Eigen::MatrixXd xi_;        // n x (s+1) control points in the chart, column 0 = 0
  // The last two steps' control points in the last step's chart: the step before's xi^0..xi^{s-1}
  // (when two_steps_back_), then the last step's xi^0..xi^s (previous(), the last s+1 columns).
  Eigen::MatrixXd history_;
  Eigen::MatrixXd earlier_;  // the last step's xi^0..xi^{s-1} in this step's chart (the next history)
  bool two_steps_back_ = false;
  Eigen::VectorXd previous_base_, last_end_, last_p_;  // the last step's g0, g1 and p1
  // Compensated sums g1 = g0 + (g1 - g0), p1 = p0 + (p1 - p0) across steps (compensated.hpp):
  // the running compensations and the increments.
  Eigen::VectorXd carry_g_, carry_p_, point_change_, point_change_low_, momentum_change_;
  std::vector<Eigen::MatrixXd> dexp_slopes_;  // d dexp_w / dw_l at w = 0, once
  std::vector<GaussRule> increment_rules_;    // k = 1 .. 10 nodes
  double previous_h_ = 0.0;
  bool has_previous_ = false;
  // The chart at a node (Manifold::chart): values, gradients and Hessians, component-major.
  Eigen::VectorXd point_, point_gradient_, point_hessian_, velocity_, velocity_gradient_, velocity_hessian_;
  Eigen::VectorXd node_xi_, node_rate_, q_, v_, grad_, node_gradient_;
  Eigen::MatrixXd hess_, chain_, hess_chain_, node_hessian_;
  double action_ = 0.0;        // S at the last evaluation
  Eigen::VectorXd gradient_;  // n (s+1)
  Eigen::MatrixXd hessian_;   // n (s+1) square
  Eigen::MatrixXd dexp_, dexp_inverse_T_, identity_;  // dexp_{w}, dexp_w^{-T}, I
  std::vector<Eigen::MatrixXd> dexp_derivative_;     // d dexp_w / dw_l
  Eigen::PartialPivLU<Eigen::MatrixXd> dexp_lu_, lu_;
  Eigen::VectorXd residual_, momentum_, dexp_momentum_;  // momentum_ = A^{-T} sigma; (dA/dw_l)^T momentum_
  Eigen::VectorXd refined_residual_, refined_update_;  // simplified Newton's last update (Equations::finish)
  Eigen::MatrixXd jacobian_;
  int unknowns_ = 0;  // the leading control points solved for: s (step) or s - 1 (evaluate)
  // The tangent map's workspace: dexp_{xi^s}^{-T}, the right sides and solutions in the control
  // points, the chart's derivatives at g1 and the end's changes.
  Eigen::MatrixXd forward_inverse_T_, tangent_rhs_, tangent_xi_, end_point_, chart_inverse_, sigma_change_;
  Eigen::VectorXd end_momentum_, local_value_;
  std::vector<double> local_gradient_;
};

}  // namespace varia
