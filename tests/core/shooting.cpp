// The shooting-based discrete Lagrangian (paper, sec. 3): orders min(p, q) measured against exact
// solutions, the Hamiltonian and Type II forms, exact derivatives, the shooting Newton iteration.
#include "varia/core/shooting.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <new>

#include "core/shooting_fixtures.hpp"
#include "varia/core/one_step_map.hpp"

using namespace varia;
using namespace varia::testing;

namespace {

constexpr double kTime = 4.0;  // the final time of the convergence runs
const std::vector<int> kSteps{10, 20, 40, 80, 160};

std::vector<double> step_sizes() {
  std::vector<double> h;
  for (int n : kSteps) h.push_back(kTime / n);
  return h;
}

// The oscillator's exact state at kTime from (q0, p0) = (1, 0.5): q0 cos t + p0 sin t.
Eigen::Vector2d oscillator_exact() {
  return {std::cos(kTime) + 0.5 * std::sin(kTime), -std::sin(kTime) + 0.5 * std::cos(kTime)};
}

// The pendulum's state at kTime from (1, 0.5), converged: 4000 steps of the 3-stage Gauss
// method (order 6, error ~1e-17).
Eigen::Vector2d pendulum_reference() {
  FlatSpace space(1);
  SeparablePendulum pendulum;
  auto gauss = gauss3();
  OneStepHamiltonianMap map(space, pendulum, gauss, {});
  return run(map, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.5),
             kTime / 4000, 4000);
}

// Global errors at kTime (max norm over q and p) of a map made per step size.
template <class Map>
std::vector<double> errors(Map&& make_and_run, const Eigen::Vector2d& reference) {
  std::vector<double> e;
  for (int n : kSteps) e.push_back((make_and_run(kTime / n, n) - reference).template lpNorm<Eigen::Infinity>());
  return e;
}

// The global errors of the shooting construction on a 1-dof Lagrangian from (1, 0.5).
std::vector<double> shooting_errors(Lagrangian& lagrangian, Quadrature& rule,
                                    OneStepMethod& method, ShootingForm form,
                                    const Eigen::Vector2d& reference) {
  return errors(
      [&](double h, int n) {
        FlatSpace space(1);
        ShootingDiscreteLagrangian shooting(space, lagrangian, rule, method, form, {});
        return run(shooting, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.5),
                   h, n);
      },
      reference);
}

// Fits the slope over all five step sizes but the coarsest (h = 0.4, pre-asymptotic), unless
// the finest has reached round-off (then it is dropped too).
double order_of(const std::vector<double>& e) {
  const int last = e.back() < 1e-12 ? 4 : 5;
  return fitted_order(step_sizes(), e, 1, last);
}

}  // namespace

TEST_CASE("SVIMID (implicit midpoint + trapezoid) is order 2 on the pendulum") {
  SeparablePendulum pendulum;
  auto rule = trapezoid();
  auto method = implicit_midpoint();
  const auto e = shooting_errors(pendulum, rule, method, ShootingForm::lagrangian,
                                 pendulum_reference());
  CAPTURE(e[4]);
  const double order = order_of(e);
  CAPTURE(order);
  CHECK(order == doctest::Approx(2.0).epsilon(0.05));
}

TEST_CASE("SVIRK4 (rk4 + simpson) is order 4 on the pendulum") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = rk4();
  const auto e = shooting_errors(pendulum, rule, method, ShootingForm::lagrangian,
                                 pendulum_reference());
  CAPTURE(e[4]);
  const double order = order_of(e);
  CAPTURE(order);
  CHECK(order == doctest::Approx(4.0).epsilon(0.05));
}

TEST_CASE("sviRK4EM (rk4 + two-term Euler-Maclaurin) is order 4 on the oscillator") {
  MassOscillator oscillator;
  EulerMaclaurin2 rule;
  auto method = rk4();
  const auto e = shooting_errors(oscillator, rule, method, ShootingForm::lagrangian,
                                 oscillator_exact());
  CAPTURE(e[4]);
  const double order = order_of(e);
  CAPTURE(order);
  CHECK(order == doctest::Approx(4.0).epsilon(0.05));
}

