// The shooting construction on SO(3) (paper, sec. 3 in the natural charts of sec. 2): jets in
// (eta, w0) with q^0 = q0 exp(eta), the Euler-Lagrange field on TSO(3), B = log(q1^{-1} R^n).
// Orders against the odeint reference of so3_reference.hpp; Crouch-Grossman is left-equivariant,
// so L_d is SO(3)-invariant for the free body and the spatial angular momentum R Pi is conserved
// (sec. 3, "Group-invariant shooting-based discrete Lagrangians").
#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/shooting_fixtures.hpp"
#include "core/so3_reference.hpp"
#include "varia/core/shooting.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

struct Composition {
  std::string name;
  std::shared_ptr<OneStepMethod> method;
  FixedRule rule;
  double order;
};

std::vector<Composition> compositions() {
  return {{"crouch-grossman 2 + trapezoid", crouch_grossman(2), trapezoid(), 2.0},
          {"crouch-grossman 3 + simpson", crouch_grossman(3), simpson(), 3.0},
          {"implicit midpoint (embedding) + trapezoid", std::make_shared<sdk::RungeKutta>(implicit_midpoint()),
           trapezoid(), 2.0}};
}

}  // namespace

TEST_CASE("shooting on SO(3): crouch-grossman 2 + trapezoid and implicit midpoint + trapezoid converge at "
          "order 2, crouch-grossman 3 + simpson at order 3 (free body and heavy top)") {
  Rotations group;
  for (bool top : {false, true}) {
    const Problem p = top ? heavy_top() : free_body();
    const double t_end = 2.0;
    const State exact = reference(p, t_end);
    for (Composition& c : compositions()) {
      std::vector<double> steps, errors;
      for (long n : {50, 100, 200, 400}) {
        ShootingDiscreteLagrangian map(group, const_cast<Top&>(p.top), c.rule, *c.method, ShootingForm::lagrangian,
                                       SolverOptions{});
        steps.push_back(t_end / n);
        errors.push_back(distance(integrate(map, p.start, t_end / n, n), exact));
        if (n == 400) MESSAGE(c.name << ": Newton iterations per step " << map.solver_statistics().mean());
      }
      // Fitted over h = 0.04 ... 0.005 (all four points: the errors are in the asymptotic range).
      const double order = fitted_order(steps, errors, 0, 4);
      MESSAGE(c.name << (top ? ", heavy top" : ", free body") << ": errors " << errors[0] << " ... " << errors[3]
                     << ", fitted order " << order);
      CHECK(order == doctest::Approx(c.order).epsilon(0.03));
    }
  }
}

TEST_CASE("shooting on SO(3) with crouch-grossman: the spatial angular momentum R Pi and R^T R = I hold to "
          "round-off over 10^4 steps of the free body") {
  Rotations group;
  Problem p = free_body();
  auto method = crouch_grossman(2);
  FixedRule rule = trapezoid();
  ShootingDiscreteLagrangian map(group, p.top, rule, *method, ShootingForm::lagrangian, SolverOptions{});
  const Vector3d pi0 = spatial_momentum(p.start);
  State y = p.start;
  double momentum = 0.0, orthogonality = 0.0;
  for (long k = 0; k < 10000; ++k) {
    y = integrate(map, y, 0.05, 1);
    momentum = std::max(momentum, (spatial_momentum(y) - pi0).norm());
    orthogonality = std::max(orthogonality, so3::orthogonality_error(so3::from_row_major(y.data())));
  }
  MESSAGE("10^4 steps of h = 0.05: max |R Pi - pi0| " << momentum << " (|pi0| = " << pi0.norm()
                                                      << "), max ||I - R^T R|| " << orthogonality
                                                      << ", Newton iterations per step " << map.solver_statistics().mean()
                                                      << " (max " << map.solver_statistics().max_iterations << ")");
  // Round-off accumulating without compensated summation (8.7e-13 measured; 2.7e-11 when the
  // chart's inverse used R0^T), against the O(1) change of a non-conserved component (next case).
  CHECK(momentum < 1e-11);
  CHECK(orthogonality < 1e-12);
  CHECK(map.solver_statistics().mean() <= 3.0);
}

