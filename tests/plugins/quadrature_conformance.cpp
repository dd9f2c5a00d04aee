// The quadrature conformance suite, run over every quadrature plugin the build made (the real .so
// files), and the Rn manifold plugin. A rule of degree d (paper, sec. 2: nodes c_i, weights b_i)
// integrates t^k on [0, 1] exactly for k <= d and no further; a symmetric rule has
// c_i + c_{n-1-i} = 1 and b_i = b_{n-1-i} (paper, sec. 3).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "plugins/load_plugin.hpp"
#include "varia/sdk/conformance/quadrature.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/abi/quadrature.hpp"

namespace {

using varia::Quadrature;
using varia::test::load_plugin;
using varia::test::LoadedPlugin;

using varia::sdk::conformance::check_degree;
using varia::sdk::conformance::check_nodes_and_weights;
using varia::sdk::conformance::Failures;
using varia::sdk::conformance::is_symmetric;
using varia::sdk::conformance::kEps;
using varia::sdk::conformance::monomial_error;
using varia::sdk::conformance::MonomialError;
using varia::test::check_conforms;
// Integer parameters are swept from their schema minimum up to this value.
constexpr int kSweepLimit = 12;

// Every quadrature plugin of the build with every parameter object of its sweep.
template <class Check>
void for_every_rule(const Check& check) {
  for (const auto& file : varia::test::plugin_files("quadrature")) {
    const LoadedPlugin plugin(file);
    for (const auto& parameters : varia::sdk::conformance::parameter_sweep(plugin.parameter_schema(), kSweepLimit)) {
      INFO("plugin ", file.filename().string(), " with ", parameters.dump());
      check(*plugin.create<Quadrature>(parameters));
    }
  }
}

}  // namespace

TEST_CASE("quadrature: the build has the bundled rules as plugin files") {
  std::set<std::string> names;
  for (const auto& file : varia::test::plugin_files("quadrature"))
    names.insert(file.filename().string());
  for (const char* type : {"midpoint", "trapezoid", "simpson", "gauss_legendre", "gauss_lobatto"})
    CHECK_MESSAGE(names.count(std::string("quadrature_") + type + ".so") == 1, type);
}

TEST_CASE(
    "quadrature: every rule integrates t^k exactly for k <= degree() and not for degree()+1") {
  for_every_rule([](const Quadrature& rule) {
    Failures failures;
    check_degree(rule, failures);
    check_conforms(failures);
  });
}

TEST_CASE(
    "quadrature: every rule has increasing nodes in [0, 1] and positive weights summing to 1") {
  for_every_rule([](const Quadrature& rule) {
    Failures failures;
    check_nodes_and_weights(rule, failures);
    check_conforms(failures);
  });
}

TEST_CASE("quadrature: symmetric() is true exactly when c_i + c_{n-1-i} = 1 and b_i = b_{n-1-i}") {
  for_every_rule([](const Quadrature& rule) { CHECK(rule.symmetric() == is_symmetric(rule)); });
}

TEST_CASE("quadrature: the Gauss rules are mirrored exactly, c_i = 1 - c_{n-1-i} in double") {
  for (const char* type : {"gauss_legendre", "gauss_lobatto"}) {
    const LoadedPlugin plugin = load_plugin("quadrature", type);
    for (int points = 2; points <= 64; ++points) {
      const auto rule = plugin.create<Quadrature>({{"points", points}});
      const int n = rule->size();
      INFO(std::string(type), " with ", points, " points");
      REQUIRE(n == points);
      for (int i = 0; i < n; ++i) {
        CHECK(rule->nodes()[i] == 1 - rule->nodes()[n - 1 - i]);
        CHECK(rule->weights()[i] == rule->weights()[n - 1 - i]);
      }
    }
  }
}

TEST_CASE(
    "quadrature: Gauss-Legendre has degree 2n-1 and Gauss-Lobatto 2n-3, exact up to 64 points") {
  for (const auto& [type, first, excess] :
       {std::tuple{"gauss_legendre", 1, 1}, std::tuple{"gauss_lobatto", 2, 3}}) {
    const LoadedPlugin plugin = load_plugin("quadrature", type);
    for (int points = first; points <= 64; ++points) {
      const auto rule = plugin.create<Quadrature>({{"points", points}});
      INFO(std::string(type), " with ", points, " points");
      REQUIRE(rule->degree() == 2 * points - excess);
      for (int k = 0; k <= rule->degree(); ++k) {
        const MonomialError e = monomial_error(*rule, k);
        CAPTURE(k);
        CAPTURE(e.relative);
        CHECK(e.relative <= e.roundoff);
      }
    }
  }
}

