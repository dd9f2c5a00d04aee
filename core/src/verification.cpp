#include "varia/core/verification.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "varia/core/trajectory.hpp"

namespace varia {

namespace {

// Least-squares slope of log(value) against log(h) over the points `kept`.
double log_log_slope(const std::vector<double>& h, const std::vector<double>& value, const std::vector<int>& kept) {
  double mx = 0, my = 0;
  for (int k : kept) mx += std::log(h[k]), my += std::log(value[k]);
  mx /= static_cast<double>(kept.size());
  my /= static_cast<double>(kept.size());
  double sxy = 0, sxx = 0;
  for (int k : kept) {
    sxy += (std::log(h[k]) - mx) * (std::log(value[k]) - my);
    sxx += (std::log(h[k]) - mx) * (std::log(h[k]) - mx);
  }
  return sxy / sxx;
}

constexpr double kWindow = 2.0 * (1.0 - 1e-9);  // a factor 2 in h, whatever the rounding of h
constexpr double kSpan = 1e6;  // an order ladder wants its largest error this far above its floor

std::vector<int> above(const std::vector<double>& value, double floor) {
  std::vector<int> kept;
  for (std::size_t k = 0; k < value.size(); ++k)
    if (value[k] > floor) kept.push_back(static_cast<int>(k));
  return kept;
}

// The errors of an order ladder (h decreasing) and their local slopes, each over a window of a
// factor 2 in h (on a fine ladder neighbouring slopes differ too little to show a trend).
struct Ladder {
  const std::vector<double>& h;
  const std::vector<double>& error;

  double slope_between(int a, int b) const { return std::log(error[a] / error[b]) / std::log(h[a] / h[b]); }
  // The window from points[a] forwards, or from points[c] backwards.
  std::size_t window_end(const std::vector<int>& points, std::size_t a) const {
    std::size_t b = a + 1;
    while (b + 1 < points.size() && h[points[a]] / h[points[b]] < kWindow) ++b;
    return b;
  }
  std::size_t window_start(const std::vector<int>& points, std::size_t c) const {
    std::size_t a = c - 1;
    while (a > 0 && h[points[a]] / h[points[c]] < kWindow) --a;
    return a;
  }
  std::vector<double> local_slopes(const std::vector<int>& points) const {
    std::vector<double> local;
    for (std::size_t a = 0; a + 1 < points.size(); ++a) {
      const std::size_t b = window_end(points, a);
      if (h[points[a]] / h[points[b]] >= kWindow) local.push_back(slope_between(points[a], points[b]));
    }
    return local;
  }
};

// Leading points whose local slope differs from the next one's by more than 0.3: pre-asymptotic.
void drop_pre_asymptotic(const Ladder& l, std::vector<int>& kept, OrderFit& fit) {
  while (kept.size() >= 3) {
    const std::size_t b = l.window_end(kept, 0);
    if (b + 1 >= kept.size()) break;
    const std::size_t c = l.window_end(kept, b);
    const double first = l.slope_between(kept[0], kept[b]), next = l.slope_between(kept[b], kept[c]);
    if (std::abs(first - next) <= 0.3) break;
    std::ostringstream why;
    why << "h = " << l.h[kept[0]] << ": pre-asymptotic (local slope " << first << ", next " << next << ")";
    fit.dropped.push_back(why.str());
    kept.erase(kept.begin());
  }
}

// Trailing points whose local slope falls below the one before: a round-off plateau (the errors
// stop falling).
void drop_round_off_plateau(const Ladder& l, std::vector<int>& kept, OrderFit& fit) {
  while (kept.size() >= 3) {
    const std::size_t last = kept.size() - 1, b = l.window_start(kept, last);
    if (b == 0) break;
    const std::size_t a = l.window_start(kept, b);
    const double tail = l.slope_between(kept[b], kept[last]), before = l.slope_between(kept[a], kept[b]);
    if (tail >= before - 0.3) break;
    std::ostringstream why;
    why << "h = " << l.h[kept.back()] << ": at round-off (local slope " << tail << ", before it " << before << ")";
    fit.dropped.push_back(why.str());
    kept.pop_back();
  }
}

// The order is the limit of the local slope as h -> 0. While a term of the next order still shows,
// the local slopes creep towards it geometrically (s(h) = p + c h^k on a geometric ladder); when
// the last four do so consistently (their differences keep one sign and shrink by a steady ratio
// below 0.9), Aitken's delta-squared takes the limit, and the note says so.
void extrapolate_creeping_slopes(const std::vector<double>& local, OrderFit& fit) {
  if (local.size() < 4) return;
  const std::size_t n = local.size();
  const double d1 = local[n - 3] - local[n - 4], d2 = local[n - 2] - local[n - 3], d3 = local[n - 1] - local[n - 2];
  const double r1 = d2 / d1, r2 = d3 / d2;
  if (!(r1 > 0 && r1 <= 0.9 && r2 > 0 && r2 <= 0.9 && std::abs(r2 - r1) <= 0.2)) return;
  const double limit = local[n - 1] + d3 * r2 / (1 - r2);
  std::ostringstream why;
  why << "local slopes " << local[n - 4] << ", " << local[n - 3] << ", " << local[n - 2] << ", " << local[n - 1]
      << " still creeping (differences shrinking by " << r1 << ", " << r2 << "): order " << limit
      << " by Aitken extrapolation, least-squares slope " << fit.slope;
  fit.extrapolated = why.str();
  fit.slope = limit;
  fit.still_rising = false;
}

}  // namespace

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor) {
  OrderFit fit;
  fit.h = h;
  fit.errors = error;
  std::vector<int> kept = above(error, floor);
  for (std::size_t k = 0; k < h.size(); ++k) {
    if (error[k] > floor) continue;
    std::ostringstream why;
    why << "h = " << h[k] << ": error " << error[k] << " at round-off (below " << floor << ")";
    fit.dropped.push_back(why.str());
  }
  const Ladder ladder{h, error};
  drop_pre_asymptotic(ladder, kept, fit);
  drop_round_off_plateau(ladder, kept, fit);
  fit.used = static_cast<int>(kept.size());
  if (!fit.fitted()) return fit;
  fit.h_span = h[kept.front()] / h[kept.back()];
  fit.slope = log_log_slope(h, error, kept);
  const std::vector<double> local = ladder.local_slopes(kept);
  if (!local.empty()) fit.slope_spread = *std::max_element(local.begin(), local.end()) - *std::min_element(local.begin(), local.end());
  // Still rising: the local slopes of every point above round-off down to the fit's end rise at its end.
  std::vector<int> trend = above(error, floor);
  trend.erase(std::find(trend.begin(), trend.end(), kept.back()) + 1, trend.end());
  const std::vector<double> trend_local = ladder.local_slopes(trend);
  const std::size_t m = trend_local.size();
  fit.still_rising = m >= 2 && trend_local[m - 1] > trend_local[m - 2] && (m == 2 || trend_local[m - 2] > trend_local[m - 3]);
  extrapolate_creeping_slopes(local, fit);
  return fit;
}

