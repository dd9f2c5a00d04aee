// MEGNO and the Lyapunov exponent's estimate (chaos_indicators.hpp) from the exact tangent map
// along a trajectory (trajectory.hpp's deviation): -> 0 on the harmonic oscillator (a stable periodic
// orbit of an isochronous system), -> 2 on a Kepler ellipse (quasi-periodic: the deviation grows
// linearly), with a Lyapunov estimate -> 0 like ln t / t. The chaotic double pendulum: tests/host/chaos.cpp.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>

#include "core/fixtures.hpp"
#include "core/shooting_fixtures.hpp"
#include "varia/core/chaos_indicators.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/trajectory.hpp"

using namespace varia;
using namespace varia::testing;

TEST_CASE("the indicators' sums: a deviation growing linearly gives <Y> -> 2, exponentially with rate r gives "
          "lambda = r and <Y> growing like r t / 2") {
  ChaosIndicators linear, exponential;
  const double h = 0.1, rate = 0.3;
  for (int k = 1; k <= 100000; ++k) {
    linear.add(k * h, std::log(static_cast<double>(k) / std::max(k - 1, 1)));
    exponential.add(k * h, rate * h);
  }
  CHECK(linear.megno() == doctest::Approx(2.0).epsilon(2e-3));
  CHECK(exponential.lyapunov() == doctest::Approx(rate));
  CHECK(exponential.megno() == doctest::Approx(rate * 1e4 / 2).epsilon(1e-3));
  CHECK(ChaosIndicators{}.megno() == 0.0);
}

TEST_CASE("megno -> 0 on the harmonic oscillator (T = 500) and -> 2 on the Kepler ellipse e = 0.5 (T = 2000)") {
  FlatSpace line(1), plane(2);
  SUBCASE("oscillator, galerkin s = 2 with 2 gauss points, h = 0.1") {
    MassOscillator oscillator;
    auto rule = gauss_legendre(2);
    GalerkinDiscreteLagrangian map(line, oscillator, rule, equispaced_control_times(2), {});
    Trajectory trajectory(map, Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1), 0.0, 0.1);
    trajectory.track_deviation(Eigen::VectorXd::Ones(2));
    trajectory.advance(5000);
    CHECK(std::abs(trajectory.chaos().megno()) < 0.1);
    CHECK(std::abs(trajectory.chaos().lyapunov()) < 1e-3);
  }
  SUBCASE("kepler, galerkin s = 2 with 3 lobatto points, h = 0.01") {
    PlanarKepler kepler;
    auto rule = lobatto3();
    GalerkinDiscreteLagrangian map(plane, kepler, rule, equispaced_control_times(2), {});
    Eigen::VectorXd q(2), p(2);
    q << 0.5, 0.0;
    p << 0.0, std::sqrt(3.0);
    Trajectory trajectory(map, q, p, 0.0, 0.01);
    trajectory.track_deviation(Eigen::VectorXd::Ones(4));
    trajectory.advance(200000);
    CHECK(std::abs(trajectory.chaos().megno() - 2.0) < 0.25);
    CHECK(trajectory.chaos().lyapunov() < 0.05);
    CHECK(trajectory.deviation().norm() == doctest::Approx(1.0));
  }
}
