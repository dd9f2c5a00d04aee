// The morse-chain plugin (a term-wise Lagrangian, varia/sdk/termwise_lagrangian.hpp) at 30
// particles, 60 degrees of freedom: L, gradient and Hessian equal to the hand-written formulas,
// a banded Hessian pattern, and Galerkin steps equal to those of the same chain written as one
// dense autodiff model, with Newton converging quadratically.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <chrono>
#include <sstream>

#include "../core/fixtures.hpp"
#include "../core/shooting_fixtures.hpp"
#include "../sdk/morse_chain.hpp"
#include "load_plugin.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/shooting.hpp"
#include "varia/sdk/conformance/lagrangian.hpp"

namespace {

using varia::test::rn;

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Json = nlohmann::json;
using varia::testing::MorseChainParameters;

std::shared_ptr<varia::Lagrangian> plugin_chain(const MorseChainParameters& p) {
  return varia::test::load_plugin("lagrangian", "morse_chain")
      .create<varia::Lagrangian>({{"mass", p.mass}, {"depth", p.depth}, {"range", p.range}, {"rest_length", p.rest_length}},
                                 rn(2 * p.particles));
}

// Galerkin of degree 2 with the 3-point Gauss-Lobatto rule (order 4) from the chain's state:
// `steps` steps of h; returns (q, p) at the end and the wall time per step.
struct Run {
  VectorXd state;
  double seconds_per_step;
  double newton_mean;
  std::vector<double> last_residuals;
};
Run galerkin(varia::Lagrangian& lagrangian, const MorseChainParameters& p, double h, int steps) {
  const int n = 2 * p.particles;
  varia::testing::FlatSpace space(n);
  auto rule = varia::testing::lobatto3();
  varia::GalerkinDiscreteLagrangian map(space, lagrangian, rule, varia::equispaced_control_times(2),
                                        varia::SolverOptions{});
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 3, q, v);
  VectorXd momentum = p.mass * v, q1(n), p1(n);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    map.step(q.data(), momentum.data(), h, q1.data(), p1.data());
    q.swap(q1);
    momentum.swap(p1);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  VectorXd state(2 * n);
  state << q, momentum;
  return {state, seconds / steps, map.solver_statistics().mean(), map.last_residuals()};
}

}  // namespace

TEST_CASE("morse-chain at 30 particles (60 DOF) gives L, the gradient and the Hessian of the hand-written "
          "formulas, and a banded Hessian pattern") {
  MorseChainParameters p;
  p.depth = 1.7;
  p.range = 1.3;
  p.mass = 0.8;
  const auto chain = plugin_chain(p);
  REQUIRE(chain->position_size() == 60);
  const varia::testing::MorseChainFormula formula{p};
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 1, q, v);
  const auto e = varia::sdk::conformance::evaluate(*chain, q, v);
  const VectorXd g = formula.gradient(q, v);
  const MatrixXd H = formula.hessian(q);
  CHECK(e.value == doctest::Approx(formula.value(q, v)).epsilon(1e-15));
  CHECK((e.gradient - g).lpNorm<Eigen::Infinity>() <= 1e-15 * g.lpNorm<Eigen::Infinity>());
  CHECK((e.hessian - H).lpNorm<Eigen::Infinity>() <= 1e-15 * H.lpNorm<Eigen::Infinity>());

  // The pattern: the mass diagonal, and the 2 x 2 blocks of each particle with itself and its
  // neighbours (30 + 2 x 29 blocks of 4): 60 + 352 entries.
  const int *rows = nullptr, *cols = nullptr;
  const int entries = chain->hessian_pattern(&rows, &cols);
  CHECK(entries == 60 + 4 * (30 + 2 * 29));
  bool banded = true;
  for (int k = 0; k < entries; ++k) {
    const bool velocity = rows[k] >= 60;
    banded = banded && (velocity ? rows[k] == cols[k] : cols[k] < 60 && std::abs(rows[k] / 2 - cols[k] / 2) <= 1);
  }
  CHECK(banded);
}

