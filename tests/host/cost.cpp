// End-to-end test of `varia cost` (spec: "Commands", "Outputs"): on two pendulum scenes it writes
// cost.csv with the spec's columns and cost.svg with one line per method, and the errors in the
// CSV fall with h at the order that the Galerkin theory predicts (paper, sec. 2: min(2s, order of
// the rule); 2 for s = 1 with the trapezoid rule, 4 for s = 2 with 3 Lobatto points).
#include <doctest/doctest.h>

#include <map>
#include <nlohmann/json.hpp>

#include "host/support.hpp"
#include "varia/core/verification.hpp"

namespace varia::test {
namespace {

struct Sweep {
  std::vector<double> h, error;
};

// cost.csv rows grouped by method (the first column).
std::map<std::string, Sweep> read_sweeps(const std::vector<std::string>& lines) {
  std::map<std::string, Sweep> sweeps;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::istringstream row(lines[i]);
    std::string method, h, steps, error;
    std::getline(row, method, ',');
    std::getline(row, h, ',');
    std::getline(row, steps, ',');
    std::getline(row, error, ',');
    sweeps[method].h.push_back(std::stod(h));
    sweeps[method].error.push_back(std::stod(error));
  }
  return sweeps;
}

TEST_CASE("cost on Galerkin s=1 and s=2 pendulum scenes writes the spec's CSV and an SVG, errors at slopes 2 and 4") {
  TempDir dir;
  const auto outcome = run_varia("cost scenes/pendulum-galerkin-s1.json scenes/pendulum-galerkin-s2.json --quiet --out '" +
                                 dir.path().string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const auto lines = lines_of(read_file(dir / "cost.csv"));
  REQUIRE(lines.size() > 1);
  CHECK(lines[0] == "method,h,steps,error,energy_error,seconds,newton_iterations,evaluations");

  const auto sweeps = read_sweeps(lines);
  const std::map<std::string, int> predicted{{"pendulum-galerkin-s1", 2}, {"pendulum-galerkin-s2", 4}};
  REQUIRE(sweeps.size() == predicted.size());
  for (const auto& [method, order] : predicted) {
    CAPTURE(method);
    REQUIRE(sweeps.count(method) == 1);
    const auto& sweep = sweeps.at(method);
    CHECK(sweep.h.size() >= 6);
    const OrderFit fit = fit_order(sweep.h, sweep.error, 1e-12);
    CAPTURE(fit.slope);
    CHECK(fit.used >= 3);
    CHECK(fit.slope == doctest::Approx(order).epsilon(0.1));
  }

  const auto record = nlohmann::json::parse(read_file(dir / "cost.json"));
  for (const auto& m : record["methods"]) {
    CHECK(m["reference"] == "exact solution");
    CHECK(m["predicted_order"] == predicted.at(m["method"].get<std::string>()));
  }
  const std::string svg = read_file(dir / "cost.svg");
  CHECK(contains(svg, "<svg"));
  for (const auto& [method, order] : predicted) CHECK(contains(svg, method));
}

TEST_CASE("cost names a method by the scene's \"name\" and runs the step sizes given with --h") {
  TempDir dir;
  write_file(dir / "named.json", R"({
    "name": "Stormer-Verlet",
    "system": {"manifold": {"type": "Rn", "dim": 1}, "lagrangian": {"type": "pendulum"}},
    "method": {"construction": "galerkin", "degree": 1, "quadrature": {"type": "trapezoid"}},
    "initial": {"q": [1.3], "p": [0.0]},
    "step": 0.01, "steps": 100})");
  const auto outcome = run_varia("cost '" + (dir / "named.json").string() + "' --h 0.02,0.01,0.005 --quiet --out '" +
                                 dir.path().string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const auto sweeps = read_sweeps(lines_of(read_file(dir / "cost.csv")));
  REQUIRE(sweeps.count("Stormer-Verlet") == 1);
  CHECK(sweeps.at("Stormer-Verlet").h == std::vector<double>{0.02, 0.01, 0.005});
}

TEST_CASE("cost shows a scene's name with terminal escapes as \\xNN in its table, and writes it as it is to cost.json") {
  TempDir dir;
  const std::string name = "pendulum\x1b]0;title\x07\x1b[2J\r";
  nlohmann::json scene = nlohmann::json::parse(read_file(kSourceDir / "scenes/pendulum-galerkin-s1.json"));
  scene["name"] = name;
  write_file(dir / "named.json", scene.dump());
  const auto outcome = run_varia("cost '" + (dir / "named.json").string() + "' --h 0.2,0.1,0.05,0.025 --out '" +
                                 dir.path().string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  CHECK(contains(outcome.out, "pendulum\\x1b]0;title\\x07\\x1b[2J\\x0d ("));
  for (const char control : {'\x1b', '\x07', '\r'}) {
    CHECK(outcome.out.find(control) == std::string::npos);
    CHECK(outcome.err.find(control) == std::string::npos);
  }
  const auto record = nlohmann::json::parse(read_file(dir / "cost.json"));
  CHECK(record["methods"][0]["method"] == name);
}

TEST_CASE("cost on forced scenes (damping, periodic force, both, galerkin and shooting) fits the predicted order 4 "
          "against a reference run of the forced system") {
  TempDir dir;
  const nlohmann::json base = nlohmann::json::parse(read_file(kSourceDir / "scenes/effects/damped-driven-oscillator.json"));
  const nlohmann::json forces = base["system"]["forces"];
  std::string files;
  for (const auto& [name, chosen] : std::map<std::string, nlohmann::json>{
           {"damping", nlohmann::json::array({forces[0]})}, {"periodic", nlohmann::json::array({forces[1]})}, {"both", forces}}) {
    nlohmann::json scene = base;
    scene["system"]["forces"] = chosen;
    scene["t_end"] = 10.0;
    scene["name"] = name;
    write_file(dir / (name + ".json"), scene.dump());
    files += " '" + (dir / (name + ".json")).string() + "'";
  }
  const auto outcome = run_varia("cost" + files + " scenes/effects/damped-driven-shooting.json --quiet --out '" +
                                 (dir / "out").string() + "'");
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const auto record = nlohmann::json::parse(read_file(dir / "out" / "cost.json"));
  REQUIRE(record["methods"].size() == 4);
  for (const auto& m : record["methods"]) {
    CAPTURE(m.dump());
    CHECK(m["predicted_order"] == 4);
    CHECK(m["points_fitted"].get<int>() >= 4);
    CHECK(m["fitted_slope"].get<double>() == doctest::Approx(4.0).epsilon(0.3 / 4));
    CHECK(m["reference"].get<std::string>().rfind("reference run", 0) == 0);
  }
}

}  // namespace
}  // namespace varia::test
