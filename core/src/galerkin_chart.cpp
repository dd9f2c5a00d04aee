#include "varia/core/galerkin_chart.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "varia/core/compensated.hpp"

namespace varia {

namespace {

// The momentum map of a Lagrangian invariant under the whole group has one component per
// dimension of the group (its Lie algebra); that is when the reduced form applies.
bool invariant_under_the_whole_group(Lagrangian& lagrangian, int dim) {
  return lagrangian.momentum_size() == dim;
}

constexpr double kEpsilon = 0x1p-52;
constexpr int kMaxIncrementNodes = 10;

}  // namespace

// The k-node Gauss-Legendre rule on [0, 1] by Golub and Welsch (Math. Comp. 23, 1969): the nodes
// are the eigenvalues of the Jacobi matrix of the Legendre polynomials, the weights the squared
// first components of its unit eigenvectors; with its error constant E_k (see point_increment).
LieGroupGalerkinDiscreteLagrangian::GaussRule LieGroupGalerkinDiscreteLagrangian::gauss_legendre(int k) {
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(k, k);
  for (int i = 1; i < k; ++i) jacobi(i, i - 1) = jacobi(i - 1, i) = i / std::sqrt(4.0 * i * i - 1.0);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jacobi);
  GaussRule rule;
  rule.nodes = (eigen.eigenvalues().array() + 1.0) / 2.0;
  rule.weights = eigen.eigenvectors().row(0).transpose().array().square();
  double factorial = 1.0, double_factorial = 1.0;  // k!, (2k)!
  for (int i = 1; i <= k; ++i) factorial *= i;
  for (int i = 1; i <= 2 * k; ++i) double_factorial *= i;
  rule.bound = std::pow(factorial, 4) / ((2 * k + 1) * std::pow(double_factorial, 3));
  return rule;
}

LieGroupGalerkinDiscreteLagrangian::LieGroupGalerkinDiscreteLagrangian(
    Manifold& manifold, Lagrangian& lagrangian, Quadrature& quadrature,
    std::vector<double> control_times, SolverOptions options, bool reduced)
    : manifold_(manifold),
      lagrangian_(lagrangian),
      basis_(control_times, quadrature),
      weights_(Eigen::Map<const Eigen::VectorXd>(quadrature.weights(), quadrature.size())),
      options_(options),
      solver_(options),
      reduced_(reduced || invariant_under_the_whole_group(lagrangian, manifold.dim())),
      m_(manifold.point_size()),
      n_(manifold.dim()),
      s_(static_cast<int>(control_times.size()) - 1) {
  if (lagrangian.position_size() != m_ || lagrangian.velocity_size() != n_)
    throw std::invalid_argument("the Lagrangian's sizes do not match the manifold's");
  if (reduced && !invariant_under_the_whole_group(lagrangian, n_))
    throw std::invalid_argument(
        "the reduced (Euler-Poincare) form needs a Lagrangian invariant under the whole group "
        "(declared symmetry '" + std::string(lagrangian.symmetry_group()) + "' with " +
        std::to_string(lagrangian.momentum_size()) + " momentum components, the group has " +
        std::to_string(n_) + ")");
  const std::vector<double>& d = basis_.control_times;
  std::vector<double> two_steps(d.begin(), d.end() - 1);
  for (double& t : two_steps) t -= 1.0;
  two_steps.insert(two_steps.end(), d.begin(), d.end());
  extrapolation_.resize(s_ + 1, s_ + 1);
  extrapolation_two_.resize(2 * s_ + 1, s_ + 1);
  for (int nu = 0; nu <= s_; ++nu) {
    extrapolation_.col(nu) = basis_.at(1.0 + d[nu]);
    extrapolation_two_.col(nu) = lagrange_basis_at(two_steps, 1.0 + d[nu]);
  }
  size_workspace();
  if (reduced_) {  // l(Omega) = 1/2 Omega^T M Omega - V(g0): its Hessian is M (a constant mass matrix), held here
    Eigen::MatrixXd mass(n_, n_);
    constant_mass_ = lagrangian.constant_mass_matrix(mass.data());
    hess_.setZero();
    if (constant_mass_) hess_.bottomRightCorner(n_, n_) = mass;
  }
  for (int k = 1; k <= kMaxIncrementNodes; ++k) increment_rules_.push_back(gauss_legendre(k));
  choose_kernels();
}

