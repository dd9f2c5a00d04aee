// The Galerkin discrete Lagrangian (paper, sec. 2): the action of the degree-s Lagrange
// interpolant through control points q^0 = q0, q^1, ..., q^s = q1 at control times
// 0 = d_0 < ... < d_s = 1, approximated by a quadrature rule and extremized over the internal
// control points:
//   L_d(q0, q1) = ext_{q^1..q^{s-1}} h sum_i b_i L(q(c_i h), qdot(c_i h)).
// Its discrete Hamiltonian map solves the IDEL equations p0 = -D1 L_d, p1 = D2 L_d together with
// the internal stationarity conditions by Newton's method with the exact Jacobian; for
// L = 1/2 v^T M v - V(q) with a constant mass matrix M (and no forces) by simplified Newton:
// the equations are
//   p0 delta_nu0 + (1/h) sum_mu K_numu M q^mu - h sum_i b_i l_nu(c_i) grad V(q(c_i h)) = 0,
// with the stiffness matrix K_numu = sum_i b_i l'_nu(c_i) l'_mu(c_i) of the interpolant, and their
// kinetic part (1/h) K (x) M, constant, is the Jacobian that the iteration keeps. With the forces
// at the nodes given, the equations are linear: the control points, and the nodes' positions on
// the interpolant, are a fixed linear map of (M^{-1} p0, M^{-1} grad V at the nodes), formed once
// when the map is built. The iteration therefore runs in the nodes' positions: each pass evaluates
// the forces at the nodes (in one plugin call) and applies that map, with no Hessian, no
// velocity, no control point. This is the fixed-point iteration of the s-stage Gauss method (s
// Gauss-Legendre points) for q'' = -M^{-1} grad V, whose contraction is O(h^2 |M^{-1} V''|). Where
// it does not contract (theta >= 1/2: large steps, stiff forces) the step is solved again with the
// exact Jacobian.
// Forces (force.hpp) enter by the discrete Lagrange-d'Alembert principle (Marsden & West 2001,
// sec. 3.2) with the discrete forces taken through the same quadrature,
//   f_d^nu = h sum_i b_i l_nu(c_i) f(t + c_i h, q(c_i h), qdot(c_i h)),
// added to the equation of control point nu: p0 = -D1 L_d - f_d^0, p1 = D2 L_d + f_d^s.
// A Lagrangian with a sparse Hessian (hessian_pattern() >= 0) gets a sparse Newton Jacobian,
// factorized by Eigen's SparseLU; no dense matrix of size n is formed. Degree 1 with the nodes at
// 0 and 1 only and a constant mass matrix (constant_mass_matrix for a dense Lagrangian,
// has_constant_mass_matrix for a sparse one) takes no Newton iteration: its equations are
// explicit (Stormer-Verlet for the trapezoid rule).
// Holonomic constraints g(q) = 0 (constraints.hpp) enter by multipliers, as blocks of the one
// Newton system (docs/constraints.md): the control points q^1..q^s lie on the constraint and each
// equation nu < s gains -G(q^nu)^T lambda_nu,
//   p0 delta_nu0 + dS/dq^nu + f_d^nu - G(q^nu)^T lambda_nu = 0 (nu < s),   g(q^mu) = 0 (mu = 1..s),
// the constrained discrete Euler-Lagrange equations of L_d(q0, q1) = ext S over internal control
// points on the constraint; p1 = D2 L_d + f_d^s - G(q1)^T mu then lies on the constraint's cotangent
// space, G(q1) M^{-1} p1 = 0. With s + 1 Lobatto points and control points at them, these are
// Jay's Lobatto IIIA-IIIB equations for constrained mechanics (order 2s).
#pragma once

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <memory>
#include <string>
#include <vector>

#include "varia/core/constraints.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/force.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/solve/newton.hpp"

