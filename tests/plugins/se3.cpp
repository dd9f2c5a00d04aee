// SE(3) as a plugin (plugins/manifold/SE3.cpp) with the spring-suspended body
// (plugins/lagrangian/spring_suspended_body.cpp): the Lie group constructions, written against
// the manifold interface only, serve a second group. Galerkin in the natural chart (paper, sec. 2)
// of degree s with s Gauss-Legendre points is of order 2s; its discrete Noether momentum (the
// vertical angular momentum about the anchor) is conserved.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <vector>

#include "load_plugin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/lagrangian.hpp"
#include "varia/core/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/quadrature.hpp"

namespace {

using nlohmann::json;
using varia::test::load_plugin;

const json kContext = {{"manifold", "SE3"}, {"point_size", 12}, {"dim", 6}};
const json kBody = {{"inertia", {1, 2, 3}}, {"mass", 1}, {"attachment", {0, 0, 0.5}}, {"anchor", {0, 0, 0}},
                    {"stiffness", 10}, {"rest_length", 1}, {"gravity", 1}};

// The scene scenes/se3/spring-body-galerkin-s2.json: R a rotation by 0.3 about e1, x below the
// anchor, v = (Omega, R^T x').
struct SpringBody {
  varia::test::LoadedPlugin manifold_file = load_plugin("manifold", "SE3");
  varia::test::LoadedPlugin body_file = load_plugin("lagrangian", "spring_suspended_body");
  varia::test::LoadedPlugin rule_file = load_plugin("quadrature", "gauss_legendre");
  std::shared_ptr<varia::Manifold> group = manifold_file.create<varia::Manifold>(json::object(), kContext);
  std::shared_ptr<varia::Lagrangian> body = body_file.create<varia::Lagrangian>(kBody, kContext);
  std::vector<double> q0, p0;

  SpringBody() {
    const double c = std::cos(0.3), s = std::sin(0.3);
    q0 = {1, 0, 0, 0, c, -s, 0, s, c, 0.3, 0.0, -1.5};
    const std::vector<double> v0 = {0.4, 0.8, -0.6, 0.5, -0.3, 0.2};
    p0.resize(6);
    varia::LagrangianEvaluator(*body).legendre(q0.data(), v0.data(), p0.data());
  }
  std::unique_ptr<varia::LieGroupGalerkinDiscreteLagrangian> galerkin(int degree, varia::Quadrature& rule) {
    return std::make_unique<varia::LieGroupGalerkinDiscreteLagrangian>(
        *group, *body, rule, varia::equispaced_control_times(degree), varia::SolverOptions{});
  }
  std::shared_ptr<varia::Quadrature> gauss(int points) {
    return rule_file.create<varia::Quadrature>(json{{"points", points}}, kContext);
  }
  // (q, p) after `steps` steps of h from (q0, p0); observe(q, p) after each.
  template <class Observe>
  void run(varia::DiscreteHamiltonianMap& map, double h, int steps, std::vector<double>& q, std::vector<double>& p,
           Observe&& observe) {
    q = q0;
    p = p0;
    std::vector<double> q1(12), p1(6);
    for (int k = 0; k < steps; ++k) {
      map.step(q.data(), p.data(), h, q1.data(), p1.data());
      q.swap(q1);
      p.swap(p1);
      observe(q, p);
    }
  }
};

}  // namespace

TEST_CASE("SE3 spring-suspended body: Lie group Galerkin s = 1, 2, 3 is of order 2, 4, 6 against a converged reference") {
  SpringBody system;
  const double T = 1.0;
  auto reference_rule = system.gauss(4);
  auto reference = system.galerkin(4, *reference_rule);  // order 8 at h = 1/80: error ~1e-16
  std::vector<double> q_ref, p_ref;
  system.run(*reference, T / 80, 80, q_ref, p_ref, [](auto&, auto&) {});
  for (int s = 1; s <= 3; ++s) {
    auto rule = system.gauss(s);
    auto map = system.galerkin(s, *rule);
    std::vector<double> errors;
    for (int steps : {10, 20, 40}) {
      std::vector<double> q, p, xi(6);
      system.run(*map, T / steps, steps, q, p, [](auto&, auto&) {});
      REQUIRE(system.group->local(q_ref.data(), q.data(), xi.data()) == nullptr);
      double error = Eigen::Map<Eigen::VectorXd>(xi.data(), 6).norm();
      for (int i = 0; i < 6; ++i) error = std::max(error, std::abs(p[i] - p_ref[i]));
      errors.push_back(error);
    }
    const double order = std::log2(errors[1] / errors[2]);
    MESSAGE("s = " << s << ": errors " << errors[0] << ", " << errors[1] << ", " << errors[2] << "; order " << order);
    CHECK(order == doctest::Approx(2 * s).epsilon(0.3 / (2 * s)));
  }
}

// The vertical angular momentum about the anchor is the Noether momentum of the declared symmetry:
// conserved to round-off; about any other vertical axis it is not (the spring's torque about it).
TEST_CASE("SE3 spring-suspended body: Galerkin conserves the vertical angular momentum about the anchor, not about another axis") {
  SpringBody system;
  auto rule = system.gauss(2);
  auto map = system.galerkin(2, *rule);
  const Eigen::Matrix<double, 6, 1> inverse_mass(1, 0.5, 1.0 / 3, 1, 1, 1);
  const auto momenta = [&](const std::vector<double>& q, const std::vector<double>& p, double& about_anchor,
                           double& about_other) {
    Eigen::Matrix<double, 6, 1> v = inverse_mass.cwiseProduct(Eigen::Map<const Eigen::Matrix<double, 6, 1>>(p.data()));
    REQUIRE(system.body->momentum(q.data(), v.data(), &about_anchor) == nullptr);
    const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(q.data());
    const Eigen::Vector3d x(q[9], q[10], q[11]), other(0.7, -0.4, 0.0);
    const Eigen::Vector3d spatial =
        (x - other).cross(R * v.tail<3>()) + R * Eigen::Vector3d(1, 2, 3).cwiseProduct(v.head<3>());
    about_other = spatial(2);
  };
  double J0 = 0, K0 = 0;
  momenta(system.q0, system.p0, J0, K0);
  double drift = 0.0, other_drift = 0.0;
  std::vector<double> q, p;
  system.run(*map, 0.05, 2000, q, p, [&](const auto& qk, const auto& pk) {
    double J = 0, K = 0;
    momenta(qk, pk, J, K);
    drift = std::max(drift, std::abs(J - J0));
    other_drift = std::max(other_drift, std::abs(K - K0));
  });
  MESSAGE("2000 steps of h = 0.05: |J - J0| max " << drift << " (J0 = " << J0 << "); about (0.7, -0.4): " << other_drift);
  CHECK(drift < 1e-13 * std::max(1.0, std::abs(J0)));
  CHECK(other_drift > 1e-3);
}
