// The S2 manifold (plugins/manifold/S2.cpp) and the products of S2 and R^n: the equations they give
// (Manifold::defining_constraint) pass the SDK's constraint suite (patterns, Taylor tests of G and
// of the weighted Hessian), each factor's rows on its own block; the chart (the sphere's
// exponential map) stays on the sphere and its inverse undoes it; a point off the sphere is named.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "load_plugin.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/sdk/conformance/constraint.hpp"

namespace {

using nlohmann::json;
using varia::Manifold;
using varia::ManifoldStructure;
using varia::test::check_conforms;
using varia::test::load_plugin;

struct Made {
  std::vector<varia::test::LoadedPlugin> files;
  std::vector<std::shared_ptr<Manifold>> factors;

  std::shared_ptr<Manifold> manifold(const std::string& type, const json& parameters = json::object()) {
    files.push_back(load_plugin("manifold", type));
    return files.back().create<Manifold>(parameters, json::object());
  }
  std::shared_ptr<Manifold> product(const std::vector<std::pair<std::string, json>>& types) {
    std::vector<varia::Part> parts;
    for (const auto& [type, parameters] : types) {
      factors.push_back(manifold(type, parameters));
      parts.push_back(varia::Part{"factors", factors.back().get()});
    }
    files.push_back(load_plugin("manifold", "product"));
    return files.back().create<Manifold>(json{{"factors", json(types.size(), json{{"type", "factor"}})}},
                                         json::object(), parts);
  }
};

}  // namespace

TEST_CASE("S2 gives |q|^2 = 1 as one row, G = q^T, and it passes the constraint suite") {
  Made made;
  auto sphere = made.manifold("S2");
  CHECK(sphere->structure() == ManifoldStructure::homogeneous_space);
  CHECK(sphere->point_size() == 3);
  CHECK(sphere->dim() == 2);
  varia::Constraint* equation = sphere->defining_constraint();
  REQUIRE(equation != nullptr);
  std::mt19937 engine(7);
  check_conforms(varia::sdk::conformance::check_constraint(*equation, 3, engine));
  const double q[3] = {0.6, 0.0, 0.8};
  double g = 1.0, G[3] = {};
  REQUIRE(equation->evaluate(q, &g, G) == nullptr);
  CHECK(std::abs(g) <= 1e-16);
  CHECK(G[0] == 0.6);
  CHECK(G[2] == 0.8);
  CHECK(equation->bind(4, 0) != nullptr);  // a point of S2 has 3 numbers
}

TEST_CASE("S2's chart moves along great circles on the sphere, and its inverse undoes it") {
  Made made;
  auto sphere = made.manifold("S2");
  std::mt19937 engine(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Vector3d q0(normal(engine), normal(engine), normal(engine));
    q0.normalize();
    const double xi[2] = {normal(engine), normal(engine)};
    if (std::hypot(xi[0], xi[1]) >= 3.0) continue;  // within the injectivity radius pi
    Eigen::Vector3d q;
    double back[2] = {};
    REQUIRE(sphere->retract(q0.data(), xi, q.data()) == nullptr);
    CHECK(std::abs(q.norm() - 1.0) <= 1e-15);
    CHECK(std::acos(std::clamp(q0.dot(q), -1.0, 1.0)) == doctest::Approx(std::hypot(xi[0], xi[1])).epsilon(1e-12));
    REQUIRE(sphere->local(q0.data(), q.data(), back) == nullptr);
    CHECK(std::abs(back[0] - xi[0]) <= 1e-12);
    CHECK(std::abs(back[1] - xi[1]) <= 1e-12);
  }
  const double north[3] = {0, 0, 1}, south[3] = {0, 0, -1};
  double xi[2];
  CHECK(sphere->local(north, south, xi) != nullptr);
  char why[200] = {};
  const double off[3] = {0.6, 0.0, 0.81};
  CHECK_FALSE(sphere->contains(off, why, sizeof why));
  CHECK(std::string(why).find("unit vector") != std::string::npos);
}

TEST_CASE("a product of S2 and R^n gives its factors' equations on their blocks, and with a Lie group it is refused") {
  Made made;
  auto pair = made.product({{"S2", json::object()}, {"Rn", json{{"dim", 2}}}, {"S2", json::object()}});
  CHECK(pair->structure() == ManifoldStructure::homogeneous_space);
  varia::Constraint* equations = pair->defining_constraint();
  REQUIRE(equations != nullptr);
  REQUIRE(equations->bind(8, 0) == nullptr);
  CHECK(equations->size() == 2);
  std::mt19937 engine(13);
  check_conforms(varia::sdk::conformance::check_constraint(*equations, 8, engine));
  const double q[8] = {0.6, 0.0, 0.8, 5.0, -7.0, 0.0, 2.0, 0.0};
  double g[2] = {}, G[6] = {};
  REQUIRE(equations->evaluate(q, g, G) == nullptr);
  CHECK(std::abs(g[0]) <= 1e-16);
  CHECK(g[1] == doctest::Approx(1.5));  // (|(0, 2, 0)|^2 - 1) / 2
  const int *rows = nullptr, *cols = nullptr;
  REQUIRE(equations->jacobian_pattern(&rows, &cols) == 6);
  CHECK(rows[3] == 1);
  CHECK(cols[3] == 5);  // the second S2's block starts after S2 (3) and R^2 (2)
  CHECK(G[4] == 2.0);
  Made mixed;
  auto refused = mixed.product({{"S2", json::object()}, {"SO3", json::object()}});
  CHECK(refused->structure() == ManifoldStructure::product);
  CHECK(refused->defining_constraint() == nullptr);
}
