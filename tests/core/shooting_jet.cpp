// Second-order jets (varia/abi/jet.hpp) and one-step methods stepped at jets: the derivatives
// that the shooting construction relies on.
#include "varia/abi/jet.hpp"

#include <doctest/doctest.h>

#include <cmath>

#include "core/shooting_fixtures.hpp"
#include "varia/core/mechanical_field.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

// y^x: the jet's pow (a constant exponent or a variable one), the reference's through exp and log.
Jet2 power(const Jet2& y, const Jet2& x) { return pow(y, x); }
sdk::Dual2 power(const sdk::Dual2& y, const sdk::Dual2& x) { return exp(x * log(y)); }

template <class T>
T sample(const T& x, const T& y) {
  using std::cos, std::exp, std::log, std::sin, std::sqrt;
  return sin(x) * y / sqrt(x * x + y * y) + exp(x) * power(y, T(3.0)) - log(y) / cos(x) + power(y, x);
}

}  // namespace

TEST_CASE("jet arithmetic gives the gradient and Hessian of nested forward AD") {
  const double x = 0.4, y = 1.3;
  const Jet2 f = sample(Jet2::variable(x, 2, 0), Jet2::variable(y, 2, 1));
  // Reference: Eigen's nested AutoDiffScalar, the SDK's Dual2.
  sdk::Dual2 a, b;
  a.value() = sdk::Dual(x, 2, 0);
  b.value() = sdk::Dual(y, 2, 1);
  a.derivatives() = sdk::Vec<sdk::Dual>::Unit(2, 0);
  b.derivatives() = sdk::Vec<sdk::Dual>::Unit(2, 1);
  for (int j = 0; j < 2; ++j) {
    a.derivatives()(j).derivatives() = sdk::Vec<double>::Zero(2);
    b.derivatives()(j).derivatives() = sdk::Vec<double>::Zero(2);
  }
  const sdk::Dual2 r = sample(a, b);
  CHECK(f.value == doctest::Approx(r.value().value()).epsilon(1e-14));
  for (int i = 0; i < 2; ++i) {
    CHECK(f.gradient(i) == doctest::Approx(r.value().derivatives()(i)).epsilon(1e-14));
    for (int j = 0; j < 2; ++j)
      CHECK(f.hessian(i, j) == doctest::Approx(r.derivatives()(j).derivatives()(i)).epsilon(1e-13));
  }
}

TEST_CASE("an implicit method at jets carries the exact derivatives of its step") {
  SeparablePendulum pendulum;
  LagrangianEvaluator evaluator(pendulum);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  auto method = gauss2();
  SolverStatistics stages;
  const double h = 0.3, y0[2] = {0.8, -0.4};
  Jet2 y[2] = {Jet2::variable(y0[0], 2, 0), Jet2::variable(y0[1], 2, 1)}, y1[2];
  field.step(method, h, y, y1, stages);
  // Test-only central differences: of the double step for the gradient, of the jet gradient for
  // the Hessian (the implicit function theorem's second correction).
  const double e = 1e-5;
  for (int j = 0; j < 2; ++j) {
    double plus[2] = {y0[0], y0[1]}, minus[2] = {y0[0], y0[1]}, fp[2], fm[2];
    plus[j] += e;
    minus[j] -= e;
    field.step(method, h, plus, fp, stages);
    field.step(method, h, minus, fm, stages);
    Jet2 jp[2] = {Jet2::variable(plus[0], 2, 0), Jet2::variable(plus[1], 2, 1)};
    Jet2 jm[2] = {Jet2::variable(minus[0], 2, 0), Jet2::variable(minus[1], 2, 1)}, gp[2], gm[2];
    field.step(method, h, jp, gp, stages);
    field.step(method, h, jm, gm, stages);
    for (int r = 0; r < 2; ++r) {
      CAPTURE(r);
      CAPTURE(j);
      CHECK(y1[r].gradient(j) == doctest::Approx((fp[r] - fm[r]) / (2 * e)).epsilon(1e-8));
      for (int i = 0; i < 2; ++i)
        CHECK(y1[r].hessian(i, j) ==
              doctest::Approx((gp[r].gradient(i) - gm[r].gradient(i)) / (2 * e)).epsilon(1e-7));
    }
  }
}

TEST_CASE("the tangent field (q, v) of a configuration-dependent mass matrix: its Jacobian and its jets' second "
          "derivatives pass Taylor tests against the field's own values (issue #18: the lagrangian form of "
          "shooting for the double pendulum)") {
  DoublePendulum pendulum;
  LagrangianEvaluator evaluator(pendulum);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  const Eigen::Vector4d y(0.7, -0.4, 0.3, -1.1), d(0.3, -0.8, 0.5, 0.6);
  Eigen::Vector4d f, f_step;
  Eigen::Matrix4d J, J_step;
  REQUIRE(field.jacobian(y.data(), f.data(), J.data()) == nullptr);
  Eigen::Vector4d f_eval;
  REQUIRE(field.eval(y.data(), f_eval.data()) == nullptr);
  CHECK((f - f_eval).lpNorm<Eigen::Infinity>() < 1e-15);
  // The field at jets along the line y + s d (one variable s): value, first and second derivative.
  Jet2 line[4], rate[4];
  const Jet2 s = Jet2::variable(0.0, 1, 0);
  for (int r = 0; r < 4; ++r) line[r] = y[r] + d[r] * s;
  REQUIRE(field.eval(line, rate) == nullptr);
  Eigen::Vector4d second;
  for (int r = 0; r < 4; ++r) {
    CHECK(rate[r].value == doctest::Approx(f[r]).epsilon(1e-15));
    CHECK(rate[r].gradient(0) == doctest::Approx((J * d)[r]).epsilon(1e-13));
    second[r] = rate[r].hessian(0, 0);
  }
  // Taylor: f(y + e d) - f - e J d = O(e^2), and J(y + e d) d - J d - e f'' = O(e^2): halving e
  // quarters both remainders.
  double previous_value = 0.0, previous_slope = 0.0;
  for (double e : {1e-2, 5e-3, 2.5e-3}) {
    const Eigen::Vector4d moved = y + e * d;
    REQUIRE(field.jacobian(moved.data(), f_step.data(), J_step.data()) == nullptr);
    const double value_remainder = (f_step - f - e * J * d).norm();
    const double slope_remainder = (J_step * d - J * d - e * second).norm();
    CAPTURE(e);
    if (previous_value > 0.0) {
      CHECK(previous_value / value_remainder == doctest::Approx(4.0).epsilon(0.05));
      CHECK(previous_slope / slope_remainder == doctest::Approx(4.0).epsilon(0.05));
    }
    previous_value = value_remainder;
    previous_slope = slope_remainder;
  }
}
