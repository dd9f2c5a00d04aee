// SE(3) as a plugin (plugins/manifold/SE3.cpp) with the spring-suspended body
// (plugins/lagrangian/spring_suspended_body.cpp): the Lie group constructions, written against
// the manifold interface only, serve a second group. Galerkin in the natural chart (paper, sec. 2)
// of degree s with s Gauss-Legendre points is of order 2s; its discrete Noether momentum (the
// vertical angular momentum about the anchor) is conserved. Crouch-Grossman on the Euler-Poincare
// field (core/lie_group_field.hpp), as the one-step construction and inside the shooting
// construction, is of its own order; only the shooting L_d (G-invariant: the method is
// left-equivariant) conserves the momentum.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <memory>
#include <vector>

#include "load_plugin.hpp"
#include "varia/core/galerkin_chart.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/core/one_step_map.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/shooting.hpp"

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
  varia::test::LoadedPlugin method_file = load_plugin("one_step", "crouch_grossman");
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
  std::shared_ptr<varia::OneStepMethod> crouch_grossman(int order) {
    return method_file.create<varia::OneStepMethod>(json{{"order", order}}, kContext);
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

// The error at T = 1 after `steps` steps of `map`: |log(q_ref^{-1} q)| and the momenta's largest
// difference, against Lie group Galerkin s = 4 (order 8) at h = 1/80, converged to ~1e-16.
struct ConvergedReference {
  SpringBody& system;
  std::vector<double> q, p;
  explicit ConvergedReference(SpringBody& s) : system(s) {
    auto rule = system.gauss(4);
    auto reference = system.galerkin(4, *rule);
    system.run(*reference, 1.0 / 80, 80, q, p, [](auto&, auto&) {});
  }
  double error(varia::DiscreteHamiltonianMap& map, int steps) {
    std::vector<double> qk, pk, xi(6);
    system.run(map, 1.0 / steps, steps, qk, pk, [](auto&, auto&) {});
    REQUIRE(system.group->local(q.data(), qk.data(), xi.data()) == nullptr);
    double e = Eigen::Map<Eigen::VectorXd>(xi.data(), 6).norm();
    for (int i = 0; i < 6; ++i) e = std::max(e, std::abs(pk[i] - p[i]));
    return e;
  }
  // The order fitted from the errors at 10, 20, 40, 80 steps (least squares in log-log).
  double order(varia::DiscreteHamiltonianMap& map, const char* what) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const int counts[] = {10, 20, 40, 80};
    std::ostringstream errors;
    errors << std::scientific << std::setprecision(3);
    for (int steps : counts) {
      const double e = error(map, steps), x = std::log(1.0 / steps), y = std::log(e);
      sx += x, sy += y, sxx += x * x, sxy += x * y;
      errors << " " << e;
    }
    const double slope = (4 * sxy - sx * sy) / (4 * sxx - sx * sx);
    MESSAGE(std::string(what) << ": errors" << errors.str() << "; order " << slope);
    return slope;
  }
};

}  // namespace

TEST_CASE("SE3 spring-suspended body: Lie group Galerkin s = 1, 2, 3 is of order 2, 4, 6 against a converged reference") {
  SpringBody system;
  ConvergedReference reference(system);
  for (int s = 1; s <= 3; ++s) {
    auto rule = system.gauss(s);
    auto map = system.galerkin(s, *rule);
    const std::vector<double> errors = {reference.error(*map, 20), reference.error(*map, 40)};
    const double order = std::log2(errors[0] / errors[1]);
    MESSAGE("s = " << s << ": errors " << errors[0] << ", " << errors[1] << "; order " << order);
    CHECK(order == doctest::Approx(2 * s).epsilon(0.3 / (2 * s)));
  }
}

TEST_CASE("SE3 spring-suspended body: Crouch-Grossman of order 2 and 3, as one-step and inside shooting, against a converged reference") {
  SpringBody system;
  ConvergedReference reference(system);
  auto rule = system.gauss(2);  // order 4: the shooting L_d is of the method's order
  for (int order : {2, 3}) {
    auto method = system.crouch_grossman(order);
    varia::OneStepHamiltonianMap one_step(*system.group, *system.body, *method, varia::SolverOptions{});
    CHECK(reference.order(one_step, order == 2 ? "one-step CG2" : "one-step CG3") == doctest::Approx(order).epsilon(0.15));
    varia::ShootingDiscreteLagrangian shooting(*system.group, *system.body, *rule, *method,
                                               varia::ShootingForm::lagrangian, varia::SolverOptions{});
    CHECK(reference.order(shooting, order == 2 ? "shooting CG2" : "shooting CG3") == doctest::Approx(order).epsilon(0.15));
  }
}

// The vertical angular momentum about the anchor is the Noether momentum of the declared symmetry:
// conserved to round-off by a G-invariant L_d (Galerkin in the natural chart; shooting with the
// left-equivariant Crouch-Grossman); about any other vertical axis it is not (the spring's torque
// about it), nor by Crouch-Grossman run directly (equivariant, but not variational).
struct MomentumDrift {
  double about_anchor = 0.0, about_other = 0.0, J0 = 0.0;
};
MomentumDrift momentum_drift(SpringBody& system, varia::DiscreteHamiltonianMap& map, int steps) {
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
  MomentumDrift d;
  double K0 = 0;
  momenta(system.q0, system.p0, d.J0, K0);
  std::vector<double> q, p;
  system.run(map, 0.05, steps, q, p, [&](const auto& qk, const auto& pk) {
    double J = 0, K = 0;
    momenta(qk, pk, J, K);
    d.about_anchor = std::max(d.about_anchor, std::abs(J - d.J0));
    d.about_other = std::max(d.about_other, std::abs(K - K0));
  });
  return d;
}

TEST_CASE("SE3 spring-suspended body: Galerkin conserves the vertical angular momentum about the anchor, not about another axis") {
  SpringBody system;
  auto rule = system.gauss(2);
  auto map = system.galerkin(2, *rule);
  const MomentumDrift d = momentum_drift(system, *map, 2000);
  MESSAGE("2000 steps of h = 0.05: |J - J0| max " << d.about_anchor << " (J0 = " << d.J0 << "); about (0.7, -0.4): " << d.about_other);
  CHECK(d.about_anchor < 1e-13 * std::max(1.0, std::abs(d.J0)));
  CHECK(d.about_other > 1e-3);
}

TEST_CASE("SE3 spring-suspended body: shooting with Crouch-Grossman conserves the momentum about the anchor, Crouch-Grossman alone does not") {
  SpringBody system;
  auto rule = system.gauss(2);
  auto method = system.crouch_grossman(3);
  varia::ShootingDiscreteLagrangian shooting(*system.group, *system.body, *rule, *method,
                                             varia::ShootingForm::lagrangian, varia::SolverOptions{});
  const MomentumDrift conserved = momentum_drift(system, shooting, 400);
  MESSAGE("shooting, 400 steps of h = 0.05: |J - J0| max " << conserved.about_anchor << "; about (0.7, -0.4): " << conserved.about_other);
  CHECK(conserved.about_anchor < 1e-13 * std::max(1.0, std::abs(conserved.J0)));
  CHECK(conserved.about_other > 1e-3);
  varia::OneStepHamiltonianMap one_step(*system.group, *system.body, *method, varia::SolverOptions{});
  const MomentumDrift drifting = momentum_drift(system, one_step, 400);
  MESSAGE("one-step, 400 steps of h = 0.05: |J - J0| max " << drifting.about_anchor);
  CHECK(drifting.about_anchor > 1e-8);
}
