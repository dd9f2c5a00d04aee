// The constrained fixtures of the core tests: the spheres in R^3 of sphere_constraints.hpp and a
// unit mass falling along -e3, which on the unit sphere is the spherical pendulum in Cartesian
// coordinates.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "fixtures.hpp"
#include "sphere_constraints.hpp"
#include "varia/core/constraints.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::testing {

// A unit mass in gravity along -e3, L = |v|^2/2 - q3, on R^3.
struct FallingMass : sdk::AutodiffLagrangian<FallingMass, 3, 3> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    return 0.5 * (v(0) * v(0) + v(1) * v(1) + v(2) * v(2)) - q(2);
  }
};

// The spherical pendulum as the constrained one-step tests take it: the falling mass on the unit
// sphere, started at angle 1 from the downward vertical with a horizontal momentum (on the sphere
// and on its hidden constraint q . p = 0).
struct SphericalPendulum {
  FlatSpace space{3};
  FallingMass mass;
  UnitSphere sphere;
  HolonomicConstraints constraints{{&sphere}, 3};
  Eigen::VectorXd q = (Eigen::VectorXd(3) << std::sin(1.0), 0.0, -std::cos(1.0)).finished();
  Eigen::VectorXd p = (Eigen::VectorXd(3) << 0.0, 2.5, 0.0).finished();
};

}  // namespace varia::testing
