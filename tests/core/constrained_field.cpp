// The constrained field and its projection (varia/core/constrained_field.hpp) against central
// differences of their values at doubles: the Jacobian an implicit method's stages take, the
// first and second derivatives at jets that the shooting construction's shot carries, and the
// one-step map's tangent map, which steps jets through both.
#include "varia/core/constrained_field.hpp"

#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/constraint_fixtures.hpp"
#include "core/shooting_fixtures.hpp"
#include "core/tangent_differences.hpp"
#include "varia/core/one_step_map.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

// A bead of masses (1, 2, 3) in a potential with a configuration-dependent force:
// L = (v1^2 + 2 v2^2 + 3 v3^2)/2 - q3 - 0.3 q1 q2^2 (a constant mass matrix, L_qq not zero).
struct Bead : sdk::AutodiffLagrangian<Bead, 3, 3> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    return 0.5 * (v(0) * v(0) + 2.0 * v(1) * v(1) + 3.0 * v(2) * v(2)) - q(2) - 0.3 * q(0) * q(1) * q(1);
  }
};

constexpr double kEps = 1e-5;

template <class Sphere = UnitSphere>
struct Setup {
  Bead bead;
  LagrangianEvaluator lagrangian{bead};
  Sphere sphere;
  HolonomicConstraints constraints{{&sphere}, 3};
  ConstrainedField field{lagrangian, constraints};
  // A state off the sphere and its tangent space: the field is defined on all of R^6.
  Eigen::VectorXd y = (Eigen::VectorXd(6) << 0.5, -0.4, -0.8, 0.7, 1.1, -0.3).finished();

  Eigen::VectorXd rate(const Eigen::VectorXd& z) {
    Eigen::VectorXd f(6);
    REQUIRE(field.eval(z.data(), f.data()) == nullptr);
    return f;
  }
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& z) {
    Eigen::VectorXd f(6);
    Eigen::MatrixXd J(6, 6);
    REQUIRE(field.jacobian(z.data(), f.data(), J.data()) == nullptr);
    return J;
  }
  // |J - central differences of the field| at y.
  double jacobian_deviation() {
    Eigen::MatrixXd differences(6, 6);
    for (int k = 0; k < 6; ++k) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, k) * kEps;
      differences.col(k) = (rate(y + e) - rate(y - e)) / (2 * kEps);
    }
    const Eigen::MatrixXd deviation = jacobian(y) - differences;
    return deviation.lpNorm<Eigen::Infinity>();
  }
};

// The 6 state numbers as jets of 6 variables.
std::vector<Jet2> seeded(const Eigen::VectorXd& z) {
  std::vector<Jet2> jets;
  for (int k = 0; k < 6; ++k) jets.push_back(Jet2::variable(z[k], 6, k));
  return jets;
}

}  // namespace

TEST_CASE("the constrained field's Jacobian (a quadratic constraint) equals central differences of the field") {
  Setup<> s;
  const double error = s.jacobian_deviation();
  MESSAGE("|J - differences| = ", error);
  CHECK(error <= 1e-8);
  CHECK(s.jacobian(s.y).bottomLeftCorner(3, 3).lpNorm<Eigen::Infinity>() >= 0.1);  // the multiplier's q-derivatives enter
}

// Not quadratic: the multiplier's derivative in q takes the constraint's curvature derivative
// (Constraint::curvature_derivative), without which the q-columns would differ by W S^-1 C.
TEST_CASE("the constrained field's Jacobian (a quartic constraint, with its curvature derivative) equals central "
          "differences of the field") {
  Setup<QuarticSphere> s;
  const double error = s.jacobian_deviation();
  MESSAGE("|J - differences| = ", error);
  CHECK(error <= 1e-8);
  // Where it must not hold: a wrong curvature derivative moves the Jacobian off the differences.
  s.sphere.cross = 3.0;
  CHECK(s.jacobian_deviation() >= 1e-3);
}

