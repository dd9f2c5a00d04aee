// The exact tangent map d(q1, p1)/d(q0, p0) of every construction that has one (the implicit
// function theorem on the step's own equations, discrete_hamiltonian_map.hpp) against central
// differences of sixth order of the step itself, and M^T J M = J where the map is symplectic; where
// it is not (a one-step method that is not symplectic, a damped system), the defect is measured as
// not vanishing. Constructions without one say why.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/damped_drive.hpp"
#include "core/fixtures.hpp"
#include "core/shooting_fixtures.hpp"
#include "core/so3_reference.hpp"
#include "core/tangent_differences.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/lie_verlet.hpp"
#include "varia/core/one_step_map.hpp"
#include "varia/core/shooting.hpp"
#include "varia/core/verification.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

// On a Lie group: the tangent map agrees with the differences in the charts, and the step moves.
void check_tangent_on(Manifold& manifold, DiscreteHamiltonianMap& map, const Eigen::VectorXd& q0,
                      const Eigen::VectorXd& p0) {
  const TangentCase m = tangent_and_differences(manifold, map, q0, p0, 0.0, 0.05);
  const double difference = (m.exact - m.differences).cwiseAbs().maxCoeff();
  MESSAGE("largest difference " << difference);
  CHECK(difference <= 1e-10);
  CHECK((m.exact - Eigen::MatrixXd::Identity(m.exact.rows(), m.exact.cols())).cwiseAbs().maxCoeff() >= 1e-3);
}

// The tangent map agrees with the differences (their error: O(d^6) and eps / d) and its
// symplecticity defect; the step continues from the last so that every warm start is exercised.
double checked_defect(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q0, const Eigen::VectorXd& p0, double h,
                      double t0 = 0.0) {
  FlatSpace space(static_cast<int>(q0.size()));
  const TangentCase m = tangent_and_differences(space, map, q0, p0, t0, h);
  CHECK((m.exact - m.differences).cwiseAbs().maxCoeff() <= 1e-10);
  return symplecticity_residual(m.exact);
}

Eigen::VectorXd vector_of(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

}  // namespace

TEST_CASE("galerkin's tangent map is exact and symplectic on every path: Newton, the node iteration, the explicit form") {
  FlatSpace line(1), plane(2);
  Pendulum pendulum;            // Newton with the exact Jacobian
  SeparablePendulum separable;  // the node iteration (constant mass matrix)
  DoublePendulum double_pendulum;
  PlanarKepler kepler;
  auto lobatto = lobatto3();
  auto gauss = gauss_legendre(3);
  auto trapezoid_rule = trapezoid();
  const Eigen::VectorXd q = vector_of({1.3}), p = vector_of({0.2});
  SUBCASE("newton, s = 2") {
    GalerkinDiscreteLagrangian map(line, pendulum, lobatto, equispaced_control_times(2), {});
    CHECK(map.tangent_map_refusal().empty());
    CHECK(checked_defect(map, q, p, 0.1) <= 1e-13);
  }
  SUBCASE("node iteration, s = 3 with 3 gauss points") {
    GalerkinDiscreteLagrangian map(line, separable, gauss, equispaced_control_times(3), {});
    CHECK(checked_defect(map, q, p, 0.3) <= 1e-13);
  }
  SUBCASE("explicit form (Stormer-Verlet)") {
    GalerkinDiscreteLagrangian map(line, separable, trapezoid_rule, equispaced_control_times(1), {});
    CHECK(checked_defect(map, q, p, 0.1) <= 1e-13);
  }
  SUBCASE("kepler, e = 0.5 at its pericentre") {
    GalerkinDiscreteLagrangian map(plane, kepler, lobatto, equispaced_control_times(2), {});
    CHECK(checked_defect(map, vector_of({0.5, 0.0}), vector_of({0.0, std::sqrt(3.0)}), 0.05) <= 1e-13);
  }
  SUBCASE("the double pendulum (a configuration-dependent mass matrix)") {
    GalerkinDiscreteLagrangian map(plane, double_pendulum, lobatto, equispaced_control_times(2), {});
    CHECK(checked_defect(map, vector_of({2.0, 2.5}), vector_of({0.3, -0.1}), 0.05) <= 1e-13);
  }
}

