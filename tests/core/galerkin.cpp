#include "varia/core/galerkin.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/fixtures.hpp"
#include "core/wall.hpp"

using namespace varia;
using namespace varia::testing;

TEST_CASE("galerkin degree 1 with the trapezoid rule is Stormer-Verlet") {
  FlatSpace space(1);
  Pendulum pendulum;
  auto rule = trapezoid();
  GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(1), {});
  const double h = 0.1;
  double q = 1.3, p = 0.0;  // velocity Verlet in (q, p), force -sin q
  double gq = q, gp = p;
  for (int k = 0; k < 200; ++k) {
    const double half = p - 0.5 * h * std::sin(q);
    q += h * half;
    p = half - 0.5 * h * std::sin(q);
    double q1, p1;
    galerkin.step(&gq, &gp, h, &q1, &p1);
    gq = q1;
    gp = p1;
  }
  CAPTURE(q - gq);
  CHECK(std::abs(q - gq) < 1e-13);
  CHECK(std::abs(p - gp) < 1e-13);
}

TEST_CASE("galerkin Newton converges quadratically from a cold start") {
  FlatSpace space(1);
  Pendulum pendulum;
  auto rule = lobatto3();
  GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(2), {});
  double q0 = 2.0, p0 = 0.5, q1, p1;
  galerkin.step(&q0, &p0, 0.5, &q1, &p1);
  const auto& r = galerkin.last_residuals();
  REQUIRE(r.size() >= 3);
  // Each residual well above round-off is at most C times the square of the one before.
  for (std::size_t k = 1; k + 1 < r.size(); ++k) {
    CAPTURE(k);
    CAPTURE(r[k - 1]);
    CAPTURE(r[k]);
    if (r[k] > 1e-12) CHECK(r[k] <= 10.0 * r[k - 1] * r[k - 1]);
  }
  CHECK(galerkin.solver_statistics().max_iterations <= 6);
}

TEST_CASE("galerkin D1 and D2 are the derivatives of L_d") {
  FlatSpace space(1);
  Pendulum pendulum;
  auto rule = lobatto3();
  GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(2), {});
  const double q0 = 0.3, q1 = 0.45, h = 0.2, e = 1e-5;
  double Ld, D1, D2, plus, minus;
  galerkin.evaluate(&q0, &q1, h, &Ld, &D1, &D2);
  // Test-only central differences of L_d in q0 and q1, an independent check of the envelope
  // argument D_k L_d = dS/dq^k at the extremum.
  double a = q0 + e, b = q0 - e;
  galerkin.evaluate(&a, &q1, h, &plus, nullptr, nullptr);
  galerkin.evaluate(&b, &q1, h, &minus, nullptr, nullptr);
  CHECK(D1 == doctest::Approx((plus - minus) / (2 * e)).epsilon(1e-8));
  a = q1 + e;
  b = q1 - e;
  galerkin.evaluate(&q0, &a, h, &plus, nullptr, nullptr);
  galerkin.evaluate(&q0, &b, h, &minus, nullptr, nullptr);
  CHECK(D2 == doctest::Approx((plus - minus) / (2 * e)).epsilon(1e-8));
}

TEST_CASE("galerkin non-convergence raises a numerical failure with the residual") {
  FlatSpace space(1);
  Pendulum pendulum;
  auto rule = lobatto3();
  SolverOptions options;
  options.max_iterations = 1;
  GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(2), options);
  double q0 = 2.0, p0 = 0.5, q1, p1;
  CHECK_THROWS_AS(galerkin.step(&q0, &p0, 0.5, &q1, &p1), NumericalFailure);
}

TEST_CASE("galerkin explicit form for a constant mass matrix agrees with the Newton solve") {
  FlatSpace space(1);
  Pendulum implicit_pendulum;
  SeparablePendulum explicit_pendulum;
  auto rule = trapezoid();
  GalerkinDiscreteLagrangian newton(space, implicit_pendulum, rule, equispaced_control_times(1), {});
  GalerkinDiscreteLagrangian direct(space, explicit_pendulum, rule, equispaced_control_times(1), {});
  double a[2] = {1.3, 0.0}, b[2] = {1.3, 0.0}, next[2];
  for (int k = 0; k < 1000; ++k) {
    newton.step(&a[0], &a[1], 0.1, &next[0], &next[1]);
    std::copy(next, next + 2, a);
    direct.step(&b[0], &b[1], 0.1, &next[0], &next[1]);
    std::copy(next, next + 2, b);
  }
  CHECK(std::abs(a[0] - b[0]) < 1e-12);
  CHECK(std::abs(a[1] - b[1]) < 1e-12);
  CHECK(direct.solver_statistics().max_iterations == 0);
  // One gradient evaluation per step (plus the first), no Hessians.
  CHECK(direct.evaluations().gradient == 1001);
  CHECK(direct.evaluations().hessian == 0);
  CHECK(newton.solver_statistics().max_iterations >= 1);
}

