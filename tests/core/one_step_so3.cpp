// The comparison methods of the paper's Figure 1 (sec. 2, "Numerical comparisons") as one-step
// constructions on SO(3): explicit midpoint (RK) and implicit midpoint (SRK) in the embedding
// R^9 x R^3, Crouch-Grossman (LGM, the plugin) on the group, against the LGVI.
#include <doctest/doctest.h>

#include <filesystem>
#include <memory>

#include "core/shooting_fixtures.hpp"
#include "core/so3_reference.hpp"
#include "varia/core/lie_verlet.hpp"
#include "varia/core/one_step_map.hpp"
#include "varia/core/lie_group_field.hpp"
#include "varia/sdk/conformance/loader.hpp"
#include "varia/sdk/runge_kutta.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

// The largest ||I - R^T R|| and |E - E0| over `steps` steps of h from p.start.
struct Drift {
  double orthogonality = 0.0, energy = 0.0;
  double energy_first_half = 0.0;  // the largest |E - E0| over the first half of the steps
};
Drift drift(DiscreteHamiltonianMap& map, const Problem& p, double h, long steps) {
  const auto energy = [&](const State& y) {
    const Vector3d Pi(y[9], y[10], y[11]);
    return 0.5 * Pi.dot(Pi.cwiseQuotient(p.top.J)) + p.top.w * p.top.chi.dot(
                                                             so3::from_row_major(y.data()).row(2));
  };
  Drift d;
  State y = p.start;
  for (long k = 0; k < steps; ++k) {
    y = integrate(map, y, h, 1);
    d.orthogonality = std::max(d.orthogonality, so3::orthogonality_error(so3::from_row_major(y.data())));
    d.energy = std::max(d.energy, std::abs(energy(y) - energy(p.start)));
    if (k < steps / 2) d.energy_first_half = d.energy;
  }
  return d;
}

}  // namespace

// The field's Jacobian comes from the field at jets; it is checked against central differences
// here, in the test only.
TEST_CASE("the Euler-Poincare field's Jacobian on SO(3) is its exact derivative") {
  Problem p = heavy_top();
  Rotations group;
  LagrangianEvaluator evaluator(p.top);
  LieGroupField field(group, evaluator);
  State y = p.start;
  for (int i = 0; i < 3; ++i) y[9 + i] /= p.top.J(i);  // (R, Omega)
  y[4] += 0.01;                                        // off the group, as RK leaves it
  Eigen::Matrix<double, 12, 12> D;
  double f[12];
  REQUIRE(field.jacobian(y.data(), f, D.data()) == nullptr);
  const double delta = 1e-6;
  for (int c = 0; c < 12; ++c) {
    State plus = y, minus = y;
    plus[c] += delta;
    minus[c] -= delta;
    double f_plus[12], f_minus[12];
    REQUIRE(field.eval(plus.data(), f_plus) == nullptr);
    REQUIRE(field.eval(minus.data(), f_minus) == nullptr);
    for (int r = 0; r < 12; ++r) {
      CAPTURE(r);
      CAPTURE(c);
      CHECK(D(r, c) == doctest::Approx((f_plus[r] - f_minus[r]) / (2 * delta)).epsilon(1e-8));
    }
  }
}

TEST_CASE("RK and SRK in the embedding are of order 2 on SO(3), Crouch-Grossman of order 2 and 3") {
  Rotations group;
  for (bool top : {false, true}) {
    Problem p = top ? heavy_top() : free_body();
    const auto check = [&](const std::string& name, int order, auto make_method) {
      std::shared_ptr<OneStepMethod> method;
      const auto orders = observed_orders(p, [&] {
        method = make_method();
        return std::make_unique<OneStepHamiltonianMap>(group, p.top, *method,
                                                       SolverOptions{});
      }, 2.0);
      for (double observed : orders) {
        MESSAGE(name << (top ? " heavy top" : " free body") << ": observed order " << observed);
        CHECK(observed == doctest::Approx(order).epsilon(0.03));
      }
    };
    check("RK", 2, [] { return std::make_shared<sdk::RungeKutta>(explicit_midpoint()); });
    check("SRK", 2, [] { return std::make_shared<sdk::RungeKutta>(implicit_midpoint()); });
    check("LGM order 2", 2, [] { return crouch_grossman(2); });
    check("LGM order 3", 3, [] { return crouch_grossman(3); });
  }
}

// Figure 1 (b), (c): the Lie group methods stay on SO(3) to round-off, SRK to its solver's
// tolerance (R R^T is a quadratic invariant of the embedded equations), RK leaves it; the energy
// of the variational LGVI stays bounded, RK's drifts.
TEST_CASE("Figure 1: orthogonality at round-off for LGVI and LGM, drifting for RK, energy") {
  Problem p = heavy_top();
  Rotations group;
  const double h = 0.05;
  const long steps = 20000;  // t = 1000
  auto rk = explicit_midpoint(), srk = implicit_midpoint();
  auto lgm = crouch_grossman(2);
  LieGroupVelocityVerlet lgvi(group, p.top, LieVerletSolver::cayley, {});
  OneStepHamiltonianMap rk_map(group, p.top, rk, {}), srk_map(group, p.top, srk, {}),
      lgm_map(group, p.top, *lgm, {});
  const Drift d_lgvi = drift(lgvi, p, h, steps), d_rk = drift(rk_map, p, h, steps),
              d_srk = drift(srk_map, p, h, steps), d_lgm = drift(lgm_map, p, h, steps);
  MESSAGE("max ||I - R^T R||: LGVI " << d_lgvi.orthogonality << ", RK " << d_rk.orthogonality
                                     << ", SRK " << d_srk.orthogonality << ", LGM " << d_lgm.orthogonality);
  MESSAGE("max |E - E0|: LGVI " << d_lgvi.energy << ", RK " << d_rk.energy << ", SRK "
                                << d_srk.energy << ", LGM " << d_lgm.energy);
  CHECK(d_lgvi.orthogonality < 1e-14);
  CHECK(d_lgm.orthogonality < 1e-13);
  CHECK(d_srk.orthogonality < 1e-12);
  CHECK(d_rk.orthogonality > 1e-4);  // where it should not hold, it does not
  // LGVI's energy error stays bounded, RK's grows with t; SRK conserves E exactly, a quadratic
  // invariant of the embedded heavy-top equations (E = 1/2 Omega . J Omega + w chi . R^T e3).
  MESSAGE("max |E - E0| over the first half: LGVI " << d_lgvi.energy_first_half << ", RK "
                                                    << d_rk.energy_first_half);
  CHECK(d_lgvi.energy < 1.2 * d_lgvi.energy_first_half);
  CHECK(d_rk.energy > 1.5 * d_rk.energy_first_half);
  CHECK(d_srk.energy < 1e-11);
}

TEST_CASE("the one-step construction refuses a manifold that is neither R^n nor SO(3)-shaped") {
  struct Sphere : FlatSpace {
    Sphere() : FlatSpace(3) {}
    int point_size() const noexcept override { return 3; }
    int dim() const noexcept override { return 2; }
    ManifoldStructure structure() const noexcept override { return ManifoldStructure::homogeneous_space; }
  } sphere;
  Top top(Vector3d(1, 2, 3), 0.0, Vector3d::Zero());
  auto rk = explicit_midpoint();
  CHECK_THROWS_AS(OneStepHamiltonianMap(sphere, top, rk, {}), std::invalid_argument);
}
