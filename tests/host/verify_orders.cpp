// verify's order fits (docs/verify.md, "The fit"): an order holds within [predicted - 0.3,
// predicted + 1], and a step size whose run left every sane range is no point of a fit.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "host/support.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

struct VerifyOutcome {
  int code = -1;
  json global_order;  // its check in verify --json
};

// varia verify on `scene` (written into `dir`) with `flags`, and its global_order check.
VerifyOutcome verify_global_order(const TempDir& dir, const json& scene, const std::string& flags) {
  const auto scene_file = dir / "scene.json", checks_file = dir / "checks.json";
  write_file(scene_file, scene.dump());
  const auto outcome =
      run_varia("verify " + quoted(scene_file) + " --json " + quoted(checks_file) + " " + flags);
  CAPTURE(outcome.err);
  REQUIRE(fs::exists(checks_file));
  VerifyOutcome verified{outcome.code, nullptr};
  const json checks = json::parse(read_file(checks_file))["checks"];
  for (const json& check : checks)
    if (check["name"] == "global_order") verified.global_order = check;
  return verified;
}

json one_dof_scene(const json& lagrangian, const json& method) {
  return {{"system", {{"manifold", {{"type", "Rn"}, {"dim", 1}}}, {"lagrangian", lagrangian}}},
          {"method", method},
          {"initial", {{"q", {1.0}}, {"p", {0.0}}}},
          {"step", 0.1},
          {"steps", 10}};
}

}  // namespace

// Issue 43, item 1: the fit below, over errors of 9.4e7 to 5.5e11, held with a slope of 61.7 (predicted 2).
TEST_CASE("a fit over runs that left every sane range is not measured: stormer-verlet beyond its stability limit") {
  TempDir dir;
  const json stormer_verlet = {{"construction", "galerkin"},
                               {"degree", 1},
                               {"quadrature", {{"type", "gauss-lobatto"}, {"points", 2}}}};
  const auto v = verify_global_order(dir, one_dof_scene({{"type", "harmonic-oscillator"}}, stormer_verlet),
                                     "--h 2.5,2.4,2.3,2.2");
  const json& check = v.global_order;
  CAPTURE(check.dump());
  CHECK(v.code == 1);
  CHECK(check["predicted"] == 2);
  CHECK(check["holds"].is_null());
  CHECK(contains(check["note"].get<std::string>(), "left every sane range"));
  CHECK(contains(check["note"].get<std::string>(), "not measured"));
}

TEST_CASE("an order more than 1 above the prediction does not hold: rk4 declaring order 2") {
  TempDir dir;
  const json modest = {{"construction", "one-step"}, {"one_step", {{"type", "modest-rk4"}}}};
  const auto v = verify_global_order(dir, one_dof_scene({{"type", "pendulum"}}, modest),
                                     "--plugin-path '" + std::string(VARIA_FAULT_PLUGIN_DIR) + "'");
  const json& check = v.global_order;
  CAPTURE(check.dump());
  CHECK(v.code == 1);
  CHECK(check["predicted"] == 2);
  REQUIRE(check["measured"].is_number());
  CHECK(check["measured"].get<double>() == doctest::Approx(4.0).epsilon(0.05));
  CHECK(check["holds"] == false);
  CHECK(contains(check["note"].get<std::string>(), "more than 1 above the predicted order"));
}

}  // namespace varia::test
