// The effect plugins (abi/effect.hpp): the SDK's effect suite (Taylor tests of the gradient and
// sparse Hessian, varia/sdk/conformance/effect.hpp) over every effect plugin built, and the
// force suite over every force plugin; and the composite Lagrangian they make
// (core/composite.hpp) integrated by the sparse Galerkin construction against an independent
// reference: the elastic pendulum, whose acceleration is written here by hand and integrated by
// Runge-Kutta-Fehlberg 7(8).
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <map>
#include <memory>

#include "../core/fixtures.hpp"
#include "load_plugin.hpp"
#include "varia/sdk/conformance/lagrangian.hpp"
#include "varia/sdk/conformance/plugin.hpp"
#include "varia/core/composite.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/shooting.hpp"
#include "varia/sdk/conformance/effect.hpp"
#include "../core/shooting_fixtures.hpp"

namespace {

using varia::test::rn;

using Eigen::VectorXd;
using Json = nlohmann::json;
using varia::Effect;

constexpr int kDim = 3;
const double kMasses[] = {1.0, 2.0, 3.0};
const double kMasses5[] = {1.0, 2.0, 1.0, 3.0, 1.0};

std::shared_ptr<Effect> make_effect(const std::string& type, const Json& parameters) {
  auto effect = varia::test::load_plugin("effect", type).create<Effect>(parameters, rn(3 * kDim));
  REQUIRE(effect->bind(kDim, 3, kMasses) == nullptr);
  return effect;
}

}  // namespace

TEST_CASE("every effect and force plugin passes the SDK's suite of its kind (Taylor tests of its derivatives)") {
  for (const char* kind : {"effect", "force"})
    for (const auto& file : varia::test::plugin_files(kind)) {
      CAPTURE(file);
      const varia::test::LoadedPlugin plugin(file);
      std::string checked;
      varia::test::check_conforms(varia::sdk::conformance::check_plugin(plugin, checked));
      CHECK(checked.find(std::string(kind) + " suite") != std::string::npos);
    }
}

TEST_CASE("effects touch only the coordinates they name, and refuse particles that do not exist") {
  const int* indices = nullptr;
  const auto between = make_effect("spring", {{"between", {0, 2}}});
  CHECK(between->coordinates(&indices) == 2 * kDim);
  CHECK(std::vector<int>(indices, indices + 6) == std::vector<int>{0, 1, 2, 6, 7, 8});
  CHECK(make_effect("central", {{"particle", 1}})->coordinates(&indices) == kDim);
  const int *rows = nullptr, *cols = nullptr;
  CHECK(make_effect("gravity", {{"g", {0, 0, -1}}})->hessian_pattern(&rows, &cols) == 0);
  auto spring = varia::test::load_plugin("effect", "spring").create<Effect>({{"between", {0, 5}}}, rn(9));
  const varia::Status status = spring->bind(kDim, 3, kMasses);
  REQUIRE(status != nullptr);
  CHECK(std::string(status) == "between: particle 5 does not exist (the system has 3)");
}

namespace {

// A composite of 5 particles in the plane with the given spring terms.
std::shared_ptr<varia::CompositeLagrangian> springs(const std::vector<Json>& terms) {
  std::vector<std::shared_ptr<Effect>> effects;
  for (const Json& term : terms)
    effects.push_back(varia::test::load_plugin("effect", "spring").create<Effect>(term, rn(10)));
  return std::make_shared<varia::CompositeLagrangian>(2, std::vector<double>{1, 2, 1, 3, 1}, std::move(effects));
}

}  // namespace

