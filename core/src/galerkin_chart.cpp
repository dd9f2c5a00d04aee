#include "varia/core/galerkin_chart.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace varia {

namespace {

// The momentum map of a Lagrangian invariant under the whole group has one component per
// dimension of the group (its Lie algebra); that is when the reduced form applies.
bool invariant_under_the_whole_group(Lagrangian& lagrangian, int dim) {
  return lagrangian.momentum_size() == dim;
}

}  // namespace

LieGroupGalerkinDiscreteLagrangian::LieGroupGalerkinDiscreteLagrangian(
    Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
    std::vector<double> control_times, SolverOptions options, bool reduced)
    : manifold_(manifold),
      lagrangian_(lagrangian),
      basis_(control_times, quadrature),
      weights_(Eigen::Map<const Eigen::VectorXd>(quadrature.weights(), quadrature.size())),
      options_(options),
      reduced_(reduced),
      m_(manifold.point_size()),
      n_(manifold.dim()),
      s_(static_cast<int>(control_times.size()) - 1) {
  if (lagrangian.position_size() != m_ || lagrangian.velocity_size() != n_)
    throw std::invalid_argument("the Lagrangian's sizes do not match the manifold's");
  if (reduced_ && !invariant_under_the_whole_group(lagrangian, n_))
    throw std::invalid_argument(
        "the reduced (Euler-Poincare) form needs a Lagrangian invariant under the whole group "
        "(declared symmetry '" + std::string(lagrangian.symmetry_group()) + "' with " +
        std::to_string(lagrangian.momentum_size()) + " momentum components, the group has " +
        std::to_string(n_) + ")");
  extrapolation_.resize(s_ + 1, s_ + 1);
  for (int nu = 0; nu <= s_; ++nu)
    extrapolation_.col(nu) = basis_.at(1.0 + basis_.control_times[nu]);
  const int size = n_ * (s_ + 1);
  xi_ = Eigen::MatrixXd::Zero(n_, s_ + 1);
  previous_.resize(n_, s_ + 1);
  previous_base_.resize(m_);
  last_end_.resize(m_);
  point_.resize(m_);
  point_gradient_.resize(m_ * 2 * n_);
  point_hessian_.resize(m_ * 4 * n_ * n_);
  velocity_.resize(n_);
  velocity_gradient_.resize(n_ * 2 * n_);
  velocity_hessian_.resize(n_ * 4 * n_ * n_);
  node_xi_.resize(n_);
  node_rate_.resize(n_);
  q_.resize(m_);
  v_.resize(n_);
  grad_.resize(m_ + n_);
  hess_.resize(m_ + n_, m_ + n_);
  chain_ = Eigen::MatrixXd::Zero(m_ + n_, 3 * n_);
  hess_chain_.resize(m_ + n_, 3 * n_);
  node_gradient_.resize(3 * n_);
  node_hessian_.resize(3 * n_, 3 * n_);
  gradient_.resize(size);
  hessian_.resize(size, size);
  dexp_.resize(n_, n_);
  dexp_inverse_T_.resize(n_, n_);
  dexp_derivative_.assign(n_, Eigen::MatrixXd(n_, n_));
  dexp_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_ * s_);
  residual_.resize(n_ * s_);
  update_.resize(n_ * s_);
  momentum_.resize(n_);
  jacobian_.resize(n_ * s_, n_ * s_);
  residuals_.reserve(options_.max_iterations + 1);
}

void LieGroupGalerkinDiscreteLagrangian::check(Status status) const {
  varia::check(manifold_, status, "manifold chart");
}

