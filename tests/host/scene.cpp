// Scene parsing without plugins (spec: "Scene files (JSON)"): what the Scene holds, and the one
// line each schema violation becomes.
#include "scene.hpp"

#include <doctest/doctest.h>

#include "host/support.hpp"
#include "registry.hpp"

namespace varia::host {
namespace {

using nlohmann::json;

json default_scene() { return json::parse(test::read_file(test::kSourceDir / "scenes" / "default.json")); }

TEST_CASE("a scene holds its construction, steps from t_end, observables and plugin objects") {
  json document = default_scene();
  document["t_end"] = 0.30000000000000004;  // 3 steps of 0.1 up to rounding
  document["step"] = 0.1;
  Scene scene = parse_scene(document);
  CHECK(std::string(scene.construction->name()) == "galerkin");
  CHECK(scene.construction->describe(scene) == "galerkin degree 2, quadrature gauss-lobatto {\"points\":3}");
  CHECK(scene.steps == 3);
  CHECK(scene.observe.energy);
  CHECK_FALSE(scene.observe.momentum);
  CHECK(scene.output_every == 1);
  CHECK(scene.lagrangian.pointer == "/system/lagrangian");
  CHECK(scene.lagrangian.type == "pendulum");
  CHECK_FALSE(scene.lagrangian.parameters.contains("type"));
  CHECK(scene.quadrature->parameters == json{{"points", 3}});
  CHECK(scene.plugins().size() == 3);
}

struct Bad {
  const char* pointer;  // where to put the value
  json value;
  const char* message;  // the start of the one-line error
};

TEST_CASE("each schema violation is one line naming its JSON pointer and what was expected") {
  const Bad cases[] = {
      {"/method/control_times", json{0.0, 1.0}, "/method/control_times: expected degree + 1 = 3 increasing"},
      {"/method/solver", json{{"tolerance", 0}}, "/method/solver/tolerance: expected a number > 0"},
      {"/method/solver", json{{"max_iterations", 0}}, "/method/solver/max_iterations: expected an integer >= 1"},
      {"/method/solver", "cayley", "/method/solver: expected an object ({\"tolerance\""},
      {"/method/construction", "galerkn", "/method/construction: expected one of \"galerkin\""},
      {"/method/form", "hamiltonian", "/method/form: unknown key 'form'; the keys allowed here are: chart, construction, "},
      {"/output", json{{"every", 0}}, "/output/every: expected an integer >= 1"},
      {"/observe", json{"energy", "energy"}, "/observe/1: a repeated item (\"energy\"); expected items that are all"},
      {"/initial/q", json{"a"}, "/initial/q/0: expected a number"},
      {"/system/manifold", json{{"dim", 1}}, "/system/manifold/type: missing"},
      {"/system/manifold/type", 3, "/system/manifold/type: expected a string"},
      {"/steps", 0, "/steps: expected an integer >= 1"},
  };
  for (const auto& c : cases) {
    const std::string pointer = c.pointer;
    CAPTURE(pointer);
    json document = default_scene();
    document[json::json_pointer(c.pointer)] = c.value;
    if (pointer == "/steps") document.erase("t_end");
    std::string message = "(nothing thrown)";
    try {
      parse_scene(document);
    } catch (const InputError& e) {
      message = e.what();
    }
    CAPTURE(message);
    CHECK(message.rfind(c.message, 0) == 0);
    CHECK(message.find('\n') == std::string::npos);
  }
}

TEST_CASE("the plugin objects a plugin's schema marks as its parts are found, checked and named from the schema") {
  Registry registry{Registry::search_path({})};
  Scene chain = parse_scene(json::parse(test::read_file(test::kSourceDir / "scenes" / "multibody" / "rigid-body-chain-3.json")));
  validate_parameters(chain, registry);
  REQUIRE(chain.manifold.parts.size() == 3);
  CHECK(chain.manifold.parts[2].pointer == "/system/manifold/factors/2");
  CHECK(chain.manifold.parts[2].role == "factors");
  CHECK(chain.manifold.parts[2].kind == "manifold");
  CHECK(chain.manifold.parts[2].type == "SO3");
  CHECK(manifold_name(chain.manifold) == "product(SO3,SO3,SO3)");
  CHECK(chain.lagrangian.parts.empty());  // its "bodies" are parameters, not plugin objects

  Scene springs = parse_scene(json::parse(test::read_file(test::kSourceDir / "scenes" / "effects" / "spring-chain-gravity.json")));
  validate_parameters(springs, registry);
  REQUIRE_FALSE(springs.lagrangian.parts.empty());
  CHECK(springs.lagrangian.parts[0].pointer == "/system/lagrangian/terms/0");
  CHECK(springs.lagrangian.parts[0].kind == "effect");
  CHECK(manifold_name(springs.manifold) == "Rn");
}

}  // namespace
}  // namespace varia::host