TEST_CASE("Galerkin on the 60-DOF morse chain: the term-wise plugin and the dense model take the same steps, "
          "by the node iteration (a constant mass matrix), which contracts") {
  MorseChainParameters p;
  const auto chain = plugin_chain(p);
  varia::testing::DenseMorseChain dense(p);
  const int steps = 20;
  const double h = 0.05;
  const Run termwise = galerkin(*chain, p, h, steps);
  const Run one_model = galerkin(dense, p, h, steps);
  MESSAGE("60 DOF, degree 2, Lobatto 3, h = " << h << ": iterations per step " << termwise.newton_mean
                                              << "; time per step: term-wise " << 1e6 * termwise.seconds_per_step
                                              << " us, dense " << 1e6 * one_model.seconds_per_step << " us");
  CHECK((termwise.state - one_model.state).lpNorm<Eigen::Infinity>() <= 1e-12);
  // The fixed-point iteration in the nodes' positions (relative residuals) contracts: each residual
  // above round-off is at most a tenth of the one before (theta ~ h^2 times the bonds' stiffness).
  const auto& r = termwise.last_residuals;
  std::ostringstream residuals;
  for (double x : r) residuals << " " << x;
  MESSAGE("the last step's residuals:" << residuals.str());
  REQUIRE(r.size() >= 2);
  for (std::size_t k = 1; k < r.size(); ++k)
    if (r[k] > 1e-13) CHECK(r[k] <= 0.1 * r[k - 1]);
}

TEST_CASE("shooting on the 60-DOF morse chain (rk4 + Simpson, lagrangian form, the sensitivities in passes of "
          "12 jet variables): Newton converges quadratically, and the linear and angular momenta of the plane's "
          "rigid motions, which every Runge-Kutta method commutes with, are conserved to round-off (issue #18)") {
  MorseChainParameters p;
  const auto chain = plugin_chain(p);
  const int n = 2 * p.particles;
  varia::testing::FlatSpace space(n);
  auto rule = varia::testing::simpson();
  auto method = varia::testing::rk4();
  varia::ShootingDiscreteLagrangian map(space, *chain, rule, method, varia::ShootingForm::lagrangian, {});
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 3, q, v);
  VectorXd momentum = p.mass * v, q1(n), p1(n);
  // The momenta of translations along x and y and of rotations about the origin.
  const auto momenta = [&](const VectorXd& x, const VectorXd& m) {
    Eigen::Vector3d J = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; i += 2) J += Eigen::Vector3d(m[i], m[i + 1], x[i] * m[i + 1] - x[i + 1] * m[i]);
    return J;
  };
  const Eigen::Vector3d J0 = momenta(q, momentum);
  const double h = 0.2;  // long enough steps for three Newton iterations
  const auto start = std::chrono::steady_clock::now();
  const int steps = 3;
  for (int k = 0; k < steps; ++k) {
    map.step(q.data(), momentum.data(), h, q1.data(), p1.data());
    q.swap(q1);
    momentum.swap(p1);
    const auto& r = map.last_residuals();
    std::ostringstream residuals;
    for (double x : r) residuals << " " << x;
    MESSAGE("step " << k << ": Newton residuals" << residuals.str());
    REQUIRE(r.size() >= 3);
    for (std::size_t i = 1; i < r.size(); ++i)
      if (r[i] > 1e-13) CHECK(r[i] <= 10 * r[i - 1] * r[i - 1]);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  MESSAGE("60 DOF, rk4 + Simpson, h = " << h << ": Newton iterations per step " << map.solver_statistics().mean()
                                        << "; time per step " << seconds / steps << " s");
  const Eigen::Vector3d J = momenta(q, momentum);
  CAPTURE(J0.transpose());
  CAPTURE(J.transpose());
  CHECK((J - J0).lpNorm<Eigen::Infinity>() <= 1e-14 * (1.0 + J0.lpNorm<Eigen::Infinity>()));
}

TEST_CASE("shooting on a chain written as one dense autodiff model above the SDK's stack size (5 particles, 20 "
          "numbers, its gradient at jets over the workspace's dual numbers, the sensitivities in passes): the "
          "steps of the term-wise plugin, in the lagrangian and hamiltonian forms") {
  MorseChainParameters p;
  p.particles = 5;
  const auto chain = plugin_chain(p);
  varia::testing::DenseMorseChain dense(p);
  const int n = 2 * p.particles;
  varia::testing::FlatSpace space(n);
  auto rule = varia::testing::simpson();
  auto method = varia::testing::rk4();
  for (auto form : {varia::ShootingForm::lagrangian, varia::ShootingForm::hamiltonian}) {
    varia::ShootingDiscreteLagrangian termwise(space, *chain, rule, method, form, {});
    varia::ShootingDiscreteLagrangian one_model(space, dense, rule, method, form, {});
    VectorXd q, v;
    varia::testing::morse_chain_state(p, 3, q, v);
    const VectorXd momentum = p.mass * v;
    const VectorXd a = varia::testing::run(termwise, q, momentum, 0.1, 5);
    const VectorXd b = varia::testing::run(one_model, q, momentum, 0.1, 5);
    CAPTURE(static_cast<int>(form));
    CHECK((a - b).lpNorm<Eigen::Infinity>() <= 1e-12);
    CHECK((a.head(n) - q).norm() > 0.05);  // the chain moved
  }
}
