// The one nonlinear solver of varia: Newton's method on a system of equations F(x) = 0 that a
// construction states (the Galerkin IDEL on R^n and in a Lie group's natural chart, shooting,
// the implicit stages of a Runge-Kutta method, the Lie group velocity Verlet's implicit equation),
// with one stopping rule and one way of counting iterations. Header-only, so that plugins (the
// SDK's Runge-Kutta methods) use the same solver without linking the core.
//
// A system (in the style of Ceres' cost functions and Eigen's nonlinear solvers' functors, but
// holding its unknowns itself, in whatever form it keeps them) provides
//
//   int size() const;                          // n equations in n unknowns
//   double evaluate(Eigen::Ref<Eigen::VectorXd> F);
//       // F(x) at the current unknowns (and the Jacobian's values, where they come with it).
//       // Returns the yardstick of F's round-off: the size of the terms that F sums (|p0| and
//       // |dS/dq|, say), so that |F| <= tolerance (1 + yardstick) is F at round-off.
//   void factorize();                          // dF/dx at the last evaluation, factorized
//   void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update);   // update = (dF/dx)^{-1} F
//   double apply(const Eigen::VectorXd& update);
//       // x -= update. Returns the yardstick of x's round-off: the size of the quantity that x
//       // stands for (the control points q^0 + offsets, not the offsets).
//   void finish(const Eigen::VectorXd& update);
//       // After the last update (no evaluation follows): the system may bring up to date what
//       // it derives from F, to first order from the Jacobian at hand.
//
// DenseLinearization is factorize() and solve() for a dense Jacobian; a system with a sparse one
// factorizes it itself.
//
// The Jacobian policy. A system may also provide
//   bool simplified() const;
// returning true when its solve() uses a constant approximation A of dF/dx (simplified Newton:
// Hairer & Wanner, "Solving ODEs II", sec. IV.8): the solver then calls factorize() once per
// solve, and the system may keep its factorization across solves (once per step size), evaluate()
// need not form the Jacobian, and the iteration converges linearly, with the contraction
// theta_k = r_k / r_{k-1}, instead of quadratically. Without it (or when it returns false) the
// Jacobian is exact.
//
// The stopping rule. Newton's method with the exact Jacobian reduces the residual quadratically
// until F's round-off, the attainable accuracy (Deuflhard, "Newton Methods for Nonlinear
// Problems", 2004, sec. 2.1); there it stagnates. With r_k = |F(x_k)|_inf and update_k computed
// from it, the solve ends after applying update_k when
//   - r_k is at round-off: r_k <= tolerance (1 + yardstick of F);
//   - or update_k is at round-off of x: |update_k| <= tolerance (1 + yardstick of x), the error
//     left after it being O(|update_k|^2);
//   - or r_k stagnates at round-off: r_k > r_{k-1} / 2 after an update, with |update_k| <=
//     sqrt(tolerance) (1 + yardstick of x), the error left after it being O(tolerance). F's
//     round-off exceeds a few eps of its visible terms when the plugin's own sums cancel (a
//     configuration-dependent mass matrix, trigonometric functions of large angles); a residual
//     that stops decreasing there, with an update that small, is converged, never a failure.
// Simplified Newton ends instead after applying update_k (k >= 1) when
//   - with theta_k < 1/2, the residual that update_k leaves, predicted from the contraction as
//     theta_k r_k, is far below F's own rounding, theta_k r_k <= 1e-3 eps (1 + yardstick of F),
//     eps the machine epsilon; or r_k itself is at round-off, r_k <= tolerance (1 + yardstick of
//     F), where what is left is theta_k times F's rounding, which has no sign. Exact Newton's last
//     update leaves O(r_k^2), which a constant Jacobian does not: what it leaves above round-off
//     has the same sign from step to step, and one of an eps at every step walks a run's energy
//     level linearly, where round-off alone walks it as the square root of the steps (Brouwer's
//     law: Hairer, McLachlan & Razakarivony, BIT 48, 2008, whose gni_irk2 iterates to round-off
//     for this reason). With eps instead of 1e-3 eps and no round-off clause, the pendulum 1e-3
//     rad below the upright lost 0.107 in phase over 10^6 steps, against 3.5e-4 with this rule
//     (docs/hard-cases.md). A system whose finish() takes one more update itself (leaving
//     theta^2 r) may allow more with double residual_left() const, the bound in eps;
//   - or the iteration stagnates at round-off: r_k no longer halves, with r_k or r_{k-1} <=
//     tolerance (1 + yardstick of F) and update_k as above (a slow contraction above round-off
//     is not a stagnation).
//   A simplified iteration that contracts too slowly to be worth going on with (theta_k >= 1/2,
//   not converged) ends as a failure of its own kind, not_contracting, so that the system can
//   solve again with the exact Jacobian.
// The update computed from the last residual is always applied: a residual left at the tolerance
// has the same sign from step to step and adds up over a run (a conserved momentum drifts
// linearly), where its update takes it to round-off. The iterations counted are the updates
// applied. A non-finite residual, or none of the above by the max_iterations-th update's
// residual, is a failure; require_converged() raises it as NumericalFailure with the residual.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace varia {

