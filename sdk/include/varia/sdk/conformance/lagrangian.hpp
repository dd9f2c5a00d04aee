// The Lagrangian conformance suite: at random points (q, v), the gradient and Hessian a plugin
// returns match central differences of its value and gradient; the Hessian is symmetric; every
// evaluate() path gives the same value; a declared constant mass matrix is the Hessian's velocity
// block; a declared symmetry leaves L invariant and its momentum map is equivariant; L's gradient
// and Hessian at jets (gradient_jet, hessian_jet, where the Lagrangian gives them) carry the values
// at doubles and derivatives that pass Taylor tests against them; gradients() at several points is
// evaluate() at each; the explicit form's
// Stormer-Verlet steps and the shooting construction's shots, where the plugin runs them itself,
// are those of their recurrences.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "varia/core/explicit_shot.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/core/stormer_verlet.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/taylor.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace varia::sdk::conformance {

using Eigen::MatrixXd;
using Eigen::VectorXd;

struct Evaluation {
  double value;
  VectorXd gradient;  // [dL/dq, dL/dv]
  MatrixXd hessian;
};

// The Hessian dense, whether the plugin writes it dense or in its sparse pattern.
inline Evaluation evaluate(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v) {
  const int k = lagrangian.position_size() + lagrangian.velocity_size();
  const int* rows = nullptr;
  const int* cols = nullptr;
  const int stored = lagrangian.hessian_pattern(&rows, &cols);
  Evaluation e{0.0, VectorXd(k), MatrixXd::Zero(k, k)};
  VectorXd entries(stored < 0 ? k * k : stored);
  check(lagrangian, lagrangian.evaluate(q.data(), v.data(), &e.value, e.gradient.data(), entries.data()), "evaluate");
  if (stored < 0) e.hessian = entries.reshaped(k, k);
  for (int i = 0; i < stored; ++i) e.hessian(rows[i], cols[i]) = entries(i);
  return e;
}

inline double value(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v) {
  double l = 0;
  check(lagrangian, lagrangian.evaluate(q.data(), v.data(), &l, nullptr, nullptr), "evaluate");
  return l;
}

inline VectorXd gradient(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v) {
  VectorXd g(lagrangian.position_size() + lagrangian.velocity_size());
  check(lagrangian, lagrangian.evaluate(q.data(), v.data(), nullptr, g.data(), nullptr), "evaluate");
  return g;
}

// z = (q, v) with component i moved by `step`.
inline std::pair<VectorXd, VectorXd> moved(const VectorXd& q, const VectorXd& v, int i, double step) {
  VectorXd qs = q, vs = v;
  (i < q.size() ? qs(i) : vs(i - q.size())) += step;
  return {qs, vs};
}

// Largest deviations of the gradient from central differences of the value, and of the Hessian
// from central differences of the gradient, relative to the derivatives' size.
struct DerivativeErrors {
  double gradient, hessian;
};
inline DerivativeErrors derivative_errors(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v) {
  constexpr double step = 1e-5;
  const Evaluation e = evaluate(lagrangian, q, v);
  const int k = static_cast<int>(e.gradient.size());
  VectorXd gradient_fd(k);
  MatrixXd hessian_fd(k, k);
  for (int i = 0; i < k; ++i) {
    const auto [qp, vp] = moved(q, v, i, step);
    const auto [qm, vm] = moved(q, v, i, -step);
    gradient_fd(i) = (value(lagrangian, qp, vp) - value(lagrangian, qm, vm)) / (2 * step);
    hessian_fd.col(i) = (gradient(lagrangian, qp, vp) - gradient(lagrangian, qm, vm)) / (2 * step);
  }
  const double g_scale = std::max(1.0, e.gradient.cwiseAbs().maxCoeff());
  const double h_scale = std::max(1.0, e.hessian.cwiseAbs().maxCoeff());
  return {(e.gradient - gradient_fd).cwiseAbs().maxCoeff() / g_scale,
          (e.hessian - hessian_fd).cwiseAbs().maxCoeff() / h_scale};
}

// |a - b| relative to 1 + max(|a|, |b|) (as doctest's Approx).
inline double gap(double a, double b) { return std::fabs(a - b) / (1 + std::max(std::fabs(a), std::fabs(b))); }

