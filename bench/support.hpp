// What the benchmarks share (bench_odeint, bench_gni): the pendulum problem both compare on, the
// planar pendulum q'' = -sin q (m = l = g = 1, so p = v) released from rest at q = 1.3 and
// measured at T = 100 against the pendulum plugin's exact solution; varia's integrators built
// from scenes; the search for the fewest steps that reach an error; the fastest of repeated runs.
#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "assemble.hpp"
#include "registry.hpp"
#include "scene.hpp"

namespace varia::bench {

inline constexpr double kQ0 = 1.3, kT = 100.0;
// A timed measurement is the fastest of at least kRepeats runs spanning at least kMinSeconds, on
// either side: on this virtual machine a window of some 0.1 s now and then runs everything about
// 1.4x slower (seen on varia's side and on GNI's), and five runs of a short integration (0.4 ms)
// fit inside one.
inline constexpr int kRepeats = 5;
inline constexpr double kMinSeconds = 0.25;
inline constexpr long kMaxSteps = 4'000'000;

// What one method costs at one setting.
struct Measure {
  std::string method;
  long steps = 0;  // -1: the error was not reached within kMaxSteps
  double error = 0.0, seconds = 0.0, evaluations_per_step = 0.0;
  double q = NAN, p = NAN;  // the final state
};

// The pendulum's exact state at t (q, p = v).
struct Exact {
  double q, p;
};
Exact exact_at(host::Assembly& pendulum, double t);
double error_of(const Exact& exact, double q, double p);

// The fastest of calls of run(), which returns the seconds it measured: at least kRepeats calls,
// and as many more as make their seconds add up to kMinSeconds.
double fastest(const std::function<double()>& run);

template <class F>
double seconds_of(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A varia integrator of the pendulum problem: its scene and assembly.
struct VariaMethod {
  std::string name;
  host::Scene scene;
  host::Assembly assembly;
};
VariaMethod make_varia(host::Registry& registry, const std::string& name, const nlohmann::json& document);

// The pendulum problem's scene (h = kT / steps) with the given method object.
nlohmann::json pendulum_scene(const nlohmann::json& method, long steps = 1000);
// The Galerkin method of degree `degree` with `points` points of the rule.
nlohmann::json galerkin_method(int degree, const std::string& rule, int points);
// varia's candidates for "its best method": Galerkin compositions of degree s with s + 1
// Gauss-Lobatto points (order 2s) or s Gauss-Legendre points (the s-stage Gauss method, order
// 2s), s = 2..6, after Stormer-Verlet (degree 1 with the trapezoid rule, the first).
std::vector<VariaMethod> galerkin_candidates(host::Registry& registry);

// `steps` steps of the stepping loop alone (host::run_timed, the loop `varia cost` times) over
// [0, kT]; with `timed`, seconds are the fastest of repeated runs (fastest). A step size too
// large for Newton's method counts as not reaching any error (error infinite).
Measure run_varia(VariaMethod& m, long steps, const Exact& exact, bool timed);

// The fewest steps (to within 2%) whose error is at most `target`, by doubling then bisection
// (the error falls monotonically with h in the asymptotic range these runs are in); then timed.
// run(steps, timed) measures one setting.
Measure fewest_steps(const std::function<Measure(long, bool)>& run, double target);

// boost::odeint's velocity_verlet on the pendulum problem, `steps` steps over [0, kT], counting
// force evaluations; with `timed`, seconds are the fastest of repeated runs (fastest).
using State1 = std::array<double, 1>;
struct PendulumForce {  // -sin q (= dp/dt), counting its calls
  long* calls;
  void operator()(const State1& q, State1& dpdt) const {
    ++*calls;
    dpdt[0] = -std::sin(q[0]);
  }
};
Measure odeint_velocity_verlet(long steps, const Exact& exact, bool timed);

// The fastest of the measures that reached their error.
const Measure& best_of(const std::vector<Measure>& measures);

}  // namespace varia::bench
