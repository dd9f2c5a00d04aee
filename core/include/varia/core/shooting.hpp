// The shooting-based discrete Lagrangian (paper, sec. 3, eqs. shooting_Ld_A/B):
//   L_d(q0, q1; h) = h sum_i b_i L(q^i, v^i),  (q^{i+1}, v^{i+1}) = Psi_{(c_{i+1}-c_i) h}(q^i, v^i),
//   q^0 = q0, q^n = q1,
// from a one-step method Psi (order p) and a quadrature rule (order q): order min(p, q). Its
// discrete Hamiltonian map is the paper's shooting-based implementation ("Implementation
// issues"): from q^0 = q0 and a guess of v^0 (the inverse Legendre transform of p0, corrected by
// the last steps' corrections extrapolated while the steps continue one another), propagate,
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
// Forces (force.hpp) enter the step by the discrete Lagrange-d'Alembert principle (Marsden &
// West 2001, sec. 3.2): p0 = -D1 L_d - f_d^-, p1 = D2 L_d + f_d^+, the discrete forces through
// the same quadrature as L_d along the same propagation,
//   f_d^- = h sum_i b_i (dq^i/dq0)^T f(t + c_i h, q^i, v^i),   f_d^+ = h sum_i b_i (dq^i/dq1)^T f_i,
// the derivatives taken at fixed q1 and q0 through w0(q0, q1) like lambda. With the virtual work
// W = h sum_i b_i <f_i, q^i(x)> (f_i frozen), f_d^- and f_d^+ are W's D1 and D2 by the formulas
// above: alpha = G_x + W_x takes G_x's place, and Phi gains dW_x/dx (f_i no longer frozen):
//   dW_x/dx = h sum_i b_i (sum_r f_ir q^i_r,xx + q^i_x^T f_i,x).
// The propagation is that of the FORCED Euler-Lagrange equations, M v' = L_q + f (mechanical_
// field.hpp). Marsden & West's exact discrete Lagrangian and exact discrete forces (sec. 3.2)
// integrate along the forced solution between q0 and q1, and only along it does the first
// variation, d/dq1 int L + int <f, dq/dq1> = p(h) + int <EL + f, dq/dq1>, reduce to p(h): with the
// unforced flow the construction is of order 2 whatever Psi and the rule (the free particle with
// f = -c v: the unforced flow is the straight line, and the step becomes the Galerkin degree-1
// map p1 = p0 (1 - ch/2)/(1 + ch/2) for every exact Psi and rule). Forces are applied in step()
// only; evaluate() (varia ld) gives the unforced L_d. The time is the step's t0 (discrete_hamiltonian_map.hpp). Not with the type-2 form nor with end-derivative quadratures.
//
// On a Lie group (a manifold that is not a vector space; the field is lie_group_field.hpp's) the same
// construction runs in the natural charts (paper, sec. 2 "Natural charts", sec. 3): the jet
// variables are x = (eta, w0) with q^0 = q0 exp(eta) at eta = 0 (Manifold::chart), the state
// (g, xi) propagated by the method with the Euler-Poincare field on TG (a Lie group method
// moves g exp(.)), S = h sum_i b_i L(g^i, xi^i), and the boundary quantity B = local(q1, g^n)
// = log(q1^{-1} g^n) (Manifold::local_derivatives), centred at g^n's value in a step. Then G_eta - B_eta^T
// lambda is D1 L_d and lambda = dG/dB at B = 0 is D2 L_d, both left-trivialized: the discrete
// momenta are body momenta, as lie-verlet's. The lagrangian form only, no forces, no end-derivative
// quadratures there.
//
// With holonomic constraints g(q) = 0 on R^N (HolonomicConstraints, quadratic ones: docs/constraints.md)
// the shot is the constrained one-step map (constrained_field.hpp): a step of the method on the
// index-1 field, then the projection onto the constraint and its hidden constraint, at jets.
// L_d is then a function on Q x Q, Q = {g = 0} of dimension n = N - m, and the construction runs in
// charts of Q: x = (a, w0) in R^2n with q^0, v^0 the projections of q0 + N0 a and N0 w0 (N0 an
// orthonormal basis of T_q0 Q), and B = N1^T (q^n - c) (N1 one of T_c Q, c = q1 or, in a step,
// q^n's value). D1 and lambda = D2 are then covectors on T_q0 Q and T_q1 Q in those bases: p0 is
// read as N0^T p0, and p1 = N1 lambda is taken onto the cotangent space as the projection's M v
// with G(q1) v = 0 (the momenta the Galerkin construction holds). Its theorem is the
// unconstrained one on Q: order min(p, q) for the projected method's order p, symplectic on Q.
// The lagrangian form only, no forces, a constant mass matrix, no tangent map.
//
// Sensitivities in passes: a jet holds at most kMaxJetVariables = 12 variables, or fewer where the
// field's derivatives at jets take fewer (MechanicalField::jet_variables). Where 2n exceeds that
// (on R^n or on a Lie group),
// the state is propagated in passes over a few numbers of x each (plan_passes): first derivatives
// over blocks of x, and of the second derivatives only Phi's columns in w0, the Newton Jacobian's,
// over pairs of blocks. Every pass has the same values; together they give the one-pass derivatives.
//
// The step on the shot's adjoint: where passes would be needed and the shot is one explicit
// recurrence at doubles (an explicit Runge-Kutta method on R^n, a Type I form, a constant mass
// matrix, no forces or end corrections), the step needs no second derivatives. Its unknowns are
// (w0, lambda), its equations D1 + p0 = 0 and dF/dw0 = 0 for F = S - <lambda, B> (which makes
// lambda = D2 L_d), whose residuals one forward and one reverse sweep give (shot_adjoint.hpp): a
// gradient and a Hessian-vector product of L a stage, at any n. Simplified Newton solves them with
// the Jacobian of the flow to first order in h (shooting_solve.cpp, AdjointEquations), and where it
// does not converge the step solves with the exact Jacobian from the passes.
//
// Where the shot is one fixed recurrence (an explicit Runge-Kutta method, the lagrangian form on
// R^n, a constant mass matrix, no forces, no end corrections: explicit_shot.hpp), the Lagrangian's
// plugin runs it whole with its model inlined (kernel::ExplicitShot), where it takes the plan (the
// SDK's models: n <= 3); the same numbers as the propagation through the method's plugin.
//
// Restrictions: none on the dimension (R^n or a Lie group). The lagrangian form with a
// configuration-dependent mass matrix needs L's Hessian at jets of at least 2 variables (the SDK
// gives 6, for models of at most 18 position and velocity numbers); the hamiltonian and type-2
// forms take any regular Lagrangian (mechanical_field.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <memory>
#include <string>
#include <vector>