TEST_CASE("shooting order is min(p, q) when the method and the rule differ in order") {
  SeparablePendulum pendulum;
  const Eigen::Vector2d reference = pendulum_reference();
  struct Pair {
    const char* name;
    OneStepMethod* method;
    Quadrature* rule;
    double order;
  };
  auto rk = rk4();
  auto em = explicit_midpoint();
  auto g2 = gauss2();
  auto trap = trapezoid();
  auto simp = simpson();
  auto mid = midpoint_rule();
  const Pair pairs[] = {{"rk4 + trapezoid", &rk, &trap, 2},
                        {"explicit-midpoint + simpson", &em, &simp, 2},
                        {"gauss-2 + midpoint rule", &g2, &mid, 2},
                        {"gauss-2 + simpson (SRK4 order)", &g2, &simp, 4}};
  for (const Pair& pair : pairs) {
    const auto e = shooting_errors(pendulum, *pair.rule, *pair.method, ShootingForm::lagrangian,
                                   reference);
    const double order = order_of(e);
    CAPTURE(pair.name);
    CAPTURE(order);
    CHECK(order == doctest::Approx(pair.order).epsilon(0.05));
  }
}

TEST_CASE("Hamiltonian and Type II forms have the method's order and agree with the Lagrangian form") {
  MassOscillator oscillator;
  auto rule = simpson();
  auto method = rk4();
  const Eigen::Vector2d exact = oscillator_exact();
  const auto lagrangian = shooting_errors(oscillator, rule, method, ShootingForm::lagrangian, exact);
  for (ShootingForm form : {ShootingForm::hamiltonian, ShootingForm::type_2}) {
    const auto e = shooting_errors(oscillator, rule, method, form, exact);
    const double order = order_of(e);
    CAPTURE(static_cast<int>(form));
    CAPTURE(order);
    CHECK(order == doctest::Approx(4.0).epsilon(0.05));
    // Both errors are O(h^4), so the forms agree to O(h^4): within a factor of the Lagrangian's.
    for (std::size_t i = 0; i < e.size(); ++i) CHECK(e[i] <= 2.0 * lagrangian[i] + 1e-13);
  }
}

TEST_CASE("the step solves the IDEL equations p0 = -D1 L_d, p1 = D2 L_d of evaluate, in every form") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = gauss2();
  FlatSpace space(1);
  for (ShootingForm form : {ShootingForm::lagrangian, ShootingForm::hamiltonian,
                            ShootingForm::type_2}) {
    CAPTURE(static_cast<int>(form));
    ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, form, {});
    const double q0 = 0.7, p0 = -0.3, h = 0.3;
    double q1, p1, Ld, D1, D2;
    shooting.step(&q0, &p0, h, &q1, &p1);
    shooting.evaluate(&q0, &q1, h, &Ld, &D1, &D2);
    CHECK(-D1 == doctest::Approx(p0).epsilon(1e-12));
    CHECK(D2 == doctest::Approx(p1).epsilon(1e-12));
  }
}

TEST_CASE("shooting D1 and D2 are the derivatives of L_d") {
  SeparablePendulum pendulum;
  EulerMaclaurin2 rule;
  auto method = rk4();
  FlatSpace space(1);
  for (ShootingForm form : {ShootingForm::lagrangian, ShootingForm::type_2}) {
    ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, form, {});
    const double q0 = 0.3, q1 = 0.45, h = 0.2, e = 1e-5;
    double Ld, D1, D2, plus, minus;
    shooting.evaluate(&q0, &q1, h, &Ld, &D1, &D2);
    // Test-only central differences of L_d in q0 and q1.
    double a = q0 + e, b = q0 - e;
    shooting.evaluate(&a, &q1, h, &plus, nullptr, nullptr);
    shooting.evaluate(&b, &q1, h, &minus, nullptr, nullptr);
    CHECK(D1 == doctest::Approx((plus - minus) / (2 * e)).epsilon(1e-8));
    a = q1 + e;
    b = q1 - e;
    shooting.evaluate(&q0, &a, h, &plus, nullptr, nullptr);
    shooting.evaluate(&q0, &b, h, &minus, nullptr, nullptr);
    CHECK(D2 == doctest::Approx((plus - minus) / (2 * e)).epsilon(1e-8));
  }
}

