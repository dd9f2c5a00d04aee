// "The stepping loop allocates nothing per step": every heap allocation of this process is counted
// (malloc is interposed: Eigen's dynamic matrices and operator new both end there), and the
// Galerkin maps' steps are run between two readings of the count, after a first step has sized
// the workspace. One case where it must not hold: resizing a dynamic vector is counted.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/constraint_fixtures.hpp"
#include "core/fixtures.hpp"
#include "core/shooting_fixtures.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/galerkin_sphere.hpp"
#include "varia/core/one_step_map.hpp"
#include "varia/core/shooting.hpp"
#include "varia/sdk/groups/so3.hpp"

extern "C" void* __libc_malloc(std::size_t size);  // glibc's own malloc, always exported
extern "C" void* __libc_calloc(std::size_t count, std::size_t size);
extern "C" void* __libc_realloc(void* pointer, std::size_t size);

namespace {
long allocations = 0;
}  // namespace

extern "C" void* malloc(std::size_t size) {
  ++allocations;
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t count, std::size_t size) {
  ++allocations;
  return __libc_calloc(count, size);
}
extern "C" void* realloc(void* pointer, std::size_t size) {
  ++allocations;
  return __libc_realloc(pointer, size);
}

using namespace varia;
using namespace varia::testing;

namespace {

// The allocations made by f().
template <class F>
long allocations_of(F&& f) {
  const long before = allocations;
  f();
  return allocations - before;
}

// `steps` steps of h by step() from (q, p), after one step that sizes everything; then, when
// `advanced`, as many by advance().
long allocations_of_stepping(DiscreteHamiltonianMap& map, Eigen::VectorXd q, Eigen::VectorXd p, double h, int steps,
                             bool advanced = false) {
  Eigen::VectorXd q1(q.size()), p1(p.size());
  map.step(q.data(), p.data(), h, q1.data(), p1.data());
  return allocations_of([&] {
    for (int k = 0; k < steps; ++k) {
      map.step(q1.data(), p1.data(), h, q.data(), p.data());
      q.swap(q1);
      p.swap(p1);
    }
    if (advanced) map.advance(q.data(), p.data(), h, steps, q1.data(), p1.data());
  });
}

// 50 steps by step() and 50 by advance() on R^n.
long allocations_of_steps(GalerkinDiscreteLagrangian& map, int n) {
  return allocations_of_stepping(map, Eigen::VectorXd::LinSpaced(n, 1.3, 0.2), Eigen::VectorXd::Zero(n), 0.1, 50, true);
}

}  // namespace

TEST_CASE("allocations are counted: resizing a dynamic vector allocates") {
  Eigen::VectorXd v;
  CHECK(allocations_of([&] { v.resize(1000); }) >= 1);
}

TEST_CASE("one-step rk4 and gauss with a constraint (the index-1 field, then the projection) allocate nothing per step, and implicit methods take quadratic constraints only") {
  SphericalPendulum s;
  for (sdk::RungeKutta method : {rk4(), gauss2()}) {
    OneStepHamiltonianMap map(s.space, s.mass, method, SolverOptions{}, &s.constraints);
    CHECK(allocations_of_stepping(map, s.q, s.p, 0.01, 50) == 0);
  }
  s.sphere.declared_quadratic = false;
  HolonomicConstraints undeclared({&s.sphere}, 3);
  sdk::RungeKutta explicit_method = rk4(), implicit_method = gauss2();
  CHECK_NOTHROW(OneStepHamiltonianMap(s.space, s.mass, explicit_method, SolverOptions{}, &undeclared));
  CHECK_THROWS_WITH_AS(OneStepHamiltonianMap(s.space, s.mass, implicit_method, SolverOptions{}, &undeclared),
                       doctest::Contains("explicit Runge-Kutta methods only"), std::invalid_argument);
}

TEST_CASE("galerkin with a constraint (degree 1 and 2, Lobatto points) allocates nothing per step: the bordered "
          "Newton system and the momentum's projection are small, factorized by a dense LU sized once") {
  SphericalPendulum s;
  auto trapezoid_rule = trapezoid();
  auto lobatto = lobatto3();
  for (int degree : {1, 2}) {
    CAPTURE(degree);
    GalerkinDiscreteLagrangian map(s.space, s.mass, degree == 1 ? static_cast<Quadrature&>(trapezoid_rule) : lobatto,
                                   equispaced_control_times(degree), {}, {}, &s.constraints);
    CHECK(allocations_of_stepping(map, s.q, s.p, 0.01, 50) == 0);
    CHECK(map.solver_statistics().iterations > 50);
  }
}