TEST_CASE("galerkin explicit form for a sparse Lagrangian with a constant mass matrix, read off its terms without a "
          "declaration: the Newton solve's steps, no Newton iteration (issues #18 and #39)") {
  const int n = 6;
  FlatSpace space(n);
  SparseChain declared(n, true), undeclared(n, false);
  CHECK(declared.has_constant_mass_matrix());
  auto rule = trapezoid();
  GalerkinDiscreteLagrangian newton(space, undeclared, rule, equispaced_control_times(1), {});
  GalerkinDiscreteLagrangian direct(space, declared, rule, equispaced_control_times(1), {});
  Eigen::VectorXd a(2 * n), b(2 * n), next(2 * n);
  for (int i = 0; i < n; ++i) a(i) = 1.05 * i + 0.1 * std::sin(i);  // stretched springs, at rest
  a.tail(n).setZero();
  b = a;
  const long steps = 1000;
  for (long k = 0; k < steps; ++k) {
    newton.step(a.data(), a.data() + n, 0.05, next.data(), next.data() + n);
    a = next;
    direct.step(b.data(), b.data() + n, 0.05, next.data(), next.data() + n);
    b = next;
  }
  CAPTURE((a - b).cwiseAbs().maxCoeff());
  CHECK((a - b).cwiseAbs().maxCoeff() < 1e-11);
  CHECK((a.head(n) - Eigen::VectorXd::LinSpaced(n, 0, 1.05 * (n - 1))).cwiseAbs().maxCoeff() > 1e-3);  // it moved
  CHECK(direct.solver_statistics().max_iterations == 0);
  CHECK(newton.solver_statistics().max_iterations >= 1);
  // One gradient a step (plus the first), and one Hessian, at the first step, for M.
  CHECK(direct.evaluations().gradient == steps + 1);
  CHECK(direct.evaluations().hessian == 1);
}

// advance() (the loop varia cost and the benchmarks time) must be the steps of step(), to the
// bit, with the state left in (q, p): the explicit form's register loop at n = 1, 2 and 5, and the
// default loop (Newton) for a Lagrangian that declares no constant mass matrix.
TEST_CASE("galerkin advance takes the same steps as step, bit for bit") {
  auto rule = trapezoid();
  const auto compare = [&](Lagrangian& lagrangian, int n, bool explicit_form) {
    CAPTURE(n);
    FlatSpace space(n);
    GalerkinDiscreteLagrangian stepped(space, lagrangian, rule, equispaced_control_times(1), {});
    GalerkinDiscreteLagrangian advanced(space, lagrangian, rule, equispaced_control_times(1), {});
    Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, 1.3, 0.2), p = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd a = q, b = p, q1(n), p1(n);
    const long steps = 300;
    for (long k = 0; k < steps; ++k) {
      stepped.step(a.data(), b.data(), 0.05, q1.data(), p1.data());
      a = q1;
      b = p1;
    }
    // Odd counts: the loop's last state is in its workspace (q1, p1) and is copied back.
    advanced.advance(q.data(), p.data(), 0.05, steps / 2 + 1, q1.data(), p1.data());
    advanced.advance(q.data(), p.data(), 0.05, steps / 2 - 1, q1.data(), p1.data());
    CHECK((q.array() == a.array()).all());
    CHECK((p.array() == b.array()).all());
    CHECK(advanced.solver_statistics().solves == steps);
    // The explicit form: one gradient per step (plus the first), the second call continuing from
    // the first's dL/dq.
    if (explicit_form) CHECK(advanced.evaluations().gradient == steps + 1);
    CHECK(advanced.evaluations().gradient == stepped.evaluations().gradient);
  };
  Pendulums one(1), two(2), five(5);
  compare(one, 1, true);
  compare(two, 2, true);
  compare(five, 5, true);
  Pendulum newton;  // no constant mass matrix: Newton, and DiscreteHamiltonianMap's loop
  compare(newton, 1, false);
}