TEST_CASE("galerkin's tangent map with a sparse Hessian (a chain of anharmonic springs): Newton and the explicit form") {
  FlatSpace four(4);
  const Eigen::VectorXd q = vector_of({0.0, 1.1, 2.0, 3.05}), p = vector_of({0.1, -0.2, 0.05, 0.3});
  auto lobatto = lobatto3();
  auto trapezoid_rule = trapezoid();
  SparseChain newton_form(4, false), explicit_form(4, true);
  GalerkinDiscreteLagrangian newton(four, newton_form, lobatto, equispaced_control_times(2), {});
  CHECK(newton.tangent_map_refusal().empty());
  CHECK(checked_defect(newton, q, p, 0.1) <= 1e-13);
  // the step's own Newton keeps its structure: the steps after a tangent step are unchanged
  Eigen::VectorXd q1(4), p1(4), q2(4), p2(4);
  newton.step(q.data(), p.data(), 0.0, 0.1, q1.data(), p1.data());
  GalerkinDiscreteLagrangian fresh(four, newton_form, lobatto, equispaced_control_times(2), {});
  fresh.step(q.data(), p.data(), 0.0, 0.1, q2.data(), p2.data());
  CHECK((q1 - q2).cwiseAbs().maxCoeff() <= 1e-12);
  GalerkinDiscreteLagrangian verlet(four, explicit_form, trapezoid_rule, equispaced_control_times(1), {});
  CHECK(checked_defect(verlet, q, p, 0.1) <= 1e-13);
}

TEST_CASE("with forces the tangent map is exact and is measured not symplectic: the damped, driven oscillator") {
  FlatSpace line(1);
  Oscillator oscillator;
  DampedDrive drive;
  auto lobatto = lobatto3();
  GalerkinDiscreteLagrangian map(line, oscillator, lobatto, equispaced_control_times(2), {}, {&drive});
  // det M = e^{-c h} to the method's order: the form shrinks by about c h = 0.01 a step
  const double defect = checked_defect(map, vector_of({1.0}), vector_of({0.0}), 0.1, 0.7);
  CHECK(defect > 5e-3);
  CHECK(defect < 2e-2);
}

TEST_CASE("the one-step construction's tangent map: jets through the method, symplectic for Gauss methods only") {
  FlatSpace line(1), plane(2);
  MassOscillator oscillator;  // (q, v) with the constant mass matrix
  DoublePendulum double_pendulum;  // Hamilton's equations in (q, p)
  SUBCASE("gauss2 on the double pendulum") {
    auto method = gauss2();
    OneStepHamiltonianMap map(plane, double_pendulum, method, {});
    CHECK(map.tangent_map_refusal().empty());
    CHECK(checked_defect(map, vector_of({2.0, 2.5}), vector_of({0.3, -0.1}), 0.05) <= 1e-13);
  }
  SUBCASE("implicit midpoint on the oscillator") {
    auto method = implicit_midpoint();
    OneStepHamiltonianMap map(line, oscillator, method, {});
    CHECK(checked_defect(map, vector_of({1.0}), vector_of({0.5}), 0.2) <= 1e-14);
  }
  SUBCASE("explicit midpoint is not symplectic: det M = 1 + h^4/4 on the oscillator") {
    auto method = explicit_midpoint();
    OneStepHamiltonianMap map(line, oscillator, method, {});
    const double defect = checked_defect(map, vector_of({1.0}), vector_of({0.5}), 0.2);
    CHECK(defect == doctest::Approx(std::pow(0.2, 4) / 4).epsilon(1e-9));
  }
}

namespace {

// The heavy top on SO(3) and a start R0 = exp(0.3, -0.5, 0.8), Pi0 = (0.5, -0.45, 1.6): the Lie
// group constructions' tangent maps are checked there.
struct HeavyTopStart {
  Rotations group;
  Top top{Eigen::Vector3d(1.0, 1.5, 0.8), 1.0, Eigen::Vector3d(0.1, 0.2, 0.5)};
  Eigen::VectorXd R0 = Eigen::VectorXd(9), p0 = (Eigen::VectorXd(3) << 0.5, -0.45, 1.6).finished();
  HeavyTopStart() {
    const Eigen::Vector3d axis(0.3, -0.5, 0.8);
    REQUIRE(group.retract(vector_of({1, 0, 0, 0, 1, 0, 0, 0, 1}).data(), axis.data(), R0.data()) == nullptr);
  }
};

}  // namespace

