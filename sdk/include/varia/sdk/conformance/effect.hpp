// The effect conformance suite (abi/effect.hpp), on an effect already bound to a system. Every
// derivative the composite Lagrangian uses is checked against the effect's own values:
//   - its coordinates are inside q, its Hessian pattern inside k x k (k coordinates);
//   - at random points x, every evaluate() path gives the same numbers, and the Hessian (its
//     pattern's values summed into a k x k matrix) is symmetric;
//   - Taylor tests along random directions d (taylor.hpp): V(x + eps d) - V(x) - eps <dV/dx, d>
//     and dV/dx (x + eps d) - dV/dx (x) - eps H d fall as eps^2. A wrong gradient fails the first,
//     a wrong or missing Hessian entry the second;
//   - where the effect evaluates at jets (gradient_jet, for shooting), dV/dx at jets along a random
//     line carries the values at doubles, and its first and second derivatives pass Taylor tests
//     against the values at doubles and the first derivative (check_at_jets).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <random>
#include <sstream>
#include <vector>

#include "varia/abi/effect.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/taylor.hpp"

namespace varia::sdk::conformance {

// V, its gradient and (when asked) its Hessian summed over the pattern, at x; throws PluginFault
// when a call fails.
struct EffectValues {
  double V = 0.0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
};
inline EffectValues effect_values(Effect& effect, const Eigen::VectorXd& x, bool with_hessian) {
  const int *rows = nullptr, *cols = nullptr;
  const int entries = effect.hessian_pattern(&rows, &cols);
  const int k = static_cast<int>(x.size());
  EffectValues e{0.0, Eigen::VectorXd(k), Eigen::MatrixXd::Zero(k, k)};
  Eigen::VectorXd values(entries);
  check(effect, effect.evaluate(x.data(), &e.V, e.gradient.data(), with_hessian ? values.data() : nullptr),
        "evaluate");
  if (with_hessian)
    for (int i = 0; i < entries; ++i) e.hessian(rows[i], cols[i]) += values(i);
  return e;
}

// The claims at one point x of the coordinates.
inline void check_effect_point(Effect& effect, const Eigen::VectorXd& x, std::mt19937& engine, Failures& failures) {
  const int k = static_cast<int>(x.size());
  const EffectValues e = effect_values(effect, x, true);
  const double scale = std::max({1.0, std::abs(e.V), e.gradient.lpNorm<Eigen::Infinity>()});
  const double h_scale = std::max(1.0, e.hessian.lpNorm<Eigen::Infinity>());
  double V = 0.0;
  Eigen::VectorXd g(k);
  check(effect, effect.evaluate(x.data(), &V, nullptr, nullptr), "evaluate");
  failures.expect(std::abs(V - e.V) <= 1e-15 * scale, "V alone is ", V, ", with the derivatives ", e.V);
  check(effect, effect.evaluate(x.data(), nullptr, g.data(), nullptr), "evaluate");
  failures.expect((g - e.gradient).lpNorm<Eigen::Infinity>() <= 1e-15 * scale,
                  "the gradient alone differs from the gradient with the Hessian");
  failures.expect((e.hessian - e.hessian.transpose()).lpNorm<Eigen::Infinity>() <= 1e-14 * h_scale,
                  "the Hessian is not symmetric (the pattern holds both triangles)");
  for (int trial = 0; trial < 3 && failures.empty(); ++trial) {
    const Eigen::VectorXd d = random_direction(k, engine);
    const auto at = [&](double eps) { return effect_values(effect, x + eps * d, false); };
    expect_taylor(
        failures, [&](double eps) { return std::abs(at(eps).V - e.V - eps * e.gradient.dot(d)); }, scale,
        "the gradient is not V's derivative");
    expect_taylor(
        failures, [&](double eps) { return (at(eps).gradient - e.gradient - eps * e.hessian * d).norm(); },
        std::max(scale, h_scale), "the Hessian is not the gradient's derivative");
  }
  if (!effect.evaluates_at_jets() || !failures.empty()) return;
  const Eigen::VectorXd d = random_direction(k, engine);
  check_at_jets(
      [&](double eps) {
        const std::vector<Jet2> line = line_jets(x, d, eps);
        std::vector<Jet2> gradient(k);
        check(effect, effect.gradient_jet(line.data(), nullptr, gradient.data()), "gradient_jet");
        return gradient;
      },
      [&](double eps) { return effect_values(effect, x + eps * d, false).gradient; }, "the gradient", failures);
}

// The whole suite on one bound effect of a system of `size` coordinates (q), at `trials` random
// points of the coordinates it names.
inline Failures check_effect(Effect& effect, int size, std::mt19937& engine, int trials = 5) {
  Failures failures;
  const int* indices = nullptr;
  const int k = effect.coordinates(&indices);
  for (int j = 0; j < k; ++j)
    failures.expect(indices[j] >= 0 && indices[j] < size, "coordinate ", j, " is index ", indices[j],
                    ", outside q (", size, " numbers)");
  const int *rows = nullptr, *cols = nullptr;
  const int entries = effect.hessian_pattern(&rows, &cols);
  for (int e = 0; e < entries; ++e)
    failures.expect(rows[e] >= 0 && rows[e] < k && cols[e] >= 0 && cols[e] < k, "Hessian entry ", e, " (", rows[e],
                    ", ", cols[e], ") is outside the ", k, " x ", k, " Hessian of the coordinates");
  for (int trial = 0; trial < trials && failures.empty(); ++trial) {
    const Eigen::VectorXd x = random_point(k, engine);
    std::ostringstream where;
    where << "at x = [" << x.transpose() << "]: ";
    Failures at_point;
    at_point.set_context(where.str());
    try {
      check_effect_point(effect, x, engine, at_point);
    } catch (const PluginFault& fault) {
      at_point.expect(false, "a call failed: ", fault.what());
    }
    failures.append(at_point);
  }
  return failures;
}

}  // namespace varia::sdk::conformance
