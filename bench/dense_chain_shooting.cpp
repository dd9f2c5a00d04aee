// Shooting on a chain written as one dense sdk::AutodiffLagrangian (the planar Morse chain of
// tests/sdk/morse_chain.hpp, N particles, 2N degrees of freedom; default 30: 60 DOF), against
// Galerkin of degree 2 with the 3-point Gauss-Lobatto rule on the same model: the time per step of
// each, their ratio, and the Newton iterations. Shooting is rk4 + Simpson in the lagrangian and the
// hamiltonian forms (issue #39 asks for at most 20x Galerkin's cost per step). Galerkin takes 20
// steps, shooting `steps` (default 1) after one untimed step. bench/README.md has the numbers.
//   build/bin/bench_dense_chain_shooting [N] [steps]
#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "tests/core/fixtures.hpp"
#include "tests/sdk/morse_chain.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/shooting.hpp"
#include "varia/core/trajectory.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

using Eigen::VectorXd;

struct Timing {
  double seconds_per_step, iterations;
};

// The time per step of `steps` steps of h from (q, p) by the trajectory driver, after one untimed
// step.
Timing time_steps(varia::DiscreteHamiltonianMap& map, const varia::SolverStatistics& statistics, const VectorXd& q,
                  const VectorXd& p, double h, int steps) {
  varia::Trajectory trajectory(map, q, p, 0.0, h);
  trajectory.step();
  const auto start = std::chrono::steady_clock::now();
  trajectory.advance(steps);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {seconds / steps, statistics.mean()};
}

}  // namespace

int main(int argc, char** argv) {
  varia::testing::MorseChainParameters p;
  p.particles = argc > 1 ? std::atoi(argv[1]) : 30;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 1;
  const int n = 2 * p.particles;
  const double h = 0.05;
  varia::testing::DenseMorseChain chain(p);
  varia::testing::FlatSpace space(n);
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 3, q, v);
  const VectorXd momentum = p.mass * v;

  auto lobatto = varia::testing::lobatto3();
  varia::GalerkinDiscreteLagrangian galerkin(space, chain, lobatto, varia::equispaced_control_times(2),
                                             varia::SolverOptions{});
  const Timing g = time_steps(galerkin, galerkin.solver_statistics(), q, momentum, h, 20);
  std::printf("%d DOF, dense autodiff model, h = %g\n", n, h);
  std::printf("%-34s %12.4e s a step, %.2f Newton iterations\n", "Galerkin degree 2, Lobatto 3", g.seconds_per_step,
              g.iterations);
  varia::sdk::RungeKutta rk4(varia::sdk::classic_rk4(), 4, false);
  for (auto [form, name] : {std::pair{varia::ShootingForm::lagrangian, "shooting rk4 + Simpson, lagrangian"},
                            std::pair{varia::ShootingForm::hamiltonian, "shooting rk4 + Simpson, hamiltonian"}}) {
    varia::ShootingDiscreteLagrangian shooting(space, chain, lobatto, rk4, form, varia::SolverOptions{});
    const Timing s = time_steps(shooting, shooting.solver_statistics(), q, momentum, h, steps);
    std::printf("%-34s %12.4e s a step, %.2f Newton iterations, %.0fx Galerkin\n", name, s.seconds_per_step,
                s.iterations, s.seconds_per_step / g.seconds_per_step);
  }
  return 0;
}