// The symmetry claims at one point: L(g q, g v) = L(q, v) and |J(g q, g v)| = |J(q, v)|.
inline void check_symmetry(Lagrangian& lagrangian, unsigned seed, const VectorXd& q, const VectorXd& v, double l,
                           Failures& failures) {
  const int m = lagrangian.position_size(), n = lagrangian.velocity_size();
  VectorXd gq(m), gv(n), j(lagrangian.momentum_size()), gj(lagrangian.momentum_size());
  check(lagrangian, lagrangian.act(seed, q.data(), v.data(), gq.data(), gv.data()), "act");
  const double gl = value(lagrangian, gq, gv);
  failures.expect(gap(gl, l) <= 1e-13, "L(g q, g v) = ", gl, " differs from L(q, v) = ", l);
  check(lagrangian, lagrangian.momentum(q.data(), v.data(), j.data()), "momentum");
  check(lagrangian, lagrangian.momentum(gq.data(), gv.data(), gj.data()), "momentum");
  failures.expect(gap(gj.norm(), j.norm()) <= 1e-13, "|J(g q, g v)| = ", gj.norm(),
                  " differs from |J(q, v)| = ", j.norm(), " (Ad*-equivariance)");
}

// gradient_jet and hessian_jet (where given) along a random line through (q, v).
inline void check_jets(Lagrangian& lagrangian, unsigned seed, const VectorXd& q, const VectorXd& v,
                       Failures& failures) {
  const int m = lagrangian.position_size(), k = m + lagrangian.velocity_size();
  VectorXd z(k);
  z << q, v;
  std::mt19937 engine(seed);
  const VectorXd d = random_direction(k, engine);
  const auto at_doubles = [&](double eps) {
    const VectorXd moved = z + eps * d;
    return evaluate(lagrangian, moved.head(m), moved.tail(k - m));
  };
  if (lagrangian.evaluates_at_jets())
    check_at_jets(
        [&](double eps) {
          const std::vector<Jet2> x = line_jets(z, d, eps);
          std::vector<Jet2> gradient(k);
          check(lagrangian, lagrangian.gradient_jet(x.data(), x.data() + m, nullptr, gradient.data()),
                "Lagrangian gradient at jets");
          return gradient;
        },
        [&](double eps) { return at_doubles(eps).gradient; }, "the gradient", failures);
  if (lagrangian.hessian_jet_variables() < 1) return;
  // Rows 1.. of the Hessian (all but the first, so that a request's offset is checked) times the unit
  // directions and one more random direction u: H(1.., :) [I, u].
  const VectorXd u = random_direction(k, engine);
  std::vector<Jet2> directions(static_cast<std::size_t>(k) * (k + 1), Jet2(0.0));
  for (int j = 0; j < k; ++j) directions[j * k + j] = Jet2(1.0);
  for (int c = 0; c < k; ++c) directions[k * k + c] = Jet2(u(c));
  check_at_jets(
      [&](double eps) {
        const std::vector<Jet2> x = line_jets(z, d, eps);
        std::vector<Jet2> rows(static_cast<std::size_t>(k - 1) * (k + 1));
        check(lagrangian, lagrangian.hessian_jet(x.data(), x.data() + m, 1, k - 1, k + 1, directions.data(), rows.data()),
              "Lagrangian Hessian at jets");
        return rows;
      },
      [&](double eps) {
        Eigen::MatrixXd product(k - 1, k + 1);
        const Eigen::MatrixXd H = at_doubles(eps).hessian;
        product << H.bottomRows(k - 1), H.bottomRows(k - 1) * u;
        return product.reshaped().eval();
      },
      "the Hessian", failures);
}

// Where the plugin runs the explicit form's Stormer-Verlet steps itself (kernel::StormerVerletSteps), five
// of them from (q, d = h v, f = dL/dq(q)) with K = h^2 M^{-1} (h = 0.1; K = h^2 I without a
// constant mass matrix: the recurrence is defined all the same) give the numbers of the same
// recurrence with dL/dq from evaluate(), at v = 0, to round-off.
inline void check_verlet_steps(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v, Failures& failures) {
  const int n = lagrangian.velocity_size();
  kernel::StormerVerletSteps verlet;
  if (!lagrangian.offers(kernel::call(verlet)) || lagrangian.position_size() != n) return;
  const double h = 0.1;
  const long steps = 5;
  const VectorXd zero = VectorXd::Zero(n);
  MatrixXd K = MatrixXd::Identity(n, n), mass(n, n);
  if (lagrangian.constant_mass_matrix(mass.data())) K = mass.llt().solve(K);
  K *= h * h;
  VectorXd plugin_q = q, plugin_d = h * v, plugin_f = gradient(lagrangian, q, zero).head(n);
  VectorXd own_q = plugin_q, own_d = plugin_d, own_f = plugin_f;
  stormer_verlet_steps(own_q, own_d, own_f, K, steps,
                       [&](const VectorXd& x, VectorXd& f) { f = gradient(lagrangian, x, zero).head(n); });
  verlet = {plugin_q.data(), plugin_d.data(), plugin_f.data(), K.data(), steps};
  check(lagrangian, lagrangian.run(kernel::call(verlet)), "the Stormer-Verlet steps kernel");
  const double scale = std::max({1.0, own_q.cwiseAbs().maxCoeff(), own_d.cwiseAbs().maxCoeff() / h,
                                 own_f.cwiseAbs().maxCoeff()});
  const double error = std::max({(plugin_q - own_q).cwiseAbs().maxCoeff(), (plugin_d - own_d).cwiseAbs().maxCoeff() / h,
                                 (plugin_f - own_f).cwiseAbs().maxCoeff()});
  failures.expect(error <= 1e-13 * scale, "the Stormer-Verlet steps kernel gives (q, d, f) ", error,
                  " away from the Stormer-Verlet recurrence with dL/dq from evaluate() (5 steps of h = 0.1)");
}

