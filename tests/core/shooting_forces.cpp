// Forces in the shooting construction through the discrete Lagrange-d'Alembert principle
// (Marsden & West 2001, sec. 3.2; shooting.hpp): the damped, driven oscillator
// x'' + c x' + x = A cos(w t) against its exact solution, at the order min(p, q) of the paper's
// sec. 3 shooting-based discrete Lagrangians.
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "core/damped_drive.hpp"
#include "core/shooting_fixtures.hpp"
#include "varia/core/shooting.hpp"

namespace {

using namespace varia;
using namespace varia::testing;

constexpr double kEnd = 10.0;

// |x(T) - x_N| and |v(T) - v_N| (p = v: unit mass) after stepping from (1, 0) with step h; the map's
// time starts at 0. Without a force, the unforced oscillator is integrated.
double final_error(OneStepMethod& method, Quadrature& rule, double h, DampedDrive* force,
                   ShootingForm form = ShootingForm::lagrangian) {
  FlatSpace space(1);
  MassOscillator oscillator;
  std::vector<Force*> forces;
  if (force != nullptr) forces.push_back(force);
  ShootingDiscreteLagrangian map(space, oscillator, rule, method, form, SolverOptions{}, forces);
  const Eigen::VectorXd end = run(map, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Zero(1), h,
                                  static_cast<int>(std::lround(kEnd / h)));
  const double amplitude = force != nullptr ? force->amplitude : 0.0;
  return std::hypot(end[0] - damped_exact(kEnd, 1.0, amplitude),
                    end[1] - damped_exact_velocity(kEnd, 1.0, amplitude));
}

// The slope of the error at T = 10 over h = 0.2, 0.1, 0.05, 0.025 (h = 0.4 dropped: pre-asymptotic).
double measured_order(OneStepMethod& method, Quadrature& rule, ShootingForm form = ShootingForm::lagrangian) {
  std::vector<double> steps, errors;
  DampedDrive force;
  for (double h : {0.2, 0.1, 0.05, 0.025}) {
    steps.push_back(h);
    errors.push_back(final_error(method, rule, h, &force, form));
  }
  MESSAGE("errors at h = 0.2 ... 0.025: " << errors[0] << ", " << errors[1] << ", " << errors[2] << ", "
                                          << errors[3]);
  return fitted_order(steps, errors, 0, 4);
}

}  // namespace

TEST_CASE("shooting with damping and a periodic drive: SVIRK4 (rk4 + simpson) converges at order 4") {
  auto method = rk4();
  FixedRule rule = simpson();
  const double order = measured_order(method, rule);
  MESSAGE("SVIRK4 with forces: order " << order);
  CHECK(order == doctest::Approx(4.0).epsilon(0.03));
}

TEST_CASE("shooting with damping and a periodic drive: SVIMID (implicit-midpoint + trapezoid) converges "
          "at order 2") {
  auto method = implicit_midpoint();
  FixedRule rule = trapezoid();
  const double order = measured_order(method, rule);
  MESSAGE("SVIMID with forces: order " << order);
  CHECK(order == doctest::Approx(2.0).epsilon(0.03));
}

TEST_CASE("shooting with forces in the hamiltonian form, and with 2-stage Gauss + simpson: order 4") {
  auto method = rk4();
  FixedRule rule = simpson();
  const double hamiltonian = measured_order(method, rule, ShootingForm::hamiltonian);
  auto gauss = gauss2();
  const double implicit = measured_order(gauss, rule);
  MESSAGE("rk4 + simpson, hamiltonian form: " << hamiltonian << "; gauss2 + simpson: " << implicit);
  CHECK(hamiltonian == doctest::Approx(4.0).epsilon(0.03));
  CHECK(implicit == doctest::Approx(4.0).epsilon(0.03));
}

TEST_CASE("shooting with forces: dropping the forces leaves an O(1) error against the damped, driven "
          "solution") {
  auto method = rk4();
  FixedRule rule = simpson();
  FlatSpace space(1);
  MassOscillator oscillator;
  ShootingDiscreteLagrangian unforced(space, oscillator, rule, method, ShootingForm::lagrangian, SolverOptions{});
  const Eigen::VectorXd end = run(unforced, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Zero(1), 0.05, 200);
  const double dropped = std::abs(end[0] - damped_exact(kEnd, 1.0, kAmplitude));
  DampedDrive force;
  const double kept = final_error(method, rule, 0.05, &force);
  MESSAGE("error at T = 10 without the forces " << dropped << ", with them " << kept);
  CHECK(dropped > 0.1);
  CHECK(kept < 1e-6);
}

