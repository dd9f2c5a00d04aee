#include "varia/core/galerkin_chart.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <sstream>

#include "core/fixtures.hpp"
#include "core/so3_reference.hpp"

using namespace varia;
using namespace varia::testing;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

// The free body declaring its invariance under the whole of SO(3) (three momentum components),
// which the reduced form needs.
struct FreeBody : Top {
  FreeBody() : Top(free_body().top) {}
  const char* symmetry_group() const noexcept override { return "SO(3)"; }
  int momentum_size() const noexcept override { return 3; }
};

std::unique_ptr<LieGroupGalerkinDiscreteLagrangian> make(Manifold& group, Lagrangian& L,
                                                        Quadrature& rule, int degree,
                                                        bool reduced = false) {
  return std::make_unique<LieGroupGalerkinDiscreteLagrangian>(
      group, L, rule, equispaced_control_times(degree), SolverOptions{}, reduced);
}

// The chart of SO(3) at R0 = exp(0.3, -0.7, 1.1), at xi = (0.4, 0.2, -0.5) with xi_dot =
// (1, -2, 0.5), as jets.
struct ChartAtJets {
  ChartAtJets() {
    so3::to_row_major(so3::exp(Vector3d(0.3, -0.7, 1.1)), R0);
    so3::chart_jets(R0, xi.data(), rate.data(), point, velocity);
  }
  Rotations group;
  double R0[9];
  const Vector3d xi{0.4, 0.2, -0.5}, rate{1.0, -2.0, 0.5};
  Jet2 point[9], velocity[3];
};

}  // namespace

TEST_CASE_FIXTURE(ChartAtJets, "SO3 chart jets: values and derivatives agree with the chart and differences of it") {
  // Value: R0 exp(xi) and dexp_{-xi} xi_dot.
  double R[9];
  group.retract(R0, xi.data(), R);
  const Vector3d omega = so3::dexp(Vector3d(-xi)) * rate;
  for (int k = 0; k < 9; ++k) CHECK(std::abs(point[k].value - R[k]) < 1e-15);
  for (int k = 0; k < 3; ++k) CHECK(std::abs(velocity[k].value - omega(k)) < 1e-15);
  // First derivatives in (eta, xi) of R0 exp(eta) exp(xi), and in (xi, xi_dot) of the velocity,
  // against central differences (a test of the jets, not inside any solve).
  const double e = 1e-6;
  const auto curve = [&](const Vector3d& eta, const Vector3d& x) {
    return Matrix3d(so3::from_row_major(R0) * so3::exp(eta) * so3::exp(x));
  };
  double worst = 0.0;
  for (int l = 0; l < 3; ++l) {
    const Vector3d d = e * Vector3d::Unit(l);
    const Matrix3d by_eta = (curve(d, xi) - curve(-d, xi)) / (2 * e);
    const Matrix3d by_xi = (curve(Vector3d::Zero(), xi + d) - curve(Vector3d::Zero(), xi - d)) / (2 * e);
    const Vector3d by_xi_v = (so3::dexp(Vector3d(-xi - d)) * rate - so3::dexp(Vector3d(-xi + d)) * rate) / (2 * e);
    const Vector3d by_rate = so3::dexp(Vector3d(-xi)) * Vector3d::Unit(l);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(point[3 * r + c].gradient(l) - by_eta(r, c)));
        worst = std::max(worst, std::abs(point[3 * r + c].gradient(3 + l) - by_xi(r, c)));
      }
    for (int k = 0; k < 3; ++k) {
      worst = std::max(worst, std::abs(velocity[k].gradient(l) - by_xi_v(k)));
      worst = std::max(worst, std::abs(velocity[k].gradient(3 + l) - by_rate(k)));
    }
  }
  CAPTURE(worst);
  CHECK(worst < 1e-9);
}