TEST_CASE("a spring term over a chain or a list of pairs is the sum of the same springs given one by one, with "
          "the same Hessian pattern") {
  // A spring of stiffness 2 and rest length 0.5 on the particles given by `key`: `value`.
  const auto spring = [](const char* key, const Json& value) {
    return Json{{"stiffness", 2.0}, {"rest_length", 0.5}, {key, value}};
  };
  std::vector<Json> one_by_one;
  for (int i = 0; i < 4; ++i) one_by_one.push_back(spring("between", {i, i + 1}));
  const auto separate = springs(one_by_one);
  const auto chain = springs({spring("chain", {0, 4})});
  const auto pairs = springs({spring("pairs", {{1, 2}, {0, 1}, {3, 2}, {4, 3}})});
  const VectorXd q = (VectorXd(10) << 0.1, 0.2, 0.9, -0.3, 1.7, 0.4, 2.2, -0.2, 3.1, 0.3).finished();
  const VectorXd v = VectorXd::LinSpaced(10, -0.5, 0.7);
  const auto expected = varia::sdk::conformance::evaluate(*separate, q, v);
  for (const auto& lagrangian : std::vector{chain, pairs}) {
    const auto e = varia::sdk::conformance::evaluate(*lagrangian, q, v);
    CHECK(e.value == doctest::Approx(expected.value).epsilon(1e-15));
    CHECK((e.gradient - expected.gradient).lpNorm<Eigen::Infinity>() <= 1e-15);
    CHECK((e.hessian - expected.hessian).lpNorm<Eigen::Infinity>() <= 1e-14);
    const int *rows = nullptr, *cols = nullptr;
    CHECK(lagrangian->hessian_pattern(&rows, &cols) == separate->hessian_pattern(&rows, &cols));
  }
  // A chain of 5 particles in the plane: 10 mass entries, and the 2 x 2 blocks of each particle with
  // itself and its neighbours (5 + 2 x 4 blocks).
  const int *rows = nullptr, *cols = nullptr;
  CHECK(chain->hessian_pattern(&rows, &cols) == 10 + 4 * (5 + 2 * 4));
}

TEST_CASE("a spring chain must run forward over particles that exist") {
  auto plugin = varia::test::load_plugin("effect", "spring");
  CHECK_THROWS_WITH(plugin.create<Effect>({{"chain", {2, 2}}}, rn(10)),
                    "parameter 'chain' must be [first, last] with first < last, got [2,2]");
  auto beyond = plugin.create<Effect>({{"chain", {0, 7}}}, rn(10));
  const varia::Status status = beyond->bind(2, 5, kMasses5);
  REQUIRE(status != nullptr);
  CHECK(std::string(status) == "chain: particle 5 does not exist (the system has 5)");
}

namespace {

// The elastic pendulum in the plane: m x'' = m g - k (1 - r/|x|) x (by hand, not from the plugins).
constexpr double kStiffness = 10.0, kRest = 1.0, kGravity = 1.0;
using State = std::array<double, 4>;

State reference(const State& start, double T) {
  namespace odeint = boost::numeric::odeint;
  State x = start;
  auto field = [](const State& s, State& ds, double) {
    const double r = std::hypot(s[0], s[1]), f = -kStiffness * (1.0 - kRest / r);
    ds = {s[2], s[3], f * s[0], f * s[1] - kGravity};
  };
  odeint::integrate_adaptive(odeint::make_controlled(1e-14, 1e-14, odeint::runge_kutta_fehlberg78<State>()), field,
                             x, 0.0, T, 1e-3);
  return x;
}

std::shared_ptr<varia::CompositeLagrangian> elastic_pendulum() {
  std::vector<std::shared_ptr<Effect>> effects{
      varia::test::load_plugin("effect", "gravity").create<Effect>({{"g", {0.0, -kGravity}}}, rn(2)),
      varia::test::load_plugin("effect", "spring")
          .create<Effect>({{"anchor", {0.0, 0.0}}, {"particle", 0}, {"stiffness", kStiffness}, {"rest_length", kRest}},
                          rn(2))};
  return std::make_shared<varia::CompositeLagrangian>(2, std::vector<double>{1.0}, std::move(effects));
}

// The Galerkin solution at T from start, step h (m = 1: p = v).
VectorXd galerkin(int degree, varia::testing::FixedRule rule, const State& start, double h, double T,
                  double* energy_drift = nullptr) {
  varia::testing::FlatSpace space(2);
  auto lagrangian = elastic_pendulum();
  varia::GalerkinDiscreteLagrangian map(space, *lagrangian, rule, varia::equispaced_control_times(degree),
                                        varia::SolverOptions{});
  varia::LagrangianEvaluator evaluator(*lagrangian);
  VectorXd q(2), p(2);
  q << start[0], start[1];
  p << start[2], start[3];
  const double e0 = evaluator.energy(q.data(), p.data());
  double drift = 0.0;
  for (long k = 0; k < std::lround(T / h); ++k) {
    map.step(q.data(), p.data(), h, q.data(), p.data());
    drift = std::max(drift, std::abs(evaluator.energy(q.data(), p.data()) - e0));
  }
  if (energy_drift != nullptr) *energy_drift = drift;
  VectorXd result(4);
  result << q, p;
  return result;
}

const State kStart{0.8, -0.9, 0.0, 0.3};

}  // namespace