TEST_CASE("the one-step construction's tangent map on a Lie group: the heavy top on SO(3) in the natural charts at "
          "R0 and R1, by the explicit midpoint rule in the embedding and by the Crouch-Grossman method on the group") {
  HeavyTopStart start;
  auto midpoint = explicit_midpoint();
  const auto crouch = crouch_grossman(2);
  for (OneStepMethod* method : {static_cast<OneStepMethod*>(&midpoint), crouch.get()}) {
    OneStepHamiltonianMap map(start.group, start.top, *method, {});
    REQUIRE(map.tangent_map_refusal().empty());
    check_tangent_on(start.group, map, start.R0, start.p0);
  }
}

TEST_CASE("the Lie group Galerkin construction's tangent map: the heavy top on SO(3) in the natural charts at R0 and R1, "
          "degrees 1, 2 and 3") {
  HeavyTopStart start;
  for (int s = 1; s <= 3; ++s) {
    CAPTURE(s);
    FixedRule rule = gauss_legendre(s + 1);
    LieGroupGalerkinDiscreteLagrangian map(start.group, start.top, rule, equispaced_control_times(s), {});
    REQUIRE(map.tangent_map_refusal().empty());
    check_tangent_on(start.group, map, start.R0, start.p0);
  }
  // The free body, invariant under the whole group: the reduced form (tau = 0 and no position
  // derivatives, exactly), its inertia declared constant.
  struct InvariantBody : Top {
    using Top::Top;
    const char* symmetry_group() const noexcept override { return "SO(3)"; }
    int momentum_size() const noexcept override { return 3; }
  } free_body(Eigen::Vector3d(1.0, 1.5, 0.8), 0.0, Eigen::Vector3d::Zero());
  FixedRule rule = gauss_legendre(3);
  LieGroupGalerkinDiscreteLagrangian reduced(start.group, free_body, rule, equispaced_control_times(2), {}, true);
  check_tangent_on(start.group, reduced, start.R0, start.p0);
}

TEST_CASE("shooting's tangent map on a Lie group: the heavy top on SO(3) in the natural charts at R0 and R1, by "
          "Crouch-Grossman of orders 2 and 3 with the trapezoidal and Simpson's rules, and refused with a Runge-Kutta "
          "method in the embedding") {
  HeavyTopStart start;
  auto trapezoid_rule = trapezoid();
  auto simpson_rule = simpson();
  const auto second = crouch_grossman(2), third = crouch_grossman(3);
  ShootingDiscreteLagrangian cg2(start.group, start.top, trapezoid_rule, *second, ShootingForm::lagrangian, {});
  ShootingDiscreteLagrangian cg3(start.group, start.top, simpson_rule, *third, ShootingForm::lagrangian, {});
  for (ShootingDiscreteLagrangian* map : {&cg2, &cg3}) {
    REQUIRE(map->tangent_map_refusal().empty());
    check_tangent_on(start.group, *map, start.R0, start.p0);
  }
  auto midpoint = explicit_midpoint();
  ShootingDiscreteLagrangian embedded(start.group, start.top, simpson_rule, midpoint, ShootingForm::lagrangian, {});
  CHECK(embedded.tangent_map_refusal().find("Lie group method") != std::string::npos);
}

TEST_CASE("the lie-verlet construction's tangent map (the LGVI, both solvers): the heavy top on SO(3) in the natural "
          "charts at R0 and R1") {
  HeavyTopStart start;
  for (LieVerletSolver solver : {LieVerletSolver::cayley, LieVerletSolver::exp}) {
    LieGroupVelocityVerlet map(start.group, start.top, solver, {});
    check_tangent_on(start.group, map, start.R0, start.p0);
  }
}

