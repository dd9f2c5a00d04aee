#include "varia/core/verification.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
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

namespace {

// The one-step map in canonical coordinates z = (xi, pi) of T*Q: xi in the natural chart at
// `base`, pi = B^T mu the chart's conjugate momentum, where mu is the (left-trivialized) momentum
// and B = d velocity / d xi_dot = dexp_{-xi} (Manifold::chart; the identity on a vector
// space, where z = (q - base, p)).
class CanonicalChart {
 public:
  CanonicalChart(DiscreteHamiltonianMap& map, Manifold& manifold, const double* base)
      : map_(map), manifold_(manifold), base_(base, base + manifold.point_size()),
        n_(manifold.dim()), q_(manifold.point_size()), q1_(manifold.point_size()), mu_(n_), mu1_(n_),
        B_(n_, n_), velocity_gradient_(2 * n_ * n_) {}
  void step(const Eigen::VectorXd& z, double h, Eigen::VectorXd& out) {
    check(manifold_, manifold_.retract(base_.data(), z.data(), q_.data()), "manifold retract");
    chart_momentum_matrix(z.data());
    mu_ = B_.transpose().partialPivLu().solve(z.tail(n_));
    map_.step(q_.data(), mu_.data(), h, q1_.data(), mu1_.data());
    check(manifold_, manifold_.local(base_.data(), q1_.data(), out.data()), "manifold local");
    chart_momentum_matrix(out.data());
    out.tail(n_) = B_.transpose() * mu1_;
  }

 private:
  void chart_momentum_matrix(const double* xi) {
    if (manifold_.is_vector_space()) {
      B_.setIdentity();
      return;
    }
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
    check(manifold_, manifold_.chart(base_.data(), xi, zero.data(), {}, {nullptr, velocity_gradient_.data(), nullptr}),
          "manifold chart");
    for (int k = 0; k < n_; ++k) B_.row(k) = velocity_gradient_.segment(k * 2 * n_ + n_, n_).transpose();
  }
  DiscreteHamiltonianMap& map_;
  Manifold& manifold_;
  std::vector<double> base_;
  int n_;
  std::vector<double> q_, q1_;
  Eigen::VectorXd mu_, mu1_;
  Eigen::MatrixXd B_;
  Eigen::VectorXd velocity_gradient_;  // d velocity / d (xi, xi_dot), component-major
};

// The one-step map's derivative in canonical chart coordinates at (xi, pi) = (0, p0) along each
// column d_j of `directions` (a difference step), by central differences of factor d_j:
// column j is M d_j.
Eigen::MatrixXd directional(CanonicalChart& chart, const double* p0, int n, double h, const Eigen::MatrixXd& directions,
                            double factor) {
  Eigen::MatrixXd images(2 * n, directions.cols());
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * n), plus(2 * n), minus(2 * n);
  for (int i = 0; i < n; ++i) z[n + i] = p0[i];
  for (Eigen::Index j = 0; j < directions.cols(); ++j) {
    chart.step(z + factor * directions.col(j), h, plus);
    chart.step(z - factor * directions.col(j), h, minus);
    images.col(j) = (plus - minus) / (2 * factor);
  }
  return images;
}

// The defect of the symplectic form on the directions D, in the rescaled coordinates S = diag(1/a, a)
// (S is symplectic) with each direction of unit length there: max |(S M D N)^T J (S M D N) -
// (S D N)^T J (S D N)|, N = diag(1 / |S d_j|). With D the coordinate directions it is
// ||(S M S^-1)^T J (S M S^-1) - J||max, zero exactly when M is symplectic; with D a basis of the
// tangent space of a submanifold, zero exactly when M preserves the form restricted to it.
// `scale` (if not null): the largest entry of the rescaled (S M D N)^T J (S M D N), the size of the
// terms the defect is a difference of.
double defect(const Eigen::MatrixXd& images, const Eigen::MatrixXd& directions, const Eigen::VectorXd& a,
              double* scale = nullptr) {
  const int n = static_cast<int>(images.rows()) / 2;
  Eigen::VectorXd s(2 * n);
  s << a.cwiseInverse(), a;
  Eigen::MatrixXd in = s.asDiagonal() * directions, out = s.asDiagonal() * images;
  for (Eigen::Index j = 0; j < in.cols(); ++j) {
    const double length = in.col(j).norm();
    in.col(j) /= length;
    out.col(j) /= length;
  }
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  J.topRightCorner(n, n).setIdentity();
  J.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd form = out.transpose() * J * out;
  if (scale != nullptr) *scale = form.cwiseAbs().maxCoeff();
  return (form - in.transpose() * J * in).cwiseAbs().maxCoeff();
}

}  // namespace

