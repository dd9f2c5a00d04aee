// The quadrature conformance suite. A rule of degree d (paper, sec. 2: nodes c_i, weights b_i)
// integrates t^k on [0, 1] exactly for k <= d and no further; its nodes increase within [0, 1],
// its weights are positive (zero allowed at an endpoint) and sum to 1; it is symmetric exactly
// when c_i + c_{n-1-i} = 1 and b_i = b_{n-1-i} (paper, sec. 3).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "varia/abi/quadrature.hpp"
#include "varia/sdk/conformance/failures.hpp"

namespace varia::sdk::conformance {

inline constexpr double kEps = std::numeric_limits<double>::epsilon();

// Q(t^k) = sum_i b_i c_i^k + sum_j (a_j f^(j)(0) + z_j f^(j)(1)) with f = t^k (the derivative
// terms of an Euler-Maclaurin rule, quadrature.hpp, with h = 1), in long double, beside the sum of
// the magnitudes of its terms, which bounds the effect of rounding the rule to double.
struct Integral {
  long double value = 0, magnitude = 0;
  void add(long double term) {
    value += term;
    magnitude += std::fabs(term);
  }
};

// f^(j)(t) for f = t^k.
inline long double monomial_derivative(int k, int j, long double t) {
  if (j > k) return 0;
  long double factor = 1;
  for (int i = k - j + 1; i <= k; ++i) factor *= i;
  return factor * std::pow(t, static_cast<long double>(k - j));
}

inline Integral integrate_monomial(const Quadrature& rule, int k) {
  Integral q;
  for (int i = 0; i < rule.size(); ++i)
    q.add(static_cast<long double>(rule.weights()[i]) *
          std::pow(static_cast<long double>(rule.nodes()[i]), static_cast<long double>(k)));
  for (int j = 1; j <= rule.derivative_terms(); ++j) {
    const double* az = rule.derivative_weights(j);
    q.add(az[0] * monomial_derivative(k, j, 0));
    q.add(az[1] * monomial_derivative(k, j, 1));
  }
  return q;
}

// |Q(t^k) - 1/(k+1)| relative to the exact 1/(k+1), and the round-off bound on it: each term
// carries the rounding of one weight and of k factors c_i, (k + 2) eps relative at most.
struct MonomialError {
  double relative, roundoff;
};

inline MonomialError monomial_error(const Quadrature& rule, int k) {
  const Integral q = integrate_monomial(rule, k);
  const long double exact = 1.0L / (k + 1);
  return {static_cast<double>(std::fabs(q.value - exact) / exact),
          static_cast<double>((k + 2) * kEps * q.magnitude / exact)};
}

inline bool is_symmetric(const Quadrature& rule) {
  const int n = rule.size();
  for (int i = 0; i < n; ++i) {
    const double c = rule.nodes()[i], c_mirror = rule.nodes()[n - 1 - i];
    const double b = rule.weights()[i], b_mirror = rule.weights()[n - 1 - i];
    if (std::fabs(c + c_mirror - 1) > kEps || std::fabs(b - b_mirror) > kEps * b) return false;
  }
  return true;
}

// Exact for t^k, k <= degree(), to round-off; not for degree() + 1.
inline void check_degree(const Quadrature& rule, Failures& failures) {
  for (int k = 0; k <= rule.degree(); ++k) {
    const MonomialError e = monomial_error(rule, k);
    failures.expect(e.relative <= e.roundoff, "t^", k, " is integrated with relative error ", e.relative,
                    " > round-off ", e.roundoff, " although degree() is ", rule.degree());
  }
  const int k = rule.degree() + 1;
  const MonomialError e = monomial_error(rule, k);
  failures.expect(e.relative > 10 * e.roundoff, "t^", k, " is integrated exactly (relative error ", e.relative,
                  "): degree() ", rule.degree(), " is too low");
}

inline void check_nodes_and_weights(const Quadrature& rule, Failures& failures) {
  const int n = rule.size();
  failures.expect(n >= 1, "size() is ", n);
  long double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double c = rule.nodes()[i], b = rule.weights()[i];
    failures.expect(c >= 0 && c <= 1, "node ", i, " = ", c, " is outside [0, 1]");
    failures.expect(i == 0 || c > rule.nodes()[i - 1], "node ", i, " = ", c, " does not increase");
    // Zero weights are allowed at the endpoints only (quadrature.hpp; paper, sec. 3).
    failures.expect(b > 0 || (b == 0 && (c == 0 || c == 1)), "weight ", i, " = ", b, " is not positive");
    sum += b;
  }
  failures.expect(std::fabs(sum - 1) <= n * kEps, "the weights sum to 1 + ", static_cast<double>(sum - 1));
}

// The whole suite on one rule.
inline Failures check_quadrature(const Quadrature& rule) {
  Failures failures;
  check_nodes_and_weights(rule, failures);
  if (!failures.empty()) return failures;
  check_degree(rule, failures);
  failures.expect(rule.symmetric() == is_symmetric(rule), "symmetric() is ", rule.symmetric(),
                  " but the nodes and weights say ", is_symmetric(rule));
  return failures;
}

// Parameter objects to test a plugin with: {} and, for each integer parameter in its schema, every
// value from the schema minimum to min(maximum, limit).
inline std::vector<nlohmann::json> parameter_sweep(const nlohmann::json& schema, int limit = 12) {
  std::vector<nlohmann::json> sweep{nlohmann::json::object()};
  const auto properties = schema.value("properties", nlohmann::json::object());
  for (const auto& [name, property] : properties.items()) {
    if (property.value("type", "") != "integer") continue;
    const int last = std::min(property.value("maximum", limit), limit);
    for (int value = property.value("minimum", 0); value <= last; ++value) sweep.push_back({{name, value}});
  }
  return sweep;
}

}  // namespace varia::sdk::conformance
