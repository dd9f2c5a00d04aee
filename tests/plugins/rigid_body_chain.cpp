// The rigid-body-chain Lagrangian (plugins/lagrangian/rigid_body_chain.cpp): the Lagrangian
// conformance suite on chains of one to three bodies; one body is the heavy top with the inertia
// about the pivot (parallel axes: J_pivot = J + m (|com|^2 I - com com^T)) on the group: in value,
// momentum, dL/dOmega, d2L/dOmega2 and the left-trivialized dL/dR (the derivative along R hat(e_a)),
// to round-off (off the group, in the embedding's other directions, the two differ: the chain's
// |R (Omega x com)|^2 is |Omega x com|^2 only where R is orthogonal); tests/host/multibody.cpp
// compares their motions. A chain refuses a product with the wrong number of factors.
#include <doctest/doctest.h>

#include <random>
#include <string>

#include "load_plugin.hpp"
#include "varia/core/so3.hpp"
#include "varia/sdk/conformance/lagrangian.hpp"

namespace {

using Eigen::VectorXd;
using nlohmann::json;
using varia::Lagrangian;

json product_of_so3(int bodies) {
  std::string name = "product(SO3";
  for (int i = 1; i < bodies; ++i) name += ",SO3";
  return {{"manifold", name + ")"}, {"point_size", 9 * bodies}, {"dim", 3 * bodies}};
}

const json kBodies = json::array({
    {{"mass", 1.0}, {"inertia", {0.10, 0.12, 0.05}}, {"com", {0, 0, -0.5}}, {"next", {0, 0, -1}}},
    {{"mass", 0.8}, {"inertia", {0.08, 0.06, 0.04}}, {"com", {0.05, 0, -0.4}}, {"next", {0, 0, -0.8}}},
    {{"mass", 0.5}, {"inertia", {0.03, 0.04, 0.02}}, {"com", {0, 0.05, -0.3}}, {"next", {0.1, 0, -0.6}}},
});

std::shared_ptr<Lagrangian> chain(varia::test::LoadedPlugin& file, int bodies, double gravity = 1.3) {
  json first(kBodies.begin(), kBodies.begin() + bodies);
  return file.create<Lagrangian>({{"bodies", first}, {"gravity", gravity}}, product_of_so3(bodies));
}

double relative_gap(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
}

// The left-trivialized derivative along the group, <dL/dR, R hat(e_a)>, a = 1..3, from the gradient
// in the 9 numbers of R (row-major).
Eigen::Vector3d along_group(const VectorXd& q, const VectorXd& gradient) {
  const Eigen::Matrix3d R = varia::so3::from_row_major(q.data());
  Eigen::Vector3d d;
  for (int a = 0; a < 3; ++a) {
    Eigen::Matrix3d tangent = R * varia::so3::hat(Eigen::Vector3d(Eigen::Vector3d::Unit(a)));
    double sum = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) sum += gradient(3 * i + j) * tangent(i, j);
    d(a) = sum;
  }
  return d;
}

}  // namespace

TEST_CASE("rigid-body-chain passes the Lagrangian conformance suite with one, two and three bodies") {
  auto file = varia::test::load_plugin("lagrangian", "rigid_body_chain");
  std::mt19937 engine(20261129);
  for (int bodies = 1; bodies <= 3; ++bodies) {
    CAPTURE(bodies);
    const auto L = chain(file, bodies);
    CHECK(L->position_size() == 9 * bodies);
    CHECK(L->velocity_size() == 3 * bodies);
    const auto failures = varia::sdk::conformance::check_lagrangian(*L, engine, 5);
    for (const auto& failure : failures.list()) FAIL_CHECK(failure);
    CHECK(failures.empty());
  }
}

TEST_CASE("rigid-body-chain with one body is the heavy top with its inertia about the pivot, to round-off") {
  auto chain_file = varia::test::load_plugin("lagrangian", "rigid_body_chain");
  auto top_file = varia::test::load_plugin("lagrangian", "heavy_top");
  const double m = 1.7, g = 1.3;
  const Eigen::Vector3d J(0.10, 0.12, 0.05), com(0, 0, -0.5);
  const Eigen::Vector3d about_pivot = J + m * (com.squaredNorm() * Eigen::Vector3d::Ones() - com.cwiseProduct(com));
  const auto body = chain_file.create<Lagrangian>(
      {{"bodies", {{{"mass", m}, {"inertia", {J(0), J(1), J(2)}}, {"com", {0, 0, -0.5}}}}}, {"gravity", g}},
      product_of_so3(1));
  const auto top = top_file.create<Lagrangian>({{"inertia", {about_pivot(0), about_pivot(1), about_pivot(2)}},
                                                {"mass", m},
                                                {"gravity", g},
                                                {"center_of_mass", {0, 0, -0.5}}},
                                               {{"manifold", "SO3"}, {"point_size", 9}, {"dim", 3}});
  std::mt19937 engine(5);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Vector3d w(normal(engine), normal(engine), normal(engine));
    VectorXd q(9), v(3);
    varia::so3::to_row_major(varia::so3::exp(w), q.data());
    v << normal(engine), normal(engine), normal(engine);
    const auto a = varia::sdk::conformance::evaluate(*body, q, v);
    const auto b = varia::sdk::conformance::evaluate(*top, q, v);
    CHECK(std::abs(a.value - b.value) <= 4e-15 * (1 + std::abs(b.value)));
    CHECK(relative_gap(a.gradient.tail(3), b.gradient.tail(3)) < 4e-15);
    CHECK(relative_gap(along_group(q, a.gradient.head(9)), along_group(q, b.gradient.head(9))) < 4e-15);
    CHECK(relative_gap(a.hessian.bottomRightCorner(3, 3), b.hessian.bottomRightCorner(3, 3)) < 4e-15);
    // Off the group the embedding's other directions differ (where they must not be compared).
    CHECK(relative_gap(a.gradient.head(9), b.gradient.head(9)) > 1e-3);
    double Ja = 0, Jb = 0;
    REQUIRE(body->momentum(q.data(), v.data(), &Ja) == nullptr);
    REQUIRE(top->momentum(q.data(), v.data(), &Jb) == nullptr);
    CHECK(std::abs(Ja - Jb) < 1e-15 * 4 * (1 + std::abs(Jb)));
  }
}

TEST_CASE("rigid-body-chain refuses a manifold that is not one SO3 per body") {
  auto file = varia::test::load_plugin("lagrangian", "rigid_body_chain");
  CHECK_THROWS_WITH_AS(file.create<Lagrangian>({{"bodies", kBodies}}, product_of_so3(2)),
                       doctest::Contains("3 bodies need the manifold product(SO3,SO3,SO3)"), std::runtime_error);
  CHECK_THROWS_WITH_AS(file.create<Lagrangian>({{"bodies", json::array({json::object()})}},
                                               {{"manifold", "SO3"}, {"point_size", 9}, {"dim", 3}}),
                       doctest::Contains("got SO3"), std::runtime_error);
}
