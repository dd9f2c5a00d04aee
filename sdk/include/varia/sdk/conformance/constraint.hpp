// The constraint conformance suite (abi/constraint.hpp), on a constraint already bound to a
// system of n coordinates. Every derivative the constructions use is checked against the
// constraint's own values:
//   - its Jacobian pattern lies inside m x n and its Hessian pattern inside n x n, no entry twice;
//   - at random points q, g alone equals g with the Jacobian, and the Hessian of sum_i lambda_i g_i
//     (its pattern's values in an n x n matrix) is symmetric;
//   - Taylor tests along random directions d (taylor.hpp): g(q + eps d) - g(q) - eps G d and
//     G(q + eps d)^T lambda - G(q)^T lambda - eps H_lambda d fall as eps^2. A wrong Jacobian fails the
//     first, a wrong or missing Hessian entry the second;
//   - a constraint declaring quadratic() has the same Hessian at every random point;
//   - where it gives curvature_derivative() (dc_i/dq, c_i = v^T H_i(q) v), a Taylor test of
//     v^T H_lambda(q + eps d) v - v^T H_lambda(q) v - eps lambda^T C d, C's entries in G's pattern.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <random>
#include <set>
#include <utility>

#include "varia/abi/constraint.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/taylor.hpp"

namespace varia::sdk::conformance {

// The dense m x n matrix of the values that write(values) gives in the constraint's Jacobian
// pattern (G; curvature_derivative's dc/dq).
template <class Write>
Eigen::MatrixXd in_jacobian_pattern(Constraint& constraint, int n, Write&& write) {
  const int *rows = nullptr, *cols = nullptr;
  const int entries = constraint.jacobian_pattern(&rows, &cols);
  Eigen::VectorXd values(entries);
  write(values.data());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(constraint.size(), n);
  for (int e = 0; e < entries; ++e) A(rows[e], cols[e]) = values(e);
  return A;
}

// g and G (dense, m x n) at q; throws PluginFault when a call fails.
struct ConstraintValues {
  Eigen::VectorXd g;
  Eigen::MatrixXd G;
};
inline ConstraintValues constraint_values(Constraint& constraint, const Eigen::VectorXd& q) {
  ConstraintValues c{Eigen::VectorXd(constraint.size()), {}};
  c.G = in_jacobian_pattern(constraint, static_cast<int>(q.size()), [&](double* values) {
    check(constraint, constraint.evaluate(q.data(), c.g.data(), values), "evaluate");
  });
  return c;
}

// The Hessian of sum_i lambda_i g_i at q, dense n x n.
inline Eigen::MatrixXd weighted_hessian(Constraint& constraint, const Eigen::VectorXd& q, const Eigen::VectorXd& lambda) {
  const int *rows = nullptr, *cols = nullptr;
  const int entries = constraint.hessian_pattern(&rows, &cols);
  Eigen::VectorXd values(entries);
  check(constraint, constraint.weighted_hessian(q.data(), lambda.data(), values.data()), "weighted_hessian");
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(q.size(), q.size());
  for (int e = 0; e < entries; ++e) H(rows[e], cols[e]) = values(e);
  return H;
}

// Whether a pattern's entries lie inside rows x cols, none twice.
inline void check_pattern(int entries, const int* r, const int* c, int rows, int cols, const char* what, Failures& failures) {
  std::set<std::pair<int, int>> seen;
  for (int e = 0; e < entries; ++e) {
    failures.expect(r[e] >= 0 && r[e] < rows && c[e] >= 0 && c[e] < cols, "the ", what, " pattern's entry (", r[e], ", ",
                    c[e], ") lies outside ", rows, " x ", cols);
    failures.expect(seen.insert({r[e], c[e]}).second, "the ", what, " pattern names (", r[e], ", ", c[e], ") twice");
  }
}

inline Failures check_constraint(Constraint& constraint, int n, std::mt19937& engine) {
  Failures failures;
  const int m = constraint.size();
  failures.expect(m >= 1, "the constraint has ", m, " rows");
  const int *rows = nullptr, *cols = nullptr;
  const int jacobian_entries = constraint.jacobian_pattern(&rows, &cols);
  check_pattern(jacobian_entries, rows, cols, m, n, "Jacobian", failures);
  const int hessian_entries = constraint.hessian_pattern(&rows, &cols);
  check_pattern(hessian_entries, rows, cols, n, n, "Hessian", failures);
  for (int trial = 0; trial < 3 && failures.empty(); ++trial) {
    const Eigen::VectorXd q = random_point(n, engine), lambda = random_direction(m, engine), d = random_direction(n, engine);
    const ConstraintValues c = constraint_values(constraint, q);
    const Eigen::MatrixXd H = weighted_hessian(constraint, q, lambda);
    Eigen::VectorXd alone(m);
    check(constraint, constraint.evaluate(q.data(), alone.data(), nullptr), "evaluate");
    const double scale = std::max({1.0, c.g.lpNorm<Eigen::Infinity>(), c.G.lpNorm<Eigen::Infinity>()});
    failures.expect((alone - c.g).lpNorm<Eigen::Infinity>() <= 1e-15 * scale, "g alone differs from g with the Jacobian");
    failures.expect((H - H.transpose()).lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, H.lpNorm<Eigen::Infinity>()),
                    "the Hessian is not symmetric (the pattern holds both triangles)");
    expect_taylor(
        failures,
        [&](double eps) { return (constraint_values(constraint, q + eps * d).g - c.g - eps * c.G * d).norm(); }, scale,
        "the Jacobian is not g's derivative");
    expect_taylor(
        failures,
        [&](double eps) {
          const Eigen::MatrixXd G = constraint_values(constraint, q + eps * d).G;
          return (G.transpose() * lambda - c.G.transpose() * lambda - eps * H * d).norm();
        },
        std::max(scale, H.lpNorm<Eigen::Infinity>()), "the weighted Hessian is not the derivative of G^T lambda");
    if (constraint.gives_curvature_derivative()) {
      const Eigen::VectorXd v = random_direction(n, engine);
      const Eigen::MatrixXd C = in_jacobian_pattern(constraint, n, [&](double* values) {
        check(constraint, constraint.curvature_derivative(q.data(), v.data(), values), "curvature_derivative");
      });
      const double curvature = v.dot(H * v);
      expect_taylor(
          failures,
          [&](double eps) { return std::abs(v.dot(weighted_hessian(constraint, q + eps * d, lambda) * v) - curvature -
                                            eps * lambda.dot(C * d)); },
          std::max({scale, H.lpNorm<Eigen::Infinity>(), C.lpNorm<Eigen::Infinity>()}),
          "curvature_derivative is not the derivative of v^T H_i(q) v in q");
    }
    if (constraint.quadratic()) {
      const Eigen::MatrixXd elsewhere = weighted_hessian(constraint, random_point(n, engine), lambda);
      failures.expect((elsewhere - H).lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, H.lpNorm<Eigen::Infinity>()),
                      "the constraint declares quadratic(), but its Hessian differs between points");
    }
  }
  return failures;
}

}  // namespace varia::sdk::conformance
