// The construction table (host/src/constructions/): every construction found by name, its method
// schema published in schemas/method/, and its own keys refused under another construction.
#include "constructions/construction.hpp"

#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>

#include "host/support.hpp"
#include "errors.hpp"
#include "scene.hpp"

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