// The second derivatives (assembled from exp(xi) and dexp at 3-variable jets, so3::chart_jets):
// the xi rows against central differences of the first derivatives at xi +- d e_l, the eta-eta
// block against second differences of R0 exp(eta) exp(xi), and d2/dxi_dot^2 = 0.
TEST_CASE_FIXTURE(ChartAtJets, "SO3 chart jets: second derivatives agree with differences of the first") {
  const double e = 1e-5;
  double worst = 0.0;
  for (int l = 0; l < 3; ++l) {
    Jet2 plus[9], minus[9], vplus[3], vminus[3];
    const Vector3d a = xi + e * Vector3d::Unit(l), b = xi - e * Vector3d::Unit(l);
    so3::chart_jets(R0, a.data(), rate.data(), plus, vplus);
    so3::chart_jets(R0, b.data(), rate.data(), minus, vminus);
    for (int k = 0; k < 9; ++k)
      for (int j = 0; j < 6; ++j)  // d/dxi_l of dR/d(eta, xi)_j
        worst = std::max(worst, std::abs(point[k].hessian(j, 3 + l) -
                                         (plus[k].gradient(j) - minus[k].gradient(j)) / (2 * e)));
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 6; ++j)  // d/dxi_l of dOmega/d(xi, xi_dot)_j
        worst = std::max(worst, std::abs(velocity[k].hessian(j, l) -
                                         (vplus[k].gradient(j) - vminus[k].gradient(j)) / (2 * e)));
  }
  for (int k = 0; k < 3; ++k)
    for (int m = 0; m < 3; ++m) worst = std::max(worst, std::abs(velocity[k].hessian(3 + k, 3 + m)));
  CAPTURE(worst);
  CHECK(worst < 1e-8);
  // eta-eta: (f(+k+l) - f(+k-l) - f(-k+l) + f(-k-l)) / (4 d^2).
  const double d = 1e-4;
  const auto curve = [&](const Vector3d& eta) {
    return Matrix3d(so3::from_row_major(R0) * so3::exp(eta) * so3::exp(xi));
  };
  double worst_eta = 0.0;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      const Vector3d u = d * Vector3d::Unit(k), v = d * Vector3d::Unit(l);
      const Matrix3d second = (curve(u + v) - curve(u - v) - curve(v - u) + curve(-u - v)) / (4 * d * d);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          worst_eta = std::max(worst_eta, std::abs(point[3 * r + c].hessian(k, l) - second(r, c)));
    }
  CAPTURE(worst_eta);
  CHECK(worst_eta < 1e-6);
}

TEST_CASE("lie group galerkin of degree s is of order 2s on SO3 (free body and heavy top)") {
  Rotations group;
  struct Case {
    int degree;
    FixedRule rule;
    std::vector<long> steps;
  };
  // Degree 3 (order 6) reaches the reference's accuracy (about 1e-12 at t = 2) from 80 steps on: coarser
  // steps, and no point past it.
  const std::vector<Case> cases{{1, trapezoid(), {50, 100, 200, 400}},
                                {2, gauss_legendre(2), {25, 50, 100, 200}},
                                {2, lobatto3(), {25, 50, 100, 200}},
                                {3, gauss_legendre(3), {10, 20, 40}}};
  for (const auto& c : cases)
    for (bool top : {false, true}) {
      Problem p = top ? heavy_top() : free_body();
      FixedRule rule = c.rule;
      const auto orders = observed_orders(p, [&] { return make(group, p.top, rule, c.degree); }, 2.0, c.steps);
      for (double order : orders) {
        MESSAGE("degree " << c.degree << ", " << rule.size() << " nodes, " << (top ? "heavy top" : "free body")
                          << ": observed order " << order);
        CHECK(std::abs(order - 2.0 * c.degree) < 0.15);
      }
    }
}

TEST_CASE("lie group galerkin conserves spatial angular momentum and orthogonality at round-off") {
  Rotations group;
  Problem p = free_body();
  auto rule = gauss_legendre(2);
  auto galerkin = make(group, p.top, rule, 2);
  const Vector3d pi0 = spatial_momentum(p.start);
  State y = p.start, next;
  double momentum = 0.0, orthogonality = 0.0;
  for (int k = 0; k < 10000; ++k) {
    galerkin->step(y.data(), y.data() + 9, 0.05, next.data(), next.data() + 9);
    y = next;
    momentum = std::max(momentum, (spatial_momentum(y) - pi0).norm() / pi0.norm());
    orthogonality = std::max(orthogonality, so3::orthogonality_error(so3::from_row_major(y.data())));
  }
  CAPTURE(momentum);
  CAPTURE(orthogonality);
  MESSAGE("10^4 steps: relative momentum error " << momentum << ", orthogonality " << orthogonality
                                                << ", Newton iterations/step "
                                                << galerkin->solver_statistics().mean());
  CHECK(momentum < 1e-13);
  CHECK(orthogonality < 1e-13);
  CHECK(galerkin->solver_statistics().max_iterations <= 3);
}

