// The one_step conformance suite, run over every one_step plugin the build made (the real .so
// files): the declared order is the measured order on the Euler-Lagrange field of the unit
// oscillator; a method declared self-adjoint satisfies Psi_{-h}(Psi_h(y)) = y (paper, sec. 3
// "Symmetric shooting-based discrete Lagrangians"); an "affine"- or "left"-equivariant method
// commutes with a rotation of a central force's phase space (sec. 3 "Group-invariant ..."); jets
// carry the derivatives of the step.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "plugins/load_plugin.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

using namespace varia;

// L = |v|^2/2 - |q|^2/2 (dim 1: the unit oscillator) or |v|^2/2 + 1/|q| (a central force).
template <bool kCentral>
struct Model : sdk::AutodiffLagrangian<Model<kCentral>> {
  explicit Model(int n) : sdk::AutodiffLagrangian<Model<kCentral>>(n, n) {}
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::sqrt;
    if constexpr (kCentral) return T(0.5) * v.dot(v) + T(1.0) / sqrt(q.dot(q));
    else return T(0.5) * v.dot(v) - T(0.5) * q.dot(q);
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    const int n = this->velocity_size();
    Eigen::Map<Eigen::MatrixXd>(mass, n, n).setIdentity();
    return true;
  }
};

// A method's parameter variants: gauss-collocation for stages 1 to 3 (order 8 would reach
// round-off at 16 steps), the others as they are.
std::vector<nlohmann::json> variants(const std::string& type) {
  if (type != "gauss-collocation") return {nlohmann::json::object()};
  return {{{"stages", 1}}, {{"stages", 2}}, {{"stages", 3}}};
}

template <class F>
void for_each_method(F&& check) {
  const auto files = test::plugin_files("one_step");
  REQUIRE(!files.empty());
  for (const auto& file : files) {
    const test::LoadedPlugin plugin(file);
    for (const auto& parameters : variants(plugin.info().type)) {
      CAPTURE(plugin.info().type);
      CAPTURE(parameters.dump());
      auto method = plugin.create<OneStepMethod>(parameters);
      check(*method);
    }
  }
}

// The error at t = 1 of the oscillator from (1, 0) after `steps` steps.
double oscillator_error(OneStepMethod& method, MechanicalField& field, int steps) {
  SolverStatistics statistics;
  double y[2] = {1.0, 0.0}, y1[2];
  for (int k = 0; k < steps; ++k) {
    field.step(method, 1.0 / steps, y, y1, statistics);
    y[0] = y1[0];
    y[1] = y1[1];
  }
  return std::hypot(y[0] - std::cos(1.0), y[1] + std::sin(1.0));
}

}  // namespace

TEST_CASE("one_step plugins have their declared order") {
  Model<false> oscillator(1);
  LagrangianEvaluator evaluator(oscillator);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  for_each_method([&](OneStepMethod& method) {
    // The order from 8 to 16 steps: asymptotic already, and above round-off up to order 8.
    const double order =
        std::log2(oscillator_error(method, field, 8) / oscillator_error(method, field, 16));
    CAPTURE(order);
    CHECK(order == doctest::Approx(method.order()).epsilon(0.1));
  });
}

TEST_CASE("one_step plugins declared self-adjoint satisfy Psi_{-h} o Psi_h = id, the others do not") {
  Model<true> central(2);
  LagrangianEvaluator evaluator(central);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  for_each_method([&](OneStepMethod& method) {
    SolverStatistics statistics;
    const double y0[4] = {1.0, 0.2, -0.1, 0.9};
    double y1[4], back[4];
    field.step(method, 0.3, y0, y1, statistics);
    field.step(method, -0.3, y1, back, statistics);
    double defect = 0.0;
    for (int i = 0; i < 4; ++i) defect = std::max(defect, std::abs(back[i] - y0[i]));
    CAPTURE(defect);
    if (method.self_adjoint()) CHECK(defect < 1e-13);
    else CHECK(defect > 1e-8);
  });
}

TEST_CASE("affine-equivariant one_step plugins commute with a rotation of a central force") {
  Model<true> central(2);
  LagrangianEvaluator evaluator(central);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  const double c = std::cos(0.7), s = std::sin(0.7);
  const auto rotate = [&](const double* y, double* out) {  // (q, v) -> (R q, R v)
    for (int half = 0; half < 4; half += 2) {
      out[half] = c * y[half] - s * y[half + 1];
      out[half + 1] = s * y[half] + c * y[half + 1];
    }
  };
  for_each_method([&](OneStepMethod& method) {
    // "left" (Lie group methods): on R^N, the group of translations, a Runge-Kutta method.
    const std::string equivariance = method.equivariance();
    REQUIRE((equivariance == "affine" || equivariance == "left"));
    SolverStatistics statistics;
    const double y0[4] = {1.0, 0.2, -0.1, 0.9};
    double y1[4], ry0[4], ry1[4], step_of_rotated[4];
    field.step(method, 0.3, y0, y1, statistics);
    rotate(y0, ry0);
    rotate(y1, ry1);
    field.step(method, 0.3, ry0, step_of_rotated, statistics);
    for (int i = 0; i < 4; ++i) CHECK(step_of_rotated[i] == doctest::Approx(ry1[i]).epsilon(1e-13));
  });
}

TEST_CASE("one_step plugins step jets: the values are the double step, the gradient its Jacobian") {
  Model<false> oscillator(1);
  LagrangianEvaluator evaluator(oscillator);
  MechanicalField field(evaluator, PhaseSpace::tangent);
  for_each_method([&](OneStepMethod& method) {
    SolverStatistics statistics;
    // On a linear field the step is linear: its Jacobian's columns are the steps of e_0, e_1.
    const double h = 0.25, e0[2] = {1.0, 0.0}, e1[2] = {0.0, 1.0};
    double c0[2], c1[2];
    field.step(method, h, e0, c0, statistics);
    field.step(method, h, e1, c1, statistics);
    const Jet2 y[2] = {Jet2::variable(0.3, 2, 0), Jet2::variable(-0.7, 2, 1)};
    Jet2 y1[2];
    field.step(method, h, y, y1, statistics);
    for (int r = 0; r < 2; ++r) {
      CHECK(y1[r].value == doctest::Approx(0.3 * c0[r] - 0.7 * c1[r]).epsilon(1e-14));
      CHECK(y1[r].gradient(0) == doctest::Approx(c0[r]).epsilon(1e-14));
      CHECK(y1[r].gradient(1) == doctest::Approx(c1[r]).epsilon(1e-14));
      CHECK(y1[r].hessian.norm() < 1e-14);
    }
  });
}