TEST_CASE("SVIMID's discrete Lagrangian is self-adjoint: L_d(q0, q1, h) = -L_d(q1, q0, -h)") {
  SeparablePendulum pendulum;
  auto rule = trapezoid();
  auto method = implicit_midpoint();
  FlatSpace space(1);
  ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, ShootingForm::lagrangian, {});
  const double q0 = 0.3, q1 = 0.5, h = 0.25;
  double forward, backward;
  shooting.evaluate(&q0, &q1, h, &forward, nullptr, nullptr);
  shooting.evaluate(&q1, &q0, -h, &backward, nullptr, nullptr);
  CHECK(forward == doctest::Approx(-backward).epsilon(1e-13));
}

TEST_CASE("shooting with an affine-equivariant method conserves the angular momentum of a central force") {
  PlanarKepler kepler;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(2);
  ShootingDiscreteLagrangian shooting(space, kepler, rule, method, ShootingForm::lagrangian, {});
  Eigen::Vector2d q(1.0, 0.0), p(0.1, 1.2), q1, p1;
  const double J0 = q.x() * p.y() - q.y() * p.x();
  double drift = 0.0;
  for (int k = 0; k < 100; ++k) {
    shooting.step(q.data(), p.data(), 0.1, q1.data(), p1.data());
    q = q1;
    p = p1;
    drift = std::max(drift, std::abs(q.x() * p.y() - q.y() * p.x() - J0));
  }
  CAPTURE(drift);
  CHECK(drift < 1e-12);
}

TEST_CASE("the shooting Newton iteration converges quadratically from the inverse Legendre guess") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(1);
  ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, ShootingForm::lagrangian, {});
  double q0 = 2.0, p0 = 0.5, q1, p1;
  shooting.step(&q0, &p0, 1.0, &q1, &p1);  // a long step: the guess is off by ~1e-3
  const auto& r = shooting.last_residuals();
  REQUIRE(r.size() >= 3);
  // Each residual well above round-off is at most C times the square of the one before.
  for (std::size_t k = 1; k < r.size(); ++k) {
    CAPTURE(k);
    CAPTURE(r[k - 1]);
    CAPTURE(r[k]);
    if (r[k] > 1e-12) CHECK(r[k] <= 10.0 * r[k - 1] * r[k - 1]);
  }
  // At the paper's h = 0.2: at most 4 iterations per step, 3 on average or fewer.
  for (int k = 0; k < 100; ++k) {
    shooting.step(&q0, &p0, 0.2, &q1, &p1);
    q0 = q1;
    p0 = p1;
  }
  const auto& statistics = shooting.solver_statistics();
  CAPTURE(statistics.mean());
  CHECK(statistics.max_iterations <= 4);
  CHECK(statistics.mean() <= 3.0);
}

TEST_CASE("steps that continue one another start from the extrapolated corrections: one shot each, the cold steps' result") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(1);
  const double h = 0.005;
  ShootingDiscreteLagrangian warm(space, pendulum, rule, method, ShootingForm::lagrangian, {});
  double q = 1.3, p = 0.0, q1, p1;
  for (int k = 0; k < 200; ++k) {
    // The same step from the inverse Legendre guess alone, by a construction that has taken none.
    ShootingDiscreteLagrangian cold(space, pendulum, rule, method, ShootingForm::lagrangian, {});
    double cold_q1, cold_p1;
    cold.step(&q, &p, h, &cold_q1, &cold_p1);
    warm.step(&q, &p, h, &q1, &p1);
    CAPTURE(k);
    CHECK(cold.solver_statistics().iterations == 2);  // the guess is off by ~1e-12 here
    CHECK(std::abs(q1 - cold_q1) <= 4e-16);
    CHECK(std::abs(p1 - cold_p1) <= 4e-16);
    q = q1;
    p = p1;
  }
  // From the fourth step on (three corrections known), every step ends after its first shot.
  CAPTURE(warm.solver_statistics().mean());
  CHECK(warm.solver_statistics().iterations <= 2 * 3 + (200 - 3));
  CHECK(warm.solver_statistics().max_iterations == 2);
  // A step that does not continue the last (another point) starts from the guess again.
  double other_q = 0.4, other_p = 0.1;
  warm.step(&other_q, &other_p, h, &q1, &p1);
  CHECK(warm.last_residuals().size() == 2);
}

