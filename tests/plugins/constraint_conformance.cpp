// The constraint plugins (abi/constraint.hpp): the SDK's constraint suite (patterns, and Taylor
// tests of the Jacobian and the weighted Hessian, varia/sdk/conformance/constraint.hpp) over every
// constraint plugin built; the rod's values at known points, and what it refuses when bound.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <string>

#include "load_plugin.hpp"
#include "varia/abi/constraint.hpp"
#include "varia/sdk/conformance/plugin.hpp"

namespace {

using varia::Constraint;
using varia::test::rn;

std::shared_ptr<Constraint> rod(const nlohmann::json& parameters, int particles, int d) {
  return varia::test::load_plugin("constraint", "rod").create<Constraint>(parameters, rn(particles * d));
}

}  // namespace

TEST_CASE("every constraint plugin passes the SDK's constraint suite (Taylor tests of its derivatives)") {
  int files = 0;
  for (const auto& file : varia::test::plugin_files("constraint")) {
    CAPTURE(file);
    ++files;
    const varia::test::LoadedPlugin plugin(file);
    std::string checked;
    varia::test::check_conforms(varia::sdk::conformance::check_plugin(plugin, checked));
    CHECK(checked.find("constraint suite") != std::string::npos);
  }
  CHECK(files >= 1);
}

TEST_CASE("a rod's g is its relative length error to first order, and a chain's Jacobian has 2 d entries a rod") {
  auto chain = rod({{"chain", {0, 2}}, {"length", 2.0}}, 3, 3);
  REQUIRE(chain->bind(9, 3) == nullptr);
  CHECK(chain->size() == 2);
  const int *rows = nullptr, *cols = nullptr;
  CHECK(chain->jacobian_pattern(&rows, &cols) == 12);
  // x0 = 0, x1 = 2.002 e1 (a 0.1 % longer rod), x2 = x1 + 2 e2 (exact).
  const double q[9] = {0, 0, 0, 2.002, 0, 0, 2.002, 2, 0};
  double g[2], G[12];
  REQUIRE(chain->evaluate(q, g, G) == nullptr);
  CHECK(std::abs(g[0] - 1.0005e-3) <= 1e-15);  // (|d|^2 - L^2) / (2 L^2) = (2.002^2 - 4) / 8
  CHECK(std::abs(g[1]) <= 1e-15);
  auto anchored = rod({{"anchor", {0, 0, 1}}, {"particle", 1}}, 2, 3);
  REQUIRE(anchored->bind(6, 3) == nullptr);
  double h[1];
  const double p[6] = {5, 5, 5, 0, 0, 0};
  REQUIRE(anchored->evaluate(p, h, nullptr) == nullptr);
  CHECK(h[0] == 0.0);  // particle 1 at distance 1 from the anchor
}

TEST_CASE("a rod refuses a system that is not one of particles, a particle it lacks, and an anchor of another size") {
  auto between = rod({{"between", {0, 4}}}, 3, 3);
  const varia::Status missing = between->bind(9, 3);
  REQUIRE(missing != nullptr);
  CHECK(std::string(missing) == "particle 4 does not exist (the system has 3)");
  auto plain = rod({{"between", {0, 1}}}, 3, 3);
  REQUIRE(plain->bind(9, 0) != nullptr);
  auto anchored = rod({{"anchor", {0, 0}}, {"particle", 0}}, 3, 3);
  const varia::Status size = anchored->bind(9, 3);
  REQUIRE(size != nullptr);
  CHECK(std::string(size).find("anchor") != std::string::npos);
}