TEST_CASE("shooting's tangent map: the lagrangian form (SVIRK4, its explicit shot run by the model's kernel), the "
          "hamiltonian and type-2 forms, and with forces") {
  FlatSpace line(1), plane(2);
  SeparablePendulum pendulum;
  DoublePendulum double_pendulum;
  auto rule = simpson();
  auto method = rk4();
  SUBCASE("SVIRK4 on the pendulum") {
    ShootingDiscreteLagrangian map(line, pendulum, rule, method, ShootingForm::lagrangian, {});
    CHECK(map.tangent_map_refusal().empty());
    CHECK(checked_defect(map, vector_of({1.3}), vector_of({0.2}), 0.1) <= 1e-13);
  }
  SUBCASE("the hamiltonian form on the double pendulum with gauss2") {
    auto gauss = gauss2();
    ShootingDiscreteLagrangian map(plane, double_pendulum, rule, gauss, ShootingForm::hamiltonian, {});
    CHECK(checked_defect(map, vector_of({2.0, 2.5}), vector_of({0.3, -0.1}), 0.05) <= 1e-13);
  }
  SUBCASE("the type-2 form (SVIRK4) on the pendulum and with gauss2 on the double pendulum") {
    ShootingDiscreteLagrangian map(line, pendulum, rule, method, ShootingForm::type_2, {});
    CHECK(map.tangent_map_refusal().empty());
    CHECK(checked_defect(map, vector_of({1.3}), vector_of({0.2}), 0.1) <= 1e-13);
    auto gauss = gauss2();
    ShootingDiscreteLagrangian coupled(plane, double_pendulum, rule, gauss, ShootingForm::type_2, {});
    CHECK(checked_defect(coupled, vector_of({2.0, 2.5}), vector_of({0.3, -0.1}), 0.05) <= 1e-13);
  }
  SUBCASE("in passes: 8 pendulums, the shot's 16 variables over jets of 12 (all of Phi from pairs of blocks)") {
    FlatSpace eight(8);
    Pendulums<> pendulums(8);
    ShootingDiscreteLagrangian map(eight, pendulums, rule, method, ShootingForm::lagrangian, {});
    CHECK(map.tangent_map_refusal().empty());
    CHECK(checked_defect(map, Eigen::VectorXd::LinSpaced(8, 1.3, 0.2), Eigen::VectorXd::LinSpaced(8, 0.1, -0.3), 0.1) <=
          1e-13);
  }
  SUBCASE("the damped, driven oscillator: exact, and not symplectic") {
    MassOscillator oscillator;
    DampedDrive drive;
    ShootingDiscreteLagrangian map(line, oscillator, rule, method, ShootingForm::lagrangian, {}, {&drive});
    CHECK(checked_defect(map, vector_of({1.0}), vector_of({0.0}), 0.1, 0.7) > 5e-3);
  }
}

TEST_CASE("constructions without a tangent map say why, and step_with_tangent refuses them") {
  // The one-step construction with a constraint (q^2 - 1)/2 = 0 on R^1 that does not declare itself
  // quadratic: its tangent map would step jets through the projection, which takes quadratic
  // constraints only (tests/core/constrained_field.cpp has the one with a quadratic constraint).
  struct UnitPoint final : Constraint {
    Status bind(int, int) noexcept override { return nullptr; }
    int size() const noexcept override { return 1; }
    int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
      static constexpr int zero[1] = {0};
      *rows = zero;
      *cols = zero;
      return 1;
    }
    int hessian_pattern(const int** rows, const int** cols) const noexcept override { return jacobian_pattern(rows, cols); }
    Status evaluate(const double* q, double* g, double* G) noexcept override {
      if (g != nullptr) g[0] = 0.5 * (q[0] * q[0] - 1.0);
      if (G != nullptr) G[0] = q[0];
      return nullptr;
    }
    Status weighted_hessian(const double*, const double* lambda, double* values) noexcept override {
      values[0] = lambda[0];
      return nullptr;
    }
  } point;
  FlatSpace line(1);
  MassOscillator oscillator;
  HolonomicConstraints constraints({&point}, 1);
  auto method = rk4();
  OneStepHamiltonianMap projected(line, oscillator, method, {}, &constraints);
  CHECK(projected.tangent_map_refusal().find("quadratic constraints only") != std::string::npos);
  double q1[1], p1[1], image[2];
  const double q0[1] = {1.0}, p0[1] = {0.0}, direction[2] = {1, 0};
  CHECK_THROWS_AS(projected.step_with_tangent(q0, p0, 0.0, 0.1, q1, p1, 1, direction, image), std::logic_error);
}
