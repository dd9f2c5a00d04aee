// Scenes compose effects (spec: "Composed systems: effects"): only the plugins a scene names are
// loaded (the run record's plugins_loaded), forces are evaluated only when the scene has them, and
// plugins the scene does not name cost a run nothing.
#include <doctest/doctest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "support.hpp"

namespace {

using Json = nlohmann::json;
using namespace varia::test;

Json run_record(const std::string& scene, const std::string& extra = "") {
  TempDir dir;
  const auto summary = dir / "summary.json";
  const Outcome outcome = run_varia("run " + scene + " --quiet --summary '" + summary.string() + "' " + extra);
  REQUIRE_MESSAGE(outcome.code == 0, outcome.err);
  return Json::parse(read_file(summary));
}

}  // namespace

TEST_CASE("a composite scene loads its manifold, composite, its effects and its quadrature, and nothing else") {
  const Json record = run_record("scenes/effects/spring-chain-gravity.json");
  CHECK(record["plugins_loaded"] == Json{"Rn", "composite", "gravity", "spring", "gauss-lobatto"});
  CHECK(record["evaluations"]["force"] == 0);
  CHECK(record["energy_error_max"].get<double>() < 1e-3);
}

TEST_CASE("a composite scene runs by shooting: its effects evaluate at jets (ABI 11)") {
  const Json record = run_record("scenes/effects/spring-pendulum-shooting.json");
  CHECK(record["plugins_loaded"] == Json{"Rn", "composite", "gravity", "spring", "gauss-lobatto", "gauss-collocation"});
  // 2-stage Gauss collocation with Lobatto-3: order 4; at h = 0.05 over 200 steps the energy
  // error measured 8.0e-7 (the Galerkin scene's degree 1 at h = 0.01: 1e-4's order).
  CHECK(record["energy_error_max"].get<double>() < 1e-5);
  CHECK(record["newton_iterations"]["mean"].get<double>() <= 3.0);
}

TEST_CASE("a scene with forces loads and evaluates them, one without evaluates no force") {
  const Json forced = run_record("scenes/effects/damped-driven-oscillator.json");
  CHECK(forced["plugins_loaded"] == Json{"Rn", "harmonic-oscillator", "damping", "periodic-force", "gauss-lobatto"});
  CHECK(forced["evaluations"]["force"].get<long>() > 0);
  const Json planets = run_record("scenes/effects/planetary.json");
  CHECK(planets["plugins_loaded"] == Json{"Rn", "composite", "central", "gauss-lobatto"});
  CHECK(planets["evaluations"]["force"] == 0);
}

TEST_CASE("unrelated plugins on the plugin path change neither what a run loads nor its time") {
  TempDir extra;
  for (const char* name : {"effect_central.so", "force_damping.so", "force_periodic_force.so"}) {
    fs::copy_file(kPluginDir / name, extra / name);
    fs::permissions(extra / name, fs::perms::owner_all);
  }
  const std::string scene = "scenes/effects/spring-pendulum-2d.json";
  const Json alone = run_record(scene);
  const Json crowded = run_record(scene, "--plugin-path '" + extra.path().string() + "'");
  CHECK(crowded["plugins_loaded"] == alone["plugins_loaded"]);
  CHECK(alone["plugins_loaded"] == Json{"Rn", "composite", "gravity", "spring", "trapezoid"});
  const double a = alone["wall_seconds"], b = crowded["wall_seconds"];
  MESSAGE("wall seconds without and with the extra plugins: " << a << ", " << b);
  CHECK(b < 3.0 * a + 0.05);
}

TEST_CASE("a composite's bad term is named by its pointer, forces on a construction without them too") {
  TempDir dir;
  Json scene = Json::parse(read_file(kSourceDir / "scenes/effects/spring-pendulum-2d.json"));
  scene["system"]["lagrangian"]["terms"][1]["particle"] = 4;
  write_file(dir / "bad-particle.json", scene.dump());
  const Outcome particle = run_varia("run '" + (dir / "bad-particle.json").string() + "'");
  CHECK(particle.code == 2);
  check_one_error_line(particle, "/system/lagrangian/terms/1: particle: particle 4 does not exist");

  scene = Json::parse(read_file(kSourceDir / "scenes/effects/damped-driven-oscillator.json"));
  scene["method"] = {{"construction", "one-step"}, {"one_step", {{"type", "rk4"}}}};
  write_file(dir / "forces-one-step.json", scene.dump());
  const Outcome forces = run_varia("run '" + (dir / "forces-one-step.json").string() + "'");
  CHECK(forces.code == 2);
  check_one_error_line(forces, "/system/forces: forces are taken by constructions 'galerkin' and 'shooting' only");
}

TEST_CASE("a shooting scene with forces runs them through the construction and agrees with the galerkin one") {
  const Json shooting = run_record("scenes/effects/damped-driven-shooting.json");
  CHECK(shooting["plugins_loaded"] == Json{"Rn", "harmonic-oscillator", "damping", "periodic-force", "simpson", "rk4"});
  CHECK(shooting["evaluations"]["force"].get<long>() > 0);
  const Json galerkin = run_record("scenes/effects/damped-driven-oscillator.json");
  for (const std::string part : {"q", "p"}) {
    const double a = shooting["final"][part][0], b = galerkin["final"][part][0];
    MESSAGE(part << "(50), shooting (rk4 + simpson) and galerkin (degree 2): " << a << ", " << b);
    CHECK(std::abs(a - b) < 1e-6);
  }
}

TEST_CASE("forces with the shooting construction on SO(3) are refused with exit 2 (vector spaces only)") {
  TempDir dir;
  Json scene = Json::parse(read_file(kSourceDir / "scenes/paper/rigid-body-shooting-cg.json"));
  scene["system"]["forces"] = Json::array({{{"type", "damping"}, {"coefficient", 0.1}}});
  write_file(dir / "so3-forces.json", scene.dump());
  const Outcome outcome = run_varia("run '" + (dir / "so3-forces.json").string() + "'");
  CHECK(outcome.code == 2);
  CHECK(outcome.err.find("the shooting construction takes forces on vector spaces only") != std::string::npos);
}
