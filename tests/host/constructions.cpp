// The construction table (host/src/constructions/): every construction found by name, its method
// schema published in schemas/method/, and its own keys refused under another construction.
#include "constructions/construction.hpp"

#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>

#include "host/support.hpp"
#include "errors.hpp"
#include "scene.hpp"
#include "assemble.hpp"
#include "registry.hpp"

namespace varia::host {
namespace {

using nlohmann::json;

// VARIA_WRITE_SCHEMAS=1 rewrites the published files from the code (after changing a schema).
TEST_CASE("each construction's method schema is published as schemas/method/<name>.schema.json") {
  for (const std::string& name : construction_names()) {
    CAPTURE(name);
    const auto file = test::kSourceDir / "schemas" / "method" / (name + ".schema.json");
    const json schema = construction_named(name).schema();
    if (std::getenv("VARIA_WRITE_SCHEMAS") != nullptr) std::ofstream(file) << schema.dump(2) << '\n';
    CHECK(json::parse(test::read_file(file)) == schema);
  }
}

TEST_CASE("a construction's keys are refused under another, with the pointer and what is allowed") {
  json document = json::parse(test::read_file(test::kSourceDir / "scenes" / "default.json"));
  document["method"] = {{"construction", "shooting"}, {"degree", 2}, {"quadrature", {{"type", "simpson"}}},
                        {"one_step", {{"type", "rk4"}}}};
  std::string message = "(nothing thrown)";
  try {
    parse_scene(document);
  } catch (const InputError& e) {
    message = e.what();
  }
  CAPTURE(message);
  CHECK(message.rfind("/method/degree: ", 0) == 0);
}

TEST_CASE("an unknown construction is refused with the table's names") {
  CHECK_THROWS_WITH_AS(construction_named("galerkn"),
                       "/method/construction: expected one of \"galerkin\", \"shooting\", \"one-step\", "
                       "\"lie-verlet\"; found \"galerkn\"",
                       InputError);
}

}  // namespace
}  // namespace varia::host

namespace varia::host {
namespace {

// The predictions of a scene's composed integrator, from its construction (verify's first step).
struct Predicted {
  Registry registry{Registry::search_path({})};
  Scene scene;
  Assembly assembly;
  Predictions predictions;
  explicit Predicted(const json& document) {
    scene = parse_scene(document);
    validate_parameters(scene, registry);
    assembly = assemble(scene, registry);
    predictions = scene.construction->predict(scene, assembly);
  }
};

json pendulum_with(const json& method) {
  return {{"system", {{"manifold", {{"type", "Rn"}, {"dim", 1}}}, {"lagrangian", {{"type", "pendulum"}}}}},
          {"method", method},
          {"initial", {{"q", {1.0}}, {"p", {0.0}}}},
          {"step", 0.1},
          {"steps", 10}};
}

json rigid_body_with(const json& method) {
  return {{"system",
           {{"manifold", {{"type", "SO3"}}},
            {"lagrangian", {{"type", "heavy-top"}, {"inertia", {1, 1.5, 0.8}}, {"mass", 1}, {"gravity", 1},
                            {"center_of_mass", {0.1, 0.2, 0.5}}}}}},
          {"method", method},
          {"initial", {{"q", {1, 0, 0, 0, 1, 0, 0, 0, 1}}, {"v", {0.5, -0.3, 2.0}}}},
          {"step", 0.01},
          {"steps", 10}};
}

json galerkin_with(int degree, const char* rule, int points) {
  json quadrature{{"type", rule}};
  if (points > 0) quadrature["points"] = points;
  return {{"construction", "galerkin"}, {"degree", degree}, {"quadrature", quadrature}};
}

TEST_CASE("predictions follow the theorems' hypotheses (issue #17, defects 1, 2, 4, 5, each failed on 5dea526)") {
  const json null;
  struct Row {
    const char* what;
    json scene;
    json ld_order, self_adjoint, symplectic, momentum_conserved;
  };
  const json shooting_type2{{"construction", "shooting"}, {"form", "type-2"}, {"one_step", {{"type", "rk4"}}},
                            {"quadrature", {{"type", "simpson"}}}};
  const std::vector<Row> rows{
      // Defect 1: s Gauss points give min(2s, 2s); Lobatto's s points min(2s, 2s - 2).
      {"galerkin s = 3, 3 Gauss points", pendulum_with(galerkin_with(3, "gauss-legendre", 3)), 6, true, true, null},
      {"galerkin s = 4, 4 Lobatto points", pendulum_with(galerkin_with(4, "gauss-lobatto", 4)), 6, true, true, null},
      // Defect 2: the self-adjointness proposition is for the Type I form.
      {"type-2 shooting, rk4 + simpson", pendulum_with(shooting_type2), "any", null, "any", null},
      // Defect 4: Runge-Kutta in the embedding of SO(3) is not canonical.
      {"one-step implicit midpoint on SO(3)",
       rigid_body_with({{"construction", "one-step"}, {"one_step", {{"type", "implicit-midpoint"}}}}), "any", "any",
       false, "any"},
      // Defect 5: shooting with a propagator that leaves SO(3) promises neither.
      {"shooting rk4 on SO(3)",
       rigid_body_with({{"construction", "shooting"}, {"one_step", {{"type", "rk4"}}},
                        {"quadrature", {{"type", "gauss-lobatto"}, {"points", 3}}}}),
       "any", "any", null, null},
  };
  const auto as_json = [](const auto& optional) { return optional ? json(*optional) : json(nullptr); };
  for (const Row& row : rows) {
    CAPTURE(std::string(row.what));
    const Predicted p(row.scene);
    CAPTURE(p.predictions.reason);
    if (row.ld_order != "any") CHECK(as_json(p.predictions.ld_order) == row.ld_order);
    if (row.self_adjoint != "any") CHECK(as_json(p.predictions.self_adjoint) == row.self_adjoint);
    if (row.symplectic != "any") CHECK(as_json(p.predictions.symplectic) == row.symplectic);
    if (row.momentum_conserved != "any") CHECK(as_json(p.predictions.momentum_conserved) == row.momentum_conserved);
  }
}

TEST_CASE("a galerkin rule with fewer weighted nodes than the degree is refused at /method/quadrature (defect 1, "
          "issue #43 item 2: s = 3 with 2 Gauss points passed validate on 5a2c708 and ran to q = -2.9e132 with exit 0)") {
  for (const json& method : {galerkin_with(2, "midpoint", 0), galerkin_with(3, "trapezoid", 0),
                             galerkin_with(4, "simpson", 0), galerkin_with(3, "gauss-legendre", 2),
                             galerkin_with(5, "gauss-legendre", 3), galerkin_with(4, "gauss-lobatto", 3)}) {
    CAPTURE(method.dump());
    std::string message;
    try {
      Predicted p(pendulum_with(method));
    } catch (const InputError& e) {
      message = e.what();
    }
    CHECK(message.rfind("/method/quadrature", 0) == 0);
    CHECK(message.find("too weak") != std::string::npos);
  }
}

}  // namespace
}  // namespace varia::host
