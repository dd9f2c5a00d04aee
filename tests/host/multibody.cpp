// Multibody systems on products of Lie groups (spec: "Constrained systems, S2 and products"):
// rigid-body-chain with one body on product(SO3) moves as the heavy top on SO3 with the inertia
// about the pivot, to round-off, under Lie group Galerkin, Crouch-Grossman shooting and the
// Crouch-Grossman one-step method: the chain's inertia is read from its Hessian (it depends on the
// attitudes in general), the top's is declared constant, so the Euler-Poincare field takes its
// general form for one and J^{-1} for the other (core/lie_group_field.hpp). The three-body chain's
// scenes run through the host.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "assemble.hpp"
#include "host/support.hpp"
#include "registry.hpp"
#include "scene.hpp"
#include "varia/core/trajectory.hpp"

namespace varia::host {
namespace {

using nlohmann::json;

// (q, p) after the scene's steps.
Eigen::VectorXd final_state(const json& document) {
  Registry registry{Registry::search_path({})};
  Scene scene = parse_scene(document);
  validate_parameters(scene, registry);
  Assembly a = assemble(scene, registry);
  Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  trajectory.advance(scene.steps);
  Eigen::VectorXd state(trajectory.q().size() + trajectory.p().size());
  state << trajectory.q(), trajectory.p();
  return state;
}

// One body of mass 1.7 with its centre of mass 0.5 below the pivot, as a chain and as a heavy top
// (J about the pivot = J about the centre + m |com|^2 on the two axes across com).
json one_body(const json& method, bool as_chain) {
  const json manifold = as_chain ? json{{"type", "product"}, {"factors", {{{"type", "SO3"}}}}} : json{{"type", "SO3"}};
  const json lagrangian =
      as_chain ? json{{"type", "rigid-body-chain"},
                      {"gravity", 1.3},
                      {"bodies", {{{"mass", 1.7}, {"inertia", {0.10, 0.12, 0.05}}, {"com", {0, 0, -0.5}}}}}}
               : json{{"type", "heavy-top"},
                      {"inertia", {0.10 + 1.7 * 0.25, 0.12 + 1.7 * 0.25, 0.05}},
                      {"mass", 1.7},
                      {"gravity", 1.3},
                      {"center_of_mass", {0, 0, -0.5}}};
  return {{"system", {{"manifold", manifold}, {"lagrangian", lagrangian}}},
          {"method", method},
          {"initial", {{"q", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"v", {0.9, -0.4, 1.1}}}},
          {"step", 0.02},
          {"steps", 100}};
}

}  // namespace

TEST_CASE("rigid-body-chain with one body on product(SO3) moves as the heavy top on SO3, to round-off") {
  const json galerkin{{"construction", "galerkin"}, {"degree", 2}, {"quadrature", {{"type", "gauss-lobatto"}, {"points", 3}}}};
  const json shooting{{"construction", "shooting"},
                      {"one_step", {{"type", "crouch-grossman"}, {"order", 2}}},
                      {"quadrature", {{"type", "trapezoid"}}}};
  const json one_step{{"construction", "one-step"}, {"one_step", {{"type", "crouch-grossman"}, {"order", 3}}}};
  for (const json& method : {galerkin, shooting, one_step}) {
    CAPTURE(method.dump());
    const Eigen::VectorXd chain = final_state(one_body(method, true)), top = final_state(one_body(method, false));
    CHECK((chain - top).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("the three-body rigid chain's scenes run on the product of three SO3 through the host") {
  for (const std::string name : {"rigid-body-chain-3.json", "rigid-body-chain-3-shooting-cg.json"}) {
    CAPTURE(name);
    json document = json::parse(test::read_file(test::kSourceDir / "scenes" / "multibody" / name));
    document.erase("t_end");
    document["steps"] = 2;  // a shooting step on this dense model of 36 numbers takes 0.3 s
    const Eigen::VectorXd state = final_state(document);
    CHECK(state.size() == 27 + 9);
    CHECK(state.allFinite());
  }
}

// About 20 s: 75 shooting steps of about 0.27 s each (a few seconds each before ABI 19, bench/README.md).
TEST_CASE("crouch-grossman shooting on the product of three SO3 (dimension 9) measures its order 2 against a "
          "converged galerkin reference") {
  test::TempDir dir;
  const auto outcome = test::run_varia("cost " + test::quoted(test::kSourceDir / "scenes" / "multibody" /
                                                              "rigid-body-chain-3-shooting-cg.json") +
                                       " --h 0.08,0.04,0.02,0.01 --quiet --out " + test::quoted(dir.path()));
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const json method = json::parse(test::read_file(dir / "cost.json"))["methods"][0];
  CAPTURE(method.dump());
  CHECK(method["predicted_order"] == 2);
  REQUIRE(method["fitted_slope"].is_number());
  CHECK(method["points_fitted"].get<int>() >= 4);
  MESSAGE("crouch-grossman order 2 + trapezoid shooting on SO(3)^3: fitted slope ", method["fitted_slope"].get<double>(),
          " on ", method["points_fitted"].get<int>(), " points");
  CHECK(std::abs(method["fitted_slope"].get<double>() - 2.0) < 0.3);
}

TEST_SUITE("long") {
  // About 45 s.
  TEST_CASE("verify holds what it predicts for the three-body rigid chain under lie group galerkin: orders 4 and "
            "momentum and symplecticity") {
    const auto outcome = test::run_varia(
        "verify " + test::quoted(test::kSourceDir / "scenes" / "multibody" / "rigid-body-chain-3.json"));
    CAPTURE(outcome.out);
    CHECK(outcome.code == 0);
    for (const char* property : {"ld_order", "global_order", "momentum_conserved", "symplectic", "g_invariant"}) {
      CAPTURE(property);
      const auto lines = test::lines_of(outcome.out);
      CHECK(std::any_of(lines.begin(), lines.end(), [&](const std::string& line) {
        return line.rfind(property, 0) == 0 && line.find(" yes") != std::string::npos;
      }));
    }
  }
}

}  // namespace varia::host