TEST_CASE("shooting on SO(3): the heavy top's vertical spatial momentum e3 . R Pi is conserved, the horizontal "
          "part is not") {
  Rotations group;
  Problem p = heavy_top();
  auto method = crouch_grossman(3);
  FixedRule rule = simpson();
  ShootingDiscreteLagrangian map(group, p.top, rule, *method, ShootingForm::lagrangian, SolverOptions{});
  const Vector3d pi0 = spatial_momentum(p.start);
  State y = p.start;
  double vertical = 0.0, horizontal = 0.0;
  for (long k = 0; k < 2000; ++k) {
    y = integrate(map, y, 0.02, 1);
    const Vector3d change = spatial_momentum(y) - pi0;
    vertical = std::max(vertical, std::abs(change(2)));
    horizontal = std::max(horizontal, change.head<2>().norm());
  }
  MESSAGE("2000 steps of h = 0.02: vertical " << vertical << ", horizontal " << horizontal);
  CHECK(vertical < 1e-10);
  CHECK(horizontal > 0.1);
}

TEST_CASE("shooting on SO(3): L_d's D1 and D2 at (q0, q1) of a step are -p0 and p1 (left-trivialized body "
          "momenta), through the chart at q1") {
  Rotations group;
  Problem p = heavy_top();
  for (Composition& c : compositions()) {
    ShootingDiscreteLagrangian map(group, p.top, c.rule, *c.method, ShootingForm::lagrangian, SolverOptions{});
    State next;
    const double h = 0.1;  // a turn of about 0.2: the chart's log away from its series branch
    map.step(p.start.data(), p.start.data() + 9, h, next.data(), next.data() + 9);
    double Ld = 0.0;
    Vector3d D1, D2;
    map.evaluate(p.start.data(), next.data(), h, &Ld, D1.data(), D2.data());
    CAPTURE(c.name);
    CHECK((D1 + Vector3d(p.start[9], p.start[10], p.start[11])).norm() < 1e-12);
    CHECK((D2 - Vector3d(next[9], next[10], next[11])).norm() < 1e-12);
  }
}

TEST_CASE("shooting on SO(3) refuses the type-2 form") {
  Rotations group;
  Problem p = free_body();
  auto method = crouch_grossman(2);
  FixedRule rule = trapezoid();
  CHECK_THROWS_AS(ShootingDiscreteLagrangian(group, p.top, rule, *method, ShootingForm::type_2, SolverOptions{}),
                  std::invalid_argument);
}

TEST_CASE("shooting on SO(3) in passes (jets of 2 and 4 variables instead of one pass of 6, as on a group of "
          "dimension above 6): the trajectory, L_d and its derivatives are the one-pass ones to round-off") {
  Rotations group;
  Problem p = heavy_top();
  for (Composition& c : compositions()) {
    CAPTURE(c.name);
    ShootingDiscreteLagrangian one_pass(group, p.top, c.rule, *c.method, ShootingForm::lagrangian, SolverOptions{});
    const State reference = integrate(one_pass, p.start, 0.05, 20);
    for (int capacity : {2, 4}) {
      CAPTURE(capacity);
      ShootingDiscreteLagrangian passes(group, p.top, c.rule, *c.method, ShootingForm::lagrangian, SolverOptions{},
                                        {}, capacity);
      const State state = integrate(passes, p.start, 0.05, 20);
      CHECK(distance(state, reference) < 1e-13);
      CHECK(passes.solver_statistics().max_iterations <= one_pass.solver_statistics().max_iterations);
      const State next = integrate(one_pass, p.start, 0.1, 1);
      double a = 0.0, b = 0.0;
      Vector3d a1, a2, b1, b2;
      one_pass.evaluate(p.start.data(), next.data(), 0.1, &a, a1.data(), a2.data());
      passes.evaluate(p.start.data(), next.data(), 0.1, &b, b1.data(), b2.data());
      CHECK(std::abs(a - b) < 1e-14);
      CHECK((a1 - b1).norm() < 1e-13);
      CHECK((a2 - b2).norm() < 1e-13);
    }
  }
}
