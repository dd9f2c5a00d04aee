// varia against boost::odeint on the planar pendulum q'' = -sin q (m = l = g = 1, so p = v),
// released from rest at q = 1.3, in one process (a benchmark, not a test). Prints Markdown tables:
//   1. Stormer-Verlet at equal steps: varia's Galerkin degree 1 with the trapezoid rule (its
//      explicit form, paper sec. 2 example) against odeint's velocity_verlet: time per step,
//      force evaluations per step, and the difference of the two final states.
//   2. Time to a global error of 1e-10 and 1e-12 at T = 100 (max norm of (q, p) against the
//      pendulum plugin's exact solution): each method at the fewest steps that reach it; varia's
//      best Galerkin composition against symplectic_rkn_sb3a_mclachlan, and against
//      runge_kutta_dopri5 with the tolerance tuned to the same error.
// Times are the fastest of kRepeats runs of the stepping loop alone.
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

#include "assemble.hpp"
#include "cost.hpp"
#include "registry.hpp"
#include "scene.hpp"

namespace {

namespace odeint = boost::numeric::odeint;
using varia::host::Assembly;
using Clock = std::chrono::steady_clock;
using State1 = std::array<double, 1>;
using State2 = std::array<double, 2>;

constexpr double kQ0 = 1.3, kT = 100.0;
constexpr int kRepeats = 5;
constexpr long kMaxSteps = 4'000'000;

// What one method costs at one setting.
struct Measure {
  std::string method;
  long steps = 0;
  double error = 0.0, seconds = 0.0, evaluations_per_step = 0.0;
  double q = NAN, p = NAN;  // the final state
};

// ---- the exact solution, from varia's pendulum plugin -------------------------------------------

struct Exact {
  double q, p;
};

Exact exact_at(Assembly& pendulum, double t) {
  double q0 = kQ0, v0 = 0.0, q = 0.0, v = 0.0;
  varia::check(*pendulum.lagrangian, pendulum.lagrangian->exact_solution(&q0, &v0, t, &q, &v), "exact solution");
  return {q, v};
}

double error_of(const Exact& exact, double q, double p) { return std::max(std::abs(q - exact.q), std::abs(p - exact.p)); }

// The fastest of kRepeats calls of run(), which returns the seconds it measured.
double fastest(const std::function<double()>& run) {
  double best = run();
  for (int r = 1; r < kRepeats; ++r) best = std::min(best, run());
  return best;
}

template <class F>
double seconds_of(F&& f) {
  const auto start = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// ---- varia ------------------------------------------------------------------------------------

nlohmann::json galerkin_scene(int degree, const std::string& rule, int points) {
  return {{"system", {{"manifold", {{"type", "Rn"}, {"dim", 1}}}, {"lagrangian", {{"type", "pendulum"}}}}},
          {"method",
           {{"construction", "galerkin"}, {"degree", degree}, {"quadrature", {{"type", rule}, {"points", points}}}}},
          {"initial", {{"q", {kQ0}}, {"p", {0.0}}}},
          {"step", 0.1},
          {"steps", 1}};
}

struct VariaMethod {
  std::string name;
  varia::host::Scene scene;
  Assembly assembly;
};

VariaMethod make_varia(varia::host::Registry& registry, const std::string& name, const nlohmann::json& document) {
  varia::host::Scene scene = varia::host::parse_scene(document);
  varia::host::validate_parameters(scene, registry);
  Assembly assembly = varia::host::assemble(scene, registry);
  return {name, std::move(scene), std::move(assembly)};
}

long evaluations(const Assembly& a) {
  const auto& c = a.map->evaluations();
  return c.lagrangian + c.gradient + c.hessian;
}

// A step size too large for Newton's method counts as not reaching any error.
Measure run_varia(VariaMethod& m, long steps, const Exact& exact, bool timed) try {
  const double h = kT / steps;
  const long before = evaluations(m.assembly);
  const auto end = varia::host::run_timed(m.assembly, h, steps);
  Measure r{m.name, steps, error_of(exact, end.q[0], end.p[0]), end.seconds,
            static_cast<double>(evaluations(m.assembly) - before) / steps, end.q[0], end.p[0]};
  if (timed) r.seconds = fastest([&] { return varia::host::run_timed(m.assembly, h, steps).seconds; });
  return r;
} catch (const varia::NumericalFailure&) {
  return {m.name, steps, INFINITY, NAN, NAN};
}

// ---- odeint -----------------------------------------------------------------------------------

// The pendulum's force -sin q (= dp/dt), counting its calls.
struct Force {
  long* calls;
  void operator()(const State1& q, State1& dpdt) const {
    ++*calls;
    dpdt[0] = -std::sin(q[0]);
  }
};

Measure run_verlet(long steps, const Exact& exact, bool timed) {
  long calls = 0;
  State1 q{}, p{};
  const auto run = [&] {
    odeint::velocity_verlet<State1> stepper;
    q = {kQ0};
    p = {0.0};
    const Force force{&calls};
    const auto system = [&](const State1& x, const State1&, State1& a, double) { force(x, a); };
    const double h = kT / steps;
    return seconds_of([&] {
      for (long k = 0; k < steps; ++k) stepper.do_step(system, std::make_pair(std::ref(q), std::ref(p)), k * h, h);
    });
  };
  double seconds = run();
  const double per_step = static_cast<double>(calls) / steps;
  if (timed) seconds = fastest(run);
  return {"odeint velocity_verlet", steps, error_of(exact, q[0], p[0]), seconds, per_step, q[0], p[0]};
}

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
        stepper.do_step(std::make_pair(velocity, Force{&calls}), std::make_pair(std::ref(q), std::ref(p)), k * h, h);
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

// The fewest steps (to within 2%) whose error is at most `target`, by doubling then bisection
// (the error falls monotonically with h in the asymptotic range these runs are in); then timed.
Measure fewest_steps(const std::function<Measure(long, bool)>& run, double target) {
  long low = 0, high = 16;
  for (Measure m = run(high, false); m.error > target; m = run(high, false)) {
    low = high;
    high *= 2;
    if (high > kMaxSteps) return {m.method, -1, NAN, NAN, NAN};
  }
  while (high - low > std::max(1L, high / 50)) {
    const long mid = (low + high) / 2;
    (run(mid, false).error > target ? low : high) = mid;
  }
  return run(high, true);
}

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
  const Measure v = run_varia(verlet, steps, exact, true), o = run_verlet(steps, exact, true);
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
  const auto best = std::min_element(varia_rows.begin(), varia_rows.end(), [](const Measure& a, const Measure& b) {
    return (a.steps < 0 ? INFINITY : a.seconds) < (b.steps < 0 ? INFINITY : b.seconds);
  });
  fmt::print("\n### Global error {:.0e} at T = {}\n\n", target, kT);
  fmt::print("| method | steps | error | seconds | evaluations / step | time / sb3a_mclachlan |\n|---|---|---|---|---|---|\n");
  for (const Measure& m : varia_rows) print_row(m, mclachlan.seconds);
  print_row(mclachlan, mclachlan.seconds);
  print_row(dopri5, mclachlan.seconds);
  fmt::print("\nvaria's best ({}) / sb3a_mclachlan: {:.2f}; / dopri5: {:.2f}\n", best->method,
             best->seconds / mclachlan.seconds, best->seconds / dopri5.seconds);
}

}  // namespace

