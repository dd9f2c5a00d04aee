// What the checks of `varia verify` share: the scene's integrator they measure, how a check is
// made, and stopping between measurements. verify.cpp makes the defect checks (self_adjoint,
// g_invariant, symplectic) and the long runs (momentum_conserved, energy_bounded);
// verify_orders.cpp the order fits (ld_order, global_order).
#pragma once

#include <fmt/format.h>

#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "assemble.hpp"
#include "scene.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/core/trajectory.hpp"
#include "varia/core/verification.hpp"
#include "verify.hpp"

namespace varia::host::verify_checks {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
// The pairs near the diagonal at which identities of L_d and its round-off are sampled (sample_pairs).
constexpr int kPairs = 5;

// The scene being verified: everything a check needs besides the scene's own integrator.
struct VerifiedScene {
  const Scene& scene;
  Assembly& a;
  Registry& registry;
  LagrangianEvaluator lagrangian;
  Predictions predictions;
  int n, m;
  const std::vector<double>& given_h;  // --h: the step sizes of the order fits, else chosen
  bool progress = false;               // a progress line through each run (not --quiet)
};

// The scene's map over `steps` steps of h from its start, `observe` at each state (step, q, p),
// with a progress line naming `what` where x.progress.
void run_from_start(VerifiedScene& x, DiscreteHamiltonianMap& map, const std::string& what, double h, long steps,
                    const std::function<void(long, const double*, const double*)>& observe);

nlohmann::json prediction(const std::optional<bool>& p);
nlohmann::json prediction(const std::optional<int>& p);
// A check of `name` with its prediction, not yet measured.
PropertyCheck check_of(const char* name, nlohmann::json predicted);
PropertyCheck not_measured(const char* name, nlohmann::json predicted, const char* why);

// Verify ends between its measurements when a signal asked to stop (Interrupted: exit 128 + the
// signal, docs/security.md, "Interrupts").
void stop_before(const char* property, double h);

// Runs `measure` (stop_before it); a numerical failure inside it names the property and the step size.
template <class F>
auto within(const char* property, double h, F&& measure) {
  stop_before(property, h);
  try {
    return measure();
  } catch (const StepFailure& e) {
    throw NumericalFailure(fmt::format("verify {} at h = {:.4g}: step {} (from t = {:.6g}), residual {:.3g}: {}",
                                       property, h, e.step(), e.t(), e.residual(), e.what()),
                           e.residual(), e.origin());
  } catch (const NumericalFailure& e) {
    throw NumericalFailure(fmt::format("verify {} at h = {:.4g}, residual {:.3g}: {}", property, h, e.residual(),
                                       e.what()),
                           e.residual(), e.origin());
  }
}

// The velocity at (q, p) (the inverse Legendre transform from `guess`), and at the initial state.
std::vector<double> velocity_of(VerifiedScene& x, const double* q, const double* p, std::vector<double> guess);
std::vector<double> initial_velocity(VerifiedScene& x);

// The order checks (verify_orders.cpp).
PropertyCheck ld_order(VerifiedScene& x);
PropertyCheck global_order(VerifiedScene& x);

}  // namespace varia::host::verify_checks