SymplecticityDefect exact_symplecticity_defect(DiscreteHamiltonianMap& map, const double* q0, const double* p0,
                                               double t0, double h, const Eigen::VectorXd& steps, double tolerance) {
  const int n = map.dim();
  const Eigen::VectorXd a = (steps.head(n).array() / steps.tail(n).array()).sqrt();
  const Eigen::MatrixXd directions = steps.asDiagonal();
  Eigen::MatrixXd images(2 * n, 2 * n);
  Eigen::VectorXd q1(map.point_size()), p1(n);
  map.step_with_tangent(q0, p0, t0, h, q1.data(), p1.data(), 2 * n, directions.data(), images.data());
  double scale = 0.0;
  const double value = defect(images, directions, a, &scale);
  constexpr double eps = std::numeric_limits<double>::epsilon();
  return {value, (2 * n * eps + tolerance) * std::max(1.0, scale)};
}

double symplecticity_residual(const Eigen::MatrixXd& M) {
  return defect(M, Eigen::MatrixXd::Identity(M.rows(), M.cols()), Eigen::VectorXd::Ones(M.rows() / 2));
}

SymplecticityDefect symplecticity_defect(DiscreteHamiltonianMap& map, Manifold& manifold,
                                         const double* q0, const double* p0, double h,
                                         const Eigen::VectorXd& steps, const Eigen::MatrixXd& tangent) {
  // Richardson: (4 M(d/2) - M(d)) / 3 cancels the O(d^2) term of central differences.
  const int n = manifold.dim();
  const Eigen::VectorXd a = (steps.head(n).array() / steps.tail(n).array()).sqrt();
  const Eigen::MatrixXd directions = tangent.size() > 0 ? tangent : Eigen::MatrixXd(steps.asDiagonal());
  CanonicalChart chart(map, manifold, q0);
  auto richardson = [&](double factor) {
    return Eigen::MatrixXd(
        (4.0 * directional(chart, p0, n, h, directions, factor / 2) - directional(chart, p0, n, h, directions, factor)) /
        3.0);
  };
  const double coarse = defect(richardson(1.0), directions, a), fine = defect(richardson(0.5), directions, a);
  return {fine, std::abs(fine - coarse) + 1e-13};
}

Eigen::MatrixXd constrained_tangent_basis(HolonomicConstraints& constraints, const Eigen::MatrixXd& mass,
                                          const double* q, const double* p, double position_step, double momentum_step) {
  const int n = constraints.dim(), m = constraints.size();
  constraints.evaluate_jacobian(q);
  const Eigen::MatrixXd G = constraints.jacobian();
  const Eigen::LLT<Eigen::MatrixXd> M(mass);
  const Eigen::VectorXd v = M.solve(Eigen::Map<const Eigen::VectorXd>(p, n));
  Eigen::MatrixXd K(m, n);  // d(G(q) v)/dq at fixed v: row i is (H_i v)^T, H_i the Hessian of g_i
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(m);
  for (int i = 0; i < m; ++i) {
    unit.setZero();
    unit[i] = 1.0;
    constraints.evaluate_hessian(q, unit.data());
    K.row(i) = (constraints.hessian() * v).transpose();
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(G.transpose());
  const Eigen::MatrixXd Z = Eigen::MatrixXd(qr.householderQ()).rightCols(n - m);  // an orthonormal basis of ker G
  const Eigen::MatrixXd MinvGt = M.solve(G.transpose());
  const Eigen::MatrixXd lift = -G.transpose() * (G * MinvGt).partialPivLu().solve(K * Z);  // dp keeping G M^-1 p = 0
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(2 * n, 2 * (n - m));
  basis.topLeftCorner(n, n - m) = position_step * Z;
  basis.bottomLeftCorner(n, n - m) = position_step * lift;
  basis.bottomRightCorner(n, n - m) = momentum_step * (mass * Z);
  return basis;
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
