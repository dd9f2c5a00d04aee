// What the conformance suites share: random points, and the Taylor test of a derivative against
// the object's own values. With f the values and f' the derivative the object claims at x, the
// remainder r(eps) = |f(x + eps d) - f(x) - eps f'(x) d| of the first-order model falls as eps^2
// when f' is right, and only as eps when it is wrong (a gradient scaled by 1.5 leaves 0.5 eps f' d).
// No finite-difference step to tune and no tolerance on the derivative itself: the slope between
// eps = 1e-2 and 5e-3 must be 2, unless the remainder is at round-off already (f is affine along
// d, and the model is exact).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <string>

#include "varia/sdk/conformance/failures.hpp"

namespace varia::sdk::conformance {

// Components of magnitude in [0.5, 1.5] with random signs: away from the origin (kepler).
inline Eigen::VectorXd random_point(int size, std::mt19937& engine) {
  std::uniform_real_distribution<double> magnitude(0.5, 1.5);
  Eigen::VectorXd x(size);
  for (int i = 0; i < size; ++i) x(i) = (engine() % 2 ? 1 : -1) * magnitude(engine);
  return x;
}

// A random unit direction.
inline Eigen::VectorXd random_direction(int size, std::mt19937& engine) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd d(size);
  for (int i = 0; i < size; ++i) d(i) = normal(engine);
  return d.normalized();
}

// The Taylor test: remainder(eps) is the norm of the first-order model's error at eps, `scale` the
// size of the values it is made of (for the round-off floor). Records a failure beginning with
// `claim` when the remainder falls other than as eps^2.
template <class Remainder>
void expect_taylor(Failures& failures, Remainder&& remainder, double scale, const std::string& claim) {
  const double coarse = remainder(1e-2), fine = remainder(5e-3);
  if (!std::isfinite(coarse) || !std::isfinite(fine)) return failures.expect(false, claim, ": not finite");
  if (coarse <= 1e-11 * scale) return;  // the first-order model is exact to round-off
  const double slope = std::log2(coarse / fine);
  failures.expect(std::abs(slope - 2.0) < 0.2, claim, ": the first-order model's error falls as eps^", slope,
                  " (expected eps^2)");
}

}  // namespace varia::sdk::conformance
