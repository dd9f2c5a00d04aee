// Scaling of the sparse Galerkin construction with N, on two chains of N particles in 3-D hanging
// from the origin under gravity. Prints the time per step against N and the exponent a of
// time ~ N^a fitted by least squares in log-log.
//   - springs (docs/effects.md): each particle joined to the next by a spring, N = 10 .. 1000;
//     about 1: degree 1 with the trapezoid rule is explicit, M factorized once by sparse Cholesky;
//   - rods (docs/constraints.md): each joined to the next by a rigid rod (the constraint `rod`),
//     N = 128 .. 1024, degree 1 with 2 Lobatto points: Newton's method on the equations bordered by
//     the multipliers, and the momenta's projection, each a sparse LU of a system of 4N unknowns.
//   build/bin/bench_chain_scaling [steps per N, default 20]
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "assemble.hpp"
#include "memory.hpp"
#include "registry.hpp"
#include "scene.hpp"
#include "varia/core/trajectory.hpp"

namespace {

using Json = nlohmann::json;

Json chain_system(int particles, const Json& terms, const Json& constraints) {
  const int n = 3 * particles;
  Json system{{"manifold", {{"type", "Rn"}, {"dim", n}}},
              {"lagrangian",
               {{"type", "composite"}, {"space_dim", 3}, {"masses", std::vector<double>(particles, 1.0)}, {"terms", terms}}}};
  if (!constraints.empty()) system["constraints"] = constraints;
  return system;
}

Json spring_chain(int particles) {
  Json terms = Json::array({{{"type", "gravity"}, {"g", {0.0, 0.0, -1.0}}},
                            {{"type", "spring"}, {"anchor", {0.0, 0.0, 0.0}}, {"particle", 0}, {"stiffness", 100.0},
                             {"rest_length", 1.0}}});
  std::vector<double> q;
  for (int i = 0; i < particles; ++i) {
    if (i > 0)
      terms.push_back({{"type", "spring"}, {"between", {i - 1, i}}, {"stiffness", 100.0}, {"rest_length", 1.0}});
    q.insert(q.end(), {1.0 + i, 0.1 * std::sin(i), 0.0});
  }
  return {{"system", chain_system(particles, terms, Json::array())},
          {"method", {{"construction", "galerkin"}, {"degree", 1}, {"quadrature", {{"type", "trapezoid"}}}}},
          {"initial", {{"q", q}, {"v", std::vector<double>(3 * particles, 0.0)}}},
          {"step", 0.01},
          {"steps", 1}};
}

// Rods of length 0.1, the chain straight at 0.3 rad from the vertical, at rest.
Json rod_chain(int particles) {
  const Json terms = Json::array({{{"type", "gravity"}, {"g", {0.0, 0.0, -9.81}}}});
  const Json rods = Json::array({{{"type", "rod"}, {"anchor", {0.0, 0.0, 0.0}}, {"particle", 0}, {"length", 0.1}},
                                 {{"type", "rod"}, {"chain", {0, particles - 1}}, {"length", 0.1}}});
  std::vector<double> q;
  for (int i = 0; i < particles; ++i) q.insert(q.end(), {0.1 * (i + 1) * std::sin(0.3), 0.0, -0.1 * (i + 1) * std::cos(0.3)});
  return {{"system", chain_system(particles, terms, rods)},
          {"method",
           {{"construction", "galerkin"}, {"degree", 1}, {"quadrature", {{"type", "gauss-lobatto"}, {"points", 2}}}}},
          {"initial", {{"q", q}, {"v", std::vector<double>(3 * particles, 0.0)}}},
          {"step", 0.002},
          {"steps", 1}};
}

// Seconds per step, after one step that analyses the sparsity pattern.
double seconds_per_step(const Json& document, int steps, varia::host::Registry& registry) {
  varia::host::Scene scene = varia::host::parse_scene(document);
  varia::host::validate_parameters(scene, registry);
  varia::host::Assembly a = varia::host::assemble(scene, registry);
  varia::Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  trajectory.step();
  const auto start = std::chrono::steady_clock::now();
  trajectory.advance(steps);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / steps;
}

// The table of one chain and its exponent.
void scaling(const char* name, const std::vector<int>& sizes, const std::function<Json(int)>& chain, int steps,
             varia::host::Registry& registry) {
  std::vector<double> log_n, log_t;
  fmt::print("{}\n{:>6} {:>8} {:>14}\n", name, "N", "n", "s per step");
  for (int particles : sizes) {
    const double t = seconds_per_step(chain(particles), steps, registry);
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
  fmt::print("exponent (time per step ~ N^a): a = {:.3f}\n\n", (count * sxy - sx * sy) / (count * sxx - sx * sx));
}

}  // namespace

int main(int argc, char** argv) {
  varia::host::keep_freed_memory();
  const int steps = argc > 1 ? std::atoi(argv[1]) : 20;
  varia::host::Registry registry(varia::host::Registry::search_path({}));
  scaling("springs (explicit form)", {10, 30, 100, 300, 1000}, spring_chain, steps, registry);
  scaling("rods (constraints with multipliers)", {128, 256, 512, 1024}, rod_chain, steps, registry);
  return 0;
}
