// Galerkin in the natural chart of S2 (core/galerkin_sphere.hpp): the spherical pendulum's orders
// against an independent reference (the constrained Galerkin construction in the embedding, Jay's
// Lobatto IIIA-IIIB equations of order 6, control points at the nodes, at a step 10 times smaller), the points on the sphere to
// round-off without multipliers, and the vertical angular momentum kept.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/constraint_fixtures.hpp"
#include "core/fixtures.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_sphere.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

FixedRule lobatto4() {
  const double r = 0.5 / std::sqrt(5.0);
  return FixedRule({0.0, 0.5 - r, 0.5 + r, 1.0}, {1.0 / 12, 5.0 / 12, 5.0 / 12, 1.0 / 12}, 5);
}

FixedRule lobatto(int points) { return points == 2 ? trapezoid() : points == 3 ? lobatto3() : lobatto4(); }

// (q, p) after `steps` steps of h from the fixture's start.
Eigen::VectorXd state_after(DiscreteHamiltonianMap& map, const SphericalPendulum& s, double h, int steps) {
  Eigen::VectorXd q = s.q, p = s.p, q1(3), p1(3);
  for (int k = 0; k < steps; ++k) {
    map.step(q.data(), p.data(), h, q1.data(), p1.data());
    q.swap(q1);
    p.swap(p1);
  }
  Eigen::VectorXd z(6);
  z << q, p;
  return z;
}

}  // namespace

TEST_CASE("galerkin in the natural chart of S2: the spherical pendulum measures orders 2, 4, 6 (s = 1, 2, 3, s + 1 "
          "Lobatto points) against the embedded construction, on the sphere without multipliers") {
  SphericalPendulum s;
  const double T = 1.0;
  auto reference_rule = lobatto4();
  GalerkinDiscreteLagrangian embedded(s.space, s.mass, reference_rule, reference_rule.c, {}, {}, &s.constraints);
  const Eigen::VectorXd reference = state_after(embedded, s, 0.0025, 400);
  for (int degree : {1, 2, 3}) {
    CAPTURE(degree);
    auto rule = lobatto(degree + 1);
    SphereGalerkinMap chart(s.mass, rule, equispaced_control_times(degree), {}, s.constraints);
    std::vector<double> errors;
    const int first = degree == 3 ? 5 : 10;
    for (int steps = first; steps <= 8 * first; steps *= 2) {
      const Eigen::VectorXd z = state_after(chart, s, T / steps, steps);
      CHECK(std::abs(z.head(3).norm() - 1.0) <= 1e-14);
      CHECK(std::abs(z.head(3).dot(z.tail(3))) <= 1e-14);  // the hidden constraint q . p = 0 (M = I)
      errors.push_back((z - reference).lpNorm<Eigen::Infinity>());
    }
    for (std::size_t k = 1; k < errors.size(); ++k) {
      const double order = std::log2(errors[k - 1] / errors[k]);
      CAPTURE(errors[k - 1]);
      CAPTURE(errors[k]);
      CHECK(order == doctest::Approx(2 * degree).epsilon(0.05));
    }
  }
}

TEST_CASE("galerkin in the natural chart of S2 keeps the spherical pendulum's vertical angular momentum to round-off "
          "and its energy bounded") {
  SphericalPendulum s;
  auto rule = lobatto3();
  SphereGalerkinMap chart(s.mass, rule, equispaced_control_times(2), {}, s.constraints);
  auto momentum = [](const Eigen::VectorXd& q, const Eigen::VectorXd& p) { return q[0] * p[1] - q[1] * p[0]; };
  auto energy = [](const Eigen::VectorXd& q, const Eigen::VectorXd& p) { return 0.5 * p.squaredNorm() + q[2]; };
  Eigen::VectorXd q = s.q, p = s.p, q1(3), p1(3);
  const double J0 = momentum(q, p), E0 = energy(q, p);
  double drift = 0.0, energy_error = 0.0;
  for (int k = 0; k < 5000; ++k) {
    chart.step(q.data(), p.data(), 0.02, q1.data(), p1.data());
    q.swap(q1);
    p.swap(p1);
    drift = std::max(drift, std::abs(momentum(q, p) - J0));
    energy_error = std::max(energy_error, std::abs(energy(q, p) - E0));
  }
  CHECK(drift <= 1e-13 * std::abs(J0));
  CHECK(energy_error <= 1e-5);
  CHECK(energy_error > 0.0);
  CHECK(chart.solver_statistics().mean() <= 4.0);
}

// L_d's derivatives are the step's momenta: after a step (q0, p0) -> (q1, p1), D1 L_d(q0, q1) = -p0
// and D2 L_d(q0, q1) = p1 on the tangent planes; and D1, D2 are L_d's derivatives along the sphere
// (central differences of L_d along geodesics through q0 and q1: a test of the derivatives, not a solve).
TEST_CASE("galerkin in the natural chart of S2: D1 L_d and D2 L_d are the step's -p0 and p1, and L_d's derivatives") {
  SphericalPendulum s;
  auto rule = lobatto4();
  SphereGalerkinMap chart(s.mass, rule, equispaced_control_times(3), {}, s.constraints);
  const double h = 0.1;
  Eigen::VectorXd q1(3), p1(3), D1(3), D2(3);
  chart.step(s.q.data(), s.p.data(), h, q1.data(), p1.data());
  double Ld = 0.0;
  chart.evaluate(s.q.data(), q1.data(), h, &Ld, D1.data(), D2.data());
  auto tangent = [](const Eigen::VectorXd& q, const Eigen::VectorXd& p) -> Eigen::VectorXd { return p - q.dot(p) * q; };
  CHECK((tangent(s.q, D1) + tangent(s.q, s.p)).lpNorm<Eigen::Infinity>() <= 1e-12);
  CHECK((tangent(q1, D2) - tangent(q1, p1)).lpNorm<Eigen::Infinity>() <= 1e-12);
  const Eigen::Vector3d direction = Eigen::Vector3d(q1).cross(Eigen::Vector3d(0.3, -0.5, 0.8)).normalized();
  auto Ld_at = [&](double t) {
    const Eigen::VectorXd q = std::cos(t) * q1 + std::sin(t) * Eigen::VectorXd(direction);
    double value = 0.0;
    chart.evaluate(s.q.data(), q.data(), h, &value, nullptr, nullptr);
    return value;
  };
  const double d = 1e-4, difference = (Ld_at(d) - Ld_at(-d)) / (2 * d);
  CHECK(difference == doctest::Approx(D2.dot(Eigen::VectorXd(direction))).epsilon(1e-7));
  // D1, which the balance of angular momentum gives without differentiating the chart's base point,
  // against L_d's differences as q0 moves along the sphere
  const Eigen::Vector3d direction0 = Eigen::Vector3d(s.q).cross(Eigen::Vector3d(-0.7, 0.2, 0.4)).normalized();
  auto Ld_from = [&](double t) {
    const Eigen::VectorXd q = std::cos(t) * s.q + std::sin(t) * Eigen::VectorXd(direction0);
    double value = 0.0;
    chart.evaluate(q.data(), q1.data(), h, &value, nullptr, nullptr);
    return value;
  };
  CHECK((Ld_from(d) - Ld_from(-d)) / (2 * d) == doctest::Approx(D1.dot(Eigen::VectorXd(direction0))).epsilon(1e-7));
  // and a wrong derivative is seen: the test's difference is not the derivative along another direction
  const Eigen::Vector3d other = Eigen::Vector3d(q1).cross(direction);
  CHECK(std::abs(difference - D2.dot(Eigen::VectorXd(other))) > 1e-3);
}
