// The Lie group manifold conformance suite, at a point q the caller gives (the Manifold interface
// has no distinguished point). Every derivative the constructions use is checked against the
// manifold's own values (Taylor tests: the error of the first-order model falls as eps^2):
//   - local is the inverse of retract (the natural chart, paper, sec. 2);
//   - the generators D(q) (Manifold::generators) are the derivative of retract(q, xi) at 0;
//   - the chart's point gradient in xi at 0 is D(q), and its velocity gives antisymmetric
//     structure constants [e_a, e_b] = -[e_b, e_a];
//   - translate at jets is retract at the values, with derivative D(q) in xi at 0;
//   - local_derivatives' gradient at q0 = q is a left inverse of D(q);
//   - at a point xi away from 0, the chart's first derivatives asked alone (as a simplified
//     Newton iteration asks them) are those asked with the Hessian, and the Hessian is the
//     derivative of the gradient (Taylor test).
// A group whose composition is not affine in its second factor fails the generators' Taylor
// test (the SDK's adapter derives D(q) from the composition, varia/sdk/lie_group.hpp).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "varia/abi/manifold.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/taylor.hpp"

namespace varia::sdk::conformance {

namespace detail {

inline Eigen::VectorXd retracted(Manifold& manifold, const Eigen::VectorXd& q, const Eigen::VectorXd& xi) {
  Eigen::VectorXd out(manifold.point_size());
  if (manifold.retract(q.data(), xi.data(), out.data()) != nullptr) out.setConstant(NAN);
  return out;
}

// D(q) at doubles (m x n), NaN where generators fails.
inline Eigen::MatrixXd generators(Manifold& manifold, const Eigen::VectorXd& q) {
  const int m = manifold.point_size(), n = manifold.dim();
  std::vector<Jet2> point(m), D(m * n);
  for (int k = 0; k < m; ++k) point[k] = Jet2(q[k]);
  Eigen::MatrixXd out(m, n);
  if (manifold.generators(point.data(), D.data()) != nullptr) return out.setConstant(NAN);
  for (int k = 0; k < m; ++k)
    for (int a = 0; a < n; ++a) out(k, a) = D[k * n + a].value;
  return out;
}

// The chart's point (in (eta, xi)) and velocity (in (xi, xi_dot)) at (xi, xi_dot): gradient alone,
// and gradient with Hessian; the two gradients agree, and the Hessian passes a Taylor test of the
// gradient in the direction u (2n numbers).
inline void check_chart_at(Failures& failures, Manifold& manifold, const Eigen::VectorXd& q, const Eigen::VectorXd& xi,
                           const Eigen::VectorXd& xi_dot, const Eigen::VectorXd& u, double scale) {
  const int m = manifold.point_size(), n = manifold.dim(), V = 2 * n;
  struct Chart {
    Eigen::VectorXd point_gradient, velocity_gradient, point_hessian, velocity_hessian;
  };
  const auto chart = [&](const Eigen::VectorXd& at, const Eigen::VectorXd& rate, bool hessian) {
    Chart c{Eigen::VectorXd(m * V), Eigen::VectorXd(n * V), Eigen::VectorXd(m * V * V), Eigen::VectorXd(n * V * V)};
    const bool ok = manifold.chart(q.data(), at.data(), rate.data(),
                                   {nullptr, c.point_gradient.data(), hessian ? c.point_hessian.data() : nullptr},
                                   {nullptr, c.velocity_gradient.data(), hessian ? c.velocity_hessian.data() : nullptr}) == nullptr;
    if (!ok) c.point_gradient.setConstant(NAN);
    return c;
  };
  const Chart alone = chart(xi, xi_dot, false), full = chart(xi, xi_dot, true);
  const double difference = std::max((alone.point_gradient - full.point_gradient).lpNorm<Eigen::Infinity>(),
                                     (alone.velocity_gradient - full.velocity_gradient).lpNorm<Eigen::Infinity>());
  failures.expect(difference <= 1e-12 * scale,
                  "the chart's gradient asked without the Hessian differs from the one asked with it by ", difference);
  // The point's gradient in (eta, xi) moves with xi only through the xi block; the velocity's with
  // both of (xi, xi_dot). Remainder of the first-order model of the gradients along u.
  const auto remainder = [&](double eps) {
    const Eigen::VectorXd moved_xi = xi + eps * u.tail(n), moved_rate = xi_dot + eps * u.head(n);
    const Chart c = chart(moved_xi, moved_rate, false);
    Eigen::VectorXd point_step = Eigen::VectorXd::Zero(V), velocity_step(V);
    point_step.tail(n) = u.tail(n);
    velocity_step << u.tail(n), u.head(n);
    double r = 0.0;
    for (int k = 0; k < m; ++k) {
      const Eigen::Map<const Eigen::MatrixXd> H(full.point_hessian.data() + k * V * V, V, V);
      r = std::max(r, (c.point_gradient.segment(k * V, V) - full.point_gradient.segment(k * V, V) - eps * H * point_step)
                          .lpNorm<Eigen::Infinity>());
    }
    for (int k = 0; k < n; ++k) {
      const Eigen::Map<const Eigen::MatrixXd> H(full.velocity_hessian.data() + k * V * V, V, V);
      r = std::max(r, (c.velocity_gradient.segment(k * V, V) - full.velocity_gradient.segment(k * V, V) -
                       eps * H * velocity_step)
                          .lpNorm<Eigen::Infinity>());
    }
    return r;
  };
  expect_taylor(failures, remainder, scale, "the chart's Hessian is not the derivative of its gradient");
}

}  // namespace detail

// The suite at the point q (a point of the manifold) with random directions from `engine`.
inline Failures check_lie_group(Manifold& manifold, const Eigen::VectorXd& q, std::mt19937& engine) {
  Failures failures;
  const int m = manifold.point_size(), n = manifold.dim();
  failures.expect(!manifold.is_vector_space(), "the suite is for Lie groups; this manifold is a vector space");
  failures.expect(q.size() == m && manifold.contains(q.data(), nullptr, 0), "the given point is not on the manifold");
  if (!failures.empty()) return failures;
  const Eigen::VectorXd d = random_direction(n, engine);
  const double scale = std::max(1.0, q.lpNorm<Eigen::Infinity>());

  // local(q, retract(q, xi)) = xi.
  const Eigen::VectorXd xi = 0.3 * d;
  Eigen::VectorXd back(n);
  failures.expect(manifold.local(q.data(), detail::retracted(manifold, q, xi).data(), back.data()) == nullptr &&
                      (back - xi).norm() <= 1e-12,
                  "local(q, retract(q, xi)) differs from xi by ", (back - xi).norm());

  // Taylor test: |retract(q, eps d) - q - eps D d| falls as eps^2.
  const Eigen::MatrixXd D = detail::generators(manifold, q);
  failures.expect(D.allFinite(), "generators() failed or is not finite");
  if (!failures.empty()) return failures;
  const auto remainder = [&](double eps) { return (detail::retracted(manifold, q, eps * d) - q - eps * D * d).norm(); };
  expect_taylor(failures, remainder, scale, "the generators are not retract's derivative at 0");

  // The chart's point gradient in xi at 0 is D; its velocity's structure constants are antisymmetric.
  const int V = 2 * n;
  std::vector<double> zero(n, 0.0), gradient(m * V), hessian(n * V * V);
  failures.expect(manifold.chart(q.data(), zero.data(), zero.data(), {nullptr, gradient.data(), nullptr},
                                 {nullptr, nullptr, hessian.data()}) == nullptr,
                  "chart() failed");
  double chart_difference = 0.0, asymmetry = 0.0;
  for (int k = 0; k < m; ++k)
    for (int a = 0; a < n; ++a) chart_difference = std::max(chart_difference, std::abs(gradient[k * V + n + a] - D(k, a)));
  for (int c = 0; c < n; ++c)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        asymmetry = std::max(asymmetry, std::abs(hessian[(c * V + a) * V + n + b] + hessian[(c * V + b) * V + n + a]));
  failures.expect(chart_difference <= 1e-12 * scale, "the chart's gradient in xi at 0 differs from the generators by ",
                  chart_difference);
  failures.expect(asymmetry <= 1e-12, "the chart's velocity gives a bracket that is not antisymmetric (by ", asymmetry,
                  ")");

  // translate at jets: retract at the values, derivative D in xi at 0.
  std::vector<Jet2> point(m), step(n), moved(m);
  for (int k = 0; k < m; ++k) point[k] = Jet2(q[k]);
  for (int a = 0; a < n; ++a) step[a] = Jet2::variable(0.0, n, a);
  failures.expect(manifold.translate(point.data(), step.data(), moved.data()) == nullptr, "translate() failed");
  double translate_difference = 0.0;
  for (int k = 0; k < m; ++k) {
    translate_difference = std::max(translate_difference, std::abs(moved[k].value - q[k]));
    for (int a = 0; a < n; ++a)
      translate_difference =
          std::max(translate_difference, std::abs((moved[k].constant() ? 0.0 : moved[k].gradient(a)) - D(k, a)));
  }
  failures.expect(translate_difference <= 1e-12 * scale, "translate(q, xi) at jets differs from q + D xi + O(xi^2) by ",
                  translate_difference);

  // d local(q0, q)/dq at q = q0 is a left inverse of D.
  std::vector<double> local_gradient(n * m);
  failures.expect(manifold.local_derivatives(q.data(), q.data(), {nullptr, local_gradient.data(), nullptr}) == nullptr,
                  "local_derivatives() failed");
  const Eigen::MatrixXd left = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                                   local_gradient.data(), n, m) * D;
  failures.expect((left - Eigen::MatrixXd::Identity(n, n)).lpNorm<Eigen::Infinity>() <= 1e-12 * scale,
                  "local_derivatives' gradient is not a left inverse of the generators (off by ",
                  (left - Eigen::MatrixXd::Identity(n, n)).lpNorm<Eigen::Infinity>(), ")");
  detail::check_chart_at(failures, manifold, q, xi, random_direction(n, engine), random_direction(2 * n, engine), scale);
  return failures;
}

}  // namespace varia::sdk::conformance