void LieGroupGalerkinDiscreteLagrangian::size_workspace() {
  const int size = n_ * (s_ + 1);
  xi_ = Eigen::MatrixXd::Zero(n_, s_ + 1);
  history_ = Eigen::MatrixXd::Zero(n_, 2 * s_ + 1);
  earlier_.resize(n_, s_);
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
  v_ = Eigen::VectorXd::Zero(n_);  // the inverse Legendre transform's first start
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
  identity_ = Eigen::MatrixXd::Identity(n_, n_);
  dexp_momentum_.resize(n_);
  dexp_derivative_.assign(n_, Eigen::MatrixXd(n_, n_));
  dexp_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_ * s_);
  residual_.resize(n_ * s_);
  refined_residual_.resize(n_ * s_);
  refined_update_.resize(n_ * s_);
  momentum_.resize(n_);
  jacobian_.resize(n_ * s_, n_ * s_);
  carry_g_ = Eigen::VectorXd::Zero(m_);
  carry_p_ = Eigen::VectorXd::Zero(n_);
  last_p_.resize(n_);
  point_change_.resize(m_);
  point_change_low_.resize(m_);
  momentum_change_.resize(n_);
}

void LieGroupGalerkinDiscreteLagrangian::check(Status status) const {
  varia::check(manifold_, status, "manifold chart");
}

double LieGroupGalerkinDiscreteLagrangian::action(const double* q0, double h, bool with_hessian, bool with_value) {
  gradient_.setZero();
  if (with_hessian) hessian_.setZero();
  action_ = 0.0;
  for (int i = 0; i < weights_.size(); ++i) action_ += (this->*add_node_)(q0, i, h, with_hessian, with_value);
  if (!with_value) action_ = NAN;
  return action_;
}

// The step's equations [p0 + D1 L_d; dS/dxi^1..s-1] (evaluate: the internal ones) in the control
// points xi^1..xi^unknowns, as a system for NewtonSolver (solve/newton.hpp), with the exact
// Jacobian, or (simplified) with the Jacobian at the first iterate kept for the whole solve
// (simplified Newton, solve/newton.hpp): from the last steps' curve continued (warm_start), the
// iterate is within O(h^(s+1)) of the solution (O(h^(2s+1)) once two steps are behind it), and
// the iteration contracts by about that much per update, at a fraction of the cost of an update
// (no Hessians of the chart and the Lagrangian).
struct LieGroupGalerkinDiscreteLagrangian::Equations {
  LieGroupGalerkinDiscreteLagrangian& g;
  const double* q0;
  const double* p0;
  double h;
  bool simplified_newton = false;
  int evaluations = 0;

  int size() const { return g.unknowns_ * g.n_; }
  bool simplified() const { return simplified_newton; }
  // F's round-off yardstick: the largest of its terms p0 and dS/d(eta, xi).
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    const bool with_jacobian = !simplified_newton || evaluations++ == 0;
    g.action(q0, h, with_jacobian, p0 == nullptr);  // a step (p0 given) needs no S
    if (p0 != nullptr) (g.*g.dexp_with_derivatives_)(q0, g.xi_.col(g.s_).data(), 1.0, with_jacobian);
    (g.*g.step_equations_)(p0, with_jacobian);
    F = g.residual_.head(size());
    double yardstick = g.gradient_.lpNorm<Eigen::Infinity>();
    if (p0 != nullptr) yardstick = std::max(yardstick, Eigen::Map<const Eigen::VectorXd>(p0, g.n_).lpNorm<Eigen::Infinity>());
    return yardstick;
  }
  void factorize() { g.lu_.compute(g.jacobian_.topLeftCorner(size(), size())); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) { update.noalias() = g.lu_.solve(F); }
  // x's round-off yardstick: the size of the points g0 exp(xi) stand for, g0's and the chart's.
  double apply(const Eigen::VectorXd& update) {
    g.xi_.middleCols(1, g.unknowns_).reshaped() -= update;
    return Eigen::Map<const Eigen::VectorXd>(q0, g.m_).lpNorm<Eigen::Infinity>() + g.xi_.lpNorm<Eigen::Infinity>();
  }
  // The gradient at the updated points, to first order from the Hessian at hand (the update is
  // at round-off: the O(|update|^2) term, and the Hessian's change since the first iterate times
  // the update in simplified Newton, are far below it), and the residual left, F - J update.
  // Simplified Newton stops with a residual of about theta r <= eps (1 + yardstick) left, which
  // the momentum update (take_step) cannot see: it enters the discrete momentum at every step
  // with the same sign, and its map drifted linearly (SO(3), h = 0.01: 3e-15 over 10^6 steps).
  // One more update, at the cost of a residual without Hessians, leaves theta^2 r: the solver may
  // stop at theta r <= eps (1 + yardstick) (solve/newton.hpp).
  double residual_left() const { return 1.0; }
  void finish(const Eigen::VectorXd& update) {
    const Eigen::VectorXd* last = &update;
    if (simplified_newton) {
      evaluate(g.refined_residual_);
      solve(g.refined_residual_, g.refined_update_);
      apply(g.refined_update_);
      last = &g.refined_update_;
    }
    g.gradient_.noalias() -= g.hessian_.middleCols(g.n_, size()) * *last;
    g.residual_.head(size()).noalias() -= g.jacobian_.topLeftCorner(size(), size()) * *last;
  }
};

