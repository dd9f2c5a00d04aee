#include "varia/core/verification.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "varia/core/trajectory.hpp"

namespace varia {

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor) {
  OrderFit fit;
  fit.errors = error;
  std::vector<int> kept;
  for (std::size_t k = 0; k < h.size(); ++k) {
    std::ostringstream why;
    if (!(error[k] > floor)) {
      why << "h = " << h[k] << ": error " << error[k] << " at round-off (below " << floor << ")";
      fit.dropped.push_back(why.str());
    } else {
      kept.push_back(static_cast<int>(k));
    }
  }
  auto local = [&](std::size_t a) {
    return std::log(error[kept[a]] / error[kept[a + 1]]) / std::log(h[kept[a]] / h[kept[a + 1]]);
  };
  while (kept.size() >= 4 && std::abs(local(0) - local(1)) > 0.3) {
    std::ostringstream why;
    why << "h = " << h[kept[0]] << ": pre-asymptotic (local slope " << local(0) << ", next "
        << local(1) << ")";
    fit.dropped.push_back(why.str());
    kept.erase(kept.begin());
  }
  // Trailing points whose local slope breaks away from the one before: a round-off plateau
  // (the errors stop falling, or fall by chance).
  while (kept.size() >= 4 &&
         std::abs(local(kept.size() - 2) - local(kept.size() - 3)) > 0.3) {
    std::ostringstream why;
    why << "h = " << h[kept.back()] << ": at round-off (local slope " << local(kept.size() - 2)
        << ", before it " << local(kept.size() - 3) << ")";
    fit.dropped.push_back(why.str());
    kept.pop_back();
  }
  fit.used = static_cast<int>(kept.size());
  if (kept.size() < 2) return fit;
  double mx = 0, my = 0;
  for (int k : kept) mx += std::log(h[k]), my += std::log(error[k]);
  mx /= kept.size();
  my /= kept.size();
  double sxy = 0, sxx = 0;
  for (int k : kept) {
    sxy += (std::log(h[k]) - mx) * (std::log(error[k]) - my);
    sxx += (std::log(h[k]) - mx) * (std::log(h[k]) - mx);
  }
  fit.slope = sxy / sxx;
  return fit;
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
         long steps, const Observer& observe) {
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

// Central-difference Jacobian of the one-step map in canonical chart coordinates at
// (xi, pi) = (0, p0), with difference step delta.
Eigen::MatrixXd jacobian(CanonicalChart& chart, const double* p0, int n, double h, double delta) {
  Eigen::MatrixXd M(2 * n, 2 * n);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * n), plus(2 * n), minus(2 * n);
  for (int i = 0; i < n; ++i) z[n + i] = p0[i];
  for (int j = 0; j < 2 * n; ++j) {
    for (double sign : {1.0, -1.0}) {
      Eigen::VectorXd w = z;
      w[j] += sign * delta;
      chart.step(w, h, sign > 0 ? plus : minus);
    }
    M.col(j) = (plus - minus) / (2 * delta);
  }
  return M;
}

double defect(const Eigen::MatrixXd& M) {
  const int n = static_cast<int>(M.rows()) / 2;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  J.topRightCorner(n, n).setIdentity();
  J.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  return (M.transpose() * J * M - J).cwiseAbs().maxCoeff();
}

}  // namespace

SymplecticityDefect symplecticity_defect(DiscreteHamiltonianMap& map, Manifold& manifold,
                                         const double* q0, const double* p0, double h) {
  // Richardson: (4 M(delta/2) - M(delta)) / 3 cancels the O(delta^2) term of central differences.
  const double delta = 1e-3;
  const int n = manifold.dim();
  CanonicalChart chart(map, manifold, q0);
  auto richardson = [&](double d) {
    return Eigen::MatrixXd((4.0 * jacobian(chart, p0, n, h, d / 2) - jacobian(chart, p0, n, h, d)) / 3.0);
  };
  const double coarse = defect(richardson(delta)), fine = defect(richardson(delta / 2));
  return {fine, std::abs(fine - coarse) + 1e-13};
}

double drift_ratio(const std::vector<double>& energy_error) {
  const std::size_t quarter = std::max<std::size_t>(1, energy_error.size() / 4);
  double first = 0.0, last = 0.0;
  for (std::size_t k = 0; k < quarter; ++k) first = std::max(first, std::abs(energy_error[k]));
  for (std::size_t k = energy_error.size() - quarter; k < energy_error.size(); ++k)
    last = std::max(last, std::abs(energy_error[k]));
  return last / std::max(first, 1e-300);
}

}  // namespace varia
