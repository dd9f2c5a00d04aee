#include "verify.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <numeric>

#include "constructions/parts.hpp"
#include "registry.hpp"

namespace varia::host {

using nlohmann::json;

namespace {

constexpr double kRoundOff = 1e-10;        // relative residuals of exact identities
constexpr double kOrderSlack = 0.3;        // a fitted order may fall this far below the prediction
constexpr double kDriftRatio = 2.0;        // energy error growth that counts as drift
constexpr int kHalvings = 7;               // step sizes of an order fit
constexpr long kLongRun = 10000;           // steps of the energy run
constexpr long kMomentumRun = 2000;        // steps of the momentum run

// Everything a check needs besides the scene's own integrator.
struct Context {
  const Scene& scene;
  Assembly& a;
  Registry& registry;
  LagrangianEvaluator lagrangian;
  Predictions predictions;
  int n, m;
};

json prediction(const std::optional<bool>& p) { return p ? json(*p) : json(nullptr); }
json prediction(const std::optional<int>& p) { return p ? json(*p) : json(nullptr); }

// A check of `name` with its prediction, not yet measured.
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

PropertyCheck residual_check(const char* name, json predicted, double residual, double tolerance,
                             std::string note) {
  PropertyCheck c = check_of(name, std::move(predicted));
  c.measured = residual;
  c.tolerance = tolerance;
  c.holds = residual <= tolerance;
  c.note = std::move(note);
  return c;
}

std::vector<double> velocity_of(Context& x, const double* q, const double* p, std::vector<double> guess) {
  x.lagrangian.inverse_legendre(q, p, guess.data(), x.scene.solver);
  return guess;
}

std::vector<double> initial_velocity(Context& x) {
  return velocity_of(x, x.a.q0.data(), x.a.p0.data(), std::vector<double>(x.n, 0.0));
}

std::shared_ptr<Quadrature> gauss_legendre(Context& x, int points) {
  return x.registry.create_as<Quadrature>("quadrature", "gauss-legendre", json{{"points", points}},
                                          sdk::Context{x.scene.manifold.type, x.m, x.n});
}

// A Galerkin construction of the scene's system (forces included) of the given degree with
// `points` Gauss-Legendre points, as a reference (constructions/galerkin.cpp): on a Lie group in the
// natural chart. It is both a discrete Lagrangian and its discrete Hamiltonian map.
Assembly reference_galerkin(Context& x, int degree, int points) {
  return assemble(galerkin_reference(x.scene, degree, points), x.registry);
}

// ---- self_adjoint --------------------------------------------------------------------------------

// For a one-step map without L_d: Phi_{-h}(Phi_h(x)) = x exactly when the map is self-adjoint.
double map_symmetry_residual(Context& x) {
  const double h = x.scene.step;
  std::vector<double> q1(x.m), p1(x.n), q2(x.m), p2(x.n);
  x.a.map->step(x.a.q0.data(), x.a.p0.data(), x.a.t0, h, q1.data(), p1.data());
  x.a.map->step(q1.data(), p1.data(), x.a.t0 + h, -h, q2.data(), p2.data());
  double worst = 0.0;
  for (int i = 0; i < x.m; ++i) worst = std::max(worst, std::abs(q2[i] - x.a.q0[i]));
  for (int i = 0; i < x.n; ++i) worst = std::max(worst, std::abs(p2[i] - x.a.p0[i]));
  return worst / (1.0 + x.a.q0.lpNorm<Eigen::Infinity>() + x.a.p0.lpNorm<Eigen::Infinity>());
}

PropertyCheck self_adjoint(Context& x) {
  const json predicted = prediction(x.predictions.self_adjoint);
  if (x.a.discrete_lagrangian == nullptr)
    return residual_check("self_adjoint", predicted, map_symmetry_residual(x), kRoundOff,
                          "|Phi_{-h}(Phi_h(x)) - x| / (1 + |x|), one step from the initial state");
  const auto v = initial_velocity(x);
  const auto pairs = sample_pairs(*x.a.manifold, x.a.q0.data(), v.data(), x.scene.step, 5);
  return residual_check("self_adjoint", predicted,
                        self_adjointness_residual(*x.a.discrete_lagrangian, pairs, x.scene.step), kRoundOff,
                        "max |L_d(q0,q1;h) + L_d(q1,q0;-h)| / |L_d| over 5 pairs near the diagonal");
}

// ---- g_invariant, momentum_conserved --------------------------------------------------------------

PropertyCheck g_invariant(Context& x) {
  const json predicted = prediction(x.predictions.g_invariant);
  if (!declares_symmetry(*x.a.lagrangian))
    return not_measured("g_invariant", predicted, "the Lagrangian declares no symmetry group");
  if (x.a.discrete_lagrangian == nullptr)
    return not_measured("g_invariant", predicted, "this construction has no discrete Lagrangian");
  const auto v = initial_velocity(x);
  const auto pairs = sample_pairs(*x.a.manifold, x.a.q0.data(), v.data(), x.scene.step, 5);
  return residual_check(
      "g_invariant", predicted,
      invariance_residual(*x.a.discrete_lagrangian, *x.a.lagrangian, pairs, x.scene.step), kRoundOff,
      fmt::format("max |L_d(g q0, g q1) - L_d(q0, q1)| / |L_d| over 5 pairs, g random in {}",
                  x.a.lagrangian->symmetry_group()));
}

PropertyCheck momentum_conserved(Context& x) {
  const json predicted = prediction(x.predictions.momentum_conserved);
  const int k = x.a.lagrangian->momentum_size();
  if (k <= 0) return not_measured("momentum_conserved", predicted, "the Lagrangian declares no momentum map");
  std::vector<double> J(k), J0(k), v(x.n, 0.0);
  double worst = 0.0, scale = 1.0;
  run(*x.a.map, x.a.q0, x.a.p0, x.a.t0, x.scene.step, kMomentumRun,
      [&](long step, const double* q, const double* p) {
        v = velocity_of(x, q, p, v);
        check(*x.a.lagrangian, x.a.lagrangian->momentum(q, v.data(), J.data()), "momentum map");
        if (step == 0) {
          J0 = J;
          for (double j : J) scale = std::max(scale, std::abs(j));
        }
        for (int i = 0; i < k; ++i) worst = std::max(worst, std::abs(J[i] - J0[i]) / scale);
      });
  return residual_check("momentum_conserved", predicted, worst, kRoundOff,
                        fmt::format("max |J - J0| / max(1, |J0|) over {} steps", kMomentumRun));
}

// ---- ld_order ------------------------------------------------------------------------------------

// L_d^E and q1 from the exact solution, or from a reference Galerkin construction of order 12,
// at a base point q0 away from special states: a release from rest is time-symmetric and can
// cancel error terms that a generic state shows.
struct ExactLd {
  std::function<void(double h, std::vector<double>& q1, double& LdE)> at;
  std::vector<double> q0;
  std::string name;
};

// A generic velocity added to the initial one, so that the sampled curve never rests.
std::vector<double> generic_velocity(std::vector<double> v) {
  for (std::size_t i = 0; i < v.size(); ++i) v[i] += 0.3 + 0.1 * static_cast<double>(i);
  return v;
}

ExactLd exact_ld(Context& x, std::shared_ptr<Quadrature>& fine, Assembly& reference) {
  const auto v0 = initial_velocity(x);
  std::vector<double> qa(x.m), va(x.n);
  if (x.a.lagrangian->has_exact_solution()) {
    constexpr double kOffset = 0.37;  // a time along the exact motion with nothing special about it
    check(*x.a.lagrangian, x.a.lagrangian->exact_solution(x.a.q0.data(), v0.data(), kOffset, qa.data(), va.data()),
          "exact solution");
    fine = gauss_legendre(x, 16);
    return {[&x, &fine, qa, va](double h, std::vector<double>& q1, double& LdE) {
              exact_discrete_lagrangian(x.lagrangian, fine->nodes(), fine->weights(), fine->size(), qa.data(),
                                        va.data(), h, q1.data(), &LdE);
            },
            qa, "the exact discrete Lagrangian (exact solution from its state at t = 0.37, 16-point Gauss-Legendre)"};
  }
  reference = reference_galerkin(x, 6, 8);
  const auto v = generic_velocity(v0);
  return {[&x, &reference, v](double h, std::vector<double>& q1, double& LdE) {
            std::vector<double> xi(v);
            for (double& c : xi) c *= h;
            check(*x.a.manifold, x.a.manifold->retract(x.a.q0.data(), xi.data(), q1.data()), "retract");
            reference.discrete_lagrangian->evaluate(x.a.q0.data(), q1.data(), h, &LdE, nullptr, nullptr);
          },
          std::vector<double>(x.a.q0.data(), x.a.q0.data() + x.m),
          "a reference Galerkin L_d of order 12 (degree 6, 8 Gauss-Legendre points)"};
}

std::string fit_note(const OrderFit& fit, const std::string& what) {
  std::string note = fmt::format("{}; {} points fitted", what, fit.used);
  if (std::getenv("VARIA_VERIFY_TRACE") != nullptr) note += fmt::format("; errors {}", fmt::join(fit.errors, " "));
  for (const auto& d : fit.dropped) note += "; dropped " + d;
  return note;
}

PropertyCheck order_check(const char* name, const std::optional<int>& predicted, const OrderFit& fit,
                          double offset, const std::string& what) {
  PropertyCheck c = check_of(name, prediction(predicted));
  c.tolerance = kOrderSlack;
  c.note = fit_note(fit, what);
  if (fit.used < 2) {
    c.note += "; too few points above round-off to fit";
    return c;
  }
  c.measured = fit.slope - offset;
  c.holds = predicted ? *c.measured >= *predicted - kOrderSlack : true;
  return c;
}

PropertyCheck ld_order(Context& x) {
  if (x.a.discrete_lagrangian == nullptr)
    return not_measured("ld_order", nullptr, "this construction has no discrete Lagrangian");
  std::shared_ptr<Quadrature> fine;
  Assembly reference;
  const ExactLd exact = exact_ld(x, fine, reference);
  std::vector<double> hs, errors, q1(x.m);
  double scale = 0.0;
  for (int k = 0; k < kHalvings; ++k) {
    const double h = 2.0 * x.scene.step / (1 << k);
    double LdE = 0.0, Ld = 0.0;
    exact.at(h, q1, LdE);
    x.a.discrete_lagrangian->evaluate(exact.q0.data(), q1.data(), h, &Ld, nullptr, nullptr);
    hs.push_back(h);
    errors.push_back(std::abs(Ld - LdE));
    scale = std::max(scale, std::abs(LdE) / h);  // |L| along the curve
  }
  const OrderFit fit = fit_order(hs, errors, 1e3 * 2.2e-16 * scale * hs.back());
  return order_check("ld_order", x.predictions.ld_order, fit, 1.0,
                     "slope of |L_d - L_d^E| against h, minus 1; L_d^E from " + exact.name);
}

// ---- global_order --------------------------------------------------------------------------------

double state_distance(Context& x, const double* q, const double* p, const double* qe, const double* pe) {
  std::vector<double> xi(x.n);
  check(*x.a.manifold, x.a.manifold->local(qe, q, xi.data()), "local");
  double d = 0.0;
  for (int i = 0; i < x.n; ++i) d = std::max({d, std::abs(xi[i]), std::abs(p[i] - pe[i])});
  return d;
}

void final_state(DiscreteHamiltonianMap& map, Context& x, double h, long steps, std::vector<double>& q,
                 std::vector<double>& p) {
  run(map, x.a.q0, x.a.p0, x.a.t0, h, steps,
      [&](long k, const double* qk, const double* pk) {
        if (k == steps) q.assign(qk, qk + x.m), p.assign(pk, pk + x.n);
      });
}

// The state at time T after the start: exact where the whole system (Lagrangian and forces) has a
// closed-form solution, else a run of a Galerkin construction of order 8 of the same system
// (degree 4, 4 Gauss-Legendre points, the scene's forces; in the natural chart on a Lie group)
// with step h.
std::string reference_state(Context& x, double T, double h, std::vector<double>& q, std::vector<double>& p) {
  q.resize(x.m);
  p.resize(x.n);
  if (has_exact_solution(x.a)) {
    auto v0 = initial_velocity(x);
    std::vector<double> v(x.n);
    check(*x.a.lagrangian, x.a.lagrangian->exact_solution(x.a.q0.data(), v0.data(), T, q.data(), v.data()), "exact solution");
    x.lagrangian.legendre(q.data(), v.data(), p.data());
    return "the exact solution";
  }
  Assembly reference = reference_galerkin(x, 4, 4);
  final_state(*reference.map, x, h, std::lround(T / h), q, p);
  return fmt::format("a reference run (Galerkin degree 4, 4 Gauss-Legendre points, h = {:.3g})", h);
}

PropertyCheck global_order(Context& x) {
  const double h0 = 2.0 * x.scene.step, T = 10.0 * h0;
  std::vector<double> qe, pe, q, p, hs, errors;
  const std::string reference = reference_state(x, T, h0 / (1 << (kHalvings + 1)), qe, pe);
  for (int k = 0; k < kHalvings; ++k) {
    const double h = h0 / (1 << k);
    final_state(*x.a.map, x, h, 10L << k, q, p);
    hs.push_back(h);
    errors.push_back(state_distance(x, q.data(), p.data(), qe.data(), pe.data()));
  }
  const double scale = 1.0 + x.a.q0.lpNorm<Eigen::Infinity>() + x.a.p0.lpNorm<Eigen::Infinity>();
  const OrderFit fit = fit_order(hs, errors, 1e-12 * scale);
  return order_check("global_order", x.predictions.global_order, fit, 0.0,
                     fmt::format("slope of the error at T = {:.3g} against h, against {}", T, reference));
}

// ---- symplectic, energy_bounded -------------------------------------------------------------------

PropertyCheck symplectic(Context& x) {
  const json predicted = prediction(x.predictions.symplectic);
  const auto d = symplecticity_defect(*x.a.map, *x.a.manifold, x.a.q0.data(), x.a.p0.data(), x.scene.step);
  const double tolerance = std::max(1e-8, 100.0 * d.noise);
  return residual_check("symplectic", predicted, d.defect, tolerance,
                        fmt::format("||M^T J M - J||max in canonical chart coordinates, M by Richardson-extrapolated "
                                    "central differences (noise floor {:.1e})",
                                    d.noise));
}

PropertyCheck energy_bounded(Context& x) {
  const json predicted = prediction(x.predictions.energy_bounded);
  std::vector<double> errors, v(x.n, 0.0);
  double E0 = 0.0;
  run(*x.a.map, x.a.q0, x.a.p0, x.a.t0, x.scene.step, kLongRun,
      [&](long k, const double* q, const double* p) {
        v = velocity_of(x, q, p, v);
        const double E = x.lagrangian.energy(q, v.data());
        if (k == 0) E0 = E;
        errors.push_back(E - E0);
      });
  // An error at round-off (a quadratic energy kept by a Gauss-like rule) cannot drift: its
  // growth ratio is noise.
  double worst = 0.0;
  for (double e : errors) worst = std::max(worst, std::abs(e));
  const bool round_off = worst <= 1e-12 * (1.0 + std::abs(E0));
  PropertyCheck c = residual_check(
      "energy_bounded", predicted, drift_ratio(errors), kDriftRatio,
      fmt::format("max |E - E0| over the last quarter / over the first quarter of {} steps (max |E - E0| = {:.2e}{})",
                  kLongRun, worst, round_off ? ", at round-off: conserved" : ""));
  if (round_off) c.holds = true;
  return c;
}

}  // namespace

bool PropertyCheck::failed() const {
  const bool predicted_to_hold = predicted.is_number() || (predicted.is_boolean() && predicted.get<bool>());
  return predicted_to_hold && holds && !*holds;
}

std::vector<PropertyCheck> verify_scene(const Scene& scene, Assembly& a, Registry& registry) {
  Context x{scene, a, registry, LagrangianEvaluator(*a.lagrangian), scene.construction->predict(scene, a),
            a.manifold->dim(), a.manifold->point_size()};
  return {self_adjoint(x), g_invariant(x), ld_order(x), global_order(x),
          momentum_conserved(x), symplectic(x), energy_bounded(x)};
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

std::string checks_table(const std::vector<PropertyCheck>& checks) {
  std::string out = fmt::format("{:<20} {:>9} {:>11} {:>10}  {:<8} {}\n", "property", "predicted", "measured",
                                "tolerance", "holds", "how");
  for (const auto& c : checks) {
    const std::string measured = c.measured ? fmt::format("{:.3g}", *c.measured) : "-";
    const std::string holds = !c.holds ? "-" : c.failed() ? "NO (!)" : *c.holds ? "yes" : "no";
    out += fmt::format("{:<20} {:>9} {:>11} {:>10.2g}  {:<8} {}\n", c.name,
                       c.predicted.is_null() ? "-" : c.predicted.dump(), measured, c.tolerance, holds, c.note);
  }
  return out;
}

}  // namespace varia::host
