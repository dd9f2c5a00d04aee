// Continuous mechanics of a Lagrangian plugin, as the constructions need it: counted and checked
// evaluations, the Legendre transform p = dL/dv and its inverse, the energy E = <p, v> - L.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <cmath>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/jet.hpp"
#include "varia/abi/lagrangian.hpp"

namespace varia {

// Every call the constructions make into a Lagrangian plugin goes through here: it checks the
// Status, counts the evaluation, and rejects non-finite results.
class LagrangianEvaluator {
 public:
  explicit LagrangianEvaluator(Lagrangian& lagrangian);
  Lagrangian& plugin() const { return lagrangian_; }
  int position_size() const { return m_; }
  int velocity_size() const { return n_; }
  double value(const double* q, const double* v);
  // gradient: m + n numbers [dL/dq, dL/dv]; the plugin is not asked for L.
  void gradient(const double* q, const double* v, double* gradient) { evaluate_gradient(q, v, nullptr, gradient); }
  // The gradients at `count` points z_i = (q, v) (m + n numbers each) in one plugin call
  // (Lagrangian::gradients), each counted and checked as gradient() does. Inline: the node
  // iteration calls it at every pass.
  void gradients(int count, const double* points, double* gradients) {
    check(lagrangian_, lagrangian_.gradients(count, points, gradients), "Lagrangian gradients");
    counters_.gradient += count;
    check_finite(gradients, count * (m_ + n_), "gradient");
  }
  // L, and its gradient as above.
  double value_and_gradient(const double* q, const double* v, double* gradient);
  // hessian: (m+n)^2 numbers, dense column-major (sparse Lagrangians are expanded).
  double hessian(const double* q, const double* v, double* gradient, double* hessian);
  // A sparse Lagrangian's Hessian values, one per entry of its pattern (pattern_rows/cols).
  double sparse_hessian(const double* q, const double* v, double* gradient, double* values);
  bool sparse() const { return pattern_size_ >= 0; }
  int pattern_size() const { return pattern_size_; }
  const int* pattern_rows() const { return pattern_rows_; }
  const int* pattern_cols() const { return pattern_cols_; }
  // L (if value is not null) and its m + n gradient numbers at jet inputs. Counted as a Hessian
  // evaluation: it carries second-order information.
  void gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient);
  // Rows first .. first + count - 1 of L's Hessian at jet inputs times `directions` jet vectors of
  // m + n numbers (Lagrangian::hessian_jet): out[j count + r]. Counted as a Hessian evaluation.
  void hessian_jet(const Jet2* q, const Jet2* v, int first, int count, int directions, const Jet2* U, Jet2* out);
  // L's Hessian at (q, v) times one direction u (m + n numbers) into out (m + n): by hessian_jet at
  // constants where the plugin gives it (the SDK: a Hessian-vector product by forward over forward
  // mode, about two gradients' cost), else from the sparse Hessian's entries, else the dense
  // Hessian. Counted as a Hessian evaluation; its workspace is sized at the first call.
  void hessian_product(const double* q, const double* v, const double* u, double* out);
  // `steps` Stormer-Verlet steps run inside the plugin (kernel::StormerVerletSteps, where the
  // plugin offers it), counted as that many gradients. False where a result is not
  // finite: a non-finite gradient makes q non-finite from the next step on, and q stays so, so the
  // end shows any. q, d, f are then unspecified; the caller retakes the steps a gradient at a time,
  // which finds the step that fails.
  bool verlet_steps(double* q, double* d, double* f, const double* K, long steps);
  // The shooting construction's shot run inside the plugin (kernel::ExplicitShot, where the plugin
  // offers it for the plan), counted as its evaluations at jets (shot_evaluations). Throws
  // NumericalFailure where S or an offset is not finite.
  void shoot(const ShotPlan& plan, const double* q0, const double* w0, double h, Jet2* action, Jet2* offsets);
  const EvaluationCounters& counters() const { return counters_; }

  // p = dL/dv (q, v).
  void legendre(const double* q, const double* v, double* p);
  // Solves dL/dv (q, v) = p for v by Newton's method from the guess in v (exact Hessian block);
  // for L = 1/2 v^T M v - V(q) with a constant mass matrix M (dense Lagrangians) v = M^{-1} p,
  // no evaluation.
  void inverse_legendre(const double* q, const double* p, double* v, const SolverOptions& options);
  // E = <dL/dv, v> - L.
  double energy(const double* q, const double* v);
  // E = <p, v> - L(q, v) at a v with dL/dv (q, v) = p (from inverse_legendre): L's value only,
  // not checked (the caller checks E: a finite state's energy may overflow).
  double energy(const double* q, const double* v, const double* p);

 private:
  // Whether every value is finite, by x * 0 (0 for a finite x, NaN otherwise) summed: one branch
  // for all the values, at every pass of the node iteration and every explicit Stormer-Verlet
  // step. Inline, with the message built out of line; scalar loads, because the plugin has just
  // stored these numbers one by one and a vectorized load would wait for the stores to be forwarded.
  void check_finite(const double* values, int count, const char* what) const {
    double zero = 0.0;
    for (int i = 0; i < count; ++i) zero += values[i] * 0.0;
    if (!(zero == 0.0)) not_finite(what);
  }
  [[noreturn]] void not_finite(const char* what) const;
  double unchecked_value(const double* q, const double* v);
  // The gradient, and L where value is not null.
  void evaluate_gradient(const double* q, const double* v, double* value, double* gradient) {
    check(lagrangian_, lagrangian_.evaluate(q, v, value, gradient, nullptr), "Lagrangian gradient");
    ++counters_.gradient;
    check_finite(gradient, m_ + n_, "gradient");
  }
  struct InverseLegendre;  // dL/dv (q, v) = p as a NewtonSolver system
  Lagrangian& lagrangian_;
  int m_, n_;
  const int* pattern_rows_ = nullptr;
  const int* pattern_cols_ = nullptr;
  int pattern_size_ = -1;
  // Workspace, sized once: an evaluation allocates nothing.
  Eigen::VectorXd sparse_values_, gradient_;
  Eigen::MatrixXd hessian_;                 // dense Lagrangians only
  Eigen::MatrixXd inverse_mass_;            // M^{-1} of a declared constant mass matrix (dense only), else empty
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;  // dense Lagrangians only
  Eigen::SparseMatrix<double> velocity_block_;  // sparse Lagrangians: d2L/dv2
  Eigen::SparseLU<Eigen::SparseMatrix<double>> sparse_lu_;
  std::vector<Eigen::Triplet<double>> triplets_;
  std::vector<Jet2> product_point_, product_direction_, product_;  // hessian_product's, at constants
  EvaluationCounters counters_;
  NewtonSolver legendre_solver_;
};

// The stored entries (row, col, value) of a constant mass matrix M = d2L/dv2 (n x n): a dense
// Lagrangian's constant_mass_matrix, a sparse one's Hessian's velocity block at q (with v = 0;
// constant, so any point gives it). Throws std::invalid_argument where a dense Lagrangian
// declares none. For the constraints' projections (constraints.hpp) and the sparse explicit form.
std::vector<Eigen::Triplet<double>> constant_mass_entries(LagrangianEvaluator& evaluator, const double* q);

}  // namespace varia