TEST_CASE("shooting with damping: the energy decays as the exact solution's and never increases") {
  auto method = rk4();
  FixedRule rule = simpson();
  FlatSpace space(1);
  MassOscillator oscillator;
  DampedDrive force;
  force.amplitude = 0.0;
  ShootingDiscreteLagrangian map(space, oscillator, rule, method, ShootingForm::lagrangian, SolverOptions{},
                                 {&force});
  const double h = 0.05;
  double q = 1.0, p = 0.0, previous = 0.5, worst = 0.0;
  for (int k = 1; k <= 400; ++k) {
    map.step(&q, &p, h, &q, &p);
    const double t = k * h, x = damped_exact(t, 1.0, 0.0), v = damped_exact_velocity(t, 1.0, 0.0);
    const double energy = 0.5 * (p * p + q * q), exact = 0.5 * (v * v + x * x);
    worst = std::max(worst, std::abs(energy - exact) / exact);
    CHECK(energy <= previous + 1e-14);  // dE/dt = -c v^2 <= 0
    previous = energy;
  }
  MESSAGE("largest relative energy error over t in [0, 20]: " << worst);
  CHECK(worst < 1e-6);
  CHECK(previous < 0.5 * std::exp(-kDamping * 20.0) * 1.1);
}

TEST_CASE("shooting with forces: the Newton Jacobian is exact (quadratic convergence on the damped, driven "
          "pendulum at h = 0.5), forces are counted, and L_d alone leaves them out") {
  auto method = rk4();
  FixedRule rule = simpson();
  FlatSpace space(1);
  struct MassPendulum : Pendulum {
    bool constant_mass_matrix(double* mass) const noexcept override {
      mass[0] = 1.0;
      return true;
    }
  } pendulum;
  DampedDrive force;
  ShootingDiscreteLagrangian forced(space, pendulum, rule, method, ShootingForm::lagrangian, SolverOptions{},
                                    {&force});
  ShootingDiscreteLagrangian unforced(space, pendulum, rule, method, ShootingForm::lagrangian, SolverOptions{});
  double q = 1.0, p = 1.5, q1 = 0.0, p1 = 0.0;
  forced.step(&q, &p, 0.7, 0.5, &q1, &p1);
  const std::vector<double>& r = forced.last_residuals();
  std::ostringstream sequence;
  for (double x : r) sequence << x << " ";
  MESSAGE("residuals: " << sequence.str());
  REQUIRE(r.size() >= 3);
  CHECK(r.back() < 1e-14);
  for (std::size_t k = 1; k + 1 < r.size(); ++k) CHECK(r[k] <= 10 * r[k - 1] * r[k - 1]);
  CHECK(forced.evaluations().force > 0);
  CHECK(unforced.evaluations().force == 0);
  double a[3], b[3];
  forced.evaluate(&q, &q1, 0.5, &a[0], &a[1], &a[2]);
  unforced.evaluate(&q, &q1, 0.5, &b[0], &b[1], &b[2]);
  for (int k = 0; k < 3; ++k) CHECK(a[k] == doctest::Approx(b[k]).epsilon(1e-14));
}

TEST_CASE("shooting refuses forces in the type-2 form and with end-derivative quadratures") {
  auto method = rk4();
  FlatSpace space(1);
  MassOscillator oscillator;
  DampedDrive force;
  FixedRule rule = simpson();
  CHECK_THROWS_AS(ShootingDiscreteLagrangian(space, oscillator, rule, method, ShootingForm::type_2,
                                             SolverOptions{}, {&force}),
                  std::invalid_argument);
  EulerMaclaurin2 corrected;
  CHECK_THROWS_AS(ShootingDiscreteLagrangian(space, oscillator, corrected, method, ShootingForm::lagrangian,
                                             SolverOptions{}, {&force}),
                  std::invalid_argument);
}