TEST_CASE("implicit stage solves converge quadratically and are counted") {
  SeparablePendulum pendulum;
  auto rule = trapezoid();
  auto method = implicit_midpoint();
  FlatSpace space(1);
  ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, ShootingForm::lagrangian, {});
  double q0 = 1.0, p0 = 0.5, q1, p1;
  shooting.step(&q0, &p0, 0.2, &q1, &p1);
  const auto& stages = shooting.stage_statistics();
  CAPTURE(stages.mean());
  CHECK(stages.solves > 0);
  CHECK(stages.max_iterations <= 5);
}

TEST_CASE("a shooting solve that does not converge raises a numerical failure") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  FlatSpace space(1);
  double q0 = 2.0, p0 = 0.5, q1, p1;
  SUBCASE("too few iterations") {
    auto method = rk4();
    SolverOptions options;
    options.max_iterations = 1;
    ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, ShootingForm::lagrangian,
                                        options);
    CHECK_THROWS_AS(shooting.step(&q0, &p0, 0.5, &q1, &p1), NumericalFailure);
  }
  SUBCASE("a non-finite Lagrangian inside the propagation (a collision of the central force)") {
    PlanarKepler kepler;
    auto method = rk4();
    FlatSpace plane(2);
    ShootingDiscreteLagrangian shooting(plane, kepler, rule, method, ShootingForm::lagrangian, {});
    const double q[2] = {0.0, 0.0}, p[2] = {1.0, 0.0};
    double qq[2], pp[2];
    CHECK_THROWS_AS(shooting.step(q, p, 0.1, qq, pp), NumericalFailure);
  }
  SUBCASE("implicit stages that do not converge") {
    auto method = implicit_midpoint();
    SolverOptions options;
    options.max_iterations = 2;
    ShootingDiscreteLagrangian shooting(space, pendulum, rule, method, ShootingForm::lagrangian,
                                        options);
    CHECK_THROWS_AS(shooting.step(&q0, &p0, 3.0, &q1, &p1), NumericalFailure);
  }
}

namespace {

// n pendulums coupled by torsion springs, L = 1/2 |v|^2 + sum_i cos q_i + 1/2 sum_i cos(q_i - q_{i+1}),
// declaring its identity mass matrix or not.
struct CoupledPendulums : sdk::AutodiffLagrangian<CoupledPendulums> {
  CoupledPendulums(int n, bool declared) : sdk::AutodiffLagrangian<CoupledPendulums>(n, n), n_(n), declared_(declared) {}
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::cos;
    T L = T(0.0);
    for (int i = 0; i < n_; ++i) L += 0.5 * v(i) * v(i) + cos(q(i));
    for (int i = 0; i + 1 < n_; ++i) L += 0.5 * cos(q(i) - q(i + 1));
    return L;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    if (declared_) Eigen::Map<Eigen::MatrixXd>(mass, n_, n_).setIdentity();
    return declared_;
  }
  int n_;
  bool declared_;
};

// The inner Lagrangian whose Hessian at jets takes at most `capacity` variables (0: none): the
// shooting construction's lagrangian form then propagates in passes of at most that many.
class CappedHessianJets final : public Lagrangian {
 public:
  CappedHessianJets(Lagrangian& inner, int capacity) : inner_(inner), capacity_(capacity) {}
  int position_size() const noexcept override { return inner_.position_size(); }
  int velocity_size() const noexcept override { return inner_.velocity_size(); }
  Status evaluate(const double* q, const double* v, double* value, double* gradient, double* hessian) noexcept override {
    return inner_.evaluate(q, v, value, gradient, hessian);
  }
  bool evaluates_at_jets() const noexcept override { return true; }
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept override {
    return inner_.gradient_jet(q, v, value, gradient);
  }
  int hessian_jet_variables() const noexcept override { return capacity_; }
  Status hessian_jet(const Jet2* q, const Jet2* v, int first, int count, int directions, const Jet2* U,
                     Jet2* out) noexcept override {
    return inner_.hessian_jet(q, v, first, count, directions, U, out);
  }

 private:
  Lagrangian& inner_;
  int capacity_;
};