// The largest difference of two jets' values and derivatives, relative to the reference's size:
// of the Hessians, their last `columns` columns.
inline double jet_gap(const Jet2& jet, const Jet2& reference, int columns) {
  double scale = std::max(1.0, std::abs(reference.value)), error = std::abs(jet.value - reference.value);
  if (reference.constant() || jet.constant()) return (jet.constant() != reference.constant() ? 1.0 : error) / scale;
  if (jet.gradient.size() != reference.gradient.size()) return 1.0;
  const auto H = reference.hessian.rightCols(columns);
  const auto plugin_H = jet.hessian.rightCols(columns);
  scale = std::max({scale, reference.gradient.cwiseAbs().maxCoeff(), H.cwiseAbs().maxCoeff()});
  error = std::max({error, (jet.gradient - reference.gradient).cwiseAbs().maxCoeff(),
                    (plugin_H - H).cwiseAbs().maxCoeff()});
  return error / scale;
}

// Where the plugin runs the shooting construction's shots itself (kernel::ExplicitShot) and declares a
// constant mass matrix: a shot of rk4 through Simpson's nodes (the paper's SVIRK4) from (q, w0 = v)
// at h = 0.1 gives S and the end's offsets, values, first derivatives in (eta, w0) and second
// derivatives in the columns of w0 (those the shooting Newton reads, kernel::ExplicitShot), of the
// recurrence (explicit_shot.hpp) with L and dL/dq from gradient_jet, to round-off.
inline void check_shot(Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v, Failures& failures) {
  const int n = lagrangian.velocity_size();
  MatrixXd mass(n, n);
  if (lagrangian.position_size() != n || !lagrangian.evaluates_at_jets() ||
      !lagrangian.constant_mass_matrix(mass.data()))
    return;
  const MatrixXd inverse_mass = mass.inverse();
  const ButcherTableau rk4 = classic_rk4();
  static constexpr double nodes[3] = {0, 0.5, 1}, weights[3] = {1.0 / 6, 4.0 / 6, 1.0 / 6};
  const ShotPlan plan{{rk4.stages(), rk4.a.data(), rk4.b.data(), rk4.c.data()}, 3, nodes, weights, n,
                      inverse_mass.data()};
  kernel::ExplicitShot shot;
  shot.plan = &plan;
  if (!lagrangian.offers(kernel::call(shot))) return;
  const double h = 0.1;
  std::vector<Jet2> offsets(n), reference_offsets(n), work(shot_workspace(plan)), gradient(2 * n);
  Jet2 action, reference_action;
  shot = {&plan, q.data(), v.data(), h, &action, offsets.data()};
  check(lagrangian, lagrangian.run(kernel::call(shot)), "the explicit shot kernel");
  explicit_shot(plan, q.data(), v.data(), h, reference_action, reference_offsets.data(), work.data(),
                [&](const Jet2* x, const Jet2* w, Jet2* L, Jet2* Lq) {
                  check(lagrangian, lagrangian.gradient_jet(x, w, L, gradient.data()), "Lagrangian gradient at jets");
                  std::copy_n(gradient.begin(), n, Lq);
                });
  double error = jet_gap(action, reference_action, n);
  for (int r = 0; r < n; ++r) error = std::max(error, jet_gap(offsets[r], reference_offsets[r], n));
  failures.expect(error <= 1e-13, "the explicit shot kernel gives S and the offsets ", error,
                  " (relative) away from the recurrence of explicit_shot.hpp with gradient_jet (rk4, Simpson, h = 0.1)");
}