#include "varia/core/constrained_field.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/force.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/shot_adjoint.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/solve/newton.hpp"
#include "varia/core/solve/small_dense.hpp"

namespace varia {

enum class ShootingForm { lagrangian, hamiltonian, type_2 };

// "lagrangian", "hamiltonian" or "type-2" (the scene's method.form); throws
// std::invalid_argument naming the valid forms otherwise.
ShootingForm shooting_form(const std::string& name);

class ShootingDiscreteLagrangian : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // The method's stage solves use options too. Throws std::invalid_argument for an unsupported
  // manifold, Lagrangian or quadrature, or forces with the type_2 form or an end-derivative rule.
  // jet_capacity: the most variables of a pass's jets (at most kMaxJetVariables; fewer: more
  // passes of smaller jets, the same derivatives). constraints: holonomic constraints on the
  // vector space (quadratic ones; throws std::invalid_argument otherwise, or for another form or
  // forces with them).
  ShootingDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
                             OneStepMethod& method, ShootingForm form, SolverOptions options,
                             std::vector<Force*> forces = {}, int jet_capacity = kMaxJetVariables,
                             HolonomicConstraints* constraints = nullptr);

  // L_d(q0, q1), D1 L_d, D2 L_d (any output may be null): the boundary-value problem
  // q^n(q0, w0) = q1 solved for w0 by Newton's method. In the type_2 form, L_d is the Legendre
  // transform of H_d^+: L_d = <p1, q1> - H_d^+(q0, p1) with q1 = D2 H_d^+ solved for p1, so that
  // D1 L_d = -D1 H_d^+ and D2 L_d = p1.
  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return m_; }
  int dim() const override { return manifold_.dim(); }
  // The shooting Newton iteration (one solve per step or evaluation).
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  // The one-step method's stage solves (zeros for explicit methods).
  const SolverStatistics& stage_statistics() const { return stages_; }
  const EvaluationCounters& evaluations() const override;
  // Residual norms of the last shooting solve, one per iteration (quadratic convergence).
  const std::vector<double>& last_residuals() const { return last_solver_->residuals(); }
  // Empty on a vector space (every form, any dimension).
  std::string tangent_map_refusal() const override;

 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  // The step, then the implicit function theorem on its equation D1(x) + p0 = 0 (type 2:
  // D1 H_d^+(x) - p0 = 0) in w0, x = (eta, w0): the shot at the solution again with all of Phi's
  // second derivatives (shooting_solve.cpp).
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 private:
  // What the Newton iteration on w0 drives to zero.
  enum class Target {
    momentum,   // D1 + p0 (Type I) or D1 - p0 (Type II): the step
    boundary,   // B - q1: evaluate in a Type I form
    lambda,     // lambda - q1: evaluate in the type_2 form
  };
  // One propagation of the state as jets: which of x = (eta, w0)'s 2n numbers are its jet
  // variables (at most the field's jet_variables()), and what it gives: first derivatives (of G,
  // W and B, in its variables) and second derivatives (in pairs of its variables). See shoot().
  struct Pass {
    std::vector<int> variables;
    bool first_order, second_order;
  };
  // Parts of the constructor (with plan_passes).
  void take_quadrature(Quadrature& quadrature);
  void refuse_unsupported() const;
  void size_workspace();
  void offer_explicit_shot(Lagrangian& lagrangian);
  void offer_adjoint();
  void plan_passes(int capacity);
  // The jet of x's number `variable` (-1: none) at `value` in the current pass: one of its
  // variables, or a jet of zero derivatives in them. Every pass's jets have jet_size_ variables,
  // its unused ones with zero derivatives: a one-step method's workspace then keeps its size.
  Jet2 seeded(double value, int variable) const;
  void start_point(const double* q0, const double* w0);
  void boundary();
  // The step with constraints (step_ there): in the charts of Q at q0 and q1 (see above).
  void step_on_constraint(const double* q0, const double* p0, double h, double* q1, double* p1);
  // The members templated on N do the shooting Newton's algebra on vectors of N = n numbers and
  // N x N matrices, N fixed at compile time on R^n for n <= 4 (fixed_size.hpp: chosen once, step_),
  // else Eigen::Dynamic.
  template <int N>
  void step_at(const double* q0, const double* p0, double h, double* q1, double* p1);
  using StepFunction = void (ShootingDiscreteLagrangian::*)(const double*, const double*, double, double*, double*);
  // step_at<n> on R^n for n <= 4, step_at<Dynamic> otherwise (shooting_solve.cpp).
  static StepFunction step_function(int n, bool vector_space);
  StepFunction step_ = nullptr;
  template <int N>
  void shoot(const double* q0, const double* w0, double h);
  void propagate(const double* q0, const double* w0, double h, const Pass& pass);
  void accumulate(int node, double h, Jet2& S);
  void add_work(double weight, const Jet2* v);
  void gather(const Pass& pass);
  template <int N>
  void first_derivatives();
  void second_derivatives(const Pass& pass);
  template <int N>
  void residual(Target target, const double* data);
  template <int N>
  struct Equations;  // the shooting equations as a NewtonSolver system
  template <int N>
  void solve(const double* q0, double h, Target target, const double* data);
  // The step's solve on the shot's adjoint (adjoint_): false where simplified Newton does not
  // converge (it stops contracting, or reaches the iteration limit: the caller then solves with the
  // exact Jacobian from the same guess, which reports a failure of its own).
  struct AdjointEquations;
  bool solve_by_adjoint(const double* q0, double h, const double* p0);
  template <int N>
  void warm_start(bool continues);
  template <int N>
  void record_correction(double h);
  template <int N>
  void add_extrapolation(int first, double* x) const;
  bool type_2() const { return form_ == ShootingForm::type_2; }
  // The boundary quantity is the offset q^n - (q0 + eta): a vector space, Type I forms.
  bool offsets() const { return mechanical_ != nullptr && !type_2(); }
  // The positions of the state: origin_ + offsets on a vector space, else the state's own.
  const Jet2* position();

  Manifold& manifold_;
  LagrangianEvaluator lagrangian_;
  Forces forces_;
  std::unique_ptr<EulerLagrangeField> field_;
  MechanicalField* mechanical_;  // field_ on a vector space without constraints, else null
  ConstrainedField* constrained_;  // field_ with constraints, else null
  HolonomicConstraints* constraints_;
  OneStepMethod& method_;
  ShootingForm form_;
  SolverOptions options_;
  NewtonSolver solver_;
  int m_, n_;  // point_size, dim
  std::vector<double> nodes_, weights_;  // with 0 and 1 included
  double start_correction_ = 0.0, end_correction_ = 0.0;  // a_1, z_1 (Euler-Maclaurin)
  double t_ = 0.0;       // the time at the start of the step being taken
  bool forced_ = false;  // forces applied in the current solve (steps of a forced system)
  bool target_is_end_ = false;  // B's chart at q^n's value (a step) or at target_ (evaluate)
  std::vector<double> target_, zero_;
  std::vector<Pass> passes_;
  std::vector<Pass> tangent_passes_;  // where there are several: passes giving all of Phi (the tangent map's)
  std::vector<int> slot_;        // the current pass's jet variable of each number of x, or -1
  int jet_size_ = 0;             // the jets' number of variables in every pass (a pass may use fewer)
  bool second_order_ = true;     // whether the current solve needs Phi (its Jacobian does)
  bool all_second_derivatives_ = false;  // Phi's columns in eta too (the tangent map's shot)
  SolverStatistics statistics_, stages_;
  mutable EvaluationCounters counters_;
  // The shot run inside the Lagrangian's plugin where it is explicit_shot.hpp's recurrence (an
  // explicit Runge-Kutta method, the lagrangian form on R^n, a constant mass matrix, no forces,
  // no end corrections, one pass) and the plugin takes the plan: one call a shot.
  ShotPlan shot_plan_;
  bool plugin_shoots_ = false;
  // The step's shot at doubles with its first derivatives by a reverse sweep, where the exact
  // Jacobian would take several passes of jets and the shot is an explicit recurrence (an explicit
  // method, R^n, a Type I form, a constant mass matrix, no forces or end corrections):
  // shot_adjoint.hpp; null otherwise.
  std::unique_ptr<ShotAdjoint> adjoint_;
  NewtonSolver adjoint_solver_;
  const NewtonSolver* last_solver_ = &solver_;
  Eigen::VectorXd adjoint_guess_, adjoint_scratch_;
  // Workspace, sized once: a step allocates nothing.
  std::vector<Jet2> state_, next_, acceleration_, gradient_, boundary_, force_;
  std::vector<Jet2> origin_;  // q0 + eta: the origin of the state's positions on a vector space
  Jet2 generating_;
  // The natural chart's derivatives (Manifold::chart, local_derivatives), component-major.
  std::vector<double> end_, chart_value_, chart_gradient_, chart_hessian_, local_value_, local_gradient_,
      local_hessian_;
  Eigen::VectorXd w_, v_values_, lambda_, D1_, residual_;
  Eigen::VectorXd alpha_;        // G_x + W_x: the forced 1-form in x = (q0, w0)
  Jet2::Gradient work_gradient_;  // W_x and dW_x/dx in the current pass's variables
  Jet2::Hessian work_jacobian_;
  Eigen::MatrixXd Bq_, Bw_, phi_, jacobian_;
  Eigen::MatrixXd lambda_jacobian_;  // dlambda/dw0 = B_w^{-T} Phi_ww
  // Compensated sums q1 = q0 + (q^n - q0), p1 = p0 + (p1 - p0) across steps (compensated.hpp):
  // the increments and the running compensations; the last step's output, whether there is one,
  // and its h.
  Eigen::VectorXd offset_, momentum_change_, carry_q_, carry_p_, end_q_, end_p_;
  bool continuing_ = false;
  double previous_h_ = 0.0;
  // The warm start (warm_start()): the inverse Legendre transform's guess of w0, and the
  // corrections w0 - guess of the last steps, newest first (corrections_ of them); on the shot's
  // adjoint also lambda's guess and corrections (the history's rows n..2n-1).
  static constexpr int kCorrections = 3;
  Eigen::VectorXd guess_, lambda_guess_;
  Eigen::MatrixXd corrections_history_;
  int corrections_ = 0;
  SmallDenseSolver BwT_solver_, jacobian_solver_;  // of B_w^T and the Jacobian
  // The tangent map's workspace: dlambda/dx and dD1/dx (n x 2n), the LUs of B_w^T and dD1/dw0, the
  // directions' right-hand sides and dw0 (n x count).
  Eigen::MatrixXd tangent_lambda_, tangent_d1_, tangent_rhs_, tangent_w_;
  Eigen::PartialPivLU<Eigen::MatrixXd> tangent_bw_lu_, tangent_lu_;
  // With constraints: the charts' bases N0, N1 (N x n) and their source, the momentum p0 on T_q0 Q
  // (n numbers), a velocity and a momentum in R^N.
  Eigen::MatrixXd start_basis_, end_basis_;
  std::unique_ptr<TangentBasis> tangent_basis_;
  Eigen::VectorXd chart_momentum_, velocity_, embedded_momentum_;
};

}  // namespace varia
