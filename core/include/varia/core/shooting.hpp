// The shooting-based discrete Lagrangian (paper, sec. 3, eqs. shooting_Ld_A/B):
//   L_d(q0, q1; h) = h sum_i b_i L(q^i, v^i),  (q^{i+1}, v^{i+1}) = Psi_{(c_{i+1}-c_i) h}(q^i, v^i),
//   q^0 = q0, q^n = q1,
// from a one-step method Psi (order p) and a quadrature rule (order q): order min(p, q). Its
// discrete Hamiltonian map is the paper's shooting-based implementation ("Implementation
// issues"): from q^0 = q0 and a guess of v^0 (the inverse Legendre transform of p0), propagate,
// and iterate on v^0 by Newton's method until p0 = -D1 L_d(q0, q^n); then q1 = q^n and
// p1 = D2 L_d.
//
// Derivatives are exact, never finite differences: the state is propagated as second-order jets
// in x = (q0, w0) (jet.hpp), so the generating function G(x) and the boundary quantity B(x) come
// out with gradients and Hessians. With w0(q0, B) defined by B(q0, w0) = B,
//   lambda = B_w^{-T} G_w   (the derivative of G in the far boundary value),
//   D1 = G_q - B_q^T lambda,
//   dD1/dw0 = Phi_qw - B_q^T B_w^{-T} Phi_ww,  Phi = G - <lambda, B> with lambda frozen,
// the last being the exact Jacobian of the shooting Newton iteration.
//
// Forms (paper, sec. 3 "Generalizations"):
//   lagrangian:  Psi on (q, v), G = S = h sum_i b_i L(q^i, v^i), B = q^n: D1 L_d, D2 L_d = lambda.
//   hamiltonian: Psi on Hamilton's equations in (q, p), the same S with v^i = dH/dp (q^i, p^i),
//                B = q^n (a Type I generating function); the unknown is p^0 (guess: p0).
//   type_2:      Psi on (q, p), G = H_d^+(q0, p1) = <p^n, q^n> - S, B = p^n: D1 H_d^+ and
//                q1 = D2 H_d^+ = lambda; the step iterates on p^0 until p0 = D1 H_d^+.
// Quadratures with Euler-Maclaurin end corrections (Quadrature::derivative_terms() = 1) add
// h^2 (a_1 dL/dt(0) + z_1 dL/dt(h)), with dL/dt = L_q v + L_v a, a = M^{-1} L_q, from the
// prolongation of the Euler-Lagrange vector field (paper, sec. 3 "More general quadrature
// formulas").
//
// Restrictions: a vector-space manifold of dimension n <= 4 (jets of 2n <= 8 variables) and a
// Lagrangian with a constant mass matrix (mechanical_field.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/core/manifold.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/one_step.hpp"
#include "varia/core/quadrature.hpp"

namespace varia {

enum class ShootingForm { lagrangian, hamiltonian, type_2 };

// "lagrangian", "hamiltonian" or "type-2" (the scene's method.form); throws
// std::invalid_argument naming the valid forms otherwise.
ShootingForm shooting_form(const std::string& name);

class ShootingDiscreteLagrangian : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // The method's stage solves use options too. Throws std::invalid_argument for an unsupported
  // manifold, Lagrangian or quadrature.
  ShootingDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
                             OneStepMethod& method, ShootingForm form, SolverOptions options);

  // L_d(q0, q1), D1 L_d, D2 L_d (any output may be null): the boundary-value problem
  // q^n(q0, w0) = q1 solved for w0 by Newton's method. In the type_2 form, L_d is the Legendre
  // transform of H_d^+: L_d = <p1, q1> - H_d^+(q0, p1) with q1 = D2 H_d^+ solved for p1, so that
  // D1 L_d = -D1 H_d^+ and D2 L_d = p1.
  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return n_; }
  int dim() const override { return n_; }
  void step(const double* q0, const double* p0, double h, double* q1, double* p1) override;
  // The shooting Newton iteration (one solve per step or evaluation).
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  // The one-step method's stage solves (zeros for explicit methods).
  const SolverStatistics& stage_statistics() const { return stages_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }
  // Residual norms of the last shooting solve, one per iteration (quadratic convergence).
  const std::vector<double>& last_residuals() const { return residuals_; }

 private:
  // What the Newton iteration on w0 drives to zero.
  enum class Target {
    momentum,   // D1 + p0 (Type I) or D1 - p0 (Type II): the step
    boundary,   // B - q1: evaluate in a Type I form
    lambda,     // lambda - q1: evaluate in the type_2 form
  };
  void shoot(const double* q0, const double* w0, double h);
  void accumulate(int node, double h, Jet2& S);
  void differentiate();
  void residual(Target target, const double* data);
  void solve(const double* q0, double h, Target target, const double* data);
  bool type_2() const { return form_ == ShootingForm::type_2; }

  LagrangianEvaluator lagrangian_;
  MechanicalField field_;
  OneStepMethod& method_;
  ShootingForm form_;
  SolverOptions options_;
  int n_;
  std::vector<double> nodes_, weights_;  // with 0 and 1 included
  double start_correction_ = 0.0, end_correction_ = 0.0;  // a_1, z_1 (Euler-Maclaurin)
  SolverStatistics statistics_, stages_;
  std::vector<double> residuals_;
  // Workspace, sized once: a step allocates nothing.
  std::vector<Jet2> state_, next_, v_, acceleration_, gradient_, boundary_;
  Jet2 generating_;
  Eigen::VectorXd w_, lambda_, D1_, residual_, update_;
  Eigen::MatrixXd Bq_, Bw_, phi_, jacobian_;
  Eigen::PartialPivLU<Eigen::MatrixXd> BwT_lu_, jacobian_lu_;  // of B_w^T and the Jacobian
};

}  // namespace varia
