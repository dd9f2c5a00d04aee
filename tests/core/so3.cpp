#include "varia/core/so3.hpp"

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <unsupported/Eigen/AutoDiff>
#include <vector>

#include "core/fixtures.hpp"
#include "varia/core/lie_verlet.hpp"

using namespace varia;
using varia::testing::Rotations;
using varia::testing::Top;
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

// Rotations by theta = pi - delta, delta = 1e-3 .. 1e-8, built independently of so3:: from the unit
// quaternion (sin(delta/2), cos(delta/2) n) by Eigen's Quaterniond; theta n and tan(theta/2) n =
// n / tan(delta/2) are then known to round-off without forming pi - delta's complement.
TEST_CASE("so3 log and the Cayley inverse within 1e-8 .. 1e-3 of pi against independent formulas") {
  double worst_log = 0, worst_exp = 0, worst_cayley = 0, worst_round_trip = 0;
  for (const Vector3d& n : directions(20))
    for (double delta : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
      const Eigen::Quaterniond quaternion(std::sin(delta / 2), std::cos(delta / 2) * n.x(),
                                          std::cos(delta / 2) * n.y(), std::cos(delta / 2) * n.z());
      const Matrix3d R = quaternion.toRotationMatrix();
      const Vector3d w = so3::log(R);
      const Vector3d f = so3::cayley_inverse(R), f_exact = n / std::tan(delta / 2);
      CAPTURE(delta);
      worst_log = std::max(worst_log, (w - (pi - delta) * n).norm());
      worst_exp = std::max(worst_exp, (so3::exp(w) - R).norm());
      worst_cayley = std::max(worst_cayley, (f - f_exact).norm() / f_exact.norm() / (1e-16 / delta));
      worst_round_trip = std::max(worst_round_trip, (so3::cayley(f) - R).norm());
    }
  MESSAGE("near pi: |log R - theta n| ", worst_log, ", ||exp(log R) - R|| ", worst_exp,
          ", |cay^-1 R - f|/|f| in units of 1e-16/delta ", worst_cayley, ", ||cay(cay^-1 R) - R|| ",
          worst_round_trip);
  CHECK(worst_log < 4e-15);
  CHECK(worst_exp < 4e-15);
  // tan(theta/2) n has condition 1/delta in theta; vee(F - F^T)/(1 + tr F) alone lost 1/delta^2
  // (infinite at delta = 1e-8, where 1 + tr F rounds to 0).
  CHECK(worst_cayley < 4);
  CHECK(worst_round_trip < 4e-15);
}

// The free body J = (1, 2, 3) spinning about its principal axis e3 at omega = 0.01 takes, with
// h = 0.01, LGVI steps F = rotation about e3 by phi = asin(h omega) (paper, sec. 2 example:
// vee(F J_d - J_d F^T) = h Pi has third component (d1 + d2) sin phi = J3 sin phi). From
// R0 = Rz(pi - 2e-3 + 5e-9), R_k = Rz(pi - 2e-3 + 5e-9 + k phi) passes through half a turn in 40 steps,
// at angles 1e-4 .. 1e-3 and 5e-9 from pi.
TEST_CASE("lgvi turning a body through a half turn keeps orthogonality at round-off and log exact") {
  for (auto solver : {LieVerletSolver::cayley, LieVerletSolver::exp}) {
    Rotations group;
    Top body(Vector3d(1, 2, 3), 0.0, Vector3d::Zero());
    LieGroupVelocityVerlet lgvi(group, body, solver, {});
    const double h = 0.01, omega = 0.01, theta0 = pi - 2e-3 + 5e-9, phi = std::asin(h * omega);
    const auto rz = [](double a) {
      Matrix3d R;
      R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
      return R;
    };
    std::array<double, 9> q, q1;
    std::array<double, 3> p = {0.0, 0.0, 3 * omega}, p1;
    so3::to_row_major(rz(theta0), q.data());
    double orthogonality = 0, attitude = 0, logarithm = 0, closest = 1;
    for (int k = 1; k <= 40; ++k) {
      lgvi.step(q.data(), p.data(), h, q1.data(), p1.data());
      q = q1;
      p = p1;
      const Matrix3d R = so3::from_row_major(q.data());
      const double angle = theta0 + k * phi;  // in (pi - 2e-3, pi + 2e-3)
      orthogonality = std::max(orthogonality, so3::orthogonality_error(R));
      attitude = std::max(attitude, (R - rz(angle)).norm());
      // log R = angle e3 below pi, (angle - 2 pi) e3 past it.
      const double wrapped = angle <= pi ? angle : angle - 2 * pi;
      logarithm = std::max(logarithm, (so3::log(R) - wrapped * Vector3d::UnitZ()).norm());
      closest = std::min(closest, std::abs(angle - pi));
    }
    MESSAGE(std::string(solver == LieVerletSolver::cayley ? "cayley" : "exp"), ": half turn, closest to pi ",
            closest, ", max ||I - R^T R|| ", orthogonality, ", max ||R - Rz|| ", attitude,
            ", max |log R - w| ", logarithm);
    CHECK(closest < 1e-8);
    CHECK(orthogonality < 4e-15);
    CHECK(attitude < 1e-14);
    CHECK(logarithm < 1e-14);
  }
}