TEST_CASE("at jets the constrained field gives its value, its Jacobian and the differences of its Jacobian") {
  Setup<> s;
  const std::vector<Jet2> y = seeded(s.y);
  std::vector<Jet2> f(6);
  REQUIRE(s.field.eval(y.data(), f.data()) == nullptr);
  const Eigen::VectorXd rate = s.rate(s.y);
  const Eigen::MatrixXd J = s.jacobian(s.y);
  double value_error = 0.0, first_error = 0.0, second_error = 0.0;
  for (int l = 0; l < 6; ++l) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, l) * kEps;
    const Eigen::MatrixXd dJ = (s.jacobian(s.y + e) - s.jacobian(s.y - e)) / (2 * kEps);
    for (int i = 0; i < 6; ++i)
      for (int k = 0; k < 6; ++k) second_error = std::max(second_error, std::abs(f[i].hessian(k, l) - dJ(i, k)));
  }
  for (int i = 0; i < 6; ++i) {
    value_error = std::max(value_error, std::abs(f[i].value - rate[i]));
    first_error = std::max(first_error, (f[i].gradient.transpose() - J.row(i)).lpNorm<Eigen::Infinity>());
  }
  MESSAGE("values ", value_error, ", first derivatives ", first_error, ", second derivatives ", second_error);
  CHECK(value_error <= 1e-14);
  CHECK(first_error <= 1e-12);
  CHECK(second_error <= 1e-7);
}

TEST_CASE("the projection at jets differentiates the projection at doubles, to second order") {
  Setup<> s;
  const SolverOptions options;
  const Eigen::VectorXd start = (Eigen::VectorXd(6) << 0.52, -0.41, -0.79, 0.7, 1.1, -0.3).finished();  // |q| = 1.02
  const auto projected = [&](const Eigen::VectorXd& z) {
    Eigen::VectorXd out = z;
    s.field.project(out.data(), out.data() + 3, options);
    return out;
  };
  std::vector<Jet2> y = seeded(start);
  s.field.project(y.data(), y.data() + 3, options);
  const Eigen::VectorXd at = projected(start);
  CHECK(std::abs(at.head(3).norm() - 1.0) <= 1e-14);
  CHECK(std::abs(at.head(3).dot(at.tail(3))) <= 1e-14);
  double value_error = 0.0, first_error = 0.0, second_error = 0.0;
  for (int k = 0; k < 6; ++k) {
    const Eigen::VectorXd e = Eigen::VectorXd::Unit(6, k) * kEps;
    const Eigen::VectorXd plus = projected(start + e), minus = projected(start - e);
    for (int i = 0; i < 6; ++i) {
      first_error = std::max(first_error, std::abs(y[i].gradient[k] - (plus[i] - minus[i]) / (2 * kEps)));
      second_error = std::max(second_error, std::abs(y[i].hessian(k, k) - (plus[i] - 2 * at[i] + minus[i]) / (kEps * kEps)));
    }
  }
  for (int i = 0; i < 6; ++i) value_error = std::max(value_error, std::abs(y[i].value - at[i]));
  MESSAGE("values ", value_error, ", first derivatives ", first_error, ", second derivatives (diagonal) ", second_error);
  CHECK(value_error <= 1e-14);
  CHECK(first_error <= 1e-9);
  CHECK(second_error <= 1e-4);  // second differences carry round-off of about 1e-16 / eps^2 = 1e-6
}

TEST_CASE("the one-step map's tangent map with a quadratic constraint (the index-1 field and the projection at jets) "
          "equals differences of its projected steps, under rk4 and the 2-stage Gauss method, and with a constraint "
          "that is not quadratic it is refused") {
  SphericalPendulum s;
  for (sdk::RungeKutta method : {rk4(), gauss2()}) {
    OneStepHamiltonianMap map(s.space, s.mass, method, SolverOptions{}, &s.constraints);
    REQUIRE(map.tangent_map_refusal().empty());
    const TangentCase t = tangent_and_differences(s.space, map, s.q, s.p, 0.0, 0.05);
    const double difference = (t.exact - t.differences).cwiseAbs().maxCoeff();
    MESSAGE("largest difference from the differences ", difference);
    CHECK(difference <= 1e-9);
    CHECK((t.exact - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff() >= 1e-2);
  }
  QuarticSphere quartic;
  HolonomicConstraints not_quadratic({&quartic}, 3);
  sdk::RungeKutta method = rk4();
  OneStepHamiltonianMap map(s.space, s.mass, method, SolverOptions{}, &not_quadratic);
  CHECK(map.tangent_map_refusal().find("quadratic constraints only") != std::string::npos);
}
