// A map's exact tangent map (discrete_hamiltonian_map.hpp: step_with_tangent) beside sixth-order
// central differences of its steps, for the tests that compare them (tests/core/tangent_map.cpp,
// constrained_field.cpp).
#pragma once

#include <doctest/doctest.h>

#include <Eigen/Core>

#include "varia/abi/manifold.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"

namespace varia::testing {

struct TangentCase {
  Eigen::MatrixXd exact, differences;
};

// The map's tangent map at (q0, p0, t0) with step h, and its sixth-order central differences
// (difference step d in every coordinate) of the step's (q1, p1). The directions' q parts are the
// natural chart's at q0, the curves retract(q0, e x), and the images' at q1, local(q1, .) of the
// perturbed steps' ends (on R^n, q0 + x and q - q1).
inline TangentCase tangent_and_differences(Manifold& manifold, DiscreteHamiltonianMap& map,
                                           const Eigen::VectorXd& q0, const Eigen::VectorXd& p0, double t0, double h,
                                           double d = 1e-3) {
  const int m = static_cast<int>(q0.size()), n = static_cast<int>(p0.size()), size = 2 * n;
  TangentCase result{Eigen::MatrixXd(size, size), Eigen::MatrixXd(size, size)};
  Eigen::VectorXd q1(m), p1(n);
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(size, size);
  map.step_with_tangent(q0.data(), p0.data(), t0, h, q1.data(), p1.data(), size, identity.data(), result.exact.data());
  const auto step = [&](const Eigen::VectorXd& x) {  // x = (chart coordinates at q0, p)
    Eigen::VectorXd q(m), a(m), b(n), y(size);
    REQUIRE(manifold.retract(q0.data(), x.data(), q.data()) == nullptr);
    map.step(q.data(), x.data() + n, t0, h, a.data(), b.data());
    REQUIRE(manifold.local(q1.data(), a.data(), y.data()) == nullptr);
    y.tail(n) = b;
    return y;
  };
  Eigen::VectorXd x0(size);
  x0 << Eigen::VectorXd::Zero(n), p0;
  for (int j = 0; j < size; ++j) {
    const Eigen::VectorXd e = d * identity.col(j);
    result.differences.col(j) = (-step(x0 - 3 * e) + 9 * step(x0 - 2 * e) - 45 * step(x0 - e) + 45 * step(x0 + e) -
                                 9 * step(x0 + 2 * e) + step(x0 + 3 * e)) /
                                (60 * d);
  }
  return result;
}

}  // namespace varia::testing