// One quadrature node of the action: z = (g, Omega) of the chart curve as jets in the node's
// variables y = (eta, xi, xi_dot) (3 blocks of n), then
//   dL/dy = Z^T dL/dz,   d2L/dy2 = Z^T (d2L/dz2) Z + sum_k dL/dz_k d2z_k/dy2,   Z = dz/dy,
// carried to the unknowns (eta, xi^1..xi^s) by xi = sum_nu l_nu(c_i) xi^nu and
// xi_dot = sum_nu l'_nu(c_i) xi^nu / h (paper, sec. 2: the interpolant in the Lie algebra).
double LieGroupGalerkinDiscreteLagrangian::add_node(const double* q0, int i, double h, bool with_hessian) {
  node_xi_.noalias() = xi_ * basis_.phi.col(i);
  node_rate_.noalias() = xi_ * basis_.dphi.col(i) / h;
  const int n = n_;
  const Derivatives point = reduced_ ? Derivatives{} : Derivatives{point_.data(), point_gradient_.data(),
                                                                   with_hessian ? point_hessian_.data() : nullptr};
  check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), point,
                        {velocity_.data(), velocity_gradient_.data(), with_hessian ? velocity_hessian_.data() : nullptr}));
  for (int k = 0; k < m_; ++k) q_(k) = reduced_ ? q0[k] : point_[k];  // reduced: l = L(g0, .)
  for (int k = 0; k < n; ++k) v_(k) = velocity_[k];
  const double L = with_hessian ? lagrangian_.hessian(q_.data(), v_.data(), grad_.data(), hess_.data())
                                : lagrangian_.value_and_gradient(q_.data(), v_.data(), grad_.data());
  // Row k of the chart's gradient in (eta, xi) or (xi, xi_dot), and its Hessian, as matrices.
  const auto row = [&](const Eigen::VectorXd& gradient, int k) { return gradient.segment(k * 2 * n, 2 * n).transpose(); };
  const auto hessian = [&](const Eigen::VectorXd& h, int k) {
    return Eigen::Map<const Eigen::MatrixXd>(h.data() + k * 4 * n * n, 2 * n, 2 * n);
  };
  if (!reduced_)
    for (int k = 0; k < m_; ++k) chain_.row(k).head(2 * n) = row(point_gradient_, k);
  for (int k = 0; k < n; ++k) chain_.row(m_ + k).tail(2 * n) = row(velocity_gradient_, k);
  node_gradient_.noalias() = chain_.transpose() * grad_;
  if (with_hessian) {
    hess_chain_.noalias() = hess_ * chain_;
    node_hessian_.noalias() = chain_.transpose() * hess_chain_;
    if (!reduced_)
      for (int k = 0; k < m_; ++k) node_hessian_.topLeftCorner(2 * n, 2 * n) += grad_(k) * hessian(point_hessian_, k);
    for (int k = 0; k < n; ++k)
      node_hessian_.bottomRightCorner(2 * n, 2 * n) += grad_(m_ + k) * hessian(velocity_hessian_, k);
  }

  // The weight of node block a (0 eta, 1 xi, 2 xi_dot) in the action's block beta (0 eta, nu >= 1
  // the control point xi^nu; xi^0 = 0 is fixed).
  const double w = h * weights_(i);
  const auto c = [&](int a, int beta) {
    if (beta == 0) return a == 0 ? 1.0 : 0.0;
    return a == 1 ? basis_.phi(beta, i) : a == 2 ? basis_.dphi(beta, i) / h : 0.0;
  };
  for (int beta = 0; beta <= s_; ++beta)
    for (int a = 0; a < 3; ++a) {
      const double ca = c(a, beta);
      if (ca == 0.0) continue;
      gradient_.segment(beta * n, n) += w * ca * node_gradient_.segment(a * n, n);
      if (!with_hessian) continue;
      for (int gamma = 0; gamma <= s_; ++gamma)
        for (int b = 0; b < 3; ++b) {
          const double cb = c(b, gamma);
          if (cb != 0.0)
            hessian_.block(beta * n, gamma * n, n, n) += (w * ca * cb) * node_hessian_.block(a * n, b * n, n, n);
        }
    }
  return w * L;
}

double LieGroupGalerkinDiscreteLagrangian::action(const double* q0, double h, bool with_hessian) {
  gradient_.setZero();
  if (with_hessian) hessian_.setZero();
  action_ = 0.0;
  for (int i = 0; i < weights_.size(); ++i) action_ += add_node(q0, i, h, with_hessian);
  return action_;
}