TEST_CASE("galerkin in the natural chart of S2 allocates nothing per step: Newton at jets of 4 variables, the "
          "momentum's projection") {
  SphericalPendulum s;
  auto lobatto = lobatto3();
  SphereGalerkinMap map(s.mass, lobatto, equispaced_control_times(2), {}, s.constraints);
  CHECK(allocations_of_stepping(map, s.q, s.p, 0.01, 50) == 0);
  CHECK(map.solver_statistics().iterations > 50);
}

TEST_CASE("shooting rk4 + simpson with a constraint allocates nothing per step, and takes quadratic constraints only") {
  FlatSpace space(3);
  FallingMass mass;
  UnitSphere sphere;
  HolonomicConstraints constraints({&sphere}, 3);
  sdk::RungeKutta method = rk4();
  auto rule = simpson();
  ShootingDiscreteLagrangian map(space, mass, rule, method, ShootingForm::lagrangian, {}, {}, kMaxJetVariables,
                                 &constraints);
  const Eigen::VectorXd q = (Eigen::VectorXd(3) << std::sin(1.0), 0.0, -std::cos(1.0)).finished();
  const Eigen::VectorXd p = (Eigen::VectorXd(3) << 0.0, 2.5, 0.0).finished();
  CHECK(allocations_of_stepping(map, q, p, 0.01, 50) == 0);
  sphere.declared_quadratic = false;
  HolonomicConstraints undeclared({&sphere}, 3);
  CHECK_THROWS_WITH_AS(ShootingDiscreteLagrangian(space, mass, rule, method, ShootingForm::lagrangian, {}, {},
                                                  kMaxJetVariables, &undeclared),
                       doctest::Contains("quadratic constraints only"), std::invalid_argument);
}

// The same pendulums not declaring their mass matrix: Newton with the exact Jacobian.
struct UndeclaredPendulums : Pendulums<> {
  using Pendulums<>::Pendulums;
  bool constant_mass_matrix(double*) const noexcept override { return false; }
};

TEST_CASE("galerkin steps allocate nothing: explicit form, simplified Newton and Newton (n = 1, 5)") {
  auto trapezoid_rule = trapezoid();
  auto lobatto = lobatto3();
  for (int n : {1, 5}) {
    CAPTURE(n);
    FlatSpace space(n);
    Pendulums explicit_form(n);
    GalerkinDiscreteLagrangian verlet(space, explicit_form, trapezoid_rule, equispaced_control_times(1), {});
    CHECK(allocations_of_steps(verlet, n) == 0);
    Pendulums simplified_form(n);
    GalerkinDiscreteLagrangian simplified(space, simplified_form, lobatto, equispaced_control_times(2), {});
    CHECK(allocations_of_steps(simplified, n) == 0);
    UndeclaredPendulums newton_form(n);
    GalerkinDiscreteLagrangian galerkin(space, newton_form, lobatto, equispaced_control_times(2), {});
    CHECK(allocations_of_steps(galerkin, n) == 0);
    CHECK(galerkin.evaluations().hessian > 100);
  }
}

TEST_CASE("galerkin's explicit form for a sparse Lagrangian allocates nothing per step") {
  const int n = 5;
  FlatSpace space(n);
  SparseChain chain(n, true);
  auto trapezoid_rule = trapezoid();
  GalerkinDiscreteLagrangian verlet(space, chain, trapezoid_rule, equispaced_control_times(1), {});
  CHECK(allocations_of_steps(verlet, n) == 0);
  CHECK(verlet.solver_statistics().max_iterations == 0);
}

TEST_CASE("galerkin's node iteration for a sparse Lagrangian (its diagonal mass matrix) allocates nothing per step") {
  const int n = 5;
  FlatSpace space(n);
  SparseChain chain(n, true);
  auto rule = lobatto3();
  GalerkinDiscreteLagrangian galerkin(space, chain, rule, equispaced_control_times(2), {});
  CHECK(allocations_of_steps(galerkin, n) == 0);
  CHECK(galerkin.evaluations().hessian == 1);  // M read once off the Hessian; then gradients only
  CHECK(galerkin.solver_statistics().iterations > 0);
}

// SO(3) through the SDK's generic adapter (no tuned chart): each simplified Newton iteration asks
// the chart for first derivatives only, at first-order duals on the stack.
class AdapterRotations final : public sdk::LieGroupManifold<sdk::groups::Rotations> {
 public:
  bool contains(const double*, char*, int) noexcept override { return true; }
};

