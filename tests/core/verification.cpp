#include "varia/core/verification.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <cmath>

#include "core/fixtures.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

// Symplectic Euler's non-symplectic cousin, explicit Euler on the unit pendulum: a map that the
// property checks must reject.
struct ExplicitEuler : DiscreteHamiltonianMap {
  int point_size() const override { return 1; }
  int dim() const override { return 1; }
  void take_step(const double* q0, const double* p0, double /*t0*/, double h, double* q1, double* p1) override {
    const double q = q0[0], p = p0[0];
    q1[0] = q + h * p;
    p1[0] = p - h * std::sin(q);
  }
  const SolverStatistics& solver_statistics() const override { return statistics; }
  const EvaluationCounters& evaluations() const override { return counters; }
  SolverStatistics statistics;
  EvaluationCounters counters;
};

std::vector<double> pendulum_energy_errors(DiscreteHamiltonianMap& map, long steps) {
  std::vector<double> errors;
  const double E0 = -std::cos(1.3);
  run(map, Eigen::VectorXd::Constant(1, 1.3), Eigen::VectorXd::Zero(1), 0.0, 0.1, steps, [&](long, const double* q, const double* p) {
    errors.push_back(0.5 * p[0] * p[0] - std::cos(q[0]) - E0);
  });
  return errors;
}

}  // namespace

TEST_CASE("order fit drops round-off and pre-asymptotic points and finds the slope") {
  std::vector<double> h, e;
  for (int k = 0; k < 8; ++k) {
    h.push_back(0.4 / (1 << k));
    e.push_back(k == 0 ? 0.5 : std::max(3.0 * std::pow(h.back(), 4), 1e-15));
  }
  const OrderFit fit = fit_order(h, e, 1e-13);
  CAPTURE(fit.slope);
  CHECK(fit.slope == doctest::Approx(4.0).epsilon(0.01));
  CHECK(fit.dropped.size() >= 1);
}

TEST_CASE("galerkin with the trapezoid rule is self-adjoint, with a one-sided rule it is not") {
  FlatSpace space(1);
  Pendulum pendulum;
  const double q = 0.4, v = 0.3, h = 0.1;
  auto pairs = sample_pairs(space, &q, &v, h, 5);
  auto symmetric = trapezoid();
  FixedRule left({0.0}, {1.0}, 0);
  GalerkinDiscreteLagrangian a(space, pendulum, symmetric, equispaced_control_times(1), {});
  GalerkinDiscreteLagrangian b(space, pendulum, left, equispaced_control_times(1), {});
  const double residual_symmetric = self_adjointness_residual(a, pairs, h);
  const double residual_left = self_adjointness_residual(b, pairs, h);
  CAPTURE(residual_symmetric);
  CAPTURE(residual_left);
  CHECK(residual_symmetric < 1e-13);
  CHECK(residual_left > 1e-4);
}

namespace {

// The symplecticity defects of Galerkin (degree 2, Lobatto-3: symplectic) and of explicit Euler
// (not) on `model` in R^n, at (q, p) with h = 0.1.
struct Defects {
  SymplecticityDefect variational, naive;
};
Defects galerkin_and_euler(Lagrangian& model, int n, const double* q, const double* p, const Eigen::VectorXd& steps) {
  FlatSpace space(n);
  auto rule = lobatto3();
  GalerkinDiscreteLagrangian galerkin(space, model, rule, equispaced_control_times(2), {});
  ExplicitEuler euler;
  return {symplecticity_defect(galerkin, space, q, p, 0.1, steps), symplecticity_defect(euler, space, q, p, 0.1, steps)};
}

}  // namespace

TEST_CASE("the symplecticity defect is at round-off for galerkin and large for explicit Euler") {
  Pendulum pendulum;
  const double q = 1.0, p = 0.2;
  const Defects d = galerkin_and_euler(pendulum, 1, &q, &p, Eigen::VectorXd::Constant(2, 1e-3));
  CAPTURE(d.variational.defect);
  CAPTURE(d.variational.noise);
  CAPTURE(d.naive.defect);
  CHECK(d.variational.defect < 1e-9);
  CHECK(d.naive.defect > 1e-3);
}

