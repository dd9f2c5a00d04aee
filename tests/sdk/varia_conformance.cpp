// varia-conformance (sdk/tools/varia_conformance.cpp) on effect and force plugins: every bundled
// effect and force conforms; an effect whose gradient is 1.5 times V's derivative
// (tests/fault_plugins/wrong_effect_gradient.cpp) is refused, exit 1, with the Taylor test's
// slope; and the suites, called as functions, refuse a force with a wrong Jacobian entry and a
// Lagrangian whose own Stormer-Verlet steps or shots are not the recurrence's.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "../core/sphere_constraints.hpp"
#include "varia/sdk/conformance/constraint.hpp"
#include "varia/sdk/conformance/force.hpp"
#include "varia/sdk/conformance/lagrangian.hpp"
#include "varia/sdk/force_base.hpp"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code;
  std::string out;
};

Outcome conformance(const fs::path& file) {
  const std::string command = "'" + (fs::path(VARIA_BUILD_DIR) / "bin" / "varia-conformance").string() + "' '" +
                              file.string() + "' 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

fs::path bundled(const std::string& name) { return fs::path(VARIA_BUILD_DIR) / "lib" / "varia" / "plugins" / name; }

// f_i = -c v_i + k q_i^2 on Rn (c = 0.3, k = 0.7): its Jacobian entries df_i/dq_i = 2 k q_i,
// df_i/dv_i = -c; `wrong` reports the first df/dq entry twice too large.
class QuadraticForce final : public varia::sdk::ForceBase {
 public:
  QuadraticForce(int n, bool wrong) : ForceBase({"Rn", n, n}), wrong_(wrong) {
    for (int i = 0; i < n; ++i) add_entry(i, i);
    for (int i = 0; i < n; ++i) add_entry(i, n + i);
  }
  void apply(double, const double* q, const double* v, double* force, double* jacobian) const override {
    for (int i = 0; i < n_; ++i) force[i] = -0.3 * v[i] + 0.7 * q[i] * q[i];
    if (jacobian == nullptr) return;
    for (int i = 0; i < n_; ++i) jacobian[i] = (wrong_ && i == 0 ? 2.8 : 1.4) * q[i];
    for (int i = 0; i < n_; ++i) jacobian[n_ + i] = -0.3;
  }

 private:
  bool wrong_;
};

// The oscillator L = v.v/2 - q.q/2 on R^2, written by hand (no SDK), that runs the explicit
// form's Stormer-Verlet steps itself: `wrong` kicks with the force from before the drift
// (d += K f; q += d; f = -q), a different method.
class Oscillator final : public varia::Lagrangian {
 public:
  explicit Oscillator(bool wrong) : wrong_(wrong) {}
  int position_size() const noexcept override { return 2; }
  int velocity_size() const noexcept override { return 2; }
  varia::Status evaluate(const double* q, const double* v, double* value, double* gradient,
                         double* hessian) noexcept override {
    if (value != nullptr) *value = 0.5 * (v[0] * v[0] + v[1] * v[1] - q[0] * q[0] - q[1] * q[1]);
    if (gradient != nullptr)
      for (int i = 0; i < 2; ++i) gradient[i] = -q[i], gradient[2 + i] = v[i];
    if (hessian != nullptr)
      for (int i = 0; i < 16; ++i) hessian[i] = i % 5 == 0 ? (i < 8 ? -1.0 : 1.0) : 0.0;
    return nullptr;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    mass[0] = mass[3] = 1.0, mass[1] = mass[2] = 0.0;
    return true;
  }
  bool offers(const varia::KernelCall& call) const noexcept override {
    return varia::kernel::arguments<varia::kernel::StormerVerletSteps>(call) != nullptr;
  }
  varia::Status run(const varia::KernelCall& call) noexcept override {
    const auto* verlet = varia::kernel::arguments<varia::kernel::StormerVerletSteps>(call);
    if (verlet == nullptr) return "not offered";
    double *q = verlet->q, *d = verlet->d, *f = verlet->f;
    const double* K = verlet->K;
    for (long k = 0; k < verlet->steps; ++k) {
      if (wrong_)
        for (int i = 0; i < 2; ++i) d[i] += K[i] * f[0] + K[2 + i] * f[1];
      for (int i = 0; i < 2; ++i) q[i] += d[i], f[i] = -q[i];
      if (!wrong_)
        for (int i = 0; i < 2; ++i) d[i] += K[i] * f[0] + K[2 + i] * f[1];
    }
    return nullptr;
  }

 private:
  bool wrong_;
};

// The oscillator L = v^2/2 - q^2/2 on R^1, written by hand (no SDK), that runs the shooting
// construction's shots itself (explicit_shot.hpp with its own model). `right` as written;
// `unread` then writes other numbers into the Hessians' block in eta x eta, which no one reads
// (kernel::ExplicitShot); `wrong` adds 1e-9 to the end offset's second derivative in (eta, w0).
class ShootingOscillator final : public varia::Lagrangian {
 public:
  enum class Shots { right, unread, wrong };
  explicit ShootingOscillator(Shots shots) : shots_(shots) {}
  int position_size() const noexcept override { return 1; }
  int velocity_size() const noexcept override { return 1; }
  varia::Status evaluate(const double* q, const double* v, double* value, double* gradient,
                         double* hessian) noexcept override {
    if (value != nullptr) *value = 0.5 * (v[0] * v[0] - q[0] * q[0]);
    if (gradient != nullptr) gradient[0] = -q[0], gradient[1] = v[0];
    if (hessian != nullptr) hessian[0] = -1.0, hessian[1] = hessian[2] = 0.0, hessian[3] = 1.0;
    return nullptr;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    mass[0] = 1.0;
    return true;
  }
  bool evaluates_at_jets() const noexcept override { return true; }
  varia::Status gradient_jet(const varia::Jet2* q, const varia::Jet2* v, varia::Jet2* value,
                             varia::Jet2* gradient) noexcept override {
    if (value != nullptr) *value = 0.5 * (v[0] * v[0] - q[0] * q[0]);
    gradient[0] = -q[0];
    gradient[1] = v[0];
    return nullptr;
  }
  bool offers(const varia::KernelCall& call) const noexcept override {
    const auto* shot = varia::kernel::arguments<varia::kernel::ExplicitShot>(call);
    return shot != nullptr && shot->plan != nullptr && shot->plan->n == 1;
  }
  varia::Status run(const varia::KernelCall& call) noexcept override {
    if (!offers(call)) return "not offered";
    const auto& shot = *varia::kernel::arguments<varia::kernel::ExplicitShot>(call);
    const varia::ShotPlan& plan = *shot.plan;
    const double *q0 = shot.q0, *w0 = shot.w0, h = shot.h;
    varia::Jet2 *action = shot.action, *offsets = shot.offsets;
    std::vector<varia::Jet2> work(varia::shot_workspace(plan));
    varia::explicit_shot(plan, q0, w0, h, *action, offsets, work.data(),
                         [](const varia::Jet2* q, const varia::Jet2* v, varia::Jet2* L, varia::Jet2* Lq) {
                           if (L != nullptr) *L = 0.5 * (v[0] * v[0] - q[0] * q[0]);
                           Lq[0] = -q[0];
                         });
    if (shots_ == Shots::unread) action->hessian(0, 0) = 12.5, offsets[0].hessian(0, 0) = -3.0;
    if (shots_ == Shots::wrong) offsets[0].hessian(0, 1) += 1e-9, offsets[0].hessian(1, 0) += 1e-9;
    return nullptr;
  }

 private:
  Shots shots_;
};

}  // namespace

