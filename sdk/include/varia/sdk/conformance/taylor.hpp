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
#include <vector>

#include "varia/abi/jet.hpp"
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

// Jets along the line z + s d at s = eps, one jet variable s: value z + eps d, derivative d.
inline std::vector<Jet2> line_jets(const Eigen::VectorXd& z, const Eigen::VectorXd& d, double eps) {
  std::vector<Jet2> x;
  const Jet2 s = Jet2::variable(0.0, 1, 0);
  for (Eigen::Index i = 0; i < z.size(); ++i) x.push_back(d(i) * s + (z(i) + eps * d(i)));
  return x;
}
// The values (order 0), first or second derivatives along the line of jets.
inline Eigen::VectorXd jet_part(const std::vector<Jet2>& jets, int order) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(jets.size()));
  for (std::size_t i = 0; i < jets.size(); ++i) {
    const Jet2& j = jets[i];
    x(static_cast<Eigen::Index>(i)) = order == 0 ? j.value : j.constant() ? 0.0 : order == 1 ? j.gradient(0) : j.hessian(0, 0);
  }
  return x;
}
// A quantity at jets, jets(eps) along the line z + s d, against the same at doubles, doubles(eps)
// at z + eps d: the values agree, the first derivative passes the Taylor test against the values at
// doubles, and the second against the first derivative at z + eps d.
template <class Jets, class Doubles>
void check_at_jets(Jets&& jets, Doubles&& doubles, const std::string& what, Failures& failures) {
  const std::vector<Jet2> at = jets(0.0);
  const Eigen::VectorXd values = doubles(0.0), first = jet_part(at, 1), second = jet_part(at, 2);
  const double scale = std::max(1.0, values.cwiseAbs().maxCoeff());
  const double gap = (jet_part(at, 0) - values).cwiseAbs().maxCoeff();
  failures.expect(gap <= 1e-13 * scale, what, " at jets: its values differ from those at doubles by ", gap);
  expect_taylor(
      failures, [&](double eps) { return (doubles(eps) - values - eps * first).norm(); }, scale,
      what + " at jets: the first derivative");
  expect_taylor(
      failures, [&](double eps) { return (jet_part(jets(eps), 1) - first - eps * second).norm(); },
      std::max(1.0, first.cwiseAbs().maxCoeff()), what + " at jets: the second derivative");
}

}  // namespace varia::sdk::conformance