TEST_CASE(
    "quadrature: the rules' defaults are Gauss-Legendre 2 points and Gauss-Lobatto 3 points") {
  CHECK(load_plugin("quadrature", "gauss_legendre").create<Quadrature>({})->size() == 2);
  CHECK(load_plugin("quadrature", "gauss_lobatto").create<Quadrature>({})->size() == 3);
}

TEST_CASE("quadrature: Gauss-Lobatto with 2 and 3 points is the trapezoid and Simpson rule") {
  const LoadedPlugin lobatto = load_plugin("quadrature", "gauss_lobatto");
  for (const auto& [points, type] : {std::pair{2, "trapezoid"}, std::pair{3, "simpson"}}) {
    const auto a = lobatto.create<Quadrature>({{"points", points}});
    const auto b = load_plugin("quadrature", type).create<Quadrature>({});
    INFO(std::string(type));
    REQUIRE(a->size() == b->size());
    for (int i = 0; i < a->size(); ++i) {
      CHECK(a->nodes()[i] == b->nodes()[i]);
      CHECK(a->weights()[i] == doctest::Approx(b->weights()[i]).epsilon(kEps));
    }
  }
}

TEST_CASE("quadrature: out-of-range and malformed parameters are refused with a message") {
  const std::vector<std::pair<const char*, nlohmann::json>> refused{
      {"gauss_legendre", {{"points", 0}}},   {"gauss_legendre", {{"points", 100000}}},
      {"gauss_legendre", {{"points", 65}}},  {"gauss_legendre", {{"points", 2.5}}},
      {"gauss_legendre", {{"points", "3"}}}, {"gauss_legendre", {{"nodes", 3}}},
      {"gauss_lobatto", {{"points", 1}}},    {"gauss_lobatto", {{"points", 100000}}},
      {"gauss_lobatto", {{"points", 0}}},    {"midpoint", {{"points", 2}}},
      {"trapezoid", {{"points", 2}}},        {"simpson", {{"points", 2}}}};
  for (const auto& [type, parameters] : refused) {
    INFO(std::string(type), " with ", parameters.dump());
    const LoadedPlugin plugin = load_plugin("quadrature", type);
    std::string message;
    try {
      plugin.create<Quadrature>(parameters);
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    CAPTURE(message);
    CHECK(!message.empty());
    const std::string key = parameters.begin().key();
    CHECK(message.find(key) != std::string::npos);
  }
}

TEST_CASE("manifold Rn: retract is q0 + xi, local inverts it, and non-finite points are out") {
  const auto rn = load_plugin("manifold", "Rn").create<varia::Manifold>({{"dim", 3}});
  CHECK(rn->point_size() == 3);
  CHECK(rn->dim() == 3);
  CHECK(rn->is_vector_space());
  const double q0[3] = {1.5, -2.0, 1e8}, xi[3] = {0.25, 3.0, -1e-3}, q1[3] = {-7.0, 0.5, 2e8};
  double q[3], xi_back[3], xi1[3], q1_back[3];
  REQUIRE(rn->retract(q0, xi, q) == nullptr);
  REQUIRE(rn->local(q0, q, xi_back) == nullptr);
  REQUIRE(rn->local(q0, q1, xi1) == nullptr);
  REQUIRE(rn->retract(q0, xi1, q1_back) == nullptr);
  for (int i = 0; i < 3; ++i) {
    CAPTURE(i);
    CHECK(q[i] == q0[i] + xi[i]);
    CHECK(xi1[i] == q1[i] - q0[i]);
    // One rounding in each direction: within eps of the largest coordinate involved.
    CHECK(std::fabs(xi_back[i] - xi[i]) <= kEps * std::fabs(q[i]));
    CHECK(std::fabs(q1_back[i] - q1[i]) <= kEps * std::fabs(q1[i]));
  }
  char why[128] = "";
  CHECK(rn->contains(q, why, sizeof why));
  q[1] = std::nan("");
  CHECK_FALSE(rn->contains(q, why, sizeof why));
  CHECK(std::string(why).find("coordinate 1") != std::string::npos);
}

TEST_CASE("manifold Rn: dim defaults to 1 and must be an integer >= 1") {
  const LoadedPlugin plugin = load_plugin("manifold", "Rn");
  CHECK(plugin.create<varia::Manifold>({})->dim() == 1);
  for (const nlohmann::json& parameters :
       {nlohmann::json{{"dim", 0}}, nlohmann::json{{"dim", 1.5}}, nlohmann::json{{"size", 2}}}) {
    INFO(parameters.dump());
    CHECK_THROWS_WITH_AS(plugin.create<varia::Manifold>(parameters),
                         doctest::Contains(parameters.begin().key().c_str()), std::runtime_error);
  }
}
