#include "support.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <boost/numeric/odeint.hpp>
#include <cmath>

#include "cost.hpp"

namespace varia::bench {

Exact exact_at(host::Assembly& pendulum, double t) {
  double q0 = kQ0, v0 = 0.0, q = 0.0, v = 0.0;
  varia::check(*pendulum.lagrangian, pendulum.lagrangian->exact_solution(&q0, &v0, t, &q, &v), "exact solution");
  return {q, v};
}

double error_of(const Exact& exact, double q, double p) { return std::max(std::abs(q - exact.q), std::abs(p - exact.p)); }

double fastest(const std::function<double()>& run) {
  double best = run(), total = best;
  for (int r = 1; r < kRepeats || total < kMinSeconds; ++r) {
    const double seconds = run();
    best = std::min(best, seconds);
    total += seconds;
  }
  return best;
}

VariaMethod make_varia(host::Registry& registry, const std::string& name, const nlohmann::json& document) {
  host::Scene scene = host::parse_scene(document);
  host::validate_parameters(scene, registry);
  host::Assembly assembly = host::assemble(scene, registry);
  return {name, std::move(scene), std::move(assembly)};
}

nlohmann::json pendulum_scene(const nlohmann::json& method, long steps) {
  return {{"system", {{"manifold", {{"type", "Rn"}, {"dim", 1}}}, {"lagrangian", {{"type", "pendulum"}}}}},
          {"method", method},
          {"initial", {{"q", {kQ0}}, {"p", {0.0}}}},
          {"step", kT / static_cast<double>(steps)},
          {"steps", steps}};
}

nlohmann::json galerkin_method(int degree, const std::string& rule, int points) {
  return {{"construction", "galerkin"}, {"degree", degree}, {"quadrature", {{"type", rule}, {"points", points}}}};
}

std::vector<VariaMethod> galerkin_candidates(host::Registry& registry) {
  std::vector<VariaMethod> methods;
  methods.push_back(make_varia(registry, "varia galerkin s=1, trapezoid (Stormer-Verlet)",
                               pendulum_scene(galerkin_method(1, "gauss-lobatto", 2))));
  for (int s = 2; s <= 6; ++s)
    methods.push_back(make_varia(registry, fmt::format("varia galerkin s={}, gauss-lobatto {}", s, s + 1),
                                 pendulum_scene(galerkin_method(s, "gauss-lobatto", s + 1))));
  for (int s = 2; s <= 6; ++s)
    methods.push_back(make_varia(registry, fmt::format("varia galerkin s={}, gauss-legendre {}", s, s),
                                 pendulum_scene(galerkin_method(s, "gauss-legendre", s))));
  return methods;
}

namespace {

long evaluations(const host::Assembly& a) {
  const auto& c = a.map->evaluations();
  return c.lagrangian + c.gradient + c.hessian;
}

}  // namespace

Measure run_varia(VariaMethod& m, long steps, const Exact& exact, bool timed) try {
  const double h = kT / static_cast<double>(steps);
  const long before = evaluations(m.assembly);
  const auto end = host::run_timed(m.assembly, h, steps);
  Measure r{m.name, steps, error_of(exact, end.q[0], end.p[0]), end.seconds,
            static_cast<double>(evaluations(m.assembly) - before) / static_cast<double>(steps), end.q[0], end.p[0]};
  if (timed) r.seconds = fastest([&] { return host::run_timed(m.assembly, h, steps).seconds; });
  return r;
} catch (const varia::NumericalFailure&) {
  return {m.name, steps, INFINITY, NAN, NAN};
}

Measure fewest_steps(const std::function<Measure(long, bool)>& run, double target) {
  long low = 0, high = 16;
  for (Measure m = run(high, false); !(m.error <= target); m = run(high, false)) {
    low = high;
    high *= 2;
    if (high > kMaxSteps) return {m.method, -1, NAN, NAN, NAN};
  }
  while (high - low > std::max(1L, high / 50)) {
    const long mid = (low + high) / 2;
    (run(mid, false).error <= target ? high : low) = mid;
  }
  return run(high, true);
}

Measure odeint_velocity_verlet(long steps, const Exact& exact, bool timed) {
  long calls = 0;
  State1 q{}, p{};
  const auto run = [&] {
    boost::numeric::odeint::velocity_verlet<State1> stepper;
    q = {kQ0};
    p = {0.0};
    const PendulumForce force{&calls};
    const auto system = [&](const State1& x, const State1&, State1& a, double) { force(x, a); };
    const double h = kT / static_cast<double>(steps);
    return seconds_of([&] {
      for (long k = 0; k < steps; ++k)
        stepper.do_step(system, std::make_pair(std::ref(q), std::ref(p)), static_cast<double>(k) * h, h);
    });
  };
  double seconds = run();
  const double per_step = static_cast<double>(calls) / static_cast<double>(steps);
  if (timed) seconds = fastest(run);
  return {"odeint velocity_verlet", steps, error_of(exact, q[0], p[0]), seconds, per_step, q[0], p[0]};
}

const Measure& best_of(const std::vector<Measure>& measures) {
  return *std::min_element(measures.begin(), measures.end(), [](const Measure& a, const Measure& b) {
    return (a.steps < 0 ? INFINITY : a.seconds) < (b.steps < 0 ? INFINITY : b.seconds);
  });
}

}  // namespace varia::bench
