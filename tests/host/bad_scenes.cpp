// Bad input (spec: "Exit codes", code 2): every scene of scenes/bad, and a few made here that
// cannot live in the repository, makes `validate` and `run` exit 2 with one line naming the JSON
// pointer of the bad field and what was expected (or the line and column of a syntax error).
#include <doctest/doctest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/support.hpp"
#include "errors.hpp"
#include "json_reader.hpp"

namespace varia::test {
namespace {

// Each bad scene and what its one error line must name. A new file in scenes/bad needs its row.
const std::map<std::string, std::string> kBadScenes{
    // syntax: line and column
    {"empty.json", "invalid JSON at line 1, column 1"},
    {"invalid-utf8.json", "invalid JSON at line 2, column 49"},
    {"nan-literal.json", "invalid JSON at line 31, column 11"},
    {"syntax-error.json", "invalid JSON at line 7, column"},
    {"trailing-garbage.json", "invalid JSON at line 36, column 3"},
    {"unterminated-string.json", "invalid JSON at line 2, column 79"},
    // numbers out of the range of double, absurd nesting
    {"huge-number-in-q.json", "/initial/q/0: expected a number within the range of double"},
    {"huge-step.json", "/step: expected a number within the range of double"},
    {"deep-nesting.json", "/system/lagrangian/extra/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0/0"},
    // wrong types, missing keys, unknown keys
    {"bad-parameter-type.json", "/system/lagrangian/mass: expected a number"},
    {"lagrangian-without-type.json", "/system/lagrangian/type: missing"},
    {"missing-q.json", "/initial/q: missing"},
    {"missing-step.json", "/step: missing"},
    {"misspelt-parameter.json", "/system/lagrangian/lenght: unknown key 'lenght'"},
    {"no-p-or-v.json", "/initial/p: missing; expected an array (the momentum, dim numbers; give exactly one of p or v)"},
    {"not-an-object.json", "/: expected an object"},
    {"q-not-array.json", "/initial/q: expected an array"},
    {"step-string.json", "/step: expected a number"},
    {"steps-not-integer.json", "/steps: expected an integer"},
    {"unknown-key.json", "/method/degre: unknown key 'degre'"},
    {"unknown-observable.json", "/observe/0: expected one of \"energy\""},
    // unknown plugin types, listing the valid ones
    {"unknown-lagrangian.json", "/system/lagrangian/type: unknown lagrangian type 'pendulm'; valid lagrangian types are: "},
    {"unknown-manifold.json", "/system/manifold/type: unknown manifold type 'R3'; valid manifold types are: Rn, S2, SE3, SO3"},
    {"unknown-quadrature.json", "/method/quadrature/type: unknown quadrature type 'gauss'; valid quadrature types are: "},
    // out-of-range parameters
    {"bad-quadrature-parameter.json", "/method/quadrature/points: expected an integer >= 2"},
    {"control-times-decreasing.json", "/method/control_times: expected degree + 1 = 3 increasing numbers"},
    {"degree-too-high.json", "/method/degree: expected an integer >= 1 and <= 32"},
    {"degree-zero.json", "/method/degree: expected an integer >= 1"},
    {"dim-zero.json", "/system/manifold/dim: expected an integer >= 1"},
    {"galerkin-derivative-quadrature.json", "/method: the Galerkin construction takes quadratures without"},
    {"galerkin-without-quadrature.json", "/method/quadrature: missing"},
    {"gauss-legendre-no-points.json", "/method/quadrature/points: expected an integer >= 1"},
    {"inertia-negative.json", "/system/lagrangian/inertia/1: expected a number > 0"},
    {"mass-zero.json", "/system/lagrangian/mass: expected a number > 0"},
    {"negative-step.json", "/step: expected a number > 0"},
    {"negative-t_end.json", "/t_end: expected a number > 0"},
    {"step-zero.json", "/step: expected a number > 0"},
    {"steps-too-many.json", "/steps: expected an integer >= 1 and <= 1000000000000"},
    {"steps-zero.json", "/steps: expected an integer >= 1"},
    {"t_end-not-whole-steps.json", "/t_end: expected a whole number of steps"},
    {"t_end-too-far.json", "/t_end: expected at most 1e+12 steps"},
    {"start-time-too-large.json", "/initial/t: expected a start time at which the times t0 + k h of the run stay "
                                  "apart: near t = 1e+16 doubles are 2 apart, and the step is 0.1"},
    // inconsistent: both, neither, sizes, states
    {"momentum-without-symmetry.json", "/observe: expected no \"momentum\""},
    {"spring-between-one-particle.json", "/system/lagrangian/terms/2: parameter 'between' must name two different particles (the spring plugin effect_spring.so)"},
    {"periodic-force-amplitude-size.json", "/system/forces/1: parameter 'amplitude' must have 1 numbers"},
    {"p-and-v.json", "/initial/p: not allowed here"},
    {"product-unknown-factor.json", "/system/manifold/factors/1/type: unknown manifold type 'SO4'"},
    {"product-factor-parameter.json", "/system/manifold/factors/0/dim: expected an integer >= 1"},
    {"product-factor-without-type.json", "/system/manifold/factors/1/type: missing"},
    {"product-reflection.json", "/initial/q: expected a point of product: factor 1: R is a reflection, not a rotation"},
    // constraints (docs/constraints.md): a start off them, a construction that does not take them, a
    // rod to a particle the system lacks
    {"rod-start-off-constraint.json", "/initial/q: expected a point on the constraints (max |g_i(q)| <= 1e-10); found max |g_i(q)| = 0.001"},
    {"rod-under-hamiltonian-shooting.json", "/system/constraints: with constraints the shooting construction takes the lagrangian form and no forces"},
    {"rod-missing-particle.json", "/system/constraints/0: particle 1 does not exist (the system has 1)"},
    {"rigid-body-chain-wrong-manifold.json", "/system/lagrangian: rigid-body-chain: 3 bodies need the manifold product(SO3,SO3,SO3)"},
    {"reduced-heavy-top.json", "/method/reduced: the reduced (Euler-Poincare) form needs a Lagrangian invariant under the whole group"},
    {"reduced-se3-spring.json", "/method/reduced: the reduced (Euler-Poincare) form needs a Lagrangian invariant under the whole group"},
    {"reduced-on-rn.json", "/method/reduced: the reduced (Euler-Poincare) form is for Lie groups"},
    {"reduced-with-shooting.json", "/method/reduced: unknown key 'reduced'; the keys allowed here are: construction, form"},
    {"so3-not-orthogonal.json", "/initial/q: expected a point of SO3: R is not orthogonal"},
    {"so3-q-size.json", "/initial/q: expected 9 numbers"},
    {"so3-reflection.json", "/initial/q: expected a point of SO3: R is a reflection, not a rotation"},
    {"steps-and-t_end.json", "/t_end: not allowed here"},
    {"wrong-p-size.json", "/initial/p: expected 1 number"},
    {"wrong-q-size.json", "/initial/q: expected 1 number"},
};

// Both commands that read a scene: the same exit code and the same line.
void check_bad_scene(const fs::path& file, const std::string& expected) {
  for (const char* command : {"validate", "run"}) {
    CAPTURE(command);
    const auto outcome = run_varia(std::string(command) + " '" + file.string() + "'");
    CAPTURE(outcome.err);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, file.string() + ": " + expected);
  }
}

TEST_CASE("every bad scene exits 2 with one line naming the file, the bad field and what was expected") {
  const auto files = files_in(kSourceDir / "scenes" / "bad", ".json");
  CHECK(files.size() == kBadScenes.size());  // a new bad scene needs its row in the table
  CHECK(files.size() >= 30);
  for (const auto& file : files) {
    CAPTURE(file);
    const auto it = kBadScenes.find(file.filename().string());
    REQUIRE(it != kBadScenes.end());
    check_bad_scene(file, it->second);
  }
}

TEST_CASE("a scene file larger than 16 MiB is refused before it is read whole, exit 2") {
  TempDir dir;
  const auto file = dir / "huge.json";
  {
    std::ofstream out(file, std::ios::binary);
    out << "{\"description\": \"";
    const std::string block(1 << 20, 'x');
    for (std::size_t i = 0; i <= host::kMaxJsonBytes >> 20; ++i) out << block;
    out << "\"}";
  }
  check_bad_scene(file, "the file is larger than 16 MiB");
}

// A harmonic oscillator (a dense autodiff Lagrangian) on Rn with dim n, integrated by Stormer-Verlet.
std::string dense_oscillator_scene(int n) {
  const nlohmann::json scene{
      {"system", {{"manifold", {{"type", "Rn"}, {"dim", n}}}, {"lagrangian", {{"type", "harmonic-oscillator"}}}}},
      {"method", {{"construction", "galerkin"}, {"degree", 1}, {"quadrature", {{"type", "trapezoid"}}}}},
      {"initial", {{"q", std::vector<double>(n, 0.1)}, {"p", std::vector<double>(n, 0.0)}}},
      {"step", 0.1},
      {"steps", 2}};
  return scene.dump();
}

TEST_CASE("a dense Lagrangian of more than 4096 position and velocity numbers is refused, exit 2, with the limit, "
          "why and what to write instead, and 4096 are taken") {
  TempDir dir;
  write_file(dir / "over.json", dense_oscillator_scene(2049));
  check_bad_scene(dir / "over.json",
                  "/system/lagrangian: the harmonic-oscillator Lagrangian has a dense Hessian over its 4098 position "
                  "and velocity numbers, and at most 4096 are taken (the Hessian and the Newton matrices grow as the "
                  "square: 134 MB for this Hessian alone); write it as a sum of terms (sdk::TermwiseLagrangian) or as "
                  "a composite system, whose Hessians are sparse");
  write_file(dir / "limit.json", dense_oscillator_scene(2048));
  CHECK(run_varia("validate '" + (dir / "limit.json").string() + "'").code == 0);
}

TEST_CASE("nesting is counted to exactly 64 levels: 64 pass the reader, 65 are refused") {
  const auto nested = [](std::size_t levels) { return std::string(levels, '[') + std::string(levels, ']'); };
  CHECK_NOTHROW(host::parse_json_text(nested(host::kMaxJsonDepth)));
  CHECK_THROWS_WITH_AS(host::parse_json_text(nested(host::kMaxJsonDepth + 1)),
                       doctest::Contains("nested too deep; expected at most 64 levels"), host::InputError);
}

}  // namespace
}  // namespace varia::test
