// `varia verify`: the defect checks (self_adjoint, g_invariant, symplectic: identities whose
// residual shrinks with h exactly when they fail), the long runs (momentum_conserved,
// energy_bounded), and the report. The order checks are in verify_orders.cpp; what both share in
// verify_checks.hpp.
#include "verify.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "commands.hpp"
#include "constructions/parts.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "verify_checks.hpp"

namespace varia::host {

using nlohmann::json;

namespace verify_checks {

json prediction(const std::optional<bool>& p) { return p ? json(*p) : json(nullptr); }
json prediction(const std::optional<int>& p) { return p ? json(*p) : json(nullptr); }

PropertyCheck check_of(const char* name, json predicted) {
  PropertyCheck c;
  c.name = name;
  c.predicted = std::move(predicted);
  return c;
}

PropertyCheck not_measured(const char* name, json predicted, const char* why) {
  PropertyCheck c = check_of(name, std::move(predicted));
  c.note = why;
  return c;
}

void run_from_start(VerifiedScene& x, DiscreteHamiltonianMap& map, const std::string& what, double h, long steps,
                    const std::function<void(long, const double*, const double*)>& observe) {
  const std::string unit = fmt::format("{} at h = {:.4g}: step", what, h);
  ProgressLine progress(unit.c_str(), steps, !x.progress);
  run(map, x.a.q0, x.a.p0, x.a.t0, h, steps, [&](long step, const double* q, const double* p) {
    observe(step, q, p);
    progress.update(step);
  });
}

void stop_before(const char* property, double h) {
  if (interruption() != 0) stop_if_interrupted(fmt::format("before verify's {} at h = {:.4g}", property, h));
}

std::vector<double> velocity_of(VerifiedScene& x, const double* q, const double* p, std::vector<double> guess) {
  x.lagrangian.inverse_legendre(q, p, guess.data(), x.scene.solver);
  return guess;
}

std::vector<double> initial_velocity(VerifiedScene& x) {
  return velocity_of(x, x.a.q0.data(), x.a.p0.data(), std::vector<double>(x.n, 0.0));
}

}  // namespace verify_checks

namespace {

using namespace verify_checks;

constexpr double kDriftShare = 0.5;     // an energy error mostly trend (EnergyDrift::share) drifts
constexpr long kLongRun = 4000;         // steps of the energy and momentum run at the scene's step

// A defect measured to vanish or not (DefectScaling), against the prediction.
PropertyCheck defect_check(const char* name, json predicted, const DefectScaling& d, const std::string& how) {
  PropertyCheck c = check_of(name, std::move(predicted));
  c.measured = d.largest;
  c.tolerance = d.noise;
  c.holds = d.zero;
  c.note = how + ": " + d.describe();
  return c;
}

// The step sizes of a defect measurement: the scene's step times 2^k for k in `powers`.
std::vector<double> steps_of(const VerifiedScene& x, std::initializer_list<int> powers) {
  std::vector<double> h;
  for (int k : powers) h.push_back(std::ldexp(x.scene.step, k));
  return h;
}

// against. A numerical failure at one step size (its equations have no solution there, or a step
// does not converge) drops that step size, named in `dropped`, as the order fits drop diverged
// runs: the others still measure the defect.
struct DefectValues {
  std::vector<double> h, values;
  double noise = 0.0;
  std::string dropped;
};

// measure(h) at each step size of hs (within: a signal stops it between two).
template <class F>
DefectValues defect_values(const char* property, const std::vector<double>& hs, double noise, F&& measure) {
  DefectValues d;
  d.noise = noise;
  for (double h : hs) {
    try {
      d.values.push_back(within(property, h, [&] { return measure(h, d.noise); }));
      d.h.push_back(h);
    } catch (const NumericalFailure& e) {
      d.dropped += fmt::format("{}{}", d.dropped.empty() ? "" : "; ", e.what());
    }
  }
  return d;
}

// The defect's scaling (defect_check) where it was measured at two step sizes or more; else not
// measured, with the failures that dropped the others.
PropertyCheck defect_check(const char* name, json predicted, const DefectValues& d, const std::string& how) {
  if (d.h.size() < 2) {
    PropertyCheck c = check_of(name, std::move(predicted));
    c.note = fmt::format("not measured: a defect's scaling takes two step sizes, and {} had a solution ({})",
                         d.h.size(), d.dropped);
    return c;
  }
  PropertyCheck c = defect_check(name, std::move(predicted), defect_scaling(d.h, d.values, d.noise), how);
  if (!d.dropped.empty()) c.note += "; step sizes dropped, a numerical failure there: " + d.dropped;
  return c;
}

// ---- self_adjoint, g_invariant ---------------------------------------------------------------------
// Relative residuals of identities of L_d near the diagonal, at the scene's step times 4, 2, 1, 1/2:
// a defect of the construction shrinks with h, round-off does not.

// For a one-step map without L_d: Phi_{-h}(Phi_h(x)) = x exactly when the map is self-adjoint.
double map_symmetry_residual(VerifiedScene& x, double h) {
  std::vector<double> q1(x.m), p1(x.n), q2(x.m), p2(x.n);
  x.a.map->step(x.a.q0.data(), x.a.p0.data(), x.a.t0, h, q1.data(), p1.data());
  x.a.map->step(q1.data(), p1.data(), x.a.t0 + h, -h, q2.data(), p2.data());
  double worst = 0.0;
  for (int i = 0; i < x.m; ++i) worst = std::max(worst, std::abs(q2[i] - x.a.q0[i]));
  for (int i = 0; i < x.n; ++i) worst = std::max(worst, std::abs(p2[i] - x.a.p0[i]));
  return worst / (1.0 + x.a.q0.lpNorm<Eigen::Infinity>() + x.a.p0.lpNorm<Eigen::Infinity>());
}

// A residual of L_d at pairs sampled at each step size of `hs` (sample_pairs), against the
// round-off measured at the same pairs (round_off_of) times kSpread, or what the scene's solver
// tolerance may leave in L_d there (solver_noise_of) times kSolverSpread, the larger.
constexpr double kSpread = 100.0, kSolverSpread = 10.0;

template <class F>
DefectValues ld_defect(VerifiedScene& x, const char* property, const std::vector<double>& hs, F&& residual) {
  const auto v = initial_velocity(x);
  return defect_values(property, hs, kSpread * kEpsilon, [&](double h, double& noise) {
    const auto pairs = sample_pairs(*x.a.manifold, x.a.q0.data(), v.data(), h, kPairs);
    const double here = std::max(kSpread * round_off_of(*x.a.discrete_lagrangian, *x.a.manifold, pairs, h),
                                 kSolverSpread * solver_noise_of(*x.a.discrete_lagrangian, *x.a.manifold, pairs, h,
                                                                 x.scene.solver.tolerance));
    const double value = residual(pairs, h);
    noise = std::max(noise, here);
    return value;
  });
}

PropertyCheck self_adjoint(VerifiedScene& x) {
  const json predicted = prediction(x.predictions.self_adjoint);
  const auto hs = steps_of(x, {2, 1, 0, -1});
  if (x.a.discrete_lagrangian == nullptr) {
    return defect_check("self_adjoint", predicted,
                        defect_values("self_adjoint", hs, kNoiseSpread * kEpsilon,
                                      [&](double h, double&) { return map_symmetry_residual(x, h); }),
                        "|Phi_{-h}(Phi_h(x)) - x| / (1 + |x|), one step from the initial state");
  }
  return defect_check("self_adjoint", predicted,
                      ld_defect(x, "self_adjoint", hs,
                                [&](const std::vector<SamplePair>& pairs, double h) {
                                  return self_adjointness_residual(*x.a.discrete_lagrangian, pairs, h);
                                }),
                      "max |L_d(q0,q1;h) + L_d(q1,q0;-h)| / |L_d| over 5 pairs near the diagonal (noise: 100 times "
                      "L_d's measured round-off, or 10 times what the solver's tolerance may leave in L_d)");
}

PropertyCheck g_invariant(VerifiedScene& x) {
  const json predicted = prediction(x.predictions.g_invariant);
  if (!declares_symmetry(*x.a.lagrangian))
    return not_measured("g_invariant", predicted, "the Lagrangian declares no symmetry group");
  if (x.a.discrete_lagrangian == nullptr)
    return not_measured("g_invariant", predicted, "this construction has no discrete Lagrangian");
  return defect_check("g_invariant", predicted,
                      ld_defect(x, "g_invariant", steps_of(x, {2, 1, 0, -1}),
                                [&](const std::vector<SamplePair>& pairs, double h) {
                                  return invariance_residual(*x.a.discrete_lagrangian, *x.a.lagrangian, pairs, h);
                                }),
                      fmt::format("max |L_d(g q0, g q1) - L_d(q0, q1)| / |L_d| over 5 pairs, g random in {} (noise: "
                                  "100 times L_d's measured round-off, or 10 times what the solver's tolerance may "
                                  "leave in L_d)",
                                  x.a.lagrangian->symmetry_group()));
}

// ---- symplectic ------------------------------------------------------------------------------------

// d^2 L / dv^2 at (q, v), dense (a test of a property).
Eigen::MatrixXd velocity_hessian(VerifiedScene& x, const double* q, const double* v) {
  std::vector<double> gradient(x.m + x.n);
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(x.n, x.n);
  if (x.lagrangian.sparse()) {
    std::vector<double> values(x.lagrangian.pattern_size());
    x.lagrangian.sparse_hessian(q, v, gradient.data(), values.data());
    for (int k = 0; k < x.lagrangian.pattern_size(); ++k)
      if (const int row = x.lagrangian.pattern_rows()[k], col = x.lagrangian.pattern_cols()[k]; row >= x.m && col >= x.m)
        block(row - x.m, col - x.m) += values[k];
    return block;
  }
  const int size = x.m + x.n;
  Eigen::MatrixXd hessian(size, size);
  x.lagrangian.hessian(q, v, gradient.data(), hessian.data());
  return hessian.bottomRightCorner(x.n, x.n);
}

// The mass of each degree of freedom at (q, v): the diagonal of d^2 L / dv^2 (1 where that is not a
// positive number).
std::vector<double> masses(VerifiedScene& x, const double* q, const double* v) {
  const Eigen::VectorXd diagonal = velocity_hessian(x, q, v).diagonal();
  std::vector<double> mass(x.n, 1.0);
  for (int j = 0; j < x.n; ++j)
    if (std::isfinite(diagonal[j]) && diagonal[j] > 0.0) mass[j] = diagonal[j];
  return mass;
}

// The symplecticity test's difference steps: a thousandth of the state's length scale (its largest
// coordinate; 1 at the origin) in each position, and of each degree of freedom's momentum scale
// (its mass times the state's largest speed; 1 at rest) in each momentum. Unit steps would move
// Pluto (1e-8 solar masses) at 1e5 AU a day and measure nothing but that (the outer solar system's
// defect read 10.5 against a noise floor of 45).
Eigen::VectorXd difference_steps(VerifiedScene& x) {
  const auto v0 = initial_velocity(x);
  const auto mass = masses(x, x.a.q0.data(), v0.data());
  auto scale_of = [](double largest) { return largest > 0.0 ? largest : 1.0; };
  const double length = scale_of(x.a.q0.lpNorm<Eigen::Infinity>());
  const double speed = scale_of(Eigen::Map<const Eigen::VectorXd>(v0.data(), x.n).lpNorm<Eigen::Infinity>());
  Eigen::VectorXd steps(2 * x.n);
  for (int j = 0; j < x.n; ++j) steps[j] = 1e-3 * length, steps[x.n + j] = 1e-3 * mass[j] * speed;
  return steps;
}

// With constraints, the directions of the constrained phase space {g = 0, G M^-1 p = 0} at the start
// (constrained_tangent_basis), with the difference steps' speed scale and their length scale or a
// thousandth of the constraints' own, 1 / max |G| (a rod's length), the smaller; else none (every
// coordinate direction).
Eigen::MatrixXd tangent_directions(VerifiedScene& x, const Eigen::VectorXd& steps) {
  if (!x.a.holonomic) return {};
  const auto v0 = initial_velocity(x);
  const Eigen::MatrixXd M = velocity_hessian(x, x.a.q0.data(), v0.data());
  const double speed = Eigen::Map<const Eigen::VectorXd>(v0.data(), x.n).lpNorm<Eigen::Infinity>();
  x.a.holonomic->evaluate_jacobian(x.a.q0.data());
  const double G = x.a.holonomic->jacobian().coeffs().cwiseAbs().maxCoeff();
  const double length = std::min(steps.head(x.n).maxCoeff(), G > 0.0 ? 1e-3 / G : INFINITY);
  return constrained_tangent_basis(*x.a.holonomic, M, x.a.q0.data(), x.a.p0.data(), length,
                                   1e-3 * (speed > 0.0 ? speed : 1.0));
}

// Where the map has its exact tangent map on a vector space (no constraints: the form is then
// restricted to the constraint's tangent space, whose basis the differences take; not on a Lie
// group: its images are in the natural charts, where the form is not J), M is the tangent map.
PropertyCheck symplectic(VerifiedScene& x) {
  const Eigen::VectorXd steps = difference_steps(x);
  const Eigen::MatrixXd tangent = tangent_directions(x, steps);
  const bool exact =
      !x.a.holonomic && x.a.manifold->is_vector_space() && x.a.map->tangent_map_refusal().empty();
  const auto d = defect_values("symplectic", steps_of(x, {1, 0, -1}), kNoiseSpread * kEpsilon, [&](double h, double& noise) {
    const auto defect =
        exact ? exact_symplecticity_defect(*x.a.map, x.a.q0.data(), x.a.p0.data(), x.a.t0, h, steps,
                                           x.scene.solver.tolerance)
              : symplecticity_defect(*x.a.map, *x.a.manifold, x.a.q0.data(), x.a.p0.data(), h, steps, tangent);
    noise = std::max(noise, 10 * defect.noise);
    return defect.defect;
  });
  const std::string form = x.a.holonomic ? "on the constraint's cotangent bundle {g = 0, G M^-1 p = 0}: max |omega(M u, "
                                           "M w) - omega(u, w)| over a basis of its tangent space, "
                                         : "||M^T J M - J||max ";
  const std::string scales =
      "in canonical chart coordinates, each in its own scale (positions in the state's length, momenta in mass times "
      "its speed), ";
  return defect_check(
      "symplectic", prediction(x.predictions.symplectic), d,
      form + scales +
          (exact ? "M the exact tangent map (the implicit function theorem on the step's equations; noise: 10 times "
                   "(2n eps + the solver's tolerance) times the form's entries)"
                 : "M by Richardson-extrapolated central differences of a thousandth of those scales (noise: 10 times "
                   "their change with the difference step)"));
}

// ---- momentum_conserved, energy_bounded: long runs at h and h/2 to the same time ---------------------

struct LongRun {
  double h = 0.0;
  std::vector<double> energy_error;
  double momentum_error = 0.0;  // max |J - J0| / max(1, |J0|)
};

LongRun long_run(VerifiedScene& x, double h, long steps) {
  LongRun r{h, {}, 0.0};
  const int k = x.a.lagrangian->momentum_size();
  std::vector<double> J(std::max(k, 0)), J0(J.size()), v(x.n, 0.0);
  double E0 = 0.0, scale = 1.0;
  within("momentum_conserved and energy_bounded", h, [&] {
    run_from_start(x, *x.a.map, "the energy and momentum run", h, steps, [&](long step, const double* q, const double* p) {
      v = velocity_of(x, q, p, v);
      const double E = x.lagrangian.energy(q, v.data());
      if (step == 0) E0 = E;
      r.energy_error.push_back(E - E0);
      if (k <= 0) return;
      check(*x.a.lagrangian, x.a.lagrangian->momentum(q, v.data(), J.data()), "momentum map");
      if (step == 0) {
        J0 = J;
        for (double j : J) scale = std::max(scale, std::abs(j));
      }
      for (int i = 0; i < k; ++i) r.momentum_error = std::max(r.momentum_error, std::abs(J[i] - J0[i]) / scale);
    });
  });
  return r;
}

PropertyCheck momentum_conserved(VerifiedScene& x, const std::vector<LongRun>& runs) {
  const json predicted = prediction(x.predictions.momentum_conserved);
  if (x.a.lagrangian->momentum_size() <= 0)
    return not_measured("momentum_conserved", predicted, "the Lagrangian declares no momentum map");
  std::vector<double> hs, values;
  for (const LongRun& r : runs) hs.push_back(r.h), values.push_back(r.momentum_error);
  // Round-off: a random walk of a few hundred eps per step, over the longest run.
  const double noise = 1e2 * kEpsilon * std::sqrt(static_cast<double>(runs.back().energy_error.size()));
  return defect_check("momentum_conserved", predicted, defect_scaling(hs, values, noise),
                      fmt::format("max |J - J0| / max(1, |J0|) over T = {:.3g}", kLongRun * x.scene.step));
}

// A drift: the energy error is mostly trend (EnergyDrift::share above kDriftShare) and the trend
// shrinks with h as a method's error does (round-off and a solver tolerance do not shrink).
PropertyCheck energy_bounded(VerifiedScene& x, const std::vector<LongRun>& runs) {
  const EnergyDrift coarse = energy_drift(runs[0].energy_error), fine = energy_drift(runs[1].energy_error);
  // Round-off of the energy: a random walk of kSpread eps |E| per step over the longer run.
  const double E = x.lagrangian.energy(x.a.q0.data(), initial_velocity(x).data());
  const double noise = kSpread * kEpsilon * (1.0 + std::abs(E)) *
                       std::sqrt(static_cast<double>(runs[1].energy_error.size()));
  const bool shrinks = fine.trend <= 0.5 * coarse.trend && coarse.trend > noise;
  PropertyCheck c = check_of("energy_bounded", prediction(x.predictions.energy_bounded));
  c.measured = coarse.share();
  c.tolerance = kDriftShare;
  c.holds = !(coarse.share() > kDriftShare && shrinks);
  c.note = fmt::format(
      "E - E0 over T = {:.3g}: trend / (trend + wander about it) at h = {:.3g} (trend {:.2e}, wander {:.2e}); at h/2 "
      "trend {:.2e}, wander {:.2e}: {}",
      kLongRun * x.scene.step, x.scene.step, coarse.trend, coarse.wander, fine.trend, fine.wander,
      *c.holds ? (coarse.share() > kDriftShare ? "a trend at round-off or not shrinking with h (the solver's tolerance)"
                                               : "bounded")
               : "drifts, shrinking with h");
  return c;
}

}  // namespace

bool PropertyCheck::failed() const {
  const bool predicted_to_hold = predicted.is_number() || (predicted.is_boolean() && predicted.get<bool>());
  return predicted_to_hold && holds && !*holds;
}

bool PropertyCheck::unmeasured() const {
  const bool predicted_to_hold = predicted.is_number() || (predicted.is_boolean() && predicted.get<bool>());
  return predicted_to_hold && !holds;
}

std::vector<PropertyCheck> verify_scene(const Scene& scene, Assembly& a, Registry& registry,
                                        const std::vector<double>& h, bool progress) {
  VerifiedScene x{scene, a, registry, LagrangianEvaluator(*a.lagrangian), scene.construction->predict(scene, a),
            a.manifold->dim(), a.manifold->point_size(), h, progress};
  std::vector<PropertyCheck> checks{self_adjoint(x), g_invariant(x), ld_order(x), global_order(x)};
  const std::vector<LongRun> runs{long_run(x, scene.step, kLongRun), long_run(x, scene.step / 2, 2 * kLongRun)};
  checks.push_back(momentum_conserved(x, runs));
  checks.push_back(symplectic(x));
  checks.push_back(energy_bounded(x, runs));
  return checks;
}

json checks_json(const std::vector<PropertyCheck>& checks) {
  json list = json::array();
  for (const auto& c : checks)
    list.push_back({{"name", c.name},
                    {"predicted", c.predicted},
                    {"holds", c.holds ? json(*c.holds) : json(nullptr)},
                    {"measured", c.measured ? json(*c.measured) : json(nullptr)},
                    {"tolerance", c.tolerance},
                    {"note", c.note}});
  return {{"checks", list}};
}

// The reason a property was not measured, from its note ("...; not measured: <reason>"), cut to
// a table cell; empty where it was measured.
std::string short_reason(const PropertyCheck& c) {
  constexpr std::size_t kShortReason = 72;
  if (!c.unmeasured()) return "";
  const auto at = c.note.rfind("not measured: ");
  std::string reason = at == std::string::npos ? c.note : c.note.substr(at + 14);
  if (reason.size() > kShortReason) reason = reason.substr(0, kShortReason - 3) + "...";
  return reason;
}

std::string checks_table(const std::vector<PropertyCheck>& checks, bool explain) {
  std::string out = fmt::format("{:<20} {:>9} {:>11} {:>10}  {:<8} {}\n", "property", "predicted", "measured",
                                "tolerance", "holds", explain ? "how" : "why not measured");
  for (const auto& c : checks) {
    const std::string measured = c.measured ? fmt::format("{:.3g}", *c.measured) : "-";
    const std::string holds = c.unmeasured() ? "NOT MEASURED (!)" : !c.holds ? "-" : c.failed() ? "NO (!)" : *c.holds ? "yes" : "no";
    std::string row = fmt::format("{:<20} {:>9} {:>11} {:>10.2g}  {:<8} {}", c.name,
                                  c.predicted.is_null() ? "-" : c.predicted.dump(), measured, c.tolerance, holds,
                                  explain ? "" : short_reason(c));
    out += row.erase(row.find_last_not_of(' ') + 1) + "\n";
    if (explain) out += fmt::format("  {}\n", c.note);
  }
  if (!explain) out += "(how each property was predicted and measured: --explain, or --json FILE)\n";
  return out;
}

}  // namespace varia::host