// method.solver of the scene: the tolerance of the stopping rule and the iteration limit.
struct SolverOptions {
  double tolerance = 1e-14;
  int max_iterations = 50;
  // |value| <= tolerance (1 + |scale|): value at round-off of a quantity of size scale.
  bool converged(double value, double scale) const { return value <= tolerance * (1.0 + scale); }
};

// Newton statistics of the solves made so far: iterations are the updates applied.
struct SolverStatistics {
  long solves = 0;
  long iterations = 0;
  int max_iterations = 0;
  void record(int iterations_of_one_solve) {
    ++solves;
    iterations += iterations_of_one_solve;
    if (iterations_of_one_solve > max_iterations) max_iterations = iterations_of_one_solve;
  }
  double mean() const { return solves ? static_cast<double>(iterations) / solves : 0.0; }
};

// A nonlinear solve that did not converge, or a non-finite value. The host adds the step index
// and time; `residual` is the last residual norm (NaN when not applicable).
// `origin` is that of the plugin object whose output was not finite (plugin_object.hpp), if one was.
class NumericalFailure : public std::runtime_error {
 public:
  NumericalFailure(const std::string& what, double residual, const void* origin = nullptr)
      : std::runtime_error(what), residual_(residual), origin_(origin) {}
  double residual() const { return residual_; }
  const void* origin() const { return origin_; }

 private:
  double residual_;
  const void* origin_;
};

// How a solve ended.
struct SolveReport {
  enum class Outcome { converged, non_finite, iteration_limit, not_contracting };
  Outcome outcome = Outcome::converged;
  int iterations = 0;     // updates applied
  double residual = 0.0;  // the last residual norm
  bool converged() const { return outcome == Outcome::converged; }
};

// Throws NumericalFailure with the last residual unless the solve converged; `equations` names
// what was solved ("the Galerkin equations").
inline void require_converged(const SolveReport& report, const char* equations) {
  if (report.converged()) return;
  if (report.outcome == SolveReport::Outcome::non_finite)
    throw NumericalFailure(std::string(equations) + " have a non-finite residual", report.residual);
  if (report.outcome == SolveReport::Outcome::not_contracting)
    throw NumericalFailure(std::string("simplified Newton does not contract on ") + equations, report.residual);
  throw NumericalFailure("Newton's method did not converge in " + std::to_string(report.iterations) +
                             " iterations on " + equations,
                         report.residual);
}

// |x|_inf by a plain loop, NaN if an entry is. The systems store F and the update entry by entry
// just before the solver measures them, and a vectorized load of two entries waits for both
// stores (the store cannot be forwarded), which Eigen's lpNorm does. Branch-free (a branch per
// new maximum is slower still): the sum carries a NaN. Measured: bench/README.md.
inline double max_norm(const Eigen::VectorXd& x) {
  double largest = 0.0, sum = 0.0;
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double a = std::abs(x[k]);
    largest = std::max(largest, a);
    sum += a;
  }
  return std::isnan(sum) ? sum : largest;
}

// factorize() and solve() of a system with a dense Jacobian, held in `jacobian` (n x n), which
// the system fills in evaluate(); sized once.
class DenseLinearization {
 public:
  explicit DenseLinearization(int n = 0) : jacobian(n, n), lu_(n) {}
  void factorize() { lu_.compute(jacobian); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) const { update.noalias() = lu_.solve(F); }
  Eigen::MatrixXd jacobian;

 private:
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

// Newton's method with the stopping rule above. Holds the residual and update vectors of the
// largest system it has solved: a solve of a system of the same size allocates nothing.
class NewtonSolver {
 public:
  static constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  static constexpr double kBrouwer = 1e-3;  // simplified Newton's residual left, in eps (above)
  explicit NewtonSolver(SolverOptions options = {}) : options_(options), root_tolerance_(std::sqrt(options.tolerance)) {
    residuals_.reserve(options_.max_iterations + 1);
  }
  const SolverOptions& options() const { return options_; }

