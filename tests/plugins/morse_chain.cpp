// The morse-chain plugin (a term-wise Lagrangian, varia/sdk/termwise_lagrangian.hpp) at 30
// particles, 60 degrees of freedom: L, gradient and Hessian equal to the hand-written formulas,
// a banded Hessian pattern, and Galerkin steps equal to those of the same chain written as one
// dense autodiff model; shooting on the chain, its step on the shot's adjoint (core/shot_adjoint.hpp).
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <chrono>
#include <memory>
#include <cmath>
#include <sstream>
#include <vector>

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

// The chain of MorseChainParameters written as one dense autodiff model, from morse_chain_state's
// state 3, under shooting rk4 + Simpson.
struct DenseChainShooting {
  MorseChainParameters p;
  varia::testing::DenseMorseChain dense{p};
  varia::testing::FlatSpace space{2 * p.particles};
  varia::testing::FixedRule rule = varia::testing::simpson();
  varia::sdk::RungeKutta method = varia::testing::rk4();
  VectorXd q, momentum;

  explicit DenseChainShooting(MorseChainParameters parameters) : p(parameters) {
    VectorXd v;
    varia::testing::morse_chain_state(p, 3, q, v);
    momentum = p.mass * v;
  }
  // The map in `form` whose jets hold `capacity` variables.
  std::unique_ptr<varia::ShootingDiscreteLagrangian> map(varia::ShootingForm form, int capacity = varia::kMaxJetVariables) {
    return std::make_unique<varia::ShootingDiscreteLagrangian>(space, dense, rule, method, form, varia::SolverOptions{},
                                                               std::vector<varia::Force*>{}, capacity);
  }
  // (q, p) after `steps` steps of h from the state.
  VectorXd run(varia::DiscreteHamiltonianMap& map, double h, int steps) {
    return varia::testing::run(map, q, momentum, h, steps);
  }
};

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

TEST_CASE("shooting on the 60-DOF morse chain (rk4 + Simpson, lagrangian form, the step on the shot's adjoint with "
          "the term-wise plugin's sparse Hessian): simplified Newton contracts, and the linear and angular momenta "
          "of the plane's rigid motions, which every Runge-Kutta method commutes with, are conserved to round-off") {
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
  const double h = 0.05;
  const int steps = 20;
  for (int k = 0; k < steps; ++k) {
    map.step(q.data(), momentum.data(), h, q1.data(), p1.data());
    q.swap(q1);
    momentum.swap(p1);
    // Each residual above round-off is at most a tenth of the one before (the contraction is of
    // the size (omega h)^2, shooting_solve.cpp).
    const auto& r = map.last_residuals();
    std::ostringstream residuals;
    for (double x : r) residuals << " " << x;
    CAPTURE(residuals.str());
    REQUIRE(r.size() >= 2);
    for (std::size_t i = 1; i < r.size(); ++i)
      if (r[i] > 1e-13) CHECK(r[i] <= 0.1 * r[i - 1]);
  }
  MESSAGE("60 DOF, rk4 + Simpson, h = " << h << ": Newton iterations per step " << map.solver_statistics().mean());
  const Eigen::Vector3d J = momenta(q, momentum);
  CAPTURE(J0.transpose());
  CAPTURE(J.transpose());
  CHECK((J - J0).lpNorm<Eigen::Infinity>() <= 1e-14 * (1.0 + J0.lpNorm<Eigen::Infinity>()));
}

