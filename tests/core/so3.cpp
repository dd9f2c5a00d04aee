#include "varia/core/so3.hpp"

#include <doctest/doctest.h>

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <random>
#include <unsupported/Eigen/AutoDiff>
#include <vector>

using namespace varia;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr double pi = std::numbers::pi;

// Unit vectors in random directions, reproducibly.
std::vector<Vector3d> directions(int count) {
  std::mt19937 engine(7);
  std::normal_distribution<double> normal;
  std::vector<Vector3d> out;
  for (int k = 0; k < count; ++k)
    out.push_back(Vector3d(normal(engine), normal(engine), normal(engine)).normalized());
  return out;
}

const std::vector<double> angles = {0.0,   1e-300, 1e-12,     1e-8,       1e-4,       0.01,
                                    0.4999, 0.5,   0.5001,    1.0,        2.0,        3.0,
                                    pi - 1e-4, pi - 1e-8, pi - 1e-12};

}  // namespace

TEST_CASE("so3 exp is a rotation at every angle") {
  for (const Vector3d& n : directions(20))
    for (double theta : angles) {
      const Matrix3d R = so3::exp(Vector3d(theta * n));
      CAPTURE(theta);
      CHECK(so3::orthogonality_error(R) < 4e-15);
      CHECK(std::abs(R.determinant() - 1.0) < 2e-15);
    }
}

TEST_CASE("so3 log inverts exp, including tiny angles and angles near pi") {
  for (const Vector3d& n : directions(20))
    for (double theta : angles) {
      const Vector3d w = theta * n;
      const Vector3d back = so3::log(so3::exp(w));
      CAPTURE(theta);
      CAPTURE((back - w).norm());
      // The axis is defined to round-off relative to the angle's digits; near pi the chart's
      // conditioning is 1/(pi - theta) only in the sign, which the symmetric branch avoids.
      CHECK((back - w).norm() <= 2e-15 * std::max(1.0, theta) + 1e-300);
    }
}

TEST_CASE("so3 log at exactly pi returns a w with exp(w) = R") {
  for (const Vector3d& n : directions(10)) {
    const Matrix3d R = so3::exp(Vector3d(pi * n));
    const Vector3d w = so3::log(R);
    CHECK(std::abs(w.norm() - pi) < 1e-14);
    CHECK((so3::exp(w) - R).norm() < 1e-14);
  }
}

TEST_CASE("so3 dexp times dexp^{-1} is the identity") {
  for (const Vector3d& n : directions(10))
    for (double theta : angles) {
      const Vector3d w = theta * n;
      CAPTURE(theta);
      CHECK((so3::dexp(w) * so3::dexp_inverse(w) - Matrix3d::Identity()).norm() < 1e-14);
    }
}

TEST_CASE("so3 dexp is the derivative of exp: d exp(w + t u)/dt = hat(dexp_w u) exp(w)") {
  using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
  const Vector3d u(0.3, -0.7, 0.2);
  for (const Vector3d& n : directions(5))
    for (double theta : {1e-9, 0.3, 0.5, 2.5}) {
      const Vector3d w = theta * n;
      so3::Vector3<Dual> wt;
      for (int i = 0; i < 3; ++i) wt(i) = Dual(w(i), Eigen::Matrix<double, 1, 1>(u(i)));
      const so3::Matrix3<Dual> E = so3::exp(wt);
      Matrix3d derivative;
      for (int i = 0; i < 9; ++i) derivative(i) = E(i).derivatives()(0);
      const Matrix3d expected = so3::hat(Vector3d(so3::dexp(w) * u)) * so3::exp(w);
      CAPTURE(theta);
      CHECK((derivative - expected).norm() < 1e-14);
    }
}

TEST_CASE("so3 series and closed forms of the coefficients meet at the series bound") {
  const double above = so3::kSeriesBound, below = std::nextafter(above, 0.0);
  CHECK(so3::sinc(below) == doctest::Approx(so3::sinc(above)).epsilon(1e-15));
  CHECK(so3::cosc(below) == doctest::Approx(so3::cosc(above)).epsilon(1e-15));
  CHECK(so3::sinc3(below) == doctest::Approx(so3::sinc3(above)).epsilon(1e-15));
  CHECK(so3::cotc(below) == doctest::Approx(so3::cotc(above)).epsilon(1e-15));
}

TEST_CASE("so3 Cayley maps onto the group and its inverse recovers f") {
  for (const Vector3d& n : directions(10))
    for (double size : {0.0, 1e-10, 0.1, 1.0, 10.0}) {
      const Vector3d f = size * n;
      const Matrix3d F = so3::cayley(f);
      CAPTURE(size);
      CHECK(so3::orthogonality_error(F) < 2e-15);
      CHECK((so3::cayley_inverse(F) - f).norm() <= 4e-15 * std::max(1.0, size * size));
      // cay(f) is the rotation by 2 atan|f| about f.
      CHECK((F - so3::exp(Vector3d(2 * std::atan(size) * n))).norm() < 4e-15);
    }
}

TEST_CASE("so3 trivialize gives the derivative along left-invariant directions") {
  const Matrix3d R = so3::exp(Vector3d(0.4, -1.2, 2.0));
  Matrix3d G;
  G << 1, 2, 3, -4, 5, 6, 0.5, -2, 1;
  const Vector3d tau = so3::trivialize(R, G);
  for (int a = 0; a < 3; ++a) {
    const Matrix3d direction = R * so3::hat(Vector3d(Vector3d::Unit(a)));
    CHECK(tau(a) == doctest::Approx((G.array() * direction.array()).sum()).epsilon(1e-15));
  }
}