Eigen::VectorXd final_state(DiscreteHamiltonianMap& map, int n, double h, int steps) {
  return run(map, Eigen::VectorXd::LinSpaced(n, 0.3, 1.1), Eigen::VectorXd::LinSpaced(n, 0.5, -0.4), h, steps);
}

}  // namespace

TEST_CASE("without a declared constant mass matrix the shooting construction's lagrangian form integrates (q, v) "
          "with the acceleration M^{-1} (L_q - L_vq v) at jets, the hamiltonian form and the one-step construction "
          "(q, p) through the exact inverse Legendre transform, each giving the declared-mass trajectory to "
          "round-off, and the lagrangian form refused where L gives no Hessian at jets") {
  Pendulum pendulum;  // declares no mass matrix
  SeparablePendulum declared;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(1);
  CHECK_THROWS_AS(shooting_form("type-3"), std::invalid_argument);
  for (ShootingForm form : {ShootingForm::lagrangian, ShootingForm::hamiltonian}) {
    ShootingDiscreteLagrangian general(space, pendulum, rule, method, form, {});
    ShootingDiscreteLagrangian constant(space, declared, rule, method, form, {});
    const Eigen::VectorXd a = final_state(general, 1, 0.1, 50), b = final_state(constant, 1, 0.1, 50);
    CAPTURE(a.transpose());
    CAPTURE(b.transpose());
    CHECK((a - b).lpNorm<Eigen::Infinity>() < 1e-13);
  }
  auto gauss = gauss2();
  OneStepHamiltonianMap general_one_step(space, pendulum, gauss, {}), constant_one_step(space, declared, gauss, {});
  const Eigen::VectorXd c = final_state(general_one_step, 1, 0.1, 50), d = final_state(constant_one_step, 1, 0.1, 50);
  CHECK((c - d).lpNorm<Eigen::Infinity>() < 1e-13);
  DoublePendulum double_pendulum;
  CappedHessianJets none(double_pendulum, 0);
  FlatSpace plane(2);
  std::string message;
  try {
    ShootingDiscreteLagrangian refused(plane, none, rule, method, ShootingForm::lagrangian, {});
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  CHECK(message.find("Hessian at jets of at least 2 variables") != std::string::npos);
  CHECK(message.find("\"hamiltonian\"") != std::string::npos);
  CHECK_NOTHROW(ShootingDiscreteLagrangian(plane, none, rule, method, ShootingForm::hamiltonian, {}));
}

TEST_CASE("above the jets' capacity the shooting construction propagates its sensitivities in passes (first "
          "derivatives in blocks, second derivatives in pairs of blocks of eta and w0): the trajectory is the "
          "one-pass trajectory to round-off, with a configuration-dependent mass matrix (the double pendulum's "
          "Hessian at jets capped at 2 and 4 variables) and without (coupled pendulums of dim 4, explicit and "
          "implicit methods, and of dim 8 and 10, the last above the SDK's stack size, where the explicit method's "
          "step runs on the shot's adjoint: issue #39) (issue #18)") {
  auto rule = simpson();
  auto explicit_method = rk4();
  auto implicit_method = gauss2();
  for (OneStepMethod* method : std::initializer_list<OneStepMethod*>{&explicit_method, &implicit_method}) {
    DoublePendulum pendulum;  // the SDK's Hessian at jets: 6 variables, one pass (2n = 4)
    FlatSpace plane(2);
    ShootingDiscreteLagrangian one_pass(plane, pendulum, rule, *method, ShootingForm::lagrangian, {});
    const Eigen::VectorXd reference = final_state(one_pass, 2, 0.05, 40);
    for (int capacity : {2, 4}) {
      CAPTURE(capacity);
      CappedHessianJets capped(pendulum, capacity);
      ShootingDiscreteLagrangian passes(plane, capped, rule, *method, ShootingForm::lagrangian, {});
      const Eigen::VectorXd state = final_state(passes, 2, 0.05, 40);
      CAPTURE(state.transpose());
      CAPTURE(reference.transpose());
      CHECK((state - reference).lpNorm<Eigen::Infinity>() < 1e-13);
    }
    // Dim 4: the declared mass takes one pass (jets of 8 <= 12 variables); without it, the
    // Hessian at jets (6 variables) takes 2 + 5 passes. Dim 8: 2 + 5 passes (blocks of 6) against
    // 3 + 12 (blocks of 3), both with coupling across the blocks.
    // Dim 10: 20 numbers, above the SDK's stack size (its workspace's dual numbers at jets).
    for (int n : {4, 8, 10}) {
      if (n >= 8 && method == &implicit_method) continue;  // L's Hessian at jets of 16 numbers: slow
      CAPTURE(n);
      CoupledPendulums general(n, false), constant(n, true);
      FlatSpace space(n);
      ShootingDiscreteLagrangian a(space, general, rule, *method, ShootingForm::lagrangian, {});
      ShootingDiscreteLagrangian b(space, constant, rule, *method, ShootingForm::lagrangian, {});
      const int steps = n == 4 ? 20 : n == 8 ? 5 : 2;
      const Eigen::VectorXd x = final_state(a, n, 0.05, steps), y = final_state(b, n, 0.05, steps);
      CAPTURE(x.transpose());
      CAPTURE(y.transpose());
      CHECK((x - y).lpNorm<Eigen::Infinity>() < 1e-13);
      // Exact Newton from the warm start; above dim 6 the explicit method's step runs on the shot's
      // adjoint, simplified Newton (shooting_solve.cpp), whose contraction here is about 0.01.
      CHECK(b.solver_statistics().max_iterations <= (method == &explicit_method && n > 6 ? 5 : 3));
    }
  }
}

TEST_CASE("the one-step construction: MID is order 2, SRK4 (2-stage Gauss) order 4") {
  SeparablePendulum pendulum;
  const Eigen::Vector2d reference = pendulum_reference();
  auto mid = implicit_midpoint();
  auto srk4 = gauss2();
  for (auto [method, expected] : {std::pair<OneStepMethod*, double>{&mid, 2.0}, {&srk4, 4.0}}) {
    const auto e = errors(
        [&](double h, int n) {
          FlatSpace space(1);
          OneStepHamiltonianMap map(space, pendulum, *method, {});
          return run(map, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.5), h, n);
        },
        reference);
    const double order = order_of(e);
    CAPTURE(order);
    CHECK(order == doctest::Approx(expected).epsilon(0.05));
  }
}