namespace {

// A Lagrangian seen through evaluate() and its constant mass matrix only: the explicit form then
// calls the plugin once a step instead of having it run the steps (kernel::StormerVerletSteps).
struct EvaluateOnly : Lagrangian {
  explicit EvaluateOnly(Lagrangian& inner) : inner(inner) {}
  int position_size() const noexcept override { return inner.position_size(); }
  int velocity_size() const noexcept override { return inner.velocity_size(); }
  Status evaluate(const double* q, const double* v, double* value, double* gradient, double* hessian) noexcept override {
    return inner.evaluate(q, v, value, gradient, hessian);
  }
  bool constant_mass_matrix(double* mass) const noexcept override { return inner.constant_mass_matrix(mass); }
  Lagrangian& inner;
};

}  // namespace

// The explicit form's steps run inside the plugin (the SDK's Stormer-Verlet kernel: one plugin call for all
// of them) are those of the loop that calls the plugin once a step, to the bit, at the fixed sizes
// and the dynamic one, with the same gradient count; and where a gradient within them is not
// finite (the wall at q = 1), advance() fails as that loop does, with the same message.
TEST_CASE("galerkin explicit form run inside the plugin: the steps of one plugin call a step, bit for bit") {
  auto rule = trapezoid();
  for (int n : {1, 3, 5}) {
    CAPTURE(n);
    FlatSpace space(n);
    Pendulums pendulums(n);
    EvaluateOnly each_step(pendulums);
    kernel::StormerVerletSteps verlet;
    REQUIRE(pendulums.offers(kernel::call(verlet)));
    GalerkinDiscreteLagrangian inside(space, pendulums, rule, equispaced_control_times(1), {});
    GalerkinDiscreteLagrangian outside(space, each_step, rule, equispaced_control_times(1), {});
    Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, 1.3, 0.2), p = Eigen::VectorXd::Zero(n), a = q, b = p;
    Eigen::VectorXd q1(n), p1(n);
    inside.advance(q.data(), p.data(), 0.05, 777, q1.data(), p1.data());
    outside.advance(a.data(), b.data(), 0.05, 777, q1.data(), p1.data());
    CHECK((q - Eigen::VectorXd::LinSpaced(n, 1.3, 0.2)).norm() + p.norm() > 0.1);  // it moved
    CHECK((q.array() == a.array()).all());
    CHECK((p.array() == b.array()).all());
    CHECK(inside.evaluations().gradient == outside.evaluations().gradient);
  }
  FlatSpace line(1);
  Wall wall;
  EvaluateOnly each_step(wall);
  const auto failure = [&](Lagrangian& lagrangian) {
    GalerkinDiscreteLagrangian map(line, lagrangian, rule, equispaced_control_times(1), {});
    double q = 0.0, p = 0.0, q1, p1;
    try {
      map.advance(&q, &p, 0.05, 1000, &q1, &p1);
    } catch (const NumericalFailure& e) {
      return std::string(e.what());
    }
    return std::string("no failure");
  };
  const std::string inside = failure(wall), outside = failure(each_step);
  CHECK(inside.find("gradient") != std::string::npos);
  CHECK(inside == outside);
}

// Order 8 (degree 4, 5 Gauss-Lobatto points) on the pendulum from rest at 1.3 to T = 100: at
// 1376 and 2752 steps the discretization error is below 1e-14, so the two runs must agree to
// round-off. A solve that stops at a residual of about its tolerance (1e-14 (1 + scale)) leaves
// an error of the same sign at every step, which grows with the number of steps: the runs then
// differed by 2.8e-13 (bench/README.md).
TEST_CASE("galerkin Newton solves to round-off: order-8 runs at 1376 and 2752 steps agree") {
  FlatSpace space(1);
  Pendulum pendulum;
  const double a = std::sqrt(3.0 / 7.0);
  FixedRule rule({0.0, (1 - a) / 2, 0.5, (1 + a) / 2, 1.0}, {1.0 / 20, 49.0 / 180, 16.0 / 45, 49.0 / 180, 1.0 / 20},
                 7);
  double end[2][2];
  for (int k = 0; k < 2; ++k) {
    GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(4), {});
    const long steps = 1376L << k;
    double q = 1.3, p = 0.0, q1, p1;
    for (long i = 0; i < steps; ++i) {
      galerkin.step(&q, &p, 100.0 / steps, &q1, &p1);
      q = q1;
      p = p1;
    }
    end[k][0] = q;
    end[k][1] = p;
    MESSAGE("order 8, ", steps, " steps: Newton updates per step ", galerkin.solver_statistics().mean());
  }
  CAPTURE(end[0][0] - end[1][0]);
  CAPTURE(end[0][1] - end[1][1]);
  CHECK(std::abs(end[0][0] - end[1][0]) < 2e-14);
  CHECK(std::abs(end[0][1] - end[1][1]) < 2e-14);
}