namespace varia {

// Lagrange basis through the control times, evaluated at the quadrature nodes:
// phi(nu, i) = l_nu(c_i), dphi(nu, i) = l'_nu(c_i) (derivative in tau in [0, 1]); column i holds
// node i's values, contiguous for the loops over control points.
struct LagrangeBasis {
  LagrangeBasis(const std::vector<double>& control_times, const Quadrature& quadrature);
  Eigen::MatrixXd phi, dphi;
  // l_nu(tau) for one tau, e.g. to extrapolate the previous step's curve as a warm start.
  Eigen::VectorXd at(double tau) const;
  std::vector<double> control_times;
};

// l_nu(tau), nu = 0..times.size() - 1, of the Lagrange basis through the distinct `times`.
Eigen::VectorXd lagrange_basis_at(const std::vector<double>& times, double tau);

// Equispaced control times d_nu = nu / s.
std::vector<double> equispaced_control_times(int degree);
// Chebyshev-Gauss-Lobatto control times d_nu = (1 - cos(pi nu / s)) / 2, exactly symmetric
// (d_{s-nu} = 1 - d_nu). The same polynomial space as any other control times, so the same L_d in
// exact arithmetic; in floating point their Lagrange basis stays well conditioned at high degree
// (Lebesgue constant O(log s) against O(2^s / s) for equispaced times), which keeps the spectral
// accuracy of Hall & Leok's spectral variational integrators: the pendulum's step at h = 1 has an
// error of about 1e-15 at s = 32, where equispaced times give 3e-4.
std::vector<double> chebyshev_lobatto_control_times(int degree);

class GalerkinDiscreteLagrangian : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // The manifold must be a vector space (is_vector_space()); Lie groups use their natural chart
  // through the same interface once the manifold provides it.
  GalerkinDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
                             std::vector<double> control_times, SolverOptions options,
                             std::vector<Force*> forces = {}, HolonomicConstraints* constraints = nullptr);
  int degree() const { return static_cast<int>(basis_.control_times.size()) - 1; }

  // L_d, D1 L_d, D2 L_d with the internal control points extremized (any output may be null);
  // the forces are not part of L_d.
  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return n_; }
  int dim() const override { return n_; }
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override;
  // Residual norms of the last Newton solve, one per iteration (to show quadratic convergence).
  const std::vector<double>& last_residuals() const { return solver_.residuals(); }
  // Empty without constraints (galerkin_tangent.cpp).
  std::string tangent_map_refusal() const override;

 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  void take_steps(double* q, double* p, double t0, double h, long steps, double* q1, double* p1) override;
  // The step, then the implicit function theorem on its equations E_nu(q^0..q^s) + p0 delta_nu0 = 0
  // (nu < s), p1 = E_s, with E_nu = dS/dq^nu + f_d^nu (galerkin_tangent.cpp).
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 private:
  // value: S only; gradient: dS/dq without S (the plugin is not asked for L); value_and_gradient;
  // hessian: S, dS/dq and d2S/dq2.
  enum class Order { value, gradient, value_and_gradient, hessian };
  // The discrete action S(q^0..q^s) = h sum_i b_i L(q(c_i h), qdot(c_i h)) of the control points
  // in points_, with its gradient dS/dq^nu in gradient_ and Hessian in hessian_ (sparse: in
  // sparse_.matrix) up to `order`; with `forced`, f_d^nu is added to gradient_ and its Jacobian to
  // the Hessian.
  double action(double h, Order order, bool forced = false) { return (this->*action_)(h, order, forced); }
  // action() compiled for N = n (the per-node loops over control points and coordinates unrolled,
  // no loop set up for a handful of numbers) when n <= 4, for Eigen::Dynamic otherwise; chosen
  // once, in action_.
  template <int N>
  double action_for(double h, Order order, bool forced);
  using ActionFunction = double (GalerkinDiscreteLagrangian::*)(double, Order, bool);
  static ActionFunction action_function(int n);  // action_for<n or Dynamic>
  // The interpolant at quadrature node i into q and v.
  template <int N, int S = Eigen::Dynamic>
  void interpolate(int i, double h, double* q, double* v);
  void add_forces(int i, double h, Order order);
  // The gradient's terms of node i with weight b and dL = [L_q; L_v] there, for the control
  // points [first, first + count), into out; the dense Hessian's (see action()).
  template <int N>
  void add_gradient(int i, double h, double b, const double* dL, double* out, int first, int count);
  template <int N>
  void add_hessian(int i, double h, double b);
  // dq_i/dq^nu = l_nu(c_i), dv_i/dq^nu = l'_nu(c_i)/h: the weight of an entry's row or column.
  double weight(int i, int nu, bool by_v, double h) const;
  // Adds w * values[k] times the row and column weights to d(equation nu)/dq^mu of every block of
  // the sparse Jacobian, for the entries [first_entry, first_entry + count).
  void add_sparse_entries(int i, double h, int first_entry, const double* values, int count, double w);
  // Newton's method on the control points [first_unknown, first_unknown + blocks) for the
  // equations dS/dq^nu (+ f_d^nu when forced) = 0, nu in [first_equation, first_equation + blocks),
  // where p0 (if not null) is added to the equation nu = 0 (IDEL: p0 + D1 L_d + f_d^0 = 0).
  void newton(double h, int first_unknown, int first_equation, int blocks, const double* p0,
              bool forced);
  struct Equations;  // those equations as a NewtonSolver system
  // With constraints: those equations bordered by the multipliers' blocks (see the top), in the
  // control points and the multipliers lambda_nu of the equations (galerkin_constrained.cpp); the
  // bordered Jacobian's pattern for these equations and unknowns; the projection of p1.
  struct ConstrainedEquations;
  void constrained_newton(double h, int first_unknown, int first_equation, int blocks, const double* p0, bool forced);
  void prepare_bordered(int first_unknown, int first_equation, int blocks);
  void project_momentum(const double* p0);
  // Simplified Newton for a constant mass matrix, in the nodes' coordinates (see the top):
  // whether it applies (and its linear maps, formed once), the extrapolation of the last steps'
  // forces to the next step's nodes, the fixed point as a NewtonSolver system, its solve (true when
  // it converged; else the step is solved again with the exact Jacobian, from warm_start()), and
  // the linear map from the forces at the nodes to offsets. Compiled for N = n <= 4 and R = the
  // nodes of nonzero weight <= 7 where both are small (loops of a fixed length), Eigen::Dynamic
  // otherwise, chosen once (step_).
  bool simplified_applies();
  void prepare_node_iteration();  // simplified_applies's last part
  Eigen::MatrixXd extrapolation_to_nodes(const std::vector<double>& times) const;
  template <int N, int R>
  struct NodeIteration;
  template <int N, int R>
  double node_residual(double h, double inverse_h, double speed, double& scale, double* F);
  template <int N>
  void inverse_mass_times(const double* g, double* a);
  void sparse_inverse_mass_times(const double* g, double* a);
  template <int N, int R>
  bool solve_at_nodes(const double* p0, double h, bool continues);
  void predict_accelerations();
  template <int N, int Rows, int C>
  void offsets_from_forces(const Eigen::MatrixXd& map, double h, const double* forces, double* offsets) const;
  // take_step() from the step's start (t_ set), at fixed sizes (step_at: see the .cpp).
  template <int N, int R>
  void step_at(const double* q0, const double* p0, double h, double* q1, double* p1);
  using StepFunction = void (GalerkinDiscreteLagrangian::*)(const double*, const double*, double, double*, double*);
  // step_at<N, R> (node_iteration) or step_at<N, Dynamic> (exact Newton), N and R fixed where small.
  static StepFunction step_function(int n, int nodes, bool node_iteration);
  void factorize_sparse();
  // The control points of the step just taken into origin_ and points_ (where the node iteration
  // solved it, from the forces at its nodes; the explicit form's q^1 = q1).
  void control_points_of_step(const double* q0, const double* q1, double h);
  // The sparse Jacobian's structure for these equations and unknowns (rebuilt when they change).
  void prepare_sparse(int first_unknown, int first_equation, int blocks);
  void gradient_after_update(double h, int first_unknown, Eigen::Ref<const Eigen::VectorXd> update, bool forced);
  // The control points' initial guess for Newton's method with the exact Jacobian; `continues`:
  // the step continues the last one (same h, from its q1).
  void warm_start(const double* q0, const double* p0, double h, bool continues);
  // Degree 1 with nodes only at 0 and 1 and a constant mass matrix M: the IDEL equations are
  // explicit (Stormer-Verlet for the trapezoid rule), solved without Newton. For a dense
  // Lagrangian the steps are compiled for N = n (fixed-size arithmetic, the state in registers
  // across steps) when n <= 4, for Eigen::Dynamic otherwise; for a sparse one M is factorized by
  // sparse Cholesky. Chosen once.
  using AdvanceFunction = void (GalerkinDiscreteLagrangian::*)(double*, double*, double, long);
  AdvanceFunction explicit_form(Quadrature& quadrature);
  template <int N>
  void explicit_advance(double* q, double* p, double h, long steps);
  void sparse_explicit_advance(double* q, double* p, double h, long steps);
  void factorize_sparse_mass(const double* q);
  void keep_explicit_state(const double* q, const double* p, double h, long steps);

  LagrangianEvaluator lagrangian_;
  Forces forces_;
  double t_ = 0.0;  // the time at the start of the step being taken
  mutable EvaluationCounters counters_;
  LagrangeBasis basis_;
  Eigen::VectorXd weights_, nodes_;
  Eigen::MatrixXd extrapolation_;  // l_mu(1 + d_nu): the last step's curve continued
  SolverOptions options_;
  NewtonSolver solver_;
  SolverStatistics statistics_;
  int n_, s_;
  // Workspace, sized once: a step allocates nothing.
  // The control points are held as offsets from q^0 = origin_: q^nu = origin_ + points_.col(nu).
  // The interpolant's velocity (1/h) sum_nu l'_nu q^nu = (1/h) sum_nu l'_nu points_.col(nu)
  // (sum_nu l'_nu = 0) is then formed from numbers of size h |v|, not |q|: its rounding error is
  // eps |v|, not eps |q|/h, which would random-walk the momentum (docs/hard-cases.md, Kepler).
  Eigen::VectorXd origin_;
  Eigen::MatrixXd points_;    // n x (s+1), offsets of the control points as columns
  Eigen::MatrixXd previous_;  // the last step's offsets (kept where the node iteration does not apply)
  Eigen::VectorXd previous_end_;  // the last step's q1
  double previous_h_ = 0.0;
  bool has_previous_ = false;
  // Compensated (Kahan) sums q1 = q0 + (q^s - q^0), p1 = p0 + (p1 - p0) across steps
  // (compensated.hpp): the running compensations, the last p1 (with previous_end_, the state they
  // belong to), and impulse_ = h sum_i b_i (L_q + f)(c_i) (see action()).
  Eigen::VectorXd carry_q_, carry_p_, end_p_, impulse_;
  Eigen::VectorXd change_;  // the gradient's change by a Newton update, (s+1) n
  Eigen::VectorXd column_;  // add_hessian's two columns, 2n
  Eigen::VectorXd q_, v_, grad_, gradient_, velocity_;
  Eigen::MatrixXd hess_, hessian_;
  DenseLinearization dense_;  // the dense Newton Jacobian (block of hessian_)
  // The entries of a Hessian of L, then of the forces' Jacobian, as (row, col) in an n x n block
  // with whether the row and column differentiate by v (else by q).
  struct Entry {
    int row, col;
    bool row_v, col_v;
  };
  std::vector<Entry> entries_;
  Eigen::VectorXd sparse_values_, force_values_, f_;
  // The sparse Newton Jacobian: slots[(entry * equations + nu) * unknowns + mu] is the index of
  // that entry's block (nu, mu) in matrix.valuePtr().
  struct SparseJacobian {
    int first_unknown = -1, first_equation = -1, blocks = 0;
    Eigen::SparseMatrix<double> matrix;
    std::vector<int> slots;
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    bool analyzed = false;
  };
  SparseJacobian sparse_;
  // A sparse Lagrangian's tangent map: the Jacobian of all s + 1 equations in all control points (its
  // own structure, swapped into sparse_ while the action fills it), the Newton block and its LU.
  SparseJacobian tangent_sparse_;
  Eigen::SparseMatrix<double> tangent_block_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> tangent_sparse_lu_;
  ActionFunction action_ = nullptr;
  // The explicit form: its steps (null when it does not apply), endpoint weights, M and M^{-1},
  // and, at the last (q1, p1) with step previous_h_, dL/dq and the increment h v (reused by a step
  // from there: one gradient evaluation per step).
  AdvanceFunction explicit_advance_ = nullptr;
  StepFunction step_ = nullptr;  // every other step: step_at<N, R>, chosen once
  // Simplified Newton in the nodes' coordinates (constant mass matrix). M^{-1} (inverse_mass_, or
  // a sparse M's factor, sparse_mass_solver_);
  // the velocity u0 = M^{-1} p0 of the step; the maps from (u0, the forces' M^{-1} g_i) to offsets
  // (see offsets_from_forces): to the nodes' (node_map_, R x (1 + R)) and to the control points'
  // q^1..q^s (control_map_, s x (1 + R); end_map_ its last row, q1's); the indices of the nodes of
  // nonzero weight (the iteration's nodes, R of them) in the quadrature; their offsets from q0 at
  // the current iterate and at the next (node_offsets_, next_offsets_, R n), their forces g_i =
  // dL/dq and M^{-1} g_i at the last evaluation (in node_gradients_, node_accelerations_) and M^{-1} g_i
  // as predicted from the last steps (predicted_accelerations_, for the exact Jacobian's start);
  // the batch of (q, v) points handed to the plugin (v = 0) and its gradients [L_q, L_v] (2 n R
  // each). The warm start: the accelerations M^{-1} dL/dq at the nodes of the last two steps
  // (acceleration_history_, n x 2R: the last step's, then the one's before), extrapolated to the
  // next step's nodes by acceleration_extrapolation_[k] (2R x R): the Lagrange basis through the last
  // step's nodes (k = 0), or through those and the two latest distinct nodes of the step before
  // (k = 1), and the nodes' offsets they give, prediction_map_[k] (R x (1 + 2R): node_map_'s
  // column of u0, then its forces' columns times E_k^T); two_steps_back_ says whether the step
  // before the last is in the history (the last continued it with the same h).
  bool node_iteration_ = false;
  bool step_at_nodes_ = false;  // the last step was solved by the node iteration
  // The tangent map's workspace: the LU of the step's Newton Jacobian, d(E_0..E_{s-1})/d(q^1..q^s),
  // the right-hand sides and the control points' images of the directions.
  Eigen::PartialPivLU<Eigen::MatrixXd> tangent_lu_;
  Eigen::MatrixXd tangent_rhs_, tangent_points_;
  Eigen::MatrixXd node_map_, control_map_, end_map_, prediction_map_[2];
  std::vector<int> iteration_nodes_;
  Eigen::VectorXd velocity0_, node_offsets_, next_offsets_, node_accelerations_, predicted_accelerations_;
  Eigen::VectorXd node_points_, node_gradients_;
  Eigen::MatrixXd acceleration_history_, acceleration_extrapolation_[2];  // n x 2R, 2R x R
  bool two_steps_back_ = false;
  double b0_ = 0.0, b1_ = 0.0;
  Eigen::MatrixXd mass_matrix_, inverse_mass_;
  Eigen::SparseMatrix<double> sparse_mass_;  // a sparse Lagrangian's constant M, and its Cholesky factor
  bool diagonal_mass_ = false;  // sparse_mass_ is diagonal: its coefficients are M's diagonal, in order
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> sparse_mass_solver_;
  Eigen::VectorXd force_, increment_, last_q_, last_p_;
  bool has_force_ = false;
  // The dense explicit form: K = h^2 (b0 + b1) M^{-1}, whether the plugin runs the steps itself
  // (kernel::StormerVerletSteps), and (q, h v, dL/dq) where its steps started, to retake them.
  Eigen::MatrixXd kick_;
  bool plugin_runs_steps_ = false;
  Eigen::VectorXd verlet_start_;
  // Constraints (null without): the multipliers lambda_nu of the equations as columns (m x s, kept
  // across steps as the next step's start), g at the unknown points (m x s), the bordered Newton
  // Jacobian and where its entries go (base: the unconstrained Jacobian's entries in its own
  // order; per equation block, the Hessian of lambda . g at its point and -G^T; per unknown block, G),
  // and the projection of p1 (made at the first step, from M).
  HolonomicConstraints* constraints_ = nullptr;
  Eigen::MatrixXd multipliers_;
  Eigen::VectorXd position_update_, momentum_;
  struct Bordered {
    int first_unknown = -1, first_equation = -1, blocks = 0;
    FixedPatternMatrix matrix;
    std::vector<int> base;
    std::vector<std::vector<int>> hessian, transposed, jacobian;
  };
  Bordered bordered_;
  std::unique_ptr<CotangentProjection> projection_;
};

}  // namespace varia