TEST_CASE("the Lagrangian suite refuses a plugin whose own shots are off by 1e-9 in a second derivative that the "
          "shooting Newton reads, and accepts it with its shots right or with other numbers where nothing reads") {
  using Shots = ShootingOscillator::Shots;
  std::mt19937 engine(13);
  for (const Shots shots : {Shots::right, Shots::unread}) {
    ShootingOscillator oscillator(shots);
    const auto accepted = varia::sdk::conformance::check_lagrangian(oscillator, engine, 5);
    const std::string first_failure = accepted.empty() ? std::string() : accepted.list()[0];
    CAPTURE(first_failure);
    CHECK(accepted.empty());
  }
  ShootingOscillator wrong(Shots::wrong);
  const auto failures = varia::sdk::conformance::check_lagrangian(wrong, engine, 5);
  REQUIRE(failures.list().size() == 1);
  CHECK(failures.list()[0].find("the explicit shot kernel gives S and the offsets") != std::string::npos);
}

TEST_CASE("the Lagrangian suite refuses a plugin whose own Stormer-Verlet steps kick before the drift, and accepts "
          "the same plugin with the recurrence's order") {
  std::mt19937 engine(11);
  Oscillator right(false), wrong(true);
  const auto accepted = varia::sdk::conformance::check_lagrangian(right, engine, 5);
  const std::string first_failure = accepted.empty() ? std::string() : accepted.list()[0];
  CAPTURE(first_failure);
  CHECK(accepted.empty());
  const auto failures = varia::sdk::conformance::check_lagrangian(wrong, engine, 5);
  REQUIRE(failures.list().size() == 1);
  CHECK(failures.list()[0].find("the Stormer-Verlet steps kernel gives (q, d, f)") != std::string::npos);
}