// For a constant mass matrix the step's equations are solved by simplified Newton in the nodes'
// coordinates (forces only), stopped when the residual its last update leaves is below F's
// rounding: the same steps as Newton with the exact Jacobian, to round-off, over a whole run (the
// issue's pendulum, s-stage Gauss at the steps of the GNI comparison). Two ways of rounding the
// same equations part along a run as a random walk, sqrt(steps) eps |x| (1.5e-14, 2.3e-14 and
// 1.1e-14 here, against 7e-14, 3e-14 and 2e-14); an error of one sign at every step adds up
// faster, and the pendulum's phase amplifies it. Stopped with the residual at the tolerance, the
// runs differed by up to 1e-11; with the maps from forces to offsets summing h M^{-1} p0 with a
// coefficient an ulp off the exact 1 and c_j (galerkin.cpp, simplified_applies), by 4e-14 at s = 6.
TEST_CASE("galerkin simplified Newton (constant mass matrix) takes the steps of exact Newton to round-off") {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  FlatSpace space(1);
  for (const auto& [s, steps] : {std::pair{2, 20000L}, {4, 4000L}, {6, 2000L}}) {
    CAPTURE(s);
    auto rule = gauss_legendre(s);
    Pendulum pendulum;  // no constant mass matrix declared: Newton with the exact Jacobian
    SeparablePendulum separable;
    GalerkinDiscreteLagrangian exact(space, pendulum, rule, equispaced_control_times(s), {});
    GalerkinDiscreteLagrangian simplified(space, separable, rule, equispaced_control_times(s), {});
    double a[2] = {1.3, 0.0}, b[2] = {1.3, 0.0}, next[2];
    double largest = 0.0, size = 0.0;
    for (long k = 0; k < steps; ++k) {
      exact.step(&a[0], &a[1], 100.0 / steps, &next[0], &next[1]);
      std::copy(next, next + 2, a);
      simplified.step(&b[0], &b[1], 100.0 / steps, &next[0], &next[1]);
      std::copy(next, next + 2, b);
      largest = std::max({largest, std::abs(a[0] - b[0]), std::abs(a[1] - b[1])});
      size = std::max({size, std::abs(a[0]), std::abs(a[1])});
    }
    const double random_walk = std::sqrt(steps) * eps * (1.0 + size);
    MESSAGE("s = ", s, ": largest difference ", largest, " (random walk ", random_walk, "), iterations per step ",
            simplified.solver_statistics().mean());
    CHECK(largest < random_walk);
    CHECK(simplified.evaluations().hessian <= 1);  // the first step's inverse Legendre transform
    CHECK(simplified.solver_statistics().mean() < 2.1);
  }
}

// Where simplified Newton does not contract (a step the forces' Jacobian makes large: theta is
// about h^2 |V''| / 12 at s = 2), the step is solved again with the exact Jacobian: the same
// steps, to round-off, and Hessians evaluated. At h = 0.1 it contracts and no Hessian is needed.
TEST_CASE("galerkin simplified Newton falls back to the exact Jacobian where it does not contract") {
  FlatSpace space(1);
  auto rule = gauss_legendre(2);
  for (const auto& [h, falls_back] : {std::pair{3.0, true}, {0.1, false}}) {
    CAPTURE(h);
    Pendulum pendulum;
    SeparablePendulum separable;
    GalerkinDiscreteLagrangian exact(space, pendulum, rule, equispaced_control_times(2), {});
    GalerkinDiscreteLagrangian simplified(space, separable, rule, equispaced_control_times(2), {});
    double a[2] = {2.5, 0.0}, b[2] = {2.5, 0.0}, next[2];
    for (int k = 0; k < 5; ++k) {
      exact.step(&a[0], &a[1], h, &next[0], &next[1]);
      std::copy(next, next + 2, a);
      simplified.step(&b[0], &b[1], h, &next[0], &next[1]);
      std::copy(next, next + 2, b);
    }
    CHECK(std::abs(a[0] - b[0]) < 1e-12);
    CHECK(std::abs(a[1] - b[1]) < 1e-12);
    CHECK((simplified.evaluations().hessian > 1) == falls_back);
  }
}