OrderFit measure_order(const ErrorAt& error_at, double h_top, double h_max, double floor,
                       const std::vector<double>& given, const NoiseAt& noise_at) {
  std::vector<double> hs, errors;
  std::vector<std::string> failures;
  // The error at h, put in order of decreasing h (at 0, below any floor, when it is within its
  // measured round-off); false on a numerical failure.
  auto measure = [&](double h) {
    try {
      double error = error_at(h);
      if (noise_at && error > floor) {
        if (const double noise = noise_at(h); error <= noise) {
          std::ostringstream why;
          why << "h = " << h << ": error " << error << " within its measured round-off " << noise;
          failures.push_back(why.str());
          error = 0.0;
        }
      }
      // A step size the measurement rounded to one already measured (a whole number of steps to
      // a final time) is one point, not two.
      if (std::find(hs.begin(), hs.end(), h) != hs.end()) return true;
      const auto at = std::find_if(hs.begin(), hs.end(), [&](double other) { return other < h; });
      errors.insert(errors.begin() + (at - hs.begin()), error);
      hs.insert(at, h);
      return true;
    } catch (const NumericalFailure& e) {
      std::ostringstream why;
      why << "h = " << h << ": numerical failure (";
      if (const auto* step = dynamic_cast<const StepFailure*>(&e))
        why << "step " << step->step() << " from t = " << step->t() << ", ";
      why << "residual " << e.residual() << ": " << e.what() << ")";
      failures.push_back(why.str());
      return false;
    }
  };
  if (!given.empty()) {
    for (double h : given) measure(h);
  } else {
    int below = 0;
    for (int k = 0; k < kLadderPoints && below < 2; ++k)
      if (measure(h_top * std::pow(2.0, -0.25 * k)) && errors.back() <= floor) ++below;
    // Too few points left by the filters, or the largest error within kSpan of the floor (close to
    // round-off, which bends the slope): more points above, while the larger steps still run.
    auto short_of_range = [&] { return !fit_order(hs, errors, floor).fitted() || errors.front() < kSpan * floor; };
    while (short_of_range() && 2 * h_top <= h_max * (1 + 1e-12) && measure(h_top * std::pow(2.0, 0.25)) &&
           measure(h_top * std::sqrt(2.0)) && measure(h_top * std::pow(2.0, 0.75)) && measure(2 * h_top))
      h_top *= 2;
  }
  OrderFit fit = fit_order(hs, errors, floor);
  fit.dropped.insert(fit.dropped.end(), failures.begin(), failures.end());
  return fit;
}