TEST_CASE("lie group galerkin steps allocate nothing through the sdk's generic chart (first-order duals)") {
  AdapterRotations group;
  Top top(Eigen::Vector3d(1, 2, 3), 1.0, Eigen::Vector3d(0, 0, 0.5));
  auto rule = lobatto3();
  LieGroupGalerkinDiscreteLagrangian map(group, top, rule, equispaced_control_times(2), {});
  Eigen::VectorXd R(9), p(3);
  R << 1, 0, 0, 0, 1, 0, 0, 0, 1;
  p << 0.4, 1.6, -1.8;
  CHECK(allocations_of_stepping(map, R, p, 0.05, 50) == 0);
  CHECK(map.solver_statistics().iterations > 100);
}

TEST_CASE("shooting steps with a configuration-dependent mass matrix allocate nothing: the lagrangian form (the "
          "acceleration from L's Hessian at jets, the implicit stages' Jacobian from it) and the hamiltonian form (the "
          "inverse Legendre transform at jets, which allocated 66 times a step through PartialPivLU::inverse)") {
  Pendulum pendulum;  // declares no mass matrix
  FlatSpace space(1);
  auto rule = lobatto3();
  for (ShootingForm form : {ShootingForm::lagrangian, ShootingForm::hamiltonian})
    for (bool implicit : {false, true}) {
      CAPTURE(form == ShootingForm::lagrangian);
      CAPTURE(implicit);
      sdk::RungeKutta method = implicit ? gauss2() : rk4();
      ShootingDiscreteLagrangian map(space, pendulum, rule, method, form, {});
      CHECK(allocations_of_stepping(map, Eigen::VectorXd::Constant(1, 1.3), Eigen::VectorXd::Constant(1, 0.2), 0.1,
                                    50) == 0);
    }
}

TEST_CASE("shooting steps in passes (R^8, jets of 16 variables over the 12 a jet holds: the sensitivities in 2 + 5 "
          "passes) allocate nothing, explicit and implicit") {
  Pendulums pendulums(8);  // declares its constant mass matrix
  FlatSpace space(8);
  auto rule = lobatto3();
  for (bool implicit : {false, true}) {
    CAPTURE(implicit);
    sdk::RungeKutta method = implicit ? gauss2() : rk4();
    ShootingDiscreteLagrangian map(space, pendulums, rule, method, ShootingForm::lagrangian, {});
    CHECK(allocations_of_stepping(map, Eigen::VectorXd::LinSpaced(8, 1.3, 0.2), Eigen::VectorXd::Zero(8), 0.1, 10) ==
          0);
  }
}

// `steps` steps with the tangent map applied to one direction (a run observing megno), after one
// that sizes the workspace.
long allocations_of_tangent_steps(DiscreteHamiltonianMap& map, Eigen::VectorXd q, Eigen::VectorXd p, double h,
                                  int steps) {
  Eigen::VectorXd q1(q.size()), p1(p.size()), w = Eigen::VectorXd::Ones(2 * q.size()), w1(w.size());
  map.step_with_tangent(q.data(), p.data(), 0.0, h, q1.data(), p1.data(), 1, w.data(), w1.data());
  return allocations_of([&] {
    for (int k = 0; k < steps; ++k) {
      map.step_with_tangent(q1.data(), p1.data(), k * h, h, q.data(), p.data(), 1, w1.data(), w.data());
      q.swap(q1);
      p.swap(p1);
      w.swap(w1);
    }
  });
}

TEST_CASE("steps with the tangent map allocate nothing: galerkin (Newton, the node iteration), shooting (SVIRK4), "
          "one-step (gauss2)") {
  FlatSpace space(2);
  const Eigen::VectorXd q = Eigen::Vector2d(1.3, 0.4), p = Eigen::Vector2d(0.1, -0.2);
  auto lobatto = lobatto3();
  UndeclaredPendulums undeclared(2);
  GalerkinDiscreteLagrangian newton(space, undeclared, lobatto, equispaced_control_times(2), {});
  CHECK(allocations_of_tangent_steps(newton, q, p, 0.1, 20) == 0);
  Pendulums declared(2);
  GalerkinDiscreteLagrangian nodes(space, declared, lobatto, equispaced_control_times(2), {});
  CHECK(allocations_of_tangent_steps(nodes, q, p, 0.1, 20) == 0);
  auto method = rk4();
  ShootingDiscreteLagrangian shooting(space, declared, lobatto, method, ShootingForm::lagrangian, {});
  CHECK(allocations_of_tangent_steps(shooting, q, p, 0.1, 20) == 0);
  auto gauss = gauss2();
  OneStepHamiltonianMap one_step(space, declared, gauss, {});
  CHECK(allocations_of_tangent_steps(one_step, q, p, 0.1, 20) == 0);
}
