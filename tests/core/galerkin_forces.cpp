// Forces through the discrete Lagrange-d'Alembert principle in the Galerkin construction
// (Marsden & West 2001, sec. 3.2): the damped, driven oscillator x'' + c x' + x = A cos(w t)
// against its exact solution, at the construction's order.
#include <doctest/doctest.h>

#include <cmath>

#include "damped_drive.hpp"
#include "fixtures.hpp"
#include "varia/core/galerkin.hpp"

namespace {

using namespace varia;
using namespace varia::testing;

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
  for (long k = 0; k < std::lround(T / h); ++k) map.step(&q, &p, static_cast<double>(k) * h, h, &q, &p);
  return std::abs(q - damped_exact(T, 1.0, amplitude));
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
    const double t = k * h, x = damped_exact(t, 1.0, 0.0), v = damped_exact_velocity(t, 1.0, 0.0);
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