  // Solves system's F(x) = 0 as solve() below, and records a converged solve's iterations in
  // `statistics`.
  template <class System>
  SolveReport solve(System& system, SolverStatistics& statistics) {
    const SolveReport report = solve(system);
    if (report.converged()) statistics.record(report.iterations);
    return report;
  }

  // Solves system's F(x) = 0 from its current unknowns, leaving the solution in the system.
  template <class System>
  SolveReport solve(System& system) {
    const int n = system.size();
    if (F_.size() != n) {
      F_.resize(n);
      update_.resize(n);
    }
    residuals_.clear();
    if constexpr (requires { system.simplified(); })
      if (system.simplified()) return solve_simplified(system);
    SolveReport report;
    for (int k = 0;; ++k) {
      const double yardstick = system.evaluate(F_);
      const double r = max_norm(F_);
      const bool decreasing = k == 0 || r < 0.5 * residuals_.back();
      if (!record(r, report)) return report;
      const bool at_round_off = options_.converged(r, yardstick);
      // The update from a residual at round-off after an iteration reuses the last
      // factorization: the Jacobians differ by O(last update), its error is
      // O(last update x this update).
      if (k == 0 || !at_round_off) system.factorize();
      system.solve(F_, update_);
      const double size_of_update = max_norm(update_);
      const double x_yardstick = system.apply(update_);
      report.iterations = k + 1;
      const bool stagnating = !decreasing && size_of_update <= root_tolerance_ * (1.0 + x_yardstick);
      if (at_round_off || options_.converged(size_of_update, x_yardstick) || stagnating) {
        system.finish(update_);
        return report;
      }
      if (at_limit(k, report)) return report;
    }
  }

  // The residual norms of the last solve, one per evaluation (to show quadratic convergence).
  const std::vector<double>& residuals() const { return residuals_; }

 private:
  // Simplified Newton's loop (the rule above): the first update cannot end the solve (no
  // contraction is measured yet); |update| enters only where the residual stopped decreasing.
  // Its own loop, without the exact Jacobian's tests, inlined into solve(): one loop for both, or
  // this one out of line, is slower (bench/README.md, "Measured design choices").
  template <class System>
  [[gnu::always_inline]] inline SolveReport solve_simplified(System& system) {
    double left = kBrouwer;
    if constexpr (requires { system.residual_left(); }) left = system.residual_left();
    SolveReport report;
    double previous = 0.0;  // the last residual
    for (int k = 0;; ++k) {
      const double yardstick = system.evaluate(F_);
      const double r = max_norm(F_);
      const bool decreasing = k == 0 || r < 0.5 * previous;
      if (!record(r, report)) return report;
      if (k == 0) system.factorize();
      system.solve(F_, update_);
      const double size_of_update = decreasing ? 0.0 : max_norm(update_);
      const double x_yardstick = system.apply(update_);
      report.iterations = k + 1;
      if (k > 0) {
        const double contraction = previous > 0.0 ? r / previous : 0.0;
        const bool stagnating = !decreasing && size_of_update <= root_tolerance_ * (1.0 + x_yardstick);
        if ((stagnating && options_.converged(std::min(r, previous), yardstick)) ||
            (contraction < 0.5 &&
             (options_.converged(r, yardstick) || contraction * r <= left * kEpsilon * (1.0 + yardstick)))) {
          system.finish(update_);
          return report;
        }
        if (!(contraction < 0.5)) {
          report.outcome = SolveReport::Outcome::not_contracting;
          return report;
        }
      }
      if (at_limit(k, report)) return report;
      previous = r;
    }
  }

  // Keeps the residual r; false (and the report says why) when it is not finite.
  bool record(double r, SolveReport& report) {
    residuals_.push_back(r);
    report.residual = r;
    if (std::isfinite(r)) return true;
    report.outcome = SolveReport::Outcome::non_finite;
    return false;
  }
  // Whether the k-th update was the last the options allow (the report then says so).
  bool at_limit(int k, SolveReport& report) const {
    if (k < options_.max_iterations) return false;
    report.outcome = SolveReport::Outcome::iteration_limit;
    report.iterations = k;
    return true;
  }

  SolverOptions options_;
  double root_tolerance_;  // sqrt(tolerance), the stagnation's bound on the update
  Eigen::VectorXd F_, update_;
  std::vector<double> residuals_;
};

}  // namespace varia
