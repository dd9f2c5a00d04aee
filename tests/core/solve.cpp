// The one nonlinear solver (core/include/varia/core/solve/newton.hpp): its stopping rule on
// systems whose round-off and roots are known.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "varia/core/solve/newton.hpp"

using namespace varia;

namespace {

// F(x) = c (x^3 - a) + noise_k, one unknown, with the yardstick of F's visible terms |c a| and a
// hidden evaluation noise of alternating sign (as a plugin's own sums would add): the residual
// cannot fall below |noise|. `evaluations` counts the calls.
struct Cubic {
  double c, a, noise;
  double x;
  int evaluations = 0;
  double jacobian = 0.0;

  int size() const { return 1; }
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    F[0] = c * (x * x * x - a) + (evaluations++ % 2 == 0 ? noise : -noise);
    jacobian = 3.0 * c * x * x;
    return std::abs(c * a);
  }
  void factorize() {}
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) { update[0] = F[0] / jacobian; }
  double apply(const Eigen::VectorXd& update) {
    x -= update[0];
    return std::abs(x);
  }
  void finish(const Eigen::VectorXd&) {}
};

}  // namespace

TEST_CASE("newton converges quadratically to round-off and counts the updates it applies") {
  Cubic cubic{1.0, 2.0, 0.0, 1.0};
  SolverStatistics statistics;
  NewtonSolver solver;
  const SolveReport report = solver.solve(cubic, statistics);
  REQUIRE(report.converged());
  const auto& r = solver.residuals();
  for (std::size_t k = 1; k < r.size(); ++k)
    if (r[k] > 1e-10) CHECK(r[k] <= 2.0 * r[k - 1] * r[k - 1]);
  CHECK(std::abs(cubic.x - std::cbrt(2.0)) <= 2 * std::numeric_limits<double>::epsilon());
  CHECK(report.iterations == static_cast<int>(r.size()));  // one update per evaluation
  CHECK(statistics.solves == 1);
  CHECK(statistics.iterations == report.iterations);
}

TEST_CASE("the update from a residual that passes the test is still applied") {
  // A start 3e-15 from the root: the residual passes the test at once, and the update from it
  // takes x to the root (a stop without it would leave the 3e-15, of one sign, step after step).
  const double root = std::cbrt(2.0);
  Cubic cubic{1.0, 2.0, 0.0, root + 3e-15};
  SolverStatistics statistics;
  NewtonSolver solver;
  REQUIRE(solver.solve(cubic, statistics).converged());
  CHECK(solver.residuals().size() == 1);
  CHECK(statistics.iterations == 1);
  CHECK(std::abs(cubic.x - root) <= 2 * std::numeric_limits<double>::epsilon());
}

TEST_CASE("a residual that stagnates at round-off is converged, not a failure") {
  // Hidden noise 1e-12 against a yardstick of 2e-3: the residual never passes tolerance
  // (1 + yardstick) = 1e-14, and with c = 1e-3 the update from the noise, 3e-10, is no update at
  // round-off of x either. It stops decreasing once x is within 3e-10 of the root.
  Cubic cubic{1e-3, 2.0, 1e-12, 1.0};
  SolverStatistics statistics;
  NewtonSolver solver;
  const SolveReport report = solver.solve(cubic, statistics);
  CAPTURE(report.residual);
  REQUIRE(report.converged());
  CHECK(report.residual > 1e-14 * (1 + 2e-3));
  CHECK(report.iterations <= 8);
  CHECK(std::abs(cubic.x - std::cbrt(2.0)) <= 1e-9);
}

TEST_CASE("a residual that stagnates far from round-off is a failure at the iteration limit") {
  // The same with noise 1e-5: the updates from the noise, 3e-3, are far above sqrt(tolerance) |x|.
  Cubic cubic{1e-3, 2.0, 1e-5, 1.0};
  SolverStatistics statistics;
  NewtonSolver solver(SolverOptions{1e-14, 20});
  const SolveReport report = solver.solve(cubic, statistics);
  CHECK(report.outcome == SolveReport::Outcome::iteration_limit);
  CHECK(report.iterations == 20);
  CHECK(report.residual > 1e-7);
  CHECK(statistics.solves == 0);
  CHECK_THROWS_WITH_AS(require_converged(report, "the cubic"),
                       doctest::Contains("did not converge in 20 iterations on the cubic"), NumericalFailure);
}

TEST_CASE("equations without a root diverge to the iteration limit, a non-finite residual fails at once") {
  // x^3 + 2 with c = 1 has a root; with the Jacobian's sign as for x^2 + 1 there is none: the
  // iterates wander, and the limit ends the solve with a residual of order one.
  struct NoRoot : Cubic {
    double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
      F[0] = x * x + 1.0;
      jacobian = 2.0 * x;
      return 1.0;
    }
  } no_root{{1.0, 0.0, 0.0, 0.3}};
  NewtonSolver solver(SolverOptions{1e-14, 30});
  const SolveReport wandering = solver.solve(no_root);
  CHECK(wandering.outcome == SolveReport::Outcome::iteration_limit);
  CHECK(wandering.residual >= 1.0);

  Cubic overflow{1.0, 2.0, std::numeric_limits<double>::infinity(), 1.0};
  const SolveReport report = solver.solve(overflow);
  CHECK(report.outcome == SolveReport::Outcome::non_finite);
  CHECK(solver.residuals().size() == 1);
  CHECK_THROWS_WITH_AS(require_converged(report, "the cubic"), "the cubic have a non-finite residual",
                       NumericalFailure);
}

// The solver's |x|_inf (a plain loop, not Eigen's lpNorm): the largest magnitude, infinite when an
// entry is, and NaN when any entry is NaN, wherever it stands (a NaN that the loop's maximum would
// pass over is carried by the sum), so that the solve reports the residual as non-finite.
TEST_CASE("the solver's max norm: the largest magnitude, NaN when any entry is NaN") {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  CHECK(max_norm(Eigen::VectorXd::Zero(0)) == 0.0);
  CHECK(max_norm(Eigen::Vector3d(-3.0, 2.0, 0.5)) == 3.0);
  CHECK(max_norm(Eigen::Vector2d(1.0, -inf)) == inf);
  for (int at = 0; at < 3; ++at) {
    Eigen::VectorXd x = Eigen::Vector3d(1.0, -4.0, 0.5);
    CHECK_FALSE(std::isnan(max_norm(x)));
    x[at] = nan;
    CAPTURE(at);
    CHECK(std::isnan(max_norm(x)));
  }
}