TEST_CASE("the composite elastic pendulum (sparse Galerkin) converges to an independent reference at the "
          "construction's order: 2 for degree 1 (trapezoid), 4 for degree 2 (Lobatto)") {
  const double T = 5.0;
  const State x = reference(kStart, T);
  const VectorXd exact = Eigen::Map<const VectorXd>(x.data(), 4);
  struct Case {
    int degree;
    varia::testing::FixedRule rule;
    double order;
  };
  for (const Case& c : {Case{1, varia::testing::trapezoid(), 2.0}, Case{2, varia::testing::lobatto3(), 4.0}}) {
    const double e1 = (galerkin(c.degree, c.rule, kStart, 0.02, T) - exact).norm();
    const double e2 = (galerkin(c.degree, c.rule, kStart, 0.01, T) - exact).norm();
    MESSAGE("degree " << c.degree << ": errors " << e1 << ", " << e2 << ", order " << std::log2(e1 / e2));
    CHECK(std::log2(e1 / e2) == doctest::Approx(c.order).epsilon(0.05));
  }
}

namespace {

// The shooting solution (rk4 + Simpson, order 4) at T from start, step h.
VectorXd shooting(varia::ShootingForm form, const State& start, double h, double T) {
  varia::testing::FlatSpace space(2);
  auto lagrangian = elastic_pendulum();
  auto rule = varia::testing::simpson();
  auto method = varia::testing::rk4();
  varia::ShootingDiscreteLagrangian map(space, *lagrangian, rule, method, form, varia::SolverOptions{});
  VectorXd q(2), p(2);
  q << start[0], start[1];
  p << start[2], start[3];
  for (long k = 0; k < std::lround(T / h); ++k) map.step(q.data(), p.data(), h, q.data(), p.data());
  VectorXd result(4);
  result << q, p;
  return result;
}

// The inner effect with the derivatives of its gradient at jets 1.5 times too large (the values
// and everything at doubles right): what the effect suite's Taylor tests at jets must refuse.
class LyingJetEffect final : public Effect {
 public:
  explicit LyingJetEffect(std::shared_ptr<Effect> inner) : inner_(std::move(inner)) {}
  varia::Status bind(int space_dim, int particles, const double* masses) noexcept override {
    return inner_->bind(space_dim, particles, masses);
  }
  int coordinates(const int** indices) const noexcept override { return inner_->coordinates(indices); }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    return inner_->hessian_pattern(rows, cols);
  }
  varia::Status evaluate(const double* x, double* value, double* gradient, double* hessian) noexcept override {
    return inner_->evaluate(x, value, gradient, hessian);
  }
  bool evaluates_at_jets() const noexcept override { return true; }
  varia::Status gradient_jet(const varia::Jet2* x, varia::Jet2* value, varia::Jet2* gradient) noexcept override {
    const varia::Status status = inner_->gradient_jet(x, value, gradient);
    const int* indices = nullptr;
    for (int j = 0; status == nullptr && j < inner_->coordinates(&indices); ++j)
      if (!gradient[j].constant()) gradient[j].gradient *= 1.5;
    return status;
  }