// dexp_{sign w} is d(velocity)/d(xi_dot) of the chart curve at xi = -w (velocity = dexp_{-xi} xi_dot),
// and its derivative in (sign w)_l is minus the mixed second derivative in (xi_l, xi_dot).
void LieGroupGalerkinDiscreteLagrangian::dexp_with_derivatives(const double* q0, const double* w,
                                                              double sign) {
  node_xi_ = -sign * Eigen::Map<const Eigen::VectorXd>(w, n_);
  node_rate_.setZero();
  check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), {},
                        {nullptr, velocity_gradient_.data(), velocity_hessian_.data()}));
  const int V = 2 * n_;
  for (int k = 0; k < n_; ++k) {
    dexp_.row(k) = velocity_gradient_.segment(k * V + n_, n_).transpose();
    for (int l = 0; l < n_; ++l)
      for (int j = 0; j < n_; ++j) dexp_derivative_[l](k, j) = -velocity_hessian_[(k * V + l) * V + n_ + j];
  }
  dexp_lu_.compute(dexp_);
  dexp_inverse_T_ = dexp_lu_.inverse();
  dexp_inverse_T_.transposeInPlace();
}

// Step (p0 given): unknowns xi^1..xi^s, equations [p0 + D1 L_d; dS/dxi^1..s-1] with
// D1 L_d = tau - dexp_{xi^s}^{-T} sigma, whose derivative in xi^s also differentiates
// dexp^{-T}: d(A^{-T} sigma)/dw_l = A^{-T} dsigma/dw_l - A^{-T} (dA/dw_l)^T A^{-T} sigma.
// Evaluate (p0 null): unknowns xi^1..xi^{s-1}, equations dS/dxi^1..s-1.
void LieGroupGalerkinDiscreteLagrangian::step_equations(const double* p0) {
  const int n = n_, U = unknowns_;
  const int first_internal_row = p0 != nullptr ? 1 : 0;
  for (int nu = 1; nu < s_; ++nu) {
    const int row = (nu - 1 + first_internal_row) * n;
    residual_.segment(row, n) = gradient_.segment(nu * n, n);
    jacobian_.block(row, 0, n, U * n) = hessian_.block(nu * n, n, n, U * n);
  }
  if (p0 == nullptr) return;
  const auto sigma = gradient_.segment(s_ * n, n);
  momentum_.noalias() = dexp_inverse_T_ * sigma;  // A^{-T} sigma
  residual_.head(n) = Eigen::Map<const Eigen::VectorXd>(p0, n) + gradient_.head(n) - momentum_;
  jacobian_.topRows(n).noalias() = hessian_.block(0, n, n, U * n);
  jacobian_.topRows(n).noalias() -= dexp_inverse_T_ * hessian_.block(s_ * n, n, n, U * n);
  for (int l = 0; l < n; ++l)
    jacobian_.block(0, (s_ - 1) * n + l, n, 1).noalias() +=
        dexp_inverse_T_ * (dexp_derivative_[l].transpose() * momentum_);
}

void LieGroupGalerkinDiscreteLagrangian::newton(const double* q0, const double* p0, double h) {
  const int size = unknowns_ * n_;
  residuals_.clear();
  auto residual = residual_.head(size);
  auto update = update_.head(size);
  auto jacobian = jacobian_.topLeftCorner(size, size);
  double previous_update = 0.0;
  for (int iteration = 0;; ++iteration) {
    action(q0, h);
    if (p0 != nullptr) dexp_with_derivatives(q0, xi_.col(s_).data(), 1.0);
    step_equations(p0);
    double scale = gradient_.lpNorm<Eigen::Infinity>();
    if (p0 != nullptr) scale = std::max(scale, Eigen::Map<const Eigen::VectorXd>(p0, n_).lpNorm<Eigen::Infinity>());
    const double norm = residual.lpNorm<Eigen::Infinity>();
    residuals_.push_back(norm);
    if (!std::isfinite(norm))
      throw NumericalFailure("the Lie group Galerkin equations have a non-finite residual", norm);
    // At least one update is taken: a warm start that passes the residual test still carries a
    // residual of the order of the tolerance, always of one sign along a trajectory.
    if (iteration > 0 && options_.converged(norm, scale)) return statistics_.record(iteration);
    if (iteration == options_.max_iterations)
      throw NumericalFailure("Newton's method did not converge in " +
                                 std::to_string(options_.max_iterations) + " iterations",
                             norm);
    lu_.compute(jacobian);
    update = lu_.solve(residual);
    xi_.middleCols(1, unknowns_).reshaped() -= update;
    // Converged when the update, or the error left after it, is below the tolerance. With the
    // contraction theta = |update_k| / |update_{k-1}| the error left is about
    // theta / (1 - theta) |update_k| (Hairer & Wanner, Solving ODEs II, sec. IV.8); Newton's
    // quadratic convergence makes it tiny after an update of 1e-9, saving the Hessians of an
    // iteration that would only confirm it.
    const double size_of_update = update.lpNorm<Eigen::Infinity>();
    const double theta = previous_update > 0.0 ? size_of_update / previous_update : 1.0;
    const double left = theta < 1.0 ? std::min(1.0, theta / (1.0 - theta)) * size_of_update : size_of_update;
    previous_update = size_of_update;
    if (options_.converged(left, xi_.lpNorm<Eigen::Infinity>())) {
      action(q0, h, false);
      return statistics_.record(iteration + 1);
    }
  }
}

