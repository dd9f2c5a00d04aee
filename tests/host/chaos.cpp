// `varia tangent` and the observables megno and lyapunov (spec "Tangent maps and ensembles"), end
// to end: the Jacobian printed is the step's (symplectic where the method is), the bundled chaos
// scenes give what the theory says, and what has no tangent map is refused with exit 2.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "host/support.hpp"
#include "varia/core/verification.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

Eigen::MatrixXd matrix_of(const json& rows) {
  const auto d = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd M(d, d);
  for (Eigen::Index r = 0; r < d; ++r)
    for (Eigen::Index c = 0; c < d; ++c) M(r, c) = rows[r][c].get<double>();
  return M;
}

TEST_CASE("tangent --json prints q1, p1 and the step's Jacobian, symplectic for SVIRK4 (type I and type 2) and Galerkin on "
          "Kepler") {
  for (const char* arguments : {"scenes/paper/svirk4-pendulum.json --q0 1.3 --p0 0.2 --h 0.1",
                                "scenes/paper/svirk4-pendulum-type2.json --q0 1.3 --p0 0.2 --h 0.1",
                                "scenes/kepler-galerkin.json --q0 0.5,0 --p0 0,1.7320508075688772 --h 0.05"}) {
    CAPTURE(arguments);
    const auto outcome = run_varia(std::string("tangent ") + arguments + " --json");
    CAPTURE(outcome.err);
    REQUIRE(outcome.code == 0);
    const json result = json::parse(outcome.out);
    CHECK(result.size() == 3);
    const auto n = result["q1"].size();
    CHECK(result["p1"].size() == n);
    REQUIRE(result["jacobian"].size() == 2 * n);
    CHECK(symplecticity_residual(matrix_of(result["jacobian"])) <= 1e-13);
  }
  const auto human = run_varia("tangent scenes/default.json --q0 1.3 --p0 0.2 --h 0.1");
  CHECK(human.code == 0);
  CHECK(contains(human.out, "symplecticity defect"));
}

TEST_CASE("tangent refuses what has no tangent map and bad flags, exit 2 with one line") {
  const auto constrained = run_varia(
      "tangent scenes/multibody/spherical-pendulum-rod-s2.json --q0 0,0,-1 --p0 0.1,0.2,0 --h 0.01");
  CHECK(constrained.code == 2);
  check_one_error_line(constrained, "/method/construction: expected a construction with a tangent map");
  const auto shooting_on_group = run_varia(
      "tangent scenes/paper/rigid-body-shooting-cg.json --q0 1,0,0,0,1,0,0,0,1 --p0 0.1,0.2,0.3 --h 0.1");
  CAPTURE(shooting_on_group.err);
  CHECK(shooting_on_group.code == 0);
  const auto galerkin_on_group = run_varia(
      "tangent scenes/paper/rigid-body-galerkin-s2.json --q0 1,0,0,0,1,0,0,0,1 --p0 0.1,0.2,0.3 --h 0.1");
  CAPTURE(galerkin_on_group.err);
  CHECK(galerkin_on_group.code == 0);
  CHECK(contains(galerkin_on_group.out, "symplecticity defect: not measured here"));
  const auto p0 = run_varia("tangent scenes/kepler-galerkin.json --q0 0.5,0 --p0 1 --h 0.05");
  CHECK(p0.code == 2);
  check_one_error_line(p0, "--p0: expected 2 comma-separated finite numbers");
  CHECK(run_varia("tangent scenes/default.json --q0 1 --p0 0 --h -1").code == 2);
}

TEST_CASE("megno and lyapunov: the chaotic double pendulum (MEGNO > 8, lambda > 0.2 at T = 200), the Kepler ellipse "
          "(MEGNO within 0.25 of 2 at T = 2000, lambda < 0.05), the oscillator (|MEGNO| < 0.1 at T = 500)") {
  TempDir dir;
  const auto summary = [&](const char* scene) {
    const auto outcome = run_varia(std::string("run ") + scene + " --quiet --summary '" +
                                   (dir / "record.json").string() + "' --out '" + (dir / "t.csv").string() + "'");
    CAPTURE(outcome.err);
    REQUIRE(outcome.code == 0);
    return json::parse(read_file(dir / "record.json"));
  };
  const json chaotic = summary("scenes/chaos/double-pendulum-megno.json");
  CHECK(chaotic["megno_final"].get<double>() > 8);
  CHECK(chaotic["lyapunov_final"].get<double>() > 0.2);
  const auto header = lines_of(read_file(dir / "t.csv")).front();
  CHECK(header == "t,q0,q1,p0,p1,energy,megno,lyapunov");
  const json kepler = summary("scenes/chaos/kepler-megno.json");
  CHECK(std::abs(kepler["megno_final"].get<double>() - 2.0) < 0.25);
  CHECK(kepler["lyapunov_final"].get<double>() < 0.05);
  const json oscillator = summary("scenes/chaos/oscillator-megno.json");
  CHECK(std::abs(oscillator["megno_final"].get<double>()) < 0.1);
}

TEST_CASE("tangent and megno with a quadratic constraint under one-step rk4: the projected step's Jacobian in the "
          "embedding, its symplecticity not measured by tangent (verify measures it on the constraint's bundle)") {
  const auto outcome = run_varia("tangent scenes/multibody/spherical-pendulum-rod-rk4.json --q0 "
                                 "0.8414709848078965,0,-0.5403023058681398 --p0 0,2.5,0 --h 0.01 --json");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const json result = json::parse(outcome.out);
  REQUIRE(result["jacobian"].size() == 6);
  const auto human = run_varia("tangent scenes/multibody/spherical-pendulum-rod-rk4.json --q0 "
                               "0.8414709848078965,0,-0.5403023058681398 --p0 0,2.5,0 --h 0.01");
  CHECK(contains(human.out, "symplecticity defect: not measured here (with constraints"));
  CHECK(run_varia("validate scenes/multibody/spherical-pendulum-rod-rk4.json --set '/observe=[\"megno\"]'").code == 0);
}

TEST_CASE("megno on a construction without a tangent map is refused at /observe, exit 2") {
  const auto outcome = run_varia("validate scenes/multibody/spherical-pendulum-rod-s2.json --set '/observe=[\"megno\"]'");
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "/observe: expected no \"megno\"");
  CHECK(run_varia("validate scenes/paper/rigid-body-galerkin-s2.json --set '/observe=[\"megno\"]'").code == 0);
}

}  // namespace
}  // namespace varia::test