DefectScaling defect_scaling(const std::vector<double>& h, const std::vector<double>& values, double noise) {
  DefectScaling d{h, values, *std::max_element(values.begin(), values.end()), noise, std::nullopt, false, false};
  // The slope over every point, each taken at least at the noise: a defect that falls into the
  // noise as h shrinks shrinks; noise alone gives a flat line.
  if (d.largest > noise && values.size() >= 2) {
    std::vector<double> floored;
    std::vector<int> all;
    for (std::size_t k = 0; k < values.size(); ++k) {
      floored.push_back(std::max(values[k], noise));
      all.push_back(static_cast<int>(k));
    }
    d.slope = log_log_slope(h, floored, all);
  }
  d.shrinks = d.slope && *d.slope >= 1.0;
  d.zero = !d.shrinks && d.largest <= noise;
  return d;
}

std::string DefectScaling::describe() const {
  std::ostringstream text;
  text.precision(2);
  text << std::scientific;
  for (std::size_t k = 0; k < h.size(); ++k) text << (k ? ", " : "") << values[k] << " at h = " << std::defaultfloat << h[k] << std::scientific;
  text << std::defaultfloat;
  if (zero) {
    text << ": at round-off (within " << std::scientific << noise << std::defaultfloat << ", not shrinking with h)";
  } else if (slope) {
    text << ": scaling as h^" << std::round(*slope * 10) / 10;
  } else {
    text << ": above round-off (" << std::scientific << noise << std::defaultfloat << ")";
  }
  return text.str();
}