void LieGroupGalerkinDiscreteLagrangian::newton(const double* q0, const double* p0, double h, bool simplified) {
  Equations equations{*this, q0, p0, h, simplified};
  SolveReport report = solver_.solve(equations, statistics_);
  if (report.outcome == SolveReport::Outcome::not_contracting) {
    equations.simplified_newton = false;
    report = solver_.solve(equations, statistics_);
  }
  require_converged(report, "the Lie group Galerkin equations");
}

// The initial guess when this step follows the last (same h, from its end): the polynomial in the
// last step's chart through the control points of the last two steps (2s + 1 of them: within
// O(h^(2s+1)) of the next step's when the steps before followed each other too), else through the
// last step's (its curve continued, O(h^(s+1))), at the times 1 + d_nu, mapped into this step's
// chart through the group. With the start that much closer, simplified Newton's first update,
// whose contraction is O(that distance), mostly leaves a residual at round-off, and the step takes
// one evaluation fewer (bench/README.md, "Measured design choices").
// Otherwise xi(t) = t v0 with v0 from the inverse Legendre transform of p0.
// The last step's control points in this step's chart (earlier_, the next step's history): xi^0
// is g0_last = g0 exp(-xi^s_last), the others through the group.
bool LieGroupGalerkinDiscreteLagrangian::warm_start(const double* q0, const double* p0, double h) {
  const Eigen::Map<const Eigen::VectorXd> start(q0, m_);
  const bool continued = has_previous_ && previous_h_ == h && last_end_ == start;
  if (continued) {
    for (int nu = 1; nu <= s_; ++nu) {
      if (two_steps_back_)
        node_xi_.noalias() = history_ * extrapolation_two_.col(nu);
      else
        node_xi_.noalias() = previous() * extrapolation_.col(nu);
      check(manifold_.retract(previous_base_.data(), node_xi_.data(), q_.data()));
      check(manifold_.local(q0, q_.data(), xi_.col(nu).data()));
    }
    earlier_.col(0) = -previous().col(s_);
    for (int nu = 1; nu < s_; ++nu) {
      check(manifold_.retract(previous_base_.data(), previous().col(nu).data(), q_.data()));
      check(manifold_.local(q0, q_.data(), earlier_.col(nu).data()));
    }
  } else {
    lagrangian_.inverse_legendre(q0, p0, v_.data(), options_);
    for (int nu = 1; nu <= s_; ++nu) xi_.col(nu) = basis_.control_times[nu] * h * v_;
  }
  xi_.col(0).setZero();
  return continued;
}

// g1 = g0 exp(xi^s) and p1 = D2 L_d, each written as its start plus a small increment summed with
// Kahan's compensation across steps (compensated.hpp) while each step continues from the last
// one's output, so that a conserved momentum stays at round-off over long runs:
//   g1 - g0 by the group's own increment where it has one (Manifold::increment, formed to more
//   than working precision, its part below double's taken into the compensation: a rounding
//   error that repeats along a steady motion adds up, and carries g off the group), else by
//   point_increment();
//   p1 - p0 = (D1 L_d + D2 L_d) - (p0 + D1 L_d) = tau + (dexp_{-xi}^{-T} - dexp_{xi}^{-T}) sigma - r0
//           = tau + A(xi)^T sigma - r0,
// r0 the residual left in the first equation. A(xi) = dexp_{-xi}^{-1} - dexp_{xi}^{-1} is linear in
// xi, twice the derivative of dexp at 0 (the series dexp_{xi}^{-1} = sum_k B_k/k! ad_xi^k has
// B_1 = -1/2 and no other odd term): every term is of the size of the step's change, and is
// computed to its own relative precision.
void LieGroupGalerkinDiscreteLagrangian::take_step(const double* q0, const double* p0, double /*t0*/, double h,
                                                   double* q1, double* p1) {
  const Eigen::Map<const Eigen::VectorXd> start(q0, m_), momentum(p0, n_);
  if (!(has_previous_ && last_end_ == start && last_p_ == momentum)) {
    carry_g_.setZero();
    carry_p_.setZero();
  }
  const bool continued = warm_start(q0, p0, h);
  unknowns_ = s_;
  newton(q0, p0, h, continued);
  if (dexp_slopes_.empty()) dexp_slopes(q0);
  const auto xi = xi_.col(s_);
  const auto sigma = gradient_.segment(s_ * n_, n_);
  momentum_change_ = gradient_.head(n_) - residual_.head(n_);
  for (int l = 0; l < n_; ++l) momentum_change_.noalias() += (2.0 * xi(l)) * (dexp_slopes_[l].transpose() * sigma);
  bool increment = true;
  point_change_low_.setZero();
  if (manifold_.has_increment())
    check(manifold_.increment(q0, xi.data(), point_change_.data(), point_change_low_.data()));
  else
    increment = point_increment(q0, xi);
  last_p_ = momentum;
  compensated_add(last_p_, momentum_change_, carry_p_);
  if (increment) {
    last_end_ = start;
    compensated_add(last_end_, point_change_, carry_g_);
    carry_g_ -= point_change_low_;  // the sum is last_end_ - carry_g_ (compensated.hpp)
  } else {
    check(manifold_.retract(q0, xi.data(), last_end_.data()));
    carry_g_.setZero();
  }
  Eigen::Map<Eigen::VectorXd>(q1, m_) = last_end_;
  Eigen::Map<Eigen::VectorXd>(p1, n_) = last_p_;
  if (continued) history_.leftCols(s_) = earlier_;
  two_steps_back_ = continued;
  previous() = xi_;
  previous_base_ = start;
  previous_h_ = h;
  has_previous_ = true;
}

