// varia against boost::odeint on the planar pendulum q'' = -sin q (m = l = g = 1, so p = v),
// released from rest at q = 1.3, in one process (a benchmark, not a test). Prints Markdown tables:
//   1. Stormer-Verlet at equal steps: varia's Galerkin degree 1 with the trapezoid rule (its
//      explicit form, paper sec. 2 example) against odeint's velocity_verlet: time per step,
//      force evaluations per step, and the difference of the two final states.
//   2. Time to a global error of 1e-10 and 1e-12 at T = 100 (max norm of (q, p) against the
//      pendulum plugin's exact solution): each method at the fewest steps that reach it; varia's
//      best Galerkin composition against symplectic_rkn_sb3a_mclachlan, and against
//      runge_kutta_dopri5 with the tolerance tuned to the same error.
// Times are the fastest of repeated runs of the stepping loop alone (support.hpp: fastest).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <chrono>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support.hpp"

namespace {

namespace odeint = boost::numeric::odeint;
using namespace varia::bench;
using State2 = std::array<double, 2>;

// ---- odeint -----------------------------------------------------------------------------------

Measure run_mclachlan(long steps, const Exact& exact, bool timed) {
  long calls = 0;
  State1 q{}, p{};
  const auto run = [&] {
    odeint::symplectic_rkn_sb3a_mclachlan<State1> stepper;
    q = {kQ0};
    p = {0.0};
    const auto velocity = [](const State1& momentum, State1& dqdt) { dqdt = momentum; };
    const double h = kT / steps;
    return seconds_of([&] {
      for (long k = 0; k < steps; ++k)
        stepper.do_step(std::make_pair(velocity, PendulumForce{&calls}), std::make_pair(std::ref(q), std::ref(p)), k * h, h);
    });
  };
  double seconds = run();
  const double per_step = static_cast<double>(calls) / steps;
  if (timed) seconds = fastest(run);
  return {"odeint symplectic_rkn_sb3a_mclachlan", steps, error_of(exact, q[0], p[0]), seconds, per_step};
}

// dopri5 with error control at absolute and relative tolerance `tolerance`, to exactly T.
Measure run_dopri5(double tolerance, const Exact& exact, bool timed) {
  long calls = 0, steps = 0;
  State2 y{};
  const auto run = [&] {
    y = {kQ0, 0.0};
    auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<State2>());
    const auto system = [&](const State2& x, State2& dxdt, double) {
      ++calls;
      dxdt = {x[1], -std::sin(x[0])};
    };
    return seconds_of([&] { steps = static_cast<long>(odeint::integrate_adaptive(stepper, system, y, 0.0, kT, 0.01)); });
  };
  double seconds = run();
  const double per_step = static_cast<double>(calls) / std::max(1L, steps);
  if (timed) seconds = fastest(run);
  return {fmt::format("odeint runge_kutta_dopri5 (tolerance {:.1e})", tolerance), steps, error_of(exact, y[0], y[1]),
          seconds, per_step};
}

// ---- reaching an error --------------------------------------------------------------------------

// The largest tolerance 10^(-x/4) whose error is at most `target`.
Measure tuned_dopri5(const Exact& exact, double target) {
  for (int x = 24; x <= 60; ++x) {
    const double tolerance = std::pow(10.0, -x / 4.0);
    if (run_dopri5(tolerance, exact, false).error <= target) return run_dopri5(tolerance, exact, true);
  }
  return {"odeint runge_kutta_dopri5 (no tolerance reaches it)", -1, NAN, NAN, NAN};
}

// ---- tables -------------------------------------------------------------------------------------

void print_row(const Measure& m, double reference_seconds) {
  if (m.steps < 0) {
    fmt::print("| {} | not reached within {} steps | | | | |\n", m.method, kMaxSteps);
    return;
  }
  fmt::print("| {} | {} | {:.2e} | {:.3e} | {:.2f} | {:.2f} |\n", m.method, m.steps, m.error, m.seconds,
             m.evaluations_per_step, m.seconds / reference_seconds);
}

void verlet_table(VariaMethod& verlet, const Exact& exact) {
  const long steps = 1'000'000;  // h = 1e-4 over T = 100
  const Measure v = run_varia(verlet, steps, exact, true), o = odeint_velocity_verlet(steps, exact, true);
  fmt::print("\n### Stormer-Verlet at equal steps (h = {}, {} steps)\n\n", kT / steps, steps);
  fmt::print("| method | steps | error | seconds | force evaluations / step | time / odeint |\n|---|---|---|---|---|---|\n");
  print_row(v, o.seconds);
  print_row(o, o.seconds);
  fmt::print("\nns per step: varia {:.1f}, odeint {:.1f}; ratio {:.2f}. Final states differ by {:.1e} (same method).\n",
             1e9 * v.seconds / steps, 1e9 * o.seconds / steps, v.seconds / o.seconds,
             std::max(std::abs(v.q - o.q), std::abs(v.p - o.p)));
}

void target_table(std::vector<VariaMethod>& methods, const Exact& exact, double target) {
  std::vector<Measure> varia_rows;
  for (VariaMethod& m : methods)
    varia_rows.push_back(fewest_steps([&](long n, bool timed) { return run_varia(m, n, exact, timed); }, target));
  const Measure mclachlan =
      fewest_steps([&](long n, bool timed) { return run_mclachlan(n, exact, timed); }, target);
  const Measure dopri5 = tuned_dopri5(exact, target);
  const Measure& best = best_of(varia_rows);
  fmt::print("\n### Global error {:.0e} at T = {}\n\n", target, kT);
  fmt::print("| method | steps | error | seconds | evaluations / step | time / sb3a_mclachlan |\n|---|---|---|---|---|---|\n");
  for (const Measure& m : varia_rows) print_row(m, mclachlan.seconds);
  print_row(mclachlan, mclachlan.seconds);
  print_row(dopri5, mclachlan.seconds);
  fmt::print("\nvaria's best ({}) / sb3a_mclachlan: {:.2f}; / dopri5: {:.2f}\n", best.method,
             best.seconds / mclachlan.seconds, best.seconds / dopri5.seconds);
}

}  // namespace

// `bench_odeint verlet` prints the first table only (for profiling the explicit step).
int main(int argc, char** argv) {
  const bool verlet_only = argc > 1 && std::string(argv[1]) == "verlet";
  varia::host::Registry registry(varia::host::Registry::search_path({}));
  std::vector<VariaMethod> methods = galerkin_candidates(registry);
  const Exact exact = exact_at(methods.front().assembly, kT);
  fmt::print("## varia against boost::odeint: pendulum from rest at q = {}, T = {}\n", kQ0, kT);
  verlet_table(methods.front(), exact);
  if (verlet_only) return 0;
  for (double target : {1e-10, 1e-12}) target_table(methods, exact, target);
  return 0;
}
