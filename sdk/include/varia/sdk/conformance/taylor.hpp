// What the conformance suites share: random points, and the Taylor test of a derivative against
// the object's own values. With f the values and f' the derivative the object claims at x, the
// remainder r(eps) = |f(x + eps d) - f(x) - eps f'(x) d| of the first-order model falls as eps^2
// when f' is right, and only as eps when it is wrong (a gradient scaled by 1.5 leaves 0.5 eps f' d).
// No finite-difference step to tune and no tolerance on the derivative itself. The remainder is
// taken at eps = 1e-2, 5e-3, ... (halving): the derivative passes when two consecutive slopes
// log2(r(eps) / r(eps/2)) are 2 (within 0.2) above the round-off floor, or when the remainder is at
// round-off already (f is affine along d, and the model is exact). Halving finds the asymptotic
// range also near a singularity (two attracting particles close together), where eps = 1e-2 is
// too coarse.
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
// `claim` when the remainder does not fall as eps^2, with the slope it falls at (at the smallest
// eps above round-off).
template <class Remainder>
void expect_taylor(Failures& failures, Remainder&& remainder, double scale, const std::string& claim) {
  const double floor = 1e-12 * scale;
  double eps = 1e-2, coarse = remainder(eps), slope = NAN;
  if (!std::isfinite(coarse)) return failures.expect(false, claim, ": not finite at eps = ", eps);
  if (coarse <= floor) return;  // the first-order model is exact to round-off
  int near_two = 0;             // consecutive slopes near 2
  for (int halving = 0; halving < 24; ++halving) {
    eps /= 2;
    const double fine = remainder(eps);
    if (!std::isfinite(fine)) return failures.expect(false, claim, ": not finite at eps = ", eps);
    // At round-off: right if it got there falling as eps^2 (or at once, from near round-off).
    if (fine <= floor && (near_two > 0 || halving == 0)) return;
    if (fine <= floor) break;
    slope = std::log2(coarse / fine);
    near_two = std::abs(slope - 2.0) < 0.2 ? near_two + 1 : 0;
    if (near_two == 2) return;
    coarse = fine;
  }
  failures.expect(false, claim, ": the first-order model's error falls as eps^", slope, " (expected eps^2)");
}

}  // namespace varia::sdk::conformance