 private:
  std::shared_ptr<Effect> inner_;
};

// An effect that gives V at doubles only (Effect::gradient_jet not implemented).
class DoublesOnly final : public Effect {
 public:
  varia::Status bind(int, int, const double*) noexcept override { return nullptr; }
  int coordinates(const int** indices) const noexcept override {
    *indices = &index_;
    return 1;
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = *cols = &entry_;
    return 1;
  }
  varia::Status evaluate(const double* x, double* value, double* gradient, double* hessian) noexcept override {
    if (value != nullptr) *value = 0.5 * x[0] * x[0];
    if (gradient != nullptr) gradient[0] = x[0];
    if (hessian != nullptr) hessian[0] = 1.0;
    return nullptr;
  }

 private:
  int index_ = 0, entry_ = 0;
};

}  // namespace

TEST_CASE("the composite elastic pendulum under shooting (rk4 + Simpson, the effects' gradients at jets) converges "
          "to the independent reference at order 4 in the lagrangian and hamiltonian forms (issue #18: composite + "
          "shooting was refused)") {
  const double T = 5.0;
  const State x = reference(kStart, T);
  const VectorXd exact = Eigen::Map<const VectorXd>(x.data(), 4);
  for (varia::ShootingForm form : {varia::ShootingForm::lagrangian, varia::ShootingForm::hamiltonian}) {
    const double e1 = (shooting(form, kStart, 0.04, T) - exact).norm();
    const double e2 = (shooting(form, kStart, 0.02, T) - exact).norm();
    MESSAGE("form " << (form == varia::ShootingForm::lagrangian ? "lagrangian" : "hamiltonian") << ": errors " << e1
                    << ", " << e2 << ", order " << std::log2(e1 / e2));
    CHECK(std::log2(e1 / e2) == doctest::Approx(4.0).epsilon(0.05));
  }
}

TEST_CASE("the effect suite refuses an effect whose gradient at jets has wrong derivatives, and shooting refuses a "
          "composite with an effect that gives no gradient at jets") {
  LyingJetEffect lying(make_effect("central", {{"particle", 1}}));
  std::mt19937 engine(7);
  const auto failures = varia::sdk::conformance::check_effect(lying, 3 * kDim, engine);
  REQUIRE_FALSE(failures.empty());
  CAPTURE(failures.list().front());
  CHECK(failures.list().front().find("the gradient at jets: the first derivative") != std::string::npos);
  auto truthful = make_effect("central", {{"particle", 1}});
  std::mt19937 same(7);
  CHECK(varia::sdk::conformance::check_effect(*truthful, 3 * kDim, same).empty());

  varia::CompositeLagrangian composite(1, {1.0}, {std::make_shared<DoublesOnly>()});
  CHECK_FALSE(composite.evaluates_at_jets());
  varia::testing::FlatSpace line(1);
  auto rule = varia::testing::simpson();
  auto method = varia::testing::rk4();
  CHECK_THROWS_WITH_AS(varia::ShootingDiscreteLagrangian(line, composite, rule, method, varia::ShootingForm::lagrangian,
                                                         varia::SolverOptions{}),
                       doctest::Contains("this Lagrangian does not evaluate at jets"), std::invalid_argument);
}

TEST_SUITE("long") {
  TEST_CASE("the composite elastic pendulum's energy stays bounded without drift over 10^5 steps") {
    double early = 0.0, whole = 0.0;
    galerkin(1, varia::testing::trapezoid(), kStart, 0.01, 100.0, &early);
    galerkin(1, varia::testing::trapezoid(), kStart, 0.01, 1000.0, &whole);
    MESSAGE("energy error max: over 10^4 steps " << early << ", over 10^5 steps " << whole);
    CHECK(whole < 1e-2);
    CHECK(whole < 1.5 * early);
  }
}