// Where the jets hold all 2n numbers of x (n = 6, 12 jet variables) the step solves with the exact
// Jacobian from one pass of second-order jets; with a capacity of 4 the same step runs on the
// shot's adjoint (simplified Newton, shooting_solve.cpp). Both solve the same equations to
// round-off. At a step long enough that simplified Newton stops contracting, the adjoint path
// falls back to the exact Jacobian: its residuals then fall quadratically.
TEST_CASE("shooting on a dense chain of 6 DOF: the step on the shot's adjoint takes the exact Jacobian's steps to "
          "round-off in the lagrangian and hamiltonian forms and with a rule without end nodes, and falls back to it "
          "where it does not contract") {
  MorseChainParameters p;
  p.particles = 3;
  DenseChainShooting chain(p);
  for (auto form : {varia::ShootingForm::lagrangian, varia::ShootingForm::hamiltonian}) {
    CAPTURE(static_cast<int>(form));
    const auto exact = chain.map(form, 12), adjoint = chain.map(form, 4);
    const VectorXd a = chain.run(*exact, 0.1, 30), b = chain.run(*adjoint, 0.1, 30);
    MESSAGE("h = 0.1: Newton iterations per step, exact " << exact->solver_statistics().mean() << ", adjoint "
                                                          << adjoint->solver_statistics().mean());
    CHECK((a - b).lpNorm<Eigen::Infinity>() <= 1e-13 * (1.0 + a.lpNorm<Eigen::Infinity>()));
    CHECK((a.head(6) - chain.q).norm() > 0.05);  // the chain moved
    const double h = 1.2;
    const VectorXd c = chain.run(*exact, h, 1), d = chain.run(*adjoint, h, 1);
    CHECK((c - d).lpNorm<Eigen::Infinity>() <= 1e-12 * (1.0 + c.lpNorm<Eigen::Infinity>()));
    const auto& r = adjoint->last_residuals();
    std::ostringstream residuals;
    for (double x : r) residuals << " " << x;
    MESSAGE("h = " << h << ": the adjoint map's last residuals" << residuals.str());
    // Quadratic at the end, as only the exact Jacobian's iteration is: the last residual above
    // round-off is at most 10 times the square of the one before.
    std::size_t last = r.size() - 1;
    while (last > 0 && r[last] <= 1e-13) --last;
    REQUIRE(last >= 1);
    CHECK(r[last] <= 10 * r[last - 1] * r[last - 1]);
  }
  // A rule without nodes at the ends (the midpoint rule: the shot's ends carry zero weight).
  chain.rule = varia::testing::midpoint_rule();
  const auto exact = chain.map(varia::ShootingForm::lagrangian, 12);
  const auto adjoint = chain.map(varia::ShootingForm::lagrangian, 4);
  const VectorXd a = chain.run(*exact, 0.1, 30), b = chain.run(*adjoint, 0.1, 30);
  CHECK((a - b).lpNorm<Eigen::Infinity>() <= 1e-13 * (1.0 + a.lpNorm<Eigen::Infinity>()));
}

// The must-show of issue #39: the chain of 30 particles written as one dense autodiff model,
// shooting rk4 + Simpson (order 4) in both Type I forms, against Galerkin degree 2 with 3 Lobatto
// points (order 4) at a step 8 times smaller than the smallest here, whose own error (measured
// against the same at twice its step) is far below the errors fitted.
TEST_CASE("shooting rk4 + Simpson on a 60-DOF chain written as one dense autodiff model measures order 4 in the "
          "lagrangian and hamiltonian forms against a converged Galerkin reference") {
  MorseChainParameters p;
  const auto termwise = plugin_chain(p);
  DenseChainShooting chain(p);
  const double T = 0.8;
  const std::vector<double> hs = {0.1, 0.05, 0.025, 0.0125};
  const double h_reference = hs.back() / 8;
  const VectorXd reference = galerkin(*termwise, p, h_reference, std::lround(T / h_reference)).state;
  const VectorXd coarser = galerkin(*termwise, p, 2 * h_reference, std::lround(T / (2 * h_reference))).state;
  const double reference_error = (reference - coarser).lpNorm<Eigen::Infinity>();
  for (auto form : {varia::ShootingForm::lagrangian, varia::ShootingForm::hamiltonian}) {
    CAPTURE(static_cast<int>(form));
    std::vector<double> errors;
    for (double h : hs)
      errors.push_back((chain.run(*chain.map(form), h, std::lround(T / h)) - reference).lpNorm<Eigen::Infinity>());
    const double order = varia::testing::fitted_order(hs, errors, 0, 4);
    MESSAGE("60 DOF dense, form " << static_cast<int>(form) << ": errors " << errors[0] << " .. " << errors[3]
                                  << ", fitted order " << order << "; the reference's own error about "
                                  << reference_error);
    CHECK(std::abs(order - 4) <= 0.25);
    CHECK(reference_error <= 1e-2 * errors.back());
  }
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
