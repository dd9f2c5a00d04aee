#include "varia/core/lie_verlet.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "core/fixtures.hpp"
#include "core/so3_reference.hpp"

using namespace varia;
using namespace varia::testing;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

std::vector<double> observed_orders(Problem p, LieVerletSolver solver, double t_end) {
  Rotations group;
  return testing::observed_orders(
      p, [&] { return std::make_unique<LieGroupVelocityVerlet>(group, p.top, solver, SolverOptions{}); },
      t_end);
}

std::string name(LieVerletSolver solver) {
  return solver == LieVerletSolver::cayley ? "cayley" : "exp";
}

}  // namespace

TEST_CASE("lie-verlet is of order 2 with both solvers, for the free body and the heavy top") {
  for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp})
    for (bool top : {false, true}) {
      CAPTURE(name(solver));
      CAPTURE(top);
      for (double order : observed_orders(top ? heavy_top() : free_body(), solver, 2.0)) {
        MESSAGE(name(solver) << (top ? " heavy top" : " free body") << ": observed order " << order);
        CHECK(std::abs(order - 2.0) < 0.05);
      }
    }
}

TEST_CASE("lie-verlet Cayley and exp solvers solve the same equation: same trajectory") {
  Problem p = heavy_top();
  Rotations group;
  LieGroupVelocityVerlet cayley(group, p.top, LieVerletSolver::cayley, {});
  LieGroupVelocityVerlet exp(group, p.top, LieVerletSolver::exp, {});
  const double d = distance(integrate(cayley, p.start, 0.05, 200), integrate(exp, p.start, 0.05, 200));
  CAPTURE(d);
  CHECK(d < 1e-12);
}

TEST_CASE("lie-verlet conserves spatial angular momentum and orthogonality to round-off") {
  Problem p = free_body();
  Rotations group;
  for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp}) {
    LieGroupVelocityVerlet lgvi(group, p.top, solver, {});
    const Vector3d pi0 = spatial_momentum(p.start);
    State y = p.start, next;
    double momentum = 0.0, orthogonality = 0.0;
    for (int k = 0; k < 20000; ++k) {
      lgvi.step(y.data(), y.data() + 9, 0.01, next.data(), next.data() + 9);
      y = next;
      momentum = std::max(momentum, (spatial_momentum(y) - pi0).norm());
      orthogonality = std::max(orthogonality, so3::orthogonality_error(so3::from_row_major(y.data())));
    }
    CAPTURE(name(solver));
    CAPTURE(momentum);
    CAPTURE(orthogonality);
    CHECK(momentum < 1e-14 * pi0.norm() * 10);
    CHECK(orthogonality < 1e-14);
  }
}

TEST_CASE("lie-verlet conserves the heavy top's vertical angular momentum to round-off") {
  Problem p = heavy_top();
  Rotations group;
  LieGroupVelocityVerlet lgvi(group, p.top, LieVerletSolver::cayley, {});
  const double pi3 = spatial_momentum(p.start)(2);
  State y = p.start, next;
  double drift = 0.0;
  for (int k = 0; k < 20000; ++k) {
    lgvi.step(y.data(), y.data() + 9, 0.01, next.data(), next.data() + 9);
    y = next;
    drift = std::max(drift, std::abs(spatial_momentum(y)(2) - pi3));
  }
  CAPTURE(drift);
  CHECK(drift < 1e-13);
  // The other components are not conserved: gravity's torque turns them.
  CHECK((spatial_momentum(y) - spatial_momentum(p.start)).head<2>().norm() > 1e-2);
}

TEST_CASE("lie-verlet Newton's method needs 2 or 3 iterations per step, warm-started") {
  Problem p = heavy_top();
  Rotations group;
  for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp})
    for (double tolerance : {1e-14, 1e-15}) {
      LieGroupVelocityVerlet lgvi(group, p.top, solver, {tolerance, 50});
      integrate(lgvi, p.start, 0.01, 3000);
      const auto& statistics = lgvi.solver_statistics();
      CAPTURE(name(solver));
      CAPTURE(tolerance);
      MESSAGE(name(solver) << " at tolerance " << tolerance << ": Newton iterations per step, mean "
                           << statistics.mean() << ", max " << statistics.max_iterations);
      CHECK(statistics.max_iterations <= 3);
      CHECK(statistics.mean() >= 1.0);
    }
}

