// What the gauss-legendre and gauss-lobatto plugins share: Legendre polynomials, the zeros of P_n
// and of P_n' to full precision, the map of a symmetric rule from [-1, 1] to the paper's [0, 1]
// (nodes c_i, weights b_i of h sum_i b_i f(c_i h), sec. 2), and the `points` parameter.
// The numerics are classical (Abramowitz & Stegun ch. 22 and 25.4; Golub & Welsch, Math. Comp.
// 23, 1969); they run in long double and each result is rounded to double once.
#pragma once

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "varia/abi/quadrature.hpp"

namespace varia::plugins::legendre {

// The largest number of nodes a Gauss rule accepts.
inline constexpr int kMaxPoints = 64;

// P_n(x), P_n'(x), P_n''(x): element d is the d-th derivative.
using Derivatives = std::array<long double, 3>;

// Bonnet's recurrence (k+1) P_{k+1} = (2k+1) x P_k - k P_{k-1}, differentiated once and twice:
// (k+1) P'_{k+1} = (2k+1) (P_k + x P'_k) - k P'_{k-1},
// (k+1) P''_{k+1} = (2k+1) (2 P'_k + x P''_k) - k P''_{k-1}.
inline Derivatives evaluate(int n, long double x) {
  Derivatives previous{0, 0, 0}, current{1, 0, 0};
  for (int k = 0; k < n; ++k) {
    const long double a = 2 * k + 1, b = k, c = k + 1;
    const Derivatives next{(a * x * current[0] - b * previous[0]) / c,
                           (a * (current[0] + x * current[1]) - b * previous[1]) / c,
                           (a * (2 * current[1] + x * current[2]) - b * previous[2]) / c};
    previous = current;
    current = next;
  }
  return current;
}

// Newton's method on P_n^(d) (d = 0 or 1) from a guess already within ~1e-15 of a simple zero:
// it converges quadratically, so a few steps reach long double precision.
inline long double polish(int n, int d, long double x) {
  constexpr int kMaxSteps = 8;
  for (int step = 0; step < kMaxSteps; ++step) {
    const Derivatives p = evaluate(n, x);
    const long double dx = p[d] / p[d + 1];
    x -= dx;
    if (std::fabs(dx) <= 2 * std::numeric_limits<long double>::epsilon()) break;
  }
  return x;
}

// The zeros x >= 0 of P_n^(d) (d = 0 or 1), increasing. P_n^(d) is a multiple of the Gegenbauer
// polynomial C^(d+1/2)_{n-d} (A&S ch. 22), whose zeros are the eigenvalues of its symmetric
// Jacobi matrix (Golub-Welsch): zero diagonal, off-diagonal sqrt(beta_k) with
// beta_k = k (k + 2d) / ((2k + 2d - 1)(2k + 2d + 1)) from its monic three-term
// recurrence. The eigenvalues are accurate to a few double roundings; Newton polishes them in
// long double (the eigenvalues alone are not accurate enough for the rules to be exact).
// The zeros are symmetric about 0, so the middle one of an odd count is exactly 0.
inline std::vector<long double> nonnegative_zeros(int n, int d) {
  const int m = n - d;
  if (m <= 0) return {};
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(m), off_diagonal(m - 1);
  for (int k = 1; k < m; ++k)
    off_diagonal(k - 1) = std::sqrt(static_cast<double>(k) * (k + 2 * d) /
                                    ((2.0 * k + 2 * d - 1) * (2.0 * k + 2 * d + 1)));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver;
  solver.computeFromTridiagonal(diagonal, off_diagonal, Eigen::EigenvaluesOnly);
  std::vector<long double> zeros;
  for (int i = m / 2; i < m; ++i)
    zeros.push_back(m % 2 == 1 && i == m / 2 ? 0.0L : polish(n, d, solver.eigenvalues()(i)));
  return zeros;
}

// A rule on [0, 1]: c_i increasing, b_i.
struct Rule {
  std::vector<double> nodes, weights;
};

// A rule on [-1, 1] symmetric about 0, given by its n_total nodes' upper half x >= 0 (increasing;
// x[0] = 0 when n_total is odd) and their weights w, mapped to [0, 1]: c = (1 + x)/2, b = w/2.
// The upper half is rounded once; the lower half mirrors it, c_i = 1 - c_{n-1-i} (exact in
// double, since c_{n-1-i} >= 1/2) and b_i = b_{n-1-i}: exactly symmetric (paper, sec. 3).
inline Rule mirrored_to_unit_interval(int n_total, const std::vector<long double>& x,
                                      const std::vector<long double>& w) {
  Rule rule{std::vector<double>(n_total), std::vector<double>(n_total)};
  const int lower = n_total - static_cast<int>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    rule.nodes[lower + i] = static_cast<double>((1 + x[i]) / 2);
    rule.weights[lower + i] = static_cast<double>(w[i] / 2);
  }
  for (int i = 0; i < lower; ++i) {
    rule.nodes[i] = 1 - rule.nodes[n_total - 1 - i];
    rule.weights[i] = rule.weights[n_total - 1 - i];
  }
  return rule;
}

// A Gauss rule made at construction: exactly symmetric; the plugin adds degree().
class SymmetricRule : public varia::Quadrature {
 public:
  explicit SymmetricRule(Rule rule) : rule_(std::move(rule)) {}
  int size() const noexcept final { return static_cast<int>(rule_.nodes.size()); }
  const double* nodes() const noexcept final { return rule_.nodes.data(); }
  const double* weights() const noexcept final { return rule_.weights.data(); }
  bool symmetric() const noexcept final { return true; }

 private:
  Rule rule_;
};

// The `points` parameter of rule `type` (its only one): an integer in [minimum, kMaxPoints],
// `fallback` when absent. The host has checked the schema already; this keeps a plugin made
// directly (tests, other hosts) just as safe.
inline int points_parameter(const nlohmann::json& parameters, const char* type, int minimum,
                            int fallback) {
  for (const auto& item : parameters.items())
    if (item.key() != "points")
      throw std::invalid_argument(std::string(type) + ": unknown parameter '" + item.key() +
                                  "' (the only parameter is 'points')");
  if (!parameters.contains("points")) return fallback;
  const auto& value = parameters.at("points");
  const double points = value.is_number() ? value.get<double>() : std::nan("");
  if (!(points >= minimum && points <= kMaxPoints && points == std::floor(points)))
    throw std::invalid_argument(std::string(type) + ": 'points' must be an integer from " +
                                std::to_string(minimum) + " to " + std::to_string(kMaxPoints) +
                                ", got " + value.dump());
  return static_cast<int>(points);
}

}  // namespace varia::plugins::legendre