// The claims at one point (q, v).
inline void check_point(Lagrangian& lagrangian, unsigned seed, const VectorXd& q, const VectorXd& v,
                        Failures& failures) {
  const int m = lagrangian.position_size(), n = lagrangian.velocity_size();
  const Evaluation e = evaluate(lagrangian, q, v);
  const auto [gradient_error, hessian_error] = derivative_errors(lagrangian, q, v);
  failures.expect(gradient_error < 1e-8, "the gradient differs from central differences by ", gradient_error);
  failures.expect(hessian_error < 1e-7, "the Hessian differs from central differences by ", hessian_error);
  const double h_scale = std::max(1.0, e.hessian.cwiseAbs().maxCoeff());
  failures.expect((e.hessian - e.hessian.transpose()).cwiseAbs().maxCoeff() <= 1e-14 * h_scale,
                  "the Hessian is not symmetric");
  const double l = value(lagrangian, q, v);
  failures.expect(gap(l, e.value) <= 1e-15, "the value alone is ", l,
                  ", with the derivatives ", e.value);
  failures.expect((gradient(lagrangian, q, v) - e.gradient).cwiseAbs().maxCoeff() <=
                      1e-15 * std::max(1.0, e.gradient.cwiseAbs().maxCoeff()),
                  "the gradient alone differs from the gradient with the Hessian");
  {  // gradients(): at (q, v) and a second point in one call, each as evaluate() gives it
    const VectorXd q2 = (0.5 * q.array() + 0.3).matrix(), v2 = (-0.7 * v.array() + 0.1).matrix();
    VectorXd points(2 * (m + n)), both(2 * (m + n)), single(2 * (m + n));
    points << q, v, q2, v2;
    single << gradient(lagrangian, q, v), gradient(lagrangian, q2, v2);
    check(lagrangian, lagrangian.gradients(2, points.data(), both.data()), "gradients");
    failures.expect((both - single).cwiseAbs().maxCoeff() <= 1e-15 * std::max(1.0, single.cwiseAbs().maxCoeff()),
                    "gradients() at two points differs from evaluate() at each");
  }
  MatrixXd mass(n, n);
  if (lagrangian.constant_mass_matrix(mass.data())) {
    failures.expect((e.hessian.bottomRightCorner(n, n) - mass).cwiseAbs().maxCoeff() < 1e-13,
                    "the declared constant mass matrix is not d2L/dv2");
    failures.expect(e.hessian.bottomLeftCorner(n, m).cwiseAbs().maxCoeff() < 1e-13,
                    "a constant mass matrix is declared but d2L/dv dq is not zero");
  }
  if (lagrangian.has_constant_mass_matrix()) {
    // Read off the Hessian (a sparse Lagrangian gives no dense M): d2L/dv dq zero and d2L/dv2 the
    // same at another point.
    const Evaluation other =
        evaluate(lagrangian, (0.5 * q.array() + 0.3).matrix(), (-0.7 * v.array() + 0.1).matrix());
    failures.expect((e.hessian.bottomRightCorner(n, n) - other.hessian.bottomRightCorner(n, n)).cwiseAbs().maxCoeff() <
                        1e-13 * h_scale,
                    "has_constant_mass_matrix() is declared but d2L/dv2 changes from point to point");
    failures.expect(e.hessian.bottomLeftCorner(n, m).cwiseAbs().maxCoeff() < 1e-13 * h_scale,
                    "has_constant_mass_matrix() is declared but d2L/dv dq is not zero");
  }
  if (lagrangian.momentum_size() > 0) check_symmetry(lagrangian, seed, q, v, e.value, failures);
  check_jets(lagrangian, seed, q, v, failures);
  check_verlet_steps(lagrangian, q, v, failures);
  check_shot(lagrangian, q, v, failures);
}

// The whole suite on one Lagrangian, at `trials` random points.
inline Failures check_lagrangian(Lagrangian& lagrangian, std::mt19937& engine, int trials = 20) {
  Failures failures;
  for (int trial = 0; trial < trials && failures.empty(); ++trial) {
    const VectorXd q = random_point(lagrangian.position_size(), engine);
    const VectorXd v = random_point(lagrangian.velocity_size(), engine);
    std::ostringstream where;
    where << "at q = [" << q.transpose() << "], v = [" << v.transpose() << "]: ";
    Failures at_point;
    at_point.set_context(where.str());
    try {
      check_point(lagrangian, static_cast<unsigned>(trial), q, v, at_point);
    } catch (const PluginFault& fault) {
      at_point.expect(false, "a call failed: ", fault.what());
    }
    failures.append(at_point);
  }
  return failures;
}

}  // namespace varia::sdk::conformance