TEST_CASE("lie-verlet step satisfies p0 = -D1 L_d and p1 = D2 L_d of its discrete Lagrangian") {
  Problem p = heavy_top();
  Rotations group;
  LieGroupVelocityVerlet lgvi(group, p.top, LieVerletSolver::exp, {});
  State y;
  const double h = 0.1;
  lgvi.step(p.start.data(), p.start.data() + 9, h, y.data(), y.data() + 9);
  double Ld, D1[3], D2[3];
  lgvi.evaluate(p.start.data(), y.data(), h, &Ld, D1, D2);
  for (int i = 0; i < 3; ++i) {
    CHECK(-D1[i] == doctest::Approx(p.start[9 + i]).epsilon(1e-13));
    CHECK(D2[i] == doctest::Approx(y[9 + i]).epsilon(1e-13));
  }
}

TEST_CASE("lie-verlet fails cleanly when the step turns the body too far") {
  // A spin about the principal axis e1 with h |Omega| = 1.2 > 1: sin(theta) = h |Omega| has no
  // solution.
  Top top(Vector3d(1, 2, 3), 0.0, Vector3d::Zero());
  Rotations group;
  State y, start{};
  so3::to_row_major(Matrix3d::Identity(), start.data());
  start[9] = 12.0;  // Pi = J Omega with Omega = 12 e1
  for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp}) {
    LieGroupVelocityVerlet lgvi(group, top, solver, {});
    CAPTURE(name(solver));
    try {
      lgvi.step(start.data(), start.data() + 9, 0.1, y.data(), y.data() + 9);
      FAIL("the step should have failed");
    } catch (const NumericalFailure& failure) {
      CHECK(std::string(failure.what()).find("too far") != std::string::npos);
    }
    // Just inside the limit the step succeeds.
    LieGroupVelocityVerlet inside(group, top, solver, {});
    CHECK_NOTHROW(inside.step(start.data(), start.data() + 9, 0.08, y.data(), y.data() + 9));
  }
}

TEST_CASE("lie-verlet refuses a Lagrangian without a constant mass matrix") {
  Rotations group;
  Pendulum pendulum;
  CHECK_THROWS_AS(LieGroupVelocityVerlet(group, pendulum, LieVerletSolver::cayley, {}),
                  std::invalid_argument);
}

TEST_SUITE("long") {
  TEST_CASE("lie-verlet over 10^6 steps: momentum and orthogonality stay at round-off") {
    Problem p = free_body();
    Rotations group;
    for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp}) {
      LieGroupVelocityVerlet lgvi(group, p.top, solver, {});
      const Vector3d pi0 = spatial_momentum(p.start);
      State y = p.start, next;
      double momentum = 0.0, orthogonality = 0.0;
      const auto start = std::chrono::steady_clock::now();
      for (long k = 0; k < 1000000; ++k) {
        lgvi.step(y.data(), y.data() + 9, 0.01, next.data(), next.data() + 9);
        y = next;
        if (k % 100 != 0) continue;
        momentum = std::max(momentum, (spatial_momentum(y) - pi0).norm());
        orthogonality =
            std::max(orthogonality, so3::orthogonality_error(so3::from_row_major(y.data())));
      }
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      MESSAGE(name(solver) << ": 10^6 steps in " << seconds << " s, mean Newton iterations "
                           << lgvi.solver_statistics().mean() << ", max |pi - pi0| " << momentum
                           << " (|pi0| " << pi0.norm() << "), max ||I - R^T R|| "
                           << orthogonality);
      CHECK(momentum < 1e-13 * pi0.norm());
      CHECK(orthogonality < 1e-14);
    }
    // The part of a step that is not the solver: one Lagrangian gradient (the torque).
    LagrangianEvaluator evaluator(p.top);
    double gradient[12];
    const double zero[3] = {0.0, 0.0, 0.0};
    const auto start = std::chrono::steady_clock::now();
    for (long k = 0; k < 1000000; ++k) evaluator.gradient(p.start.data(), zero, gradient);
    MESSAGE("10^6 torque evaluations (AD gradient of L) take "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s");
  }
}