// The point's increment g0 exp(xi) - g0 from the group in extended precision (Manifold::increment)
// against the chart's quadrature in double: the quadrature's rounding, repeated along the steady
// motion, carries R off SO(3) by about 2.5 eps |xi|^2 a step (|xi| = h |Omega| ~ 0.05 here), and
// with it the spatial momentum R pi (docs/lie-groups.md, "Long runs").
TEST_CASE("lie group galerkin: the group's increment keeps R on SO3 over a long run, the chart's quadrature does not") {
  struct WithoutIncrement : Rotations {
    bool has_increment() const noexcept override { return false; }
  };
  Problem p = free_body();
  auto rule = gauss_legendre(2);
  const Vector3d pi0 = spatial_momentum(p.start);
  const auto run = [&](Manifold& group, double& momentum) {
    auto galerkin = make(group, p.top, rule, 2);
    State y = p.start, next;
    for (int k = 0; k < 20000; ++k) {
      galerkin->step(y.data(), y.data() + 9, 0.05, next.data(), next.data() + 9);
      y = next;
    }
    momentum = (spatial_momentum(y) - pi0).norm() / pi0.norm();
    return so3::orthogonality_error(so3::from_row_major(y.data()));
  };
  Rotations own;
  WithoutIncrement quadrature;
  double momentum_own = 0.0, momentum_quadrature = 0.0;
  const double own_error = run(own, momentum_own), quadrature_error = run(quadrature, momentum_quadrature);
  MESSAGE("2*10^4 steps of h = 0.05: orthogonality " << own_error << " (the group's increment), " << quadrature_error
                                                     << " (the quadrature); relative momentum error " << momentum_own
                                                     << ", " << momentum_quadrature);
  CHECK(own_error < 2e-15);
  CHECK(quadrature_error > 1e-14);
}

TEST_CASE("lie group galerkin conserves the heavy top's vertical angular momentum at round-off") {
  Rotations group;
  Problem p = heavy_top();
  auto rule = lobatto3();
  auto galerkin = make(group, p.top, rule, 2);
  const auto vertical = [](const State& y) { return spatial_momentum(y)(2); };
  State y = p.start, next;
  double drift = 0.0;
  for (int k = 0; k < 5000; ++k) {
    galerkin->step(y.data(), y.data() + 9, 0.02, next.data(), next.data() + 9);
    y = next;
    drift = std::max(drift, std::abs(vertical(y) - vertical(p.start)));
  }
  CAPTURE(drift);
  CHECK(drift < 1e-13 * spatial_momentum(p.start).norm());
  // The other components are not conserved (gravity's torque is horizontal).
  CHECK((spatial_momentum(y) - spatial_momentum(p.start)).head<2>().norm() > 1e-3);
}

TEST_CASE("lie group galerkin: the step solves p0 = -D1 L_d and p1 = D2 L_d, and D1, D2 differentiate L_d") {
  Rotations group;
  Problem p = heavy_top();
  auto rule = gauss_legendre(3);
  auto galerkin = make(group, p.top, rule, 3);
  const double h = 0.1;
  State y;
  galerkin->step(p.start.data(), p.start.data() + 9, h, y.data(), y.data() + 9);
  double Ld, D1[3], D2[3];
  galerkin->evaluate(p.start.data(), y.data(), h, &Ld, D1, D2);
  for (int k = 0; k < 3; ++k) {
    CHECK(std::abs(D1[k] + p.start[9 + k]) < 1e-13);
    CHECK(std::abs(D2[k] - y[9 + k]) < 1e-13);
  }
  // Left-trivialized: D1 . e_l = d/de L_d(q0 exp(e e_l), q1), by central differences.
  const double e = 1e-5;
  for (int l = 0; l < 3; ++l) {
    double a[9], b[9], La, Lb;
    const Vector3d d = e * Vector3d::Unit(l);
    group.retract(p.start.data(), d.data(), a);
    group.retract(p.start.data(), Vector3d(-d).data(), b);
    galerkin->evaluate(a, y.data(), h, &La, nullptr, nullptr);
    galerkin->evaluate(b, y.data(), h, &Lb, nullptr, nullptr);
    CHECK(std::abs((La - Lb) / (2 * e) - D1[l]) < 1e-8);
    group.retract(y.data(), d.data(), a);
    group.retract(y.data(), Vector3d(-d).data(), b);
    galerkin->evaluate(p.start.data(), a, h, &La, nullptr, nullptr);
    galerkin->evaluate(p.start.data(), b, h, &Lb, nullptr, nullptr);
    CHECK(std::abs((La - Lb) / (2 * e) - D2[l]) < 1e-8);
  }
}