TEST_SUITE("long") {
  // The paper's "Energy error, step size h = 0.2" panels: bounded, no drift over 10^4 steps.
  TEST_CASE("SVIRK4 and SVIMID energy errors stay bounded without drift over 10^4 steps at h = 0.2") {
    SeparablePendulum pendulum;
    auto simp = simpson();
    auto trap = trapezoid();
    auto rk = rk4();
    auto mid = implicit_midpoint();
    for (auto [method, rule] : {std::pair<OneStepMethod*, Quadrature*>{&rk, &simp}, {&mid, &trap}}) {
      FlatSpace space(1);
      ShootingDiscreteLagrangian shooting(space, pendulum, *rule, *method,
                                          ShootingForm::lagrangian, {});
      double q = 1.0, p = 0.5, q1, p1;
      const double E0 = 0.5 * p * p - std::cos(q);
      double first = 0.0, last = 0.0;  // the largest error in the first and the last 1000 steps
      for (int k = 0; k < 10000; ++k) {
        shooting.step(&q, &p, 0.2, &q1, &p1);
        q = q1;
        p = p1;
        const double error = std::abs(0.5 * p * p - std::cos(q) - E0);
        if (k < 1000) first = std::max(first, error);
        if (k >= 9000) last = std::max(last, error);
      }
      CAPTURE(first);
      CAPTURE(last);
      CHECK(last <= 1.5 * first);
      CHECK(last < 1e-2);
    }
  }
}

namespace {

// rk4 that does not give its Butcher tableau: the shooting construction then propagates through
// the method's steps (the field's plugin calls), not inside the Lagrangian's plugin.
struct TableaulessRk4 : OneStepMethod {
  sdk::RungeKutta method = rk4();
  int order() const noexcept override { return method.order(); }
  bool self_adjoint() const noexcept override { return method.self_adjoint(); }
  const char* equivariance() const noexcept override { return method.equivariance(); }
  void set_solver(double tolerance, int max_iterations) noexcept override { method.set_solver(tolerance, max_iterations); }
  Status step(VectorField& field, double h, const double* y0, double* y1, StageSolve* report) noexcept override {
    return method.step(field, h, y0, y1, report);
  }
  Status step(VectorField& field, double h, const Jet2* y0, Jet2* y1, StageSolve* report) noexcept override {
    return method.step(field, h, y0, y1, report);
  }
};

}  // namespace

