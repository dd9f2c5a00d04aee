// The Lie group Galerkin map's tangent map (spec "Tangent maps and ensembles"), by the implicit
// function theorem on the step's equations (galerkin_chart.hpp): with S(eta, xi^1..xi^s) the
// action of the curve g0 exp(eta) exp(xi(t)), tau = dS/deta and sigma = dS/dxi^s at eta = 0,
//   R_nu = dS/dxi^nu = 0 (0 < nu < s),   R_0 = p0 + tau - dexp_{xi^s}^{-T} sigma = 0,
//   g1 = g0 exp(xi^s),   p1 = dexp_{-xi^s}^{-T} sigma.
// A direction (a, b) moves g0 to g0 exp(e a) and p0 to p0 + e b. At the moved base the curve is
// g0 exp(e a) exp(xi(t)), the chart's eta = e a exactly, so dR_nu and d sigma take the action's
// Hessian block in eta, H_{., eta} a. The momentum equation's tau is the derivative along
// g0 exp(e a) exp(d e_b) = g0 exp(e a + d e_b + (e d / 2) [a, e_b] + ...) (Baker-Campbell-Hausdorff),
// so d tau = H_{eta eta} a + 1/2 ad_a^T tau (coadjoint, lie_group_field.hpp). With J the step's Newton Jacobian in xi^1..xi^s:
//   J dxi = -(dR/da a + (b; 0)),
//   dg1 = C1 (P_eta a + P_xi dxi^s)   (P: the chart's point gradient at xi^s; C1 = d local(g1, g)/dg),
//   dp1 = A^{-T} (d sigma - sum_l dxi^s_l (dA/dxi_l)^T p1),   A = dexp_{-xi^s}.
// The reduced form is the same with tau = 0 and no position derivatives, which vanish exactly for
// a Lagrangian invariant under the whole group.
#include "varia/core/galerkin_chart.hpp"
#include "varia/core/lie_group_field.hpp"

namespace varia {

std::string LieGroupGalerkinDiscreteLagrangian::tangent_map_refusal() const { return {}; }

void LieGroupGalerkinDiscreteLagrangian::take_tangent_step(const double* q0, const double* p0, double t0, double h,
                                                           double* q1, double* p1, int count,
                                                           const double* directions, double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  const int n = n_, m = m_, s = s_, U = s_ * n_;
  using Strided = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  const Strided a(directions, n, count, Eigen::OuterStride<>(2 * n));
  const Strided b(directions + n, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dq1(images, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dp1(images + n, n, count, Eigen::OuterStride<>(2 * n));
  // The equations and their Jacobian at the solution.
  unknowns_ = s;
  action(q0, h, true, false);
  (this->*dexp_with_derivatives_)(q0, xi_.col(s).data(), 1.0, true);
  (this->*step_equations_)(p0, true);
  forward_inverse_T_ = dexp_inverse_T_;
  const auto tau = gradient_.head(n);
  const auto sigma = gradient_.segment(s * n, n);
  tangent_rhs_.resize(U, count);
  for (int nu = 1; nu < s; ++nu) tangent_rhs_.middleRows(nu * n, n).noalias() = hessian_.block(nu * n, 0, n, n) * a;
  auto momentum_row = tangent_rhs_.topRows(n);
  momentum_row.noalias() = hessian_.block(0, 0, n, n) * a;
  momentum_row.noalias() -= forward_inverse_T_ * (hessian_.block(s * n, 0, n, n) * a);
  momentum_row += b;
  momentum_row += 0.5 * coadjoint(structure_constants(manifold_, q0), a, tau);
  lu_.compute(jacobian_.topLeftCorner(U, U));
  tangent_xi_.noalias() = -lu_.solve(tangent_rhs_);
  const auto dxi = tangent_xi_.bottomRows(n);
  // dg1 in the chart at g1.
  node_xi_ = xi_.col(s);
  node_rate_.setZero();
  check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), {nullptr, point_gradient_.data(), nullptr}, {}));
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> P(
      point_gradient_.data(), m, 2 * n);
  end_point_.noalias() = P.leftCols(n) * a;
  end_point_.noalias() += P.rightCols(n) * dxi;
  local_value_.resize(n);
  local_gradient_.resize(static_cast<std::size_t>(n) * m);
  check(manifold_.local_derivatives(q1, q1, {local_value_.data(), local_gradient_.data(), nullptr}));
  chart_inverse_ = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      local_gradient_.data(), n, m);
  dq1.noalias() = chart_inverse_ * end_point_;
  // dp1 from A = dexp_{-xi^s} (its derivatives in -xi^s: dA/dxi_l = -dexp_derivative_[l]).
  sigma_change_.noalias() = hessian_.block(s * n, 0, n, n) * a;
  sigma_change_.noalias() += hessian_.block(s * n, n, n, U) * tangent_xi_;
  (this->*dexp_with_derivatives_)(q0, xi_.col(s).data(), -1.0, true);
  end_momentum_.noalias() = dexp_inverse_T_ * sigma;
  for (int l = 0; l < n; ++l) sigma_change_.noalias() += (dexp_derivative_[l].transpose() * end_momentum_) * dxi.row(l);
  dp1.noalias() = dexp_inverse_T_ * sigma_change_;
}

}  // namespace varia