namespace {

// A pendulum of unit mass beside one of mass 1e-9 (a planet beside Pluto): difference steps on the
// scale of each coordinate measure the symplecticity of both; a unit momentum step moves the light
// one at 1e9 times its speed, and the defect then measures the nonlinearity of that motion.
struct HeavyAndLight : sdk::AutodiffLagrangian<HeavyAndLight, 2, 2> {
  static constexpr double light = 1e-9;
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::cos;
    return 0.5 * v(0) * v(0) + cos(q(0)) + light * (0.5 * v(1) * v(1) + cos(q(1)));
  }
};

}  // namespace

TEST_CASE("the symplecticity defect takes each coordinate in its own scale") {
  HeavyAndLight model;
  const double q[2] = {1.0, 0.5}, p[2] = {0.2, 0.3 * HeavyAndLight::light};
  Eigen::VectorXd scaled(4);
  scaled << 1e-3, 1e-3, 1e-3, 1e-3 * HeavyAndLight::light;
  const Defects d = galerkin_and_euler(model, 2, q, p, scaled);
  const Defects unit = galerkin_and_euler(model, 2, q, p, Eigen::VectorXd::Constant(4, 1e-3));
  CAPTURE(d.variational.defect);
  CAPTURE(d.variational.noise);
  CAPTURE(d.naive.defect);
  CAPTURE(unit.variational.defect);
  CHECK(d.variational.defect < 1e-9);
  CHECK(d.naive.defect > 1e-3);
  CHECK(unit.variational.defect > 1e-3);  // what the unscaled test measured: not the map's symplecticity
}

TEST_CASE("the energy error of galerkin does not drift, that of explicit Euler does") {
  FlatSpace space(1);
  Pendulum pendulum;
  auto rule = trapezoid();
  GalerkinDiscreteLagrangian galerkin(space, pendulum, rule, equispaced_control_times(1), {});
  ExplicitEuler euler;
  const double bounded = energy_drift(pendulum_energy_errors(galerkin, 4000)).share();
  const double drifting = energy_drift(pendulum_energy_errors(euler, 4000)).share();
  CAPTURE(bounded);
  CAPTURE(drifting);
  CHECK(bounded < 0.5);
  CHECK(drifting > 0.5);
}

namespace {

// Lie-Euler for the free body, R1 = R0 exp(h Omega0), Pi1 = Pi0 + h Pi0 x Omega0: a Lie group
// method that is not symplectic.
struct LieEuler : DiscreteHamiltonianMap {
  Eigen::Vector3d J{1, 2, 3};
  int point_size() const override { return 9; }
  int dim() const override { return 3; }
  void take_step(const double* q0, const double* p0, double /*t0*/, double h, double* q1, double* p1) override {
    const Eigen::Vector3d Pi(p0[0], p0[1], p0[2]), Omega = Pi.cwiseQuotient(J);
    so3::to_row_major(so3::from_row_major(q0) * so3::exp(Eigen::Vector3d(h * Omega)), q1);
    Eigen::Map<Eigen::Vector3d>{p1} = Pi + h * Pi.cross(Omega);
  }
  const SolverStatistics& solver_statistics() const override { return statistics; }
  const EvaluationCounters& evaluations() const override { return counters; }
  SolverStatistics statistics;
  EvaluationCounters counters;
};

}  // namespace

TEST_CASE("on SO(3), in canonical chart coordinates: the galerkin map is symplectic, Lie-Euler is not") {
  Rotations group;
  Top body(Eigen::Vector3d(1, 2, 3), 0.0, Eigen::Vector3d::Zero());
  auto rule = lobatto3();
  LieGroupGalerkinDiscreteLagrangian galerkin(group, body, rule, equispaced_control_times(2), {});
  LieEuler euler;
  double R[9];
  so3::to_row_major(so3::exp(Eigen::Vector3d(0.1, 0.2, 0.3)), R);
  const double Pi[3] = {0.4, 1.6, -1.8};
  const Eigen::VectorXd steps = Eigen::VectorXd::Constant(6, 1e-3);
  const auto variational = symplecticity_defect(galerkin, group, R, Pi, 0.1, steps);
  const auto naive = symplecticity_defect(euler, group, R, Pi, 0.1, steps);
  CAPTURE(variational.defect);
  CAPTURE(variational.noise);
  CAPTURE(naive.defect);
  CHECK(variational.defect < 1e-9);
  CHECK(naive.defect > 1e-3);
}
