// Spheres in R^3 as holonomic constraints (abi/constraint.hpp), written by hand: the unit sphere as
// a quadratic and as a quartic g. Plain ABI code, no SDK: the core and SDK tests and the fault
// plugin quartic-anchor share it.
#pragma once

#include <algorithm>

#include "varia/abi/constraint.hpp"

namespace varia::testing {

// One constraint on the first three numbers of q (G's pattern: row 0, columns 0..2).
struct SphereConstraint : Constraint {
  Status bind(int, int) noexcept override { return nullptr; }
  int size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    static constexpr int r[3] = {0, 0, 0}, c[3] = {0, 1, 2};
    *rows = r;
    *cols = c;
    return 3;
  }
};

// A unit sphere in R^3 as one holonomic constraint, g = (|q|^2 - 1)/2, declared quadratic or not.
struct UnitSphere final : SphereConstraint {
  bool declared_quadratic = true;
  bool quadratic() const noexcept override { return declared_quadratic; }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    static constexpr int c[3] = {0, 1, 2};
    *rows = c;
    *cols = c;
    return 3;
  }
  Status evaluate(const double* q, double* g, double* G) noexcept override {
    if (g != nullptr) g[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 1.0);
    if (G != nullptr) std::copy_n(q, 3, G);
    return nullptr;
  }
  Status weighted_hessian(const double*, const double* lambda, double* values) noexcept override {
    std::fill_n(values, 3, lambda[0]);
    return nullptr;
  }
};

// The unit sphere written as the quartic g = (|q|^4 - 1)/4, not quadratic: G = |q|^2 q^T, the
// Hessian of lambda g is lambda (|q|^2 I + 2 q q^T), and c = v^T H v = |q|^2 |v|^2 + 2 (q . v)^2 has
// the derivative 2 |v|^2 q + 4 (q . v) v in q (Constraint::curvature_derivative). `cross` is that
// last factor: another value gives a wrong derivative, for the conformance suite's own test.
struct QuarticSphere : SphereConstraint {
  double cross = 4.0;
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    static constexpr int r[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2}, c[9] = {0, 1, 2, 0, 1, 2, 0, 1, 2};
    *rows = r;
    *cols = c;
    return 9;
  }
  Status evaluate(const double* q, double* g, double* G) noexcept override {
    const double r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    if (g != nullptr) g[0] = 0.25 * (r2 * r2 - 1.0);
    if (G != nullptr)
      for (int k = 0; k < 3; ++k) G[k] = r2 * q[k];
    return nullptr;
  }
  Status weighted_hessian(const double* q, const double* lambda, double* values) noexcept override {
    const double r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    for (int e = 0; e < 9; ++e) values[e] = lambda[0] * ((e % 4 == 0 ? r2 : 0.0) + 2.0 * q[e / 3] * q[e % 3]);
    return nullptr;
  }
  bool gives_curvature_derivative() const noexcept override { return true; }
  Status curvature_derivative(const double* q, const double* v, double* values) noexcept override {
    const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], qv = q[0] * v[0] + q[1] * v[1] + q[2] * v[2];
    for (int k = 0; k < 3; ++k) values[k] = 2.0 * v2 * q[k] + cross * qv * v[k];
    return nullptr;
  }
};

}  // namespace varia::testing
