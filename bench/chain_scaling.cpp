// Scaling of the sparse Galerkin construction (docs/effects.md): a chain of N particles in 3-D,
// the first tied to the origin, each joined to the next by a spring, under gravity, for N from 10
// to 1000. Prints the time per step against N and the exponent a of time ~ N^a fitted by least
// squares in log-log (about 1: degree 1 with the trapezoid rule is explicit, M factorized once by
// sparse Cholesky).
//   build/bin/bench_chain_scaling [steps per N, default 20]
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <vector>

#include "assemble.hpp"
#include "registry.hpp"
#include "scene.hpp"
#include "varia/core/trajectory.hpp"

namespace {

using Json = nlohmann::json;

Json chain_scene(int particles) {
  Json terms = Json::array({{{"type", "gravity"}, {"g", {0.0, 0.0, -1.0}}},
                            {{"type", "spring"}, {"anchor", {0.0, 0.0, 0.0}}, {"particle", 0}, {"stiffness", 100.0},
                             {"rest_length", 1.0}}});
  std::vector<double> q;
  for (int i = 0; i < particles; ++i) {
    if (i > 0)
      terms.push_back({{"type", "spring"}, {"between", {i - 1, i}}, {"stiffness", 100.0}, {"rest_length", 1.0}});
    q.insert(q.end(), {1.0 + i, 0.1 * std::sin(i), 0.0});
  }
  const int n = 3 * particles;
  return {{"system",
           {{"manifold", {{"type", "Rn"}, {"dim", n}}},
            {"lagrangian",
             {{"type", "composite"}, {"space_dim", 3}, {"masses", std::vector<double>(particles, 1.0)}, {"terms", terms}}}}},
          {"method", {{"construction", "galerkin"}, {"degree", 1}, {"quadrature", {{"type", "trapezoid"}}}}},
          {"initial", {{"q", q}, {"v", std::vector<double>(n, 0.0)}}},
          {"step", 0.01},
          {"steps", 1}};
}

// Seconds per step, after one step that analyses the sparsity pattern.
double seconds_per_step(int particles, int steps, varia::host::Registry& registry) {
  varia::host::Scene scene = varia::host::parse_scene(chain_scene(particles));
  varia::host::validate_parameters(scene, registry);
  varia::host::Assembly a = varia::host::assemble(scene, registry);
  varia::Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  trajectory.step();
  const auto start = std::chrono::steady_clock::now();
  trajectory.advance(steps);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / steps;
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 20;
  varia::host::Registry registry(varia::host::Registry::search_path({}));
  std::vector<double> log_n, log_t;
  fmt::print("{:>6} {:>8} {:>14}\n", "N", "n", "s per step");
  for (int particles : {10, 30, 100, 300, 1000}) {
    const double t = seconds_per_step(particles, steps, registry);
    fmt::print("{:>6} {:>8} {:>14.4e}\n", particles, 3 * particles, t);
    log_n.push_back(std::log(particles));
    log_t.push_back(std::log(t));
  }
  const double count = static_cast<double>(log_n.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < log_n.size(); ++i) {
    sx += log_n[i];
    sy += log_t[i];
    sxx += log_n[i] * log_n[i];
    sxy += log_n[i] * log_t[i];
  }
  fmt::print("exponent (time per step ~ N^a): a = {:.3f}\n", (count * sxy - sx * sy) / (count * sxx - sx * sx));
  return 0;
}