TEST_CASE("lie group galerkin Newton converges quadratically from a cold start") {
  Rotations group;
  Problem p = heavy_top();
  auto rule = gauss_legendre(3);
  auto galerkin = make(group, p.top, rule, 3);
  State y;
  galerkin->step(p.start.data(), p.start.data() + 9, 0.3, y.data(), y.data() + 9);
  const auto& r = galerkin->last_residuals();
  std::ostringstream shown;
  for (double x : r) shown << x << " ";
  CAPTURE(shown.str());
  REQUIRE(r.size() >= 3);
  // Quadratic: each residual about the square of the previous (relative to the first), until
  // round-off.
  for (std::size_t k = 1; k + 1 < r.size() && r[k] > 1e-13; ++k)
    CHECK(r[k] < 10 * r[k - 1] * r[k - 1] / r[0] + 1e-13);
}

TEST_CASE("reduced (discrete Euler-Poincare) form agrees with the unreduced one for the free body") {
  Rotations group;
  FreeBody body;
  Problem p = free_body();
  auto rule = gauss_legendre(2);
  auto full = make(group, body, rule, 2);
  auto reduced = make(group, body, rule, 2, true);
  const State a = integrate(*full, p.start, 0.05, 400), b = integrate(*reduced, p.start, 0.05, 400);
  // L(R, Omega) = l(Omega) for the free body, so the two forms do the same arithmetic on the
  // velocities: they agree to the last bit; the reduced one forms no position jets.
  CAPTURE(distance(a, b));
  CHECK(distance(a, b) < 1e-12);
  CHECK(distance(a, p.start) > 0.1);  // it moved
}

// The reduced form with a declared constant mass matrix takes dl/dOmega = M Omega in a step and asks
// the Lagrangian for nothing; L_d (evaluate) still asks for l's value. A step that continues the
// last two takes the polynomial through their control points as its start (warm_start): on the
// free body at h = 0.05 one update then leaves the residual at round-off (2 updates a step, the
// second measuring the contraction); from the last step's curve alone, at the second step, it takes 3.
TEST_CASE("reduced lie group galerkin with a constant mass matrix: no Lagrangian evaluation in a step, 2 updates a step") {
  Rotations group;
  FreeBody body;
  Problem p = free_body();
  auto rule = gauss_legendre(2);
  auto galerkin = make(group, body, rule, 2, true);
  State y = p.start, next;
  galerkin->step(y.data(), y.data() + 9, 0.05, next.data(), next.data() + 9);  // a cold start
  const long cold = galerkin->solver_statistics().iterations;
  y = next;
  galerkin->step(y.data(), y.data() + 9, 0.05, next.data(), next.data() + 9);  // the last step's curve
  CHECK(galerkin->solver_statistics().iterations - cold == 3);
  const long before = galerkin->solver_statistics().iterations;
  y = integrate(*galerkin, next, 0.05, 400);
  const auto& statistics = galerkin->solver_statistics();
  CAPTURE(statistics.iterations - before);
  CHECK(statistics.iterations - before == 2 * 400);
  CHECK(galerkin->evaluations().lagrangian + galerkin->evaluations().gradient + galerkin->evaluations().hessian == 0);
  galerkin->step(y.data(), y.data() + 9, 0.05, next.data(), next.data() + 9);
  double Ld = NAN;
  galerkin->evaluate(y.data(), next.data(), 0.05, &Ld, nullptr, nullptr);
  CHECK(std::isfinite(Ld));
  CHECK(galerkin->evaluations().lagrangian + galerkin->evaluations().gradient > 0);
}

TEST_CASE("reduced form is refused for a Lagrangian not invariant under the whole group") {
  Rotations group;
  Problem p = heavy_top();
  auto rule = gauss_legendre(2);
  CHECK_THROWS_WITH_AS(make(group, p.top, rule, 2, true), doctest::Contains("invariant under the whole group"),
                       std::invalid_argument);
}