std::vector<SamplePair> sample_pairs(Manifold& manifold, const double* q, const double* v, double h,
                                     int count) {
  const int n = manifold.dim(), m = manifold.point_size();
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<SamplePair> pairs;
  Eigen::VectorXd shift(n);
  for (int k = 0; k < count; ++k) {
    SamplePair pair{std::vector<double>(m), std::vector<double>(m)};
    for (int i = 0; i < n; ++i) shift[i] = 0.1 * uniform(random);
    check(manifold, manifold.retract(q, shift.data(), pair.q0.data()), "retract");
    for (int i = 0; i < n; ++i) shift[i] = h * (v[i] + 0.1 * uniform(random));
    check(manifold, manifold.retract(pair.q0.data(), shift.data(), pair.q1.data()), "retract");
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

double self_adjointness_residual(DiscreteLagrangian& Ld, const std::vector<SamplePair>& pairs,
                                 double h) {
  double worst = 0.0;
  for (const auto& pair : pairs) {
    double forward = 0.0, backward = 0.0;
    Ld.evaluate(pair.q0.data(), pair.q1.data(), h, &forward, nullptr, nullptr);
    Ld.evaluate(pair.q1.data(), pair.q0.data(), -h, &backward, nullptr, nullptr);
    worst = std::max(worst, std::abs(forward + backward) / std::max(std::abs(forward), 1e-300));
  }
  return worst;
}

double round_off_of(DiscreteLagrangian& Ld, Manifold& manifold, const std::vector<SamplePair>& pairs, double h) {
  const int n = manifold.dim(), m = manifold.point_size();
  std::vector<double> xi(n), there(m), back0(m), back1(m);
  auto round_trip = [&](const std::vector<double>& q, std::vector<double>& back) {
    for (int i = 0; i < n; ++i) xi[i] = 1e-3 * (i + 1);
    check(manifold, manifold.retract(q.data(), xi.data(), there.data()), "retract");
    for (double& c : xi) c = -c;
    check(manifold, manifold.retract(there.data(), xi.data(), back.data()), "retract");
  };
  // q moved by one unit in the last place of every coordinate, away from zero: the rounding of an
  // endpoint, which L_d near the diagonal magnifies by |q| / |q1 - q0|.
  auto ulp = [](const std::vector<double>& q, std::vector<double>& moved) {
    for (std::size_t i = 0; i < q.size(); ++i) moved[i] = std::nextafter(q[i], q[i] < 0 ? -INFINITY : INFINITY);
  };
  double worst = 0.0;
  for (const auto& pair : pairs) {
    double original = 0.0, moved = 0.0;
    Ld.evaluate(pair.q0.data(), pair.q1.data(), h, &original, nullptr, nullptr);
    const double scale = std::max(std::abs(original), 1e-300);
    round_trip(pair.q0, back0);
    round_trip(pair.q1, back1);
    Ld.evaluate(back0.data(), back1.data(), h, &moved, nullptr, nullptr);
    worst = std::max(worst, std::abs(moved - original) / scale);
    ulp(pair.q1, back1);
    Ld.evaluate(pair.q0.data(), back1.data(), h, &moved, nullptr, nullptr);
    worst = std::max(worst, std::abs(moved - original) / scale);
  }
  return worst;
}

double solver_noise_of(DiscreteLagrangian& Ld, const Manifold& manifold, const std::vector<SamplePair>& pairs, double h,
                       double tolerance) {
  Eigen::VectorXd D2(manifold.dim());
  double worst = 0.0;
  for (const auto& pair : pairs) {
    double value = 0.0;
    Ld.evaluate(pair.q0.data(), pair.q1.data(), h, &value, nullptr, D2.data());
    const double reach = tolerance * (1.0 + Eigen::Map<const Eigen::VectorXd>(pair.q1.data(), pair.q1.size()).lpNorm<Eigen::Infinity>());
    worst = std::max(worst, D2.lpNorm<1>() * reach / std::max(std::abs(value), 1e-300));
  }
  return worst;
}

double invariance_residual(DiscreteLagrangian& Ld, Lagrangian& lagrangian,
                           const std::vector<SamplePair>& pairs, double h) {
  double worst = 0.0;
  unsigned seed = 1;
  // The action moves points; the velocities it also moves are not needed here.
  std::vector<double> v(lagrangian.velocity_size(), 0.0), gv(v.size());
  for (const auto& pair : pairs) {
    std::vector<double> g0(pair.q0.size()), g1(pair.q1.size());
    check(lagrangian, lagrangian.act(seed, pair.q0.data(), v.data(), g0.data(), gv.data()), "group action");
    check(lagrangian, lagrangian.act(seed, pair.q1.data(), v.data(), g1.data(), gv.data()), "group action");
    ++seed;
    double original = 0.0, moved = 0.0;
    Ld.evaluate(pair.q0.data(), pair.q1.data(), h, &original, nullptr, nullptr);
    Ld.evaluate(g0.data(), g1.data(), h, &moved, nullptr, nullptr);
    worst = std::max(worst, std::abs(moved - original) / std::max(std::abs(original), 1e-300));
  }
  return worst;
}

void exact_discrete_lagrangian(LagrangianEvaluator& lagrangian, const double* nodes,
                               const double* weights, int points, const double* q0,
                               const double* v0, double h, double* q1, double* LdE) {
  Lagrangian& plugin = lagrangian.plugin();
  std::vector<double> q(lagrangian.position_size()), v(lagrangian.velocity_size());
  double sum = 0.0;
  for (int i = 0; i < points; ++i) {
    check(plugin, plugin.exact_solution(q0, v0, nodes[i] * h, q.data(), v.data()), "exact solution");
    sum += weights[i] * lagrangian.value(q.data(), v.data());
  }
  *LdE = h * sum;
  check(plugin, plugin.exact_solution(q0, v0, h, q1, v.data()), "exact solution");
}

void run(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q, const Eigen::VectorXd& p, double t0, double h,
         long steps, const StateVisitor& observe) {
  Trajectory trajectory(map, q, p, t0, h);
  observe(0, q.data(), p.data());
  trajectory.run_to(steps, [&](const Trajectory& x) {
    observe(x.steps(), x.q().data(), x.p().data());
    return true;
  });
}

EnergyDrift energy_drift(const std::vector<double>& energy_error) {
  const double n = static_cast<double>(energy_error.size());
  double mt = 0, me = 0;
  for (std::size_t k = 0; k < energy_error.size(); ++k) mt += static_cast<double>(k), me += energy_error[k];
  mt /= n;
  me /= n;
  double ste = 0, stt = 0;
  for (std::size_t k = 0; k < energy_error.size(); ++k) {
    ste += (static_cast<double>(k) - mt) * (energy_error[k] - me);
    stt += (static_cast<double>(k) - mt) * (static_cast<double>(k) - mt);
  }
  const double slope = stt > 0 ? ste / stt : 0.0;
  EnergyDrift drift{std::abs(slope) * (n - 1), 0.0};
  for (std::size_t k = 0; k < energy_error.size(); ++k)
    drift.wander = std::max(drift.wander, std::abs(energy_error[k] - me - slope * (static_cast<double>(k) - mt)));
  return drift;
}

}  // namespace varia