TEST_CASE("varia-conformance: every bundled effect and force plugin conforms, by the Taylor tests of its "
          "derivatives") {
  for (const char* name : {"effect_gravity.so", "effect_spring.so", "effect_central.so", "effect_gravitation.so",
                           "force_damping.so", "force_periodic_force.so"}) {
    const Outcome outcome = conformance(bundled(name));
    CAPTURE(outcome.out);
    CHECK(outcome.code == 0);
    CHECK(outcome.out.find("conforms") != std::string::npos);
    CHECK(outcome.out.find("Taylor tests") != std::string::npos);
  }
}

// The slope the first line of `claim` reports ("... falls as eps^SLOPE (expected eps^2)").
double reported_slope(const std::string& out, const std::string& claim) {
  const std::string lead = claim + ": the first-order model's error falls as eps^";
  const auto at = out.find(lead);
  REQUIRE(at != std::string::npos);
  return std::stod(out.substr(at + lead.size()));
}

TEST_CASE("varia-conformance refuses an effect whose gradient is 1.5 times V's derivative, exit 1, naming the "
          "gradient and the error's slope eps^1") {
  const Outcome outcome = conformance(fs::path(VARIA_FAULT_PLUGIN_DIR) / "fault_wrong_effect_gradient.so");
  CAPTURE(outcome.out);
  CHECK(outcome.code == 1);
  CHECK(outcome.out.find("effect 'wrong-gradient' does not conform") != std::string::npos);
  CHECK(reported_slope(outcome.out, "the gradient is not V's derivative") == doctest::Approx(1.0).epsilon(0.05));
  // Its Hessian, the identity, is not the derivative of the gradient it reports (1.5 I) either.
  CHECK(reported_slope(outcome.out, "the Hessian is not the gradient's derivative") ==
        doctest::Approx(1.0).epsilon(0.05));
}

TEST_CASE("the constraint suite refuses a curvature derivative with a wrong term, and accepts the right one") {
  std::mt19937 engine(11);
  varia::testing::QuarticSphere right, wrong;
  wrong.cross = 3.0;
  CHECK(varia::sdk::conformance::check_constraint(right, 3, engine).empty());
  const auto failures = varia::sdk::conformance::check_constraint(wrong, 3, engine);
  REQUIRE(failures.list().size() >= 1);
  CHECK(reported_slope(failures.list()[0], "curvature_derivative is not the derivative of v^T H_i(q) v in q") ==
        doctest::Approx(1.0).epsilon(0.05));
}

TEST_CASE("the force suite refuses a force with one wrong Jacobian entry, and accepts the same force without it") {
  std::mt19937 engine(7);
  QuadraticForce right(3, false), wrong(3, true);
  CHECK(varia::sdk::conformance::check_force(right, engine).empty());
  const auto failures = varia::sdk::conformance::check_force(wrong, engine);
  REQUIRE(failures.list().size() >= 1);
  CHECK(reported_slope(failures.list()[0], "the Jacobian is not the force's derivative in (q, v)") ==
        doctest::Approx(1.0).epsilon(0.05));
}