// The initial guess: the previous step's curve continued past its end (mapped into this step's
// chart through the group) when this step follows it; otherwise xi(t) = t v0 with v0 from the
// inverse Legendre transform of p0.
void LieGroupGalerkinDiscreteLagrangian::warm_start(const double* q0, const double* p0, double h) {
  const Eigen::Map<const Eigen::VectorXd> start(q0, m_);
  if (has_previous_ && previous_h_ == h && last_end_ == start) {
    for (int nu = 1; nu <= s_; ++nu) {
      node_xi_.noalias() = previous_ * extrapolation_.col(nu);
      check(manifold_.retract(previous_base_.data(), node_xi_.data(), q_.data()));
      check(manifold_.local(q0, q_.data(), xi_.col(nu).data()));
    }
  } else {
    lagrangian_.inverse_legendre(q0, p0, v_.data(), options_);
    for (int nu = 1; nu <= s_; ++nu) xi_.col(nu) = basis_.control_times[nu] * h * v_;
  }
  xi_.col(0).setZero();
}

void LieGroupGalerkinDiscreteLagrangian::take_step(const double* q0, const double* p0, double /*t0*/, double h,
                                                   double* q1, double* p1) {
  warm_start(q0, p0, h);
  unknowns_ = s_;
  newton(q0, p0, h);
  check(manifold_.retract(q0, xi_.col(s_).data(), q1));
  dexp_with_derivatives(q0, xi_.col(s_).data(), -1.0);  // dexp_{-xi^s}: p1 = D2 L_d
  Eigen::Map<Eigen::VectorXd>(p1, n_).noalias() = dexp_inverse_T_ * gradient_.segment(s_ * n_, n_);
  previous_ = xi_;
  previous_base_ = Eigen::Map<const Eigen::VectorXd>(q0, m_);
  last_end_ = Eigen::Map<const Eigen::VectorXd>(q1, m_);
  previous_h_ = h;
  has_previous_ = true;
}

void LieGroupGalerkinDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h,
                                                  double* Ld, double* D1, double* D2) {
  check(manifold_.local(q0, q1, xi_.col(s_).data()));
  for (int nu = 0; nu < s_; ++nu) xi_.col(nu) = basis_.control_times[nu] * xi_.col(s_);
  unknowns_ = s_ - 1;
  // Newton leaves the action and its gradient at the solution.
  if (unknowns_ > 0)
    newton(q0, nullptr, h);
  else
    action(q0, h, false);
  const auto sigma = gradient_.segment(s_ * n_, n_);
  if (Ld != nullptr) *Ld = action_;
  if (D1 != nullptr) {
    dexp_with_derivatives(q0, xi_.col(s_).data(), 1.0);
    Eigen::Map<Eigen::VectorXd>(D1, n_) = gradient_.head(n_) - dexp_inverse_T_ * sigma;
  }
  if (D2 != nullptr) {
    dexp_with_derivatives(q0, xi_.col(s_).data(), -1.0);
    Eigen::Map<Eigen::VectorXd>(D2, n_) = dexp_inverse_T_ * sigma;
  }
}

}  // namespace varia
