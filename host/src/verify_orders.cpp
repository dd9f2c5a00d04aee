// `varia verify`'s order checks: ld_order (the slope of L_d's error against the exact discrete
// Lagrangian or a reference L_d) and global_order (the slope of the error at a fixed time), each
// fitted over a ladder of step sizes that stops at round-off, with the points that left every sane
// range dropped and named.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>

#include "commands.hpp"
#include "constructions/parts.hpp"
#include "registry.hpp"
#include "verify_checks.hpp"

namespace varia::host {
namespace verify_checks {

using nlohmann::json;

namespace {

constexpr double kOrderSlack = 0.3;     // a fitted order may fall this far below the prediction
constexpr double kOrderExcess = 1.0;    // and rise this far above it (more, no theorem explains it)
constexpr double kSaneFactor = 1e6;     // an error this many times its scale: the run left every sane range
// The widest range of local slopes over a fit that is still an asymptotic range (order_check).
constexpr double kAsymptoticSpread = 1.0;
constexpr double kOrderSpan = 20.0;     // global_order: the final time in scene steps
constexpr double kRaise = 16.0;         // the order ladders may rise this far above their start

std::shared_ptr<Quadrature> gauss_legendre(VerifiedScene& x, int points) {
  return x.registry.create_as<Quadrature>("quadrature", "gauss-legendre", json{{"points", points}},
                                          sdk::Context{x.scene.manifold.type, x.m, x.n});
}

// A Galerkin construction of the scene's system (forces included) of the given degree with
// `points` Gauss-Legendre points, as a reference (constructions/galerkin.cpp): on a Lie group in the
// natural chart. It is both a discrete Lagrangian and its discrete Hamiltonian map.
Assembly reference_galerkin(VerifiedScene& x, int degree, int points) {
  return assemble(galerkin_reference(x.scene, x.a, degree, points), x.registry);
}

// ---- ld_order, global_order ----------------------------------------------------------------------

std::string fit_note(const OrderFit& fit, const std::string& what) {
  std::string note = fmt::format("{}; {} points fitted", what, fit.used);
  if (std::getenv("VARIA_VERIFY_TRACE") != nullptr)
    note += fmt::format("; h {}; errors {}", fmt::join(fit.h, " "), fmt::join(fit.errors, " "));
  for (const auto& d : fit.dropped) note += "; dropped " + d;
  if (!fit.extrapolated.empty()) note += "; " + fit.extrapolated;
  return note;
}

// An error that no integrator following the motion at all makes: not finite, or over kSaneFactor
// times its scale (the state's size; 1 for L_d's relative error). Such a point measures no order:
// it is thrown as a numerical failure, which measure_order drops and names, and `diverged` keeps
// its step size for order_check.
void check_sane(double error, double scale, double h, std::vector<double>& diverged) {
  if (std::isfinite(error) && error <= kSaneFactor * scale) return;
  diverged.push_back(h);
  throw NumericalFailure(fmt::format("the run left every sane range: error {:.3g}, over {:g} times its scale {:.3g}",
                                     error, kSaneFactor, scale),
                         error);
}

std::string diverged_at(const std::vector<double>& diverged) {
  return fmt::format("the runs at h = {:.4g} left every sane range (an error not finite or over {:g} times its "
                     "scale)",
                     fmt::join(diverged, ", "), kSaneFactor);
}

// Why a fit is no asymptotic range, or "" when it is one: its local slopes still rise at its
// smallest step (a slope below the prediction is then a lower bound), range over more than
// kAsymptoticSpread, or cannot be formed (the fitted step sizes span less than a factor 2).
std::string weak_fit(const OrderFit& fit, bool low) {
  if (low && fit.still_rising)
    return fmt::format("the local slopes still rise at the smallest step above round-off, so {:.3g} is a lower bound "
                       "and the asymptotic range was not reached",
                       fit.slope);
  if (fit.slope_spread > kAsymptoticSpread)
    return fmt::format("the local slopes over the fitted points range over {:.3g} (more than {}), so the errors bend "
                       "between the pre-asymptotic regime and round-off and {:.3g} measures no order",
                       fit.slope_spread, kAsymptoticSpread, fit.slope);
  if (fit.h_span < 2.0)
    return fmt::format("the fitted step sizes span only a factor {:.3g} between the pre-asymptotic range and "
                       "round-off, too narrow for a local slope: {:.3g} measures no order",
                       fit.h_span, fit.slope);
  return "";
}

// A fitted order holds within [predicted - kOrderSlack, predicted + kOrderExcess]. Points that
// diverged (check_sane) are dropped; where one lies below a step size that did not diverge, the
// errors are not those of an asymptotic range, and the order is not measured.
PropertyCheck order_check(const char* name, const std::optional<int>& predicted, bool bound, const OrderFit& fit,
                          const std::vector<double>& diverged, const std::string& what) {
  PropertyCheck c = check_of(name, prediction(predicted));
  c.tolerance = kOrderSlack;
  c.note = fit_note(fit, what);
  if (!fit.fitted()) {
    c.note += fmt::format("; not measured: fewer than {} points in the asymptotic range above round-off{} (set the "
                          "step sizes with --h)",
                          kMinimumFitPoints, diverged.empty() ? "" : "; " + diverged_at(diverged));
    return c;
  }
  c.measured = fit.slope;
  const bool low = predicted && fit.slope < *predicted - kOrderSlack;
  const bool high = predicted && fit.slope > *predicted + kOrderExcess;
  c.holds = !low && !high;
  if (low || high) {
    // "Does not hold" only from a clean asymptotic range; a fit that is not one measures nothing.
    if (const std::string why = weak_fit(fit, low); !why.empty()) {
      c.holds.reset();
      c.note += fmt::format("; not measured: {} (set the step sizes with --h)", why);
    } else if (high && bound) {
      c.holds.reset();
      c.note += fmt::format("; not measured: {:.3g} is more than {} above the predicted order, which the theorem "
                            "gives as a lower bound that this system exceeds (a Lagrangian constant along the flow "
                            "makes any rule exact), so the prediction is not what was measured",
                            fit.slope, kOrderExcess);
    } else if (high) {
      c.note += fmt::format("; does not hold: {:.3g} is more than {} above the predicted order, which no theorem "
                            "explains (errors falling this fast are not the method's asymptotic ones)",
                            fit.slope, kOrderExcess);
    }
  }
  const double largest = fit.h.front();  // the fit's step sizes, largest first
  if (std::any_of(diverged.begin(), diverged.end(), [&](double h) { return h < largest; })) {
    c.holds.reset();
    c.note += fmt::format("; not measured: {}, below h = {:.4g}, which did not: these errors are not those of an "
                          "asymptotic range",
                          diverged_at(diverged), largest);
  }
  return c;
}

// The reference Galerkin L_d's degree: order 2 * 6 = 12 with 8 Gauss-Legendre points.
constexpr int kReferenceDegree = 6;

// L_d^E and q1 from the exact solution, or from a reference Galerkin construction of order 12,
// at kBases base states away from special ones: a release from rest is time-symmetric and can
// cancel error terms that a generic state shows, and at one base state the error's leading terms
// can cancel near some h (a sign change), bending the local slopes far below and above the order
// over the decades that follow. The order is fitted at each base state; the measurement is the
// median of the fitted orders, so that one base state's cancellation does not decide it.
constexpr int kBases = 3;

struct ExactLd {
  struct Base {
    std::vector<double> q0, v;  // v: the exact state's velocity, or the reference curve's
  };
  std::vector<Base> bases;
  std::function<void(const Base& base, double h, std::vector<double>& q1, double& LdE)> at;
  std::string name;
};

// A generic velocity added to the initial one, so that the sampled curve never rests; `base`
// turns the added vector, so that each base state differs. A moving state is nudged by a tenth of
// its largest velocity component, so that the curve stays the scene's kind of motion: a velocity of
// 0.3 added to planets moving at 0.005 AU a day flings them across the system in one step, where
// L_d's error says nothing about the scene's motion and the Sun's kinetic energy buries it in
// round-off (the outer solar system's ld_order read 0.53). A state at rest gets unit velocities.
std::vector<double> generic_velocity(std::vector<double> v, int base) {
  double speed = 0.0;
  for (double c : v) speed = std::max(speed, std::abs(c));
  const double scale = speed > 0.0 ? 0.1 * speed : 1.0;
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] += scale * (0.3 + 0.1 * static_cast<double>((i + static_cast<std::size_t>(base)) % v.size()) - 0.2 * base);
  return v;
}

ExactLd exact_ld(VerifiedScene& x, std::shared_ptr<Quadrature>& fine, Assembly& reference) {
  const auto v0 = initial_velocity(x);
  ExactLd exact;
  if (x.a.lagrangian->has_exact_solution()) {
    fine = gauss_legendre(x, 16);
    for (int b = 0; b < kBases; ++b) {  // times along the exact motion with nothing special about them
      ExactLd::Base base{std::vector<double>(x.m), std::vector<double>(x.n)};
      check(*x.a.lagrangian,
            x.a.lagrangian->exact_solution(x.a.q0.data(), v0.data(), 0.37 + 0.61 * b, base.q0.data(), base.v.data()),
            "exact solution");
      exact.bases.push_back(std::move(base));
    }
    exact.at = [&x, &fine](const ExactLd::Base& base, double h, std::vector<double>& q1, double& LdE) {
      exact_discrete_lagrangian(x.lagrangian, fine->nodes(), fine->weights(), fine->size(), base.q0.data(),
                                base.v.data(), h, q1.data(), &LdE);
    };
    exact.name = fmt::format("the exact discrete Lagrangian at {} states of the exact motion (t = 0.37, 0.98, 1.59; "
                             "16-point Gauss-Legendre)", kBases);
    return exact;
  }
  reference = reference_galerkin(x, kReferenceDegree, kReferenceDegree + 2);
  for (int b = 0; b < kBases; ++b)
    exact.bases.push_back({std::vector<double>(x.a.q0.data(), x.a.q0.data() + x.m), generic_velocity(v0, b)});
  exact.at = [&x, &reference](const ExactLd::Base& base, double h, std::vector<double>& q1, double& LdE) {
    std::vector<double> xi(base.v);
    for (double& c : xi) c *= h;
    check(*x.a.manifold, x.a.manifold->retract(base.q0.data(), xi.data(), q1.data()), "retract");
    reference.discrete_lagrangian->evaluate(base.q0.data(), q1.data(), h, &LdE, nullptr, nullptr);
  };
  exact.name = fmt::format("a reference Galerkin L_d of order 12 (degree 6, 8 Gauss-Legendre points) at {} initial "
                           "velocities",
                           kBases);
  return exact;
}

// The order ladder's start and ceiling: the scene's step (twice it for L_d, whose error is local)
// and kRaise times that; `property` measured at each step size (stop_before it).
OrderFit ladder(VerifiedScene& x, const char* property, const ErrorAt& error_at, double top, double floor,
                const NoiseAt& noise_at = {}) {
  const ErrorAt stopping = [&](double& h) {
    stop_before(property, h);
    return error_at(h);
  };
  return measure_order(stopping, top, kRaise * top, floor, x.given_h, noise_at);
}

}  // namespace

// The slope of |L_d - L_d^E| / (h |L|) against h: the order of L_d (paper, sec. 1: variational
// error analysis), its round-off a relative 1000 eps.
PropertyCheck ld_order(VerifiedScene& x) {
  if (x.a.discrete_lagrangian == nullptr)
    return not_measured("ld_order", nullptr, "this construction has no discrete Lagrangian");
  if (x.a.holonomic)
    return not_measured("ld_order", prediction(x.predictions.ld_order),
                        "with constraints the exact discrete Lagrangian is the action of the constrained flow between "
                        "points on the constraint, and the pairs this measurement samples leave it");
  if (const auto& p = x.predictions.ld_order; p && *p >= 2 * kReferenceDegree && !x.a.lagrangian->has_exact_solution()) {
    const std::string why = fmt::format("{}. The Lagrangian has no exact solution, and the reference L_d (Galerkin of "
                                        "order {}) cannot measure an order of {} or more: its own error would dominate",
                                        x.predictions.reason, 2 * kReferenceDegree, 2 * kReferenceDegree);
    return not_measured("ld_order", *p, why.c_str());
  }
  std::shared_ptr<Quadrature> fine;
  Assembly reference;
  const ExactLd exact = exact_ld(x, fine, reference);
  std::vector<double> q1(x.m);
  std::vector<OrderFit> fits;
  std::vector<std::vector<double>> diverged(exact.bases.size());  // per base state (check_sane)
  for (std::size_t b = 0; b < exact.bases.size(); ++b) {
    const ExactLd::Base& base = exact.bases[b];
    double scale = 0.0;  // |L| along the curve, fixed at the first (largest) step size
    fits.push_back(ladder(
        x, "ld_order",
        [&](double& h) {
          double LdE = 0.0, Ld = 0.0;
          exact.at(base, h, q1, LdE);
          x.a.discrete_lagrangian->evaluate(base.q0.data(), q1.data(), h, &Ld, nullptr, nullptr);
          if (scale == 0.0) scale = std::max(std::abs(LdE) / h, kEpsilon);
          const double error = std::abs(Ld - LdE) / (h * scale);
          check_sane(error, 1.0, h, diverged[b]);
          return error;
        },
        2.0 * x.scene.step, 1e3 * kEpsilon,
        // L_d's own round-off near this base state at h (it grows as h shrinks), ten times: a whole
        // unit in the last place of every coordinate is already the largest rounding.
        [&](double h) {
          const auto pairs = sample_pairs(*x.a.manifold, base.q0.data(), base.v.data(), h, kPairs);
          return 10 * round_off_of(*x.a.discrete_lagrangian, *x.a.manifold, pairs, h);
        }));
  }
  std::vector<const OrderFit*> fitted;
  std::string slopes;
  for (const OrderFit& fit : fits) {
    slopes += (slopes.empty() ? "" : ", ") + (fit.fitted() ? fmt::format("{:.3g}", fit.slope) : std::string("-"));
    if (fit.fitted()) fitted.push_back(&fit);
  }
  std::sort(fitted.begin(), fitted.end(), [](const OrderFit* a, const OrderFit* b) { return a->slope < b->slope; });
  const OrderFit& median = fitted.empty() ? fits.front() : *fitted[(fitted.size() - 1) / 2];
  PropertyCheck c = order_check("ld_order", x.predictions.ld_order, x.predictions.orders_are_bounds, median,
                                diverged[&median - fits.data()],
                                x.predictions.reason + ". Measured: slope of |L_d - L_d^E| / (h |L|) against h; L_d^E "
                                "from " + exact.name + "; fitted orders " + slopes + ", the median's fit");
  // The base states measure one order; where their fits disagree by more than kAsymptoticSpread,
  // none of them is in a range common to all, and where only one has a fit, nothing confirms it: a
  // median outside the prediction then measures nothing.
  if (c.holds == false && fitted.size() >= 2 && fitted.back()->slope - fitted.front()->slope > kAsymptoticSpread) {
    c.holds.reset();
    c.note += fmt::format("; not measured: the base states' fitted orders ({}) disagree by more than {}",
                          slopes, kAsymptoticSpread);
  } else if (c.holds == false && fitted.size() < 2) {
    c.holds.reset();
    c.note += fmt::format("; not measured: only one of the {} base states has a fit ({})", kBases, slopes);
  }
  return c;
}

namespace {

// max |c|; NaN when a value is NaN (std::max would drop it).
double largest_magnitude(const std::vector<double>& values) {
  double largest = 0.0;
  for (double c : values) largest = std::isnan(c) ? c : std::max(largest, std::abs(c));
  return largest;
}

double state_distance(VerifiedScene& x, const double* q, const double* p, const double* qe, const double* pe) {
  std::vector<double> xi(x.n);
  check(*x.a.manifold, x.a.manifold->local(qe, q, xi.data()), "local");
  double d = 0.0;
  for (int i = 0; i < x.n; ++i) d = std::max({d, std::abs(xi[i]), std::abs(p[i] - pe[i])});
  return d;
}

void final_state(DiscreteHamiltonianMap& map, VerifiedScene& x, double h, long steps, std::vector<double>& q,
                 std::vector<double>& p) {
  run_from_start(x, map, "an order run", h, steps, [&](long k, const double* qk, const double* pk) {
    if (k == steps) q.assign(qk, qk + x.m), p.assign(pk, pk + x.n);
  });
}

// The state at time T after the start: exact where the whole system (Lagrangian and forces) has a
// closed-form solution, else a run of a Galerkin construction of order 8 of the same system
// (degree 4, 4 Gauss-Legendre points, the scene's forces; in the natural chart on a Lie group; with
// constraints 5 Lobatto points)
// with `steps` steps, whose change on doubling them is returned as its uncertainty.
std::string reference_state(VerifiedScene& x, double T, long steps, std::vector<double>& q, std::vector<double>& p,
                            double& uncertainty) {
  q.resize(x.m);
  p.resize(x.n);
  uncertainty = 0.0;
  if (has_exact_solution(x.a)) {
    auto v0 = initial_velocity(x);
    std::vector<double> v(x.n);
    check(*x.a.lagrangian, x.a.lagrangian->exact_solution(x.a.q0.data(), v0.data(), T, q.data(), v.data()), "exact solution");
    x.lagrangian.legendre(q.data(), v.data(), p.data());
    return "the exact solution";
  }
  const Scene scene = galerkin_reference(x.scene, x.a, 4, 4);
  Assembly reference = assemble(scene, x.registry);
  std::vector<double> qc, pc;
  within("global_order (reference)", T / steps, [&] { final_state(*reference.map, x, T / steps, steps, qc, pc); });
  within("global_order (reference)", T / (2 * steps),
         [&] { final_state(*reference.map, x, T / (2 * steps), 2 * steps, q, p); });
  uncertainty = state_distance(x, qc.data(), pc.data(), q.data(), p.data());
  return fmt::format("a reference run ({}, h = {:.3g}, changing by {:.1e} on halving h)",
                     scene.construction->describe(scene), T / (2 * steps), uncertainty);
}

// The largest step size of global_order's fit: the scene's step or the largest given one.
double top_step(const Scene& scene, const std::vector<double>& given_h) {
  double top = scene.step;
  for (double h : given_h) top = std::max(top, h);
  return top;
}

}  // namespace

// The slope of the error at T = kOrderSpan top steps against h (each h made a whole number of
// steps to T).
PropertyCheck global_order(VerifiedScene& x) {
  const double top = top_step(x.scene, x.given_h);
  const double T = kOrderSpan * top;
  std::vector<double> qe, pe, q, p;
  double uncertainty = 0.0;
  const std::string reference = reference_state(x, T, std::lround(16 * kOrderSpan), qe, pe, uncertainty);
  const double scale = 1.0 + x.a.q0.lpNorm<Eigen::Infinity>() + x.a.p0.lpNorm<Eigen::Infinity>();
  const double state_scale = scale + largest_magnitude(qe) + largest_magnitude(pe);  // at both ends
  std::vector<double> diverged;
  const OrderFit fit = ladder(
      x, "global_order",
      [&](double& h) {
        const long steps = std::max(1L, std::lround(T / h));
        h = T / static_cast<double>(steps);
        final_state(*x.a.map, x, h, steps, q, p);
        // A non-finite state is not handed to the manifold's chart.
        const double error = std::isfinite(largest_magnitude(q) + largest_magnitude(p))
                                 ? state_distance(x, q.data(), p.data(), qe.data(), pe.data())
                                 : std::numeric_limits<double>::quiet_NaN();
        check_sane(error, state_scale, h, diverged);
        return error;
      },
      top, std::max(1e3 * kEpsilon * scale, 10 * uncertainty));
  return order_check("global_order", x.predictions.global_order, x.predictions.orders_are_bounds, fit, diverged,
                     x.predictions.reason + fmt::format(". Measured: slope of the error at T = {:.3g} against h, against {}", T, reference));
}

}  // namespace verify_checks

void check_fit_steps(const Scene& scene, const std::vector<double>& h) {
  using namespace verify_checks;
  if (h.empty()) return;
  const double T = kOrderSpan * top_step(scene, h);
  const std::string span = fmt::format("T = {:g} (global_order's final time, {:g} times the largest step size)", T,
                                       kOrderSpan);
  std::map<long, double> by_steps;  // the number of steps to T: the step size that gives it
  for (double step : h) {
    check_step_flag(step, T, span);
    if (const auto [given, fresh] = by_steps.emplace(std::lround(T / step), step); !fresh)
      throw InputError(fmt::format("--h: expected distinct step sizes; {} and {} both take {} steps to {}",
                                   given->second, step, given->first, span));
  }
  if (h.size() < static_cast<std::size_t>(kMinimumFitPoints))
    throw InputError(fmt::format("--h: expected at least {} distinct step sizes to fit an order to; found {}",
                                 kMinimumFitPoints, h.size()));
}

}  // namespace varia::host
