// The constrained fixtures of the core tests: a unit sphere in R^3 as one holonomic constraint and
// a unit mass falling along -e3 (the spherical pendulum in Cartesian coordinates).
#pragma once

#include <algorithm>

#include "varia/abi/constraint.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::testing {

// A unit sphere in R^3 as one holonomic constraint, g = (|q|^2 - 1)/2, declared quadratic or not.
struct UnitSphere final : Constraint {
  bool declared_quadratic = true;
  bool quadratic() const noexcept override { return declared_quadratic; }
  Status bind(int, int) noexcept override { return nullptr; }
  int size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    static constexpr int r[3] = {0, 0, 0}, c[3] = {0, 1, 2};
    *rows = r;
    *cols = c;
    return 3;
  }
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

// A unit mass in gravity along -e3, L = |v|^2/2 - q3, on R^3.
struct FallingMass : sdk::AutodiffLagrangian<FallingMass, 3, 3> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    return 0.5 * (v(0) * v(0) + v(1) * v(1) + v(2) * v(2)) - q(2);
  }
};

}  // namespace varia::testing