// `bench_odeint verlet` prints the first table only (for profiling the explicit step).
int main(int argc, char** argv) {
  const bool verlet_only = argc > 1 && std::string(argv[1]) == "verlet";
  varia::host::Registry registry(varia::host::Registry::search_path({}));
  std::vector<VariaMethod> methods;
  methods.push_back(make_varia(registry, "varia galerkin s=1, trapezoid (Stormer-Verlet)", galerkin_scene(1, "gauss-lobatto", 2)));
  for (int s : {2, 3, 4, 5, 6})
    methods.push_back(make_varia(registry, fmt::format("varia galerkin s={}, gauss-lobatto {}", s, s + 1),
                                 galerkin_scene(s, "gauss-lobatto", s + 1)));
  for (int s : {2, 3})
    methods.push_back(make_varia(registry, fmt::format("varia galerkin s={}, gauss-legendre {}", s, s),
                                 galerkin_scene(s, "gauss-legendre", s)));
  const Exact exact = exact_at(methods.front().assembly, kT);
  fmt::print("## varia against boost::odeint: pendulum from rest at q = {}, T = {}\n", kQ0, kT);
  verlet_table(methods.front(), exact);
  if (verlet_only) return 0;
  for (double target : {1e-10, 1e-12}) target_table(methods, exact, target);
  return 0;
}
