// Forces through the discrete Lagrange-d'Alembert principle in the Galerkin construction
// (Marsden & West 2001, sec. 3.2): the damped, driven oscillator x'' + c x' + x = A cos(w t)
// against its exact solution, at the construction's order.
#include <doctest/doctest.h>

#include <cmath>

#include "fixtures.hpp"
#include "varia/core/galerkin.hpp"

namespace {

using namespace varia;
using namespace varia::testing;

constexpr double kDamping = 0.1, kAmplitude = 0.5, kFrequency = 1.3;

// f = -c v + A cos(w t) on R^1, with its Jacobian entry df/dv = -c.
struct DampedDrive : Force {
  int position_size() const noexcept override { return 1; }
  int velocity_size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = &zero;
    *cols = &one;
    return 1;
  }
  Status evaluate(double t, const double*, const double* v, double* f, double* jacobian) noexcept override {
    f[0] = -kDamping * v[0] + amplitude * std::cos(kFrequency * t);
    if (jacobian != nullptr) jacobian[0] = -kDamping;
    return nullptr;
  }
  double amplitude = kAmplitude;
  int zero = 0, one = 1;
};

// x'' + c x' + x = A cos(w t), x(0) = x0, x'(0) = 0: the steady state X cos + Y sin plus the
// underdamped transient e^{-gt} (a cos + b sin)(w_d t), g = c/2, w_d = sqrt(1 - g^2).
double exact(double t, double x0, double amplitude) {
  const double k = 1.0 - kFrequency * kFrequency, den = k * k + kDamping * kDamping * kFrequency * kFrequency;
  const double X = amplitude * k / den, Y = amplitude * kDamping * kFrequency / den;
  const double g = kDamping / 2, wd = std::sqrt(1.0 - g * g);
  const double a = x0 - X, b = (-Y * kFrequency + g * a) / wd;
  return std::exp(-g * t) * (a * std::cos(wd * t) + b * std::sin(wd * t)) + X * std::cos(kFrequency * t) +
         Y * std::sin(kFrequency * t);
}

// |x(T) - x_N| for step h from (1, 0); the map's time starts at 0.
double final_error(int degree, FixedRule rule, double h, double amplitude) {
  FlatSpace space(1);
  Oscillator oscillator;
  DampedDrive force;
  force.amplitude = amplitude;
  GalerkinDiscreteLagrangian map(space, oscillator, rule, equispaced_control_times(degree), SolverOptions{},
                                 {&force});
  const double T = 10.0;
  double q = 1.0, p = 0.0;
  for (long k = 0; k < std::lround(T / h); ++k) map.step(&q, &p, h, &q, &p);
  return std::abs(q - exact(T, 1.0, amplitude));
}

}  // namespace

TEST_CASE("galerkin with damping and a periodic drive: order 2 for degree 1 (trapezoid), 4 for degree 2 "
          "(Lobatto)") {
  struct Case {
    int degree;
    FixedRule rule;
    double order;
  };
  for (const Case& c : {Case{1, trapezoid(), 2.0}, Case{2, lobatto3(), 4.0}}) {
    const double e1 = final_error(c.degree, c.rule, 0.05, kAmplitude);
    const double e2 = final_error(c.degree, c.rule, 0.025, kAmplitude);
    const double order = std::log2(e1 / e2);
    CAPTURE(c.degree);
    MESSAGE("degree " << c.degree << ": errors " << e1 << ", " << e2 << ", order " << order);
    CHECK(order == doctest::Approx(c.order).epsilon(0.03));
  }
}

TEST_CASE("galerkin with damping: the energy decays as x'' + c x' + x = 0 says, E(t) = E0 e^{-ct} on average") {
  // Undriven: E = (x'^2 + x^2)/2 of the exact solution, against the discrete p^2/2 + q^2/2.
  FlatSpace space(1);
  Oscillator oscillator;
  DampedDrive force;
  force.amplitude = 0.0;
  FixedRule rule = lobatto3();
  GalerkinDiscreteLagrangian map(space, oscillator, rule, equispaced_control_times(2), SolverOptions{}, {&force});
  const double h = 0.05;
  double q = 1.0, p = 0.0, previous = 0.5;
  for (int k = 1; k <= 400; ++k) {
    map.step(&q, &p, h, &q, &p);
    const double t = k * h, x = exact(t, 1.0, 0.0), dt = 1e-6;
    const double v = (exact(t + dt, 1.0, 0.0) - exact(t - dt, 1.0, 0.0)) / (2 * dt);
    const double energy = 0.5 * (p * p + q * q);
    CHECK(energy == doctest::Approx(0.5 * (v * v + x * x)).epsilon(1e-5));
    CHECK(energy <= previous + 1e-12);  // dE/dt = -c v^2 <= 0
    previous = energy;
  }
  CHECK(previous < 0.5 * std::exp(-kDamping * 20.0) * 1.1);
}

TEST_CASE("galerkin evaluates forces only when a system has them") {
  FlatSpace space(1);
  Oscillator oscillator;
  FixedRule rule = lobatto3();
  double q = 1.0, p = 0.0;
  GalerkinDiscreteLagrangian unforced(space, oscillator, rule, equispaced_control_times(2), SolverOptions{});
  unforced.step(&q, &p, 0.1, &q, &p);
  CHECK(unforced.evaluations().force == 0);
  DampedDrive force;
  GalerkinDiscreteLagrangian forced(space, oscillator, rule, equispaced_control_times(2), SolverOptions{}, {&force});
  forced.step(&q, &p, 0.1, &q, &p);
  CHECK(forced.evaluations().force > 0);
}