TEST_CASE("the shot inside the Lagrangian's plugin (explicit_shot.hpp) takes the steps of the propagation through "
          "the method, with 9 evaluations a shot of SVIRK4 instead of 11, where the plan allows it") {
  // n pendulums asking for the shot inside the plugin (inline_shot), with sizes given at compile
  // time (Fixed) or read at run time: only the former run shots inside the plugin, for n <= 3 (the
  // kernel is one template in n: its two ends, 1 and 3, are compiled here).
  const auto compare = [&]<int Size>(int n) {
    CAPTURE(Size);
    CAPTURE(n);
    Pendulums<Size> pendulums(n);
    auto rule = simpson();
    auto method = rk4();
    TableaulessRk4 tableauless;
    FlatSpace space(n);
    ShootingDiscreteLagrangian inside(space, pendulums, rule, method, ShootingForm::lagrangian, {});
    ShootingDiscreteLagrangian through(space, pendulums, rule, tableauless, ShootingForm::lagrangian, {});
    const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, 0.3, 1.2), p = Eigen::VectorXd::LinSpaced(n, 0.1, -0.4);
    const Eigen::VectorXd a = run(inside, q, p, 0.05, 100), b = run(through, q, p, 0.05, 100);
    CAPTURE(a.transpose());
    CHECK((a - b).lpNorm<Eigen::Infinity>() <= 1e-14 * a.lpNorm<Eigen::Infinity>());
    // A shot is one solve iteration: through the method L at 3 nodes and the field at 8 stages;
    // inside the plugin one evaluation a node gives L and the next step's first stage (n <= 3,
    // sdk::kMaxShotDimension, sizes known at compile time; otherwise the construction propagates
    // through the method).
    const long shots = inside.solver_statistics().iterations;
    CHECK(inside.evaluations().hessian == (Size != Eigen::Dynamic && n <= 3 ? 9 : 11) * shots);
    CHECK(through.evaluations().hessian == 11 * through.solver_statistics().iterations);
  };
  compare.operator()<1>(1);
  compare.operator()<3>(3);
  compare.operator()<4>(4);
  compare.operator()<Eigen::Dynamic>(2);
  // Not the recurrence: the hamiltonian form integrates (q, p), and propagates through the method.
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(1);
  ShootingDiscreteLagrangian hamiltonian(space, pendulum, rule, method, ShootingForm::hamiltonian, {});
  run(hamiltonian, Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 0.5), 0.05, 10);
  CHECK(hamiltonian.evaluations().hessian == 11 * hamiltonian.solver_statistics().iterations);
}

// The construction's own workspace is set before it is read: built in memory full of garbage
// (0x41 bytes: doubles of 2e6, where a fresh allocation is usually zero), it takes the same steps
// as one built in zeroed memory. The shot inside the plugin once returned before zeroing the
// virtual work's derivatives, which the solve adds in: right in a fresh process, wrong in a used
// heap (with that defect this case fails: Newton's method does not converge).
TEST_CASE("a shooting construction built in memory full of garbage takes the steps of one built in zeroed memory") {
  SeparablePendulum pendulum;
  auto rule = simpson();
  auto method = rk4();
  FlatSpace space(1);
  const auto steps_in = [&](unsigned char fill) {
    alignas(ShootingDiscreteLagrangian) unsigned char memory[sizeof(ShootingDiscreteLagrangian)];
    std::memset(memory, fill, sizeof memory);
    auto* shooting = new (memory) ShootingDiscreteLagrangian(space, pendulum, rule, method, ShootingForm::lagrangian, {});
    const Eigen::VectorXd end = run(*shooting, Eigen::VectorXd::Constant(1, 1.3), Eigen::VectorXd::Zero(1), 0.005, 50);
    shooting->~ShootingDiscreteLagrangian();
    return end;
  };
  const Eigen::VectorXd zeroed = steps_in(0x00), garbage = steps_in(0x41);
  CAPTURE(zeroed.transpose());
  CAPTURE(garbage.transpose());
  CHECK(garbage == zeroed);
}
