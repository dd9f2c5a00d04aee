// The constrained fixtures of the core tests: the spheres in R^3 of sphere_constraints.hpp and a
// unit mass falling along -e3 (the spherical pendulum in Cartesian coordinates).
#pragma once

#include "sphere_constraints.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::testing {

// A unit mass in gravity along -e3, L = |v|^2/2 - q3, on R^3.
struct FallingMass : sdk::AutodiffLagrangian<FallingMass, 3, 3> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    return 0.5 * (v(0) * v(0) + v(1) * v(1) + v(2) * v(2)) - q(2);
  }
};

}  // namespace varia::testing