// d dexp_w / dw_l at w = 0 (the Lie algebra's structure: dexp_w = I -/+ ad_w / 2 + O(w^2)).
void LieGroupGalerkinDiscreteLagrangian::dexp_slopes(const double* q0) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
  (this->*dexp_with_derivatives_)(q0, zero.data(), 1.0, true);
  dexp_slopes_ = dexp_derivative_;
}

// point_change_ = g0 exp(xi) - g0 = int_0^1 d/dt g0 exp(t xi) dt, the integrand the chart's
// derivative in xi at t xi applied to xi (Manifold::chart), by the Gauss-Legendre rule of
// fewest nodes k whose error bound E_k |xi|^{2k} relative to |xi| is below eps/8, E_k =
// (k!)^4 / ((2k + 1) ((2k)!)^3) (Abramowitz & Stegun 25.4.30; the integrand's 2k-th derivative is
// of size |xi|^{2k+1} on a compact group's chart, and on SE(3)'s translations too). Each node's
// value carries an error of eps |g0| |xi|: the increment is exact to its own relative precision.
// False (no increment formed) when |xi|_1 is beyond the largest rule's reach (a step past
// |xi| ~ 4.8, near the chart's edge).
bool LieGroupGalerkinDiscreteLagrangian::point_increment(const double* q0, const Eigen::Ref<const Eigen::VectorXd>& xi) {
  const double size = xi.lpNorm<1>();
  const GaussRule* rule = nullptr;
  for (const GaussRule& candidate : increment_rules_)
    if (candidate.bound * std::pow(size, 2.0 * candidate.nodes.size()) <= 0.125 * kEpsilon) {
      rule = &candidate;
      break;
    }
  if (rule == nullptr) return false;
  point_change_.setZero();
  node_rate_.setZero();
  for (Eigen::Index i = 0; i < rule->nodes.size(); ++i) {
    node_xi_ = rule->nodes[i] * xi;
    check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), {nullptr, point_gradient_.data(), nullptr}, {}));
    for (int k = 0; k < m_; ++k)  // the xi block of component k's gradient in (eta, xi)
      point_change_[k] += rule->weights[i] * Eigen::Map<const Eigen::VectorXd>(&point_gradient_[k * 2 * n_ + n_], n_).dot(xi);
  }
  return true;
}

void LieGroupGalerkinDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h,
                                                  double* Ld, double* D1, double* D2) {
  check(manifold_.local(q0, q1, xi_.col(s_).data()));
  for (int nu = 0; nu < s_; ++nu) xi_.col(nu) = basis_.control_times[nu] * xi_.col(s_);
  unknowns_ = s_ - 1;
  // Newton leaves the action and its gradient at the solution.
  if (unknowns_ > 0)
    newton(q0, nullptr, h, false);
  else
    action(q0, h, false);
  const auto sigma = gradient_.segment(s_ * n_, n_);
  if (Ld != nullptr) *Ld = action_;
  if (D1 != nullptr) {
    (this->*dexp_with_derivatives_)(q0, xi_.col(s_).data(), 1.0, false);
    Eigen::Map<Eigen::VectorXd>(D1, n_) = gradient_.head(n_) - dexp_inverse_T_ * sigma;
  }
  if (D2 != nullptr) {
    (this->*dexp_with_derivatives_)(q0, xi_.col(s_).data(), -1.0, false);
    Eigen::Map<Eigen::VectorXd>(D2, n_) = dexp_inverse_T_ * sigma;
  }
}

}  // namespace varia
