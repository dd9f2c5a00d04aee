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
  v_.resize(n_);
  grad_.resize(m_ + n_);
  hess_.resize(m_ + n_, m_ + n_);
  if (reduced_) {  // l(Omega) = 1/2 Omega^T M Omega - V(g0): its Hessian is M (a constant mass matrix), held here
    Eigen::MatrixXd mass(n_, n_);
    constant_mass_ = lagrangian.constant_mass_matrix(mass.data());
    hess_.setZero();
    if (constant_mass_) hess_.bottomRightCorner(n_, n_) = mass;
  }
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
  for (int k = 1; k <= kMaxIncrementNodes; ++k) increment_rules_.push_back(gauss_legendre(k));
  choose_kernels();
}

void LieGroupGalerkinDiscreteLagrangian::check(Status status) const {
  varia::check(manifold_, status, "manifold chart");
}

namespace {

// Sizes of the chart's blocks: k times the group's dimension, and the sum of two sizes, fixed
// where both are (Eigen::Dynamic otherwise).
constexpr int times(int k, int size) { return size == Eigen::Dynamic ? Eigen::Dynamic : k * size; }
constexpr int plus(int a, int b) { return a == Eigen::Dynamic || b == Eigen::Dynamic ? Eigen::Dynamic : a + b; }

template <int Rows, int Columns>
using Matrix = Eigen::Matrix<double, Rows, Columns>;
template <int Rows>
using Vector = Eigen::Matrix<double, Rows, 1>;

}  // namespace

// The kernels at the group's sizes: fixed-size for the groups listed, whose 3 x 3 (SO(3)) or
// 6 x 6 (SE(3)) blocks then take unrolled products, and Eigen::Dynamic for any other.
void LieGroupGalerkinDiscreteLagrangian::choose_kernels() {
  const auto use = [this](auto N, auto M) {
    add_node_ = &LieGroupGalerkinDiscreteLagrangian::add_node<decltype(N)::value, decltype(M)::value>;
    dexp_with_derivatives_ = &LieGroupGalerkinDiscreteLagrangian::dexp_with_derivatives<decltype(N)::value>;
    step_equations_ = &LieGroupGalerkinDiscreteLagrangian::step_equations<decltype(N)::value>;
  };
  using std::integral_constant;
  if (n_ == 3 && m_ == 9)
    use(integral_constant<int, 3>{}, integral_constant<int, 9>{});  // SO(3)
  else if (n_ == 6 && m_ == 12)
    use(integral_constant<int, 6>{}, integral_constant<int, 12>{});  // SE(3)
  else
    use(integral_constant<int, Eigen::Dynamic>{}, integral_constant<int, Eigen::Dynamic>{});
}

// One quadrature node of the action: z = (g, Omega) of the chart curve as jets in the node's
// variables y = (eta, xi, xi_dot) (3 blocks of n), then
//   dL/dy = Z^T dL/dz,   d2L/dy2 = Z^T (d2L/dz2) Z + sum_k dL/dz_k d2z_k/dy2,   Z = dz/dy,
// carried to the unknowns (eta, xi^1..xi^s) by xi = sum_nu l_nu(c_i) xi^nu and
// xi_dot = sum_nu l'_nu(c_i) xi^nu / h (paper, sec. 2: the interpolant in the Lie algebra).
// Z = [dg/d(eta, xi) 0; 0 dOmega/d(xi, xi_dot)]; the reduced form has only its velocity rows
// (l depends on Omega alone), and takes the chain rule on that block: (xi, xi_dot) by Omega.
// N = dim, M = point_size (or Eigen::Dynamic): the workspace is mapped at those sizes.
template <int N, int M>
double LieGroupGalerkinDiscreteLagrangian::add_node(const double* q0, int i, double h, bool with_hessian,
                                                    bool with_value) {
  constexpr int N2 = times(2, N), N3 = times(3, N), Z = plus(M, N);
  const int n = n_, m = m_;
  const Eigen::Map<const Matrix<N, Eigen::Dynamic>> control(xi_.data(), n, s_ + 1);
  Eigen::Map<Vector<N>> node_xi(node_xi_.data(), n), node_rate(node_rate_.data(), n);
  node_xi.noalias() = control.lazyProduct(basis_.phi.col(i));
  node_rate.noalias() = control.lazyProduct(basis_.dphi.col(i));
  node_rate /= h;
  const Derivatives point = reduced_ ? Derivatives{} : Derivatives{point_.data(), point_gradient_.data(),
                                                                   with_hessian ? point_hessian_.data() : nullptr};
  check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), point,
                        {velocity_.data(), velocity_gradient_.data(), with_hessian ? velocity_hessian_.data() : nullptr}));
  for (int k = 0; k < m; ++k) q_(k) = reduced_ ? q0[k] : point_[k];  // reduced: l = L(g0, .)
  for (int k = 0; k < n; ++k) v_(k) = velocity_[k];
  // The reduced form needs only the velocity block of L's Hessian, d2l/dOmega2, which a declared
  // constant mass matrix gives without an evaluation (hess_ holds it from the start), and, where
  // l's value is not wanted, only dl/dOmega = M Omega (the chain rule reads no other entry of grad_).
  double L = 0.0;
  if (constant_mass_ && !with_value)
    Eigen::Map<Vector<N>>(grad_.data() + m, n).noalias() =
        Eigen::Map<const Matrix<Z, Z>>(hess_.data(), m + n, m + n).template bottomRightCorner<N, N>(n, n) *
        Eigen::Map<const Vector<N>>(v_.data(), n);
  else
    L = with_hessian && !constant_mass_ ? lagrangian_.hessian(q_.data(), v_.data(), grad_.data(), hess_.data())
                                        : lagrangian_.value_and_gradient(q_.data(), v_.data(), grad_.data());
  // The chart's gradients are component-major: component k's gradient in (eta, xi) or (xi, xi_dot)
  // is column k of these transposes, and its Hessian the 2n x 2n matrix k.
  const Eigen::Map<const Matrix<N2, M>> point_T(point_gradient_.data(), 2 * n, m);
  const Eigen::Map<const Matrix<N2, N>> velocity_T(velocity_gradient_.data(), 2 * n, n);
  const auto hessian = [&](const Eigen::VectorXd& h, int k) {
    return Eigen::Map<const Matrix<N2, N2>>(h.data() + k * 4 * n * n, 2 * n, 2 * n);
  };
  const Eigen::Map<const Vector<Z>> grad(grad_.data(), m + n);
  const Eigen::Map<const Matrix<Z, Z>> hess(hess_.data(), m + n, m + n);
  Eigen::Map<Matrix<Z, N3>> chain(chain_.data(), m + n, 3 * n), hess_chain(hess_chain_.data(), m + n, 3 * n);
  Eigen::Map<Vector<N3>> node_gradient(node_gradient_.data(), 3 * n);
  Eigen::Map<Matrix<N3, N3>> node_hessian(node_hessian_.data(), 3 * n, 3 * n);
  if (!reduced_) chain.template topLeftCorner<M, N2>(m, 2 * n) = point_T.transpose();
  chain.template bottomRightCorner<N, N2>(n, 2 * n) = velocity_T.transpose();
  // The chain rule on Z's block of R rows from z_row and C columns from y_column.
  const auto chain_rule = [&](auto R, auto C, int z_row, int rows, int y_column, int columns) {
    constexpr int Rows = decltype(R)::value, Columns = decltype(C)::value;
    const auto block = chain.template block<Rows, Columns>(z_row, y_column, rows, columns);
    node_gradient.template segment<Columns>(y_column, columns).noalias() =
        block.transpose() * grad.template segment<Rows>(z_row, rows);
    if (!with_hessian) return;
    auto hess_block = hess_chain.template block<Rows, Columns>(z_row, y_column, rows, columns);
    hess_block.noalias() = hess.template block<Rows, Rows>(z_row, z_row, rows, rows) * block;
    node_hessian.template block<Columns, Columns>(y_column, y_column, columns, columns).noalias() =
        block.transpose() * hess_block;
  };
  using std::integral_constant;
  if (reduced_)
    chain_rule(integral_constant<int, N>{}, integral_constant<int, N2>{}, m, n, n, 2 * n);
  else
    chain_rule(integral_constant<int, Z>{}, integral_constant<int, N3>{}, 0, m + n, 0, 3 * n);
  if (with_hessian) {
    if (!reduced_)
      for (int k = 0; k < m; ++k) node_hessian.template topLeftCorner<N2, N2>(2 * n, 2 * n) += grad(k) * hessian(point_hessian_, k);
    for (int k = 0; k < n; ++k)
      node_hessian.template bottomRightCorner<N2, N2>(2 * n, 2 * n) += grad(m + k) * hessian(velocity_hessian_, k);
  }

  // The weight of node block a (0 eta, 1 xi, 2 xi_dot) in the action's block beta (0 eta, nu >= 1
  // the control point xi^nu; xi^0 = 0 is fixed). The reduced form has no eta: tau = 0.
  const double w = h * weights_(i);
  const auto c = [&](int a, int beta) {
    if (beta == 0) return a == 0 ? 1.0 : 0.0;
    return a == 1 ? basis_.phi(beta, i) : a == 2 ? basis_.dphi(beta, i) / h : 0.0;
  };
  const int first = reduced_ ? 1 : 0;
  for (int beta = 0; beta <= s_; ++beta)
    for (int a = first; a < 3; ++a) {
      const double ca = c(a, beta);
      if (ca == 0.0) continue;
      gradient_.template segment<N>(beta * n, n) += w * ca * node_gradient.template segment<N>(a * n, n);
      if (!with_hessian) continue;
      for (int gamma = 0; gamma <= s_; ++gamma)
        for (int b = first; b < 3; ++b) {
          const double cb = c(b, gamma);
          if (cb != 0.0)
            hessian_.template block<N, N>(beta * n, gamma * n, n, n) +=
                (w * ca * cb) * node_hessian.template block<N, N>(a * n, b * n, n, n);
        }
    }
  return w * L;
}

double LieGroupGalerkinDiscreteLagrangian::action(const double* q0, double h, bool with_hessian, bool with_value) {
  gradient_.setZero();
  if (with_hessian) hessian_.setZero();
  action_ = 0.0;
  for (int i = 0; i < weights_.size(); ++i) action_ += (this->*add_node_)(q0, i, h, with_hessian, with_value);
  if (!with_value) action_ = NAN;
  return action_;
}

// dexp_{sign w} is d(velocity)/d(xi_dot) of the chart curve at xi = -w (velocity = dexp_{-xi} xi_dot),
// and its derivative in (sign w)_l is minus the mixed second derivative in (xi_l, xi_dot).
template <int N>
void LieGroupGalerkinDiscreteLagrangian::dexp_with_derivatives(const double* q0, const double* w,
                                                              double sign, bool with_derivatives) {
  const int n = n_;
  Eigen::Map<Vector<N>>(node_xi_.data(), n) = -sign * Eigen::Map<const Vector<N>>(w, n);
  node_rate_.setZero();
  check(manifold_.chart(q0, node_xi_.data(), node_rate_.data(), {},
                        {nullptr, velocity_gradient_.data(), with_derivatives ? velocity_hessian_.data() : nullptr}));
  Eigen::Map<Matrix<N, N>> dexp(dexp_.data(), n, n), inverse_T(dexp_inverse_T_.data(), n, n);
  const int V = 2 * n;
  for (int k = 0; k < n; ++k) {
    dexp.row(k) = Eigen::Map<const Vector<N>>(velocity_gradient_.data() + k * V + n, n).transpose();
    if (with_derivatives)
      for (int l = 0; l < n; ++l)
        for (int j = 0; j < n; ++j) dexp_derivative_[l](k, j) = -velocity_hessian_[(k * V + l) * V + n + j];
  }
  // dexp^{-T}: at a fixed size by inverse() (cofactors up to 4 x 4, else an LU on the stack); at
  // dynamic size by the member LU (inverse() would allocate a temporary).
  if constexpr (N == Eigen::Dynamic) {
    dexp_lu_.compute(dexp);
    inverse_T.noalias() = dexp_lu_.solve(identity_);
    inverse_T.transposeInPlace();
  } else {
    inverse_T.noalias() = dexp.inverse().transpose();
  }
}

// Step (p0 given): unknowns xi^1..xi^s, equations [p0 + D1 L_d; dS/dxi^1..s-1] with
// D1 L_d = tau - dexp_{xi^s}^{-T} sigma, whose derivative in xi^s also differentiates
// dexp^{-T}: d(A^{-T} sigma)/dw_l = A^{-T} dsigma/dw_l - A^{-T} (dA/dw_l)^T A^{-T} sigma.
// Evaluate (p0 null): unknowns xi^1..xi^{s-1}, equations dS/dxi^1..s-1.
template <int N>
void LieGroupGalerkinDiscreteLagrangian::step_equations(const double* p0, bool with_jacobian) {
  const int n = n_, U = unknowns_;
  const int first_internal_row = p0 != nullptr ? 1 : 0;
  for (int nu = 1; nu < s_; ++nu) {
    const int row = (nu - 1 + first_internal_row) * n;
    residual_.template segment<N>(row, n) = gradient_.template segment<N>(nu * n, n);
    if (with_jacobian) jacobian_.block(row, 0, n, U * n) = hessian_.block(nu * n, n, n, U * n);
  }
  if (p0 == nullptr) return;
  const Eigen::Map<const Matrix<N, N>> inverse_T(dexp_inverse_T_.data(), n, n);
  Eigen::Map<Vector<N>> momentum(momentum_.data(), n);
  momentum.noalias() = inverse_T * gradient_.template segment<N>(s_ * n, n);  // A^{-T} sigma
  residual_.template head<N>(n) =
      Eigen::Map<const Vector<N>>(p0, n) + gradient_.template head<N>(n) - momentum;
  if (!with_jacobian) return;
  for (int u = 0; u < U; ++u) {
    auto block = jacobian_.template block<N, N>(0, u * n, n, n);
    block = hessian_.template block<N, N>(0, (u + 1) * n, n, n);
    block.noalias() -= inverse_T * hessian_.template block<N, N>(s_ * n, (u + 1) * n, n, n);
  }
  Eigen::Map<Vector<N>> dexp_momentum(dexp_momentum_.data(), n);
  for (int l = 0; l < n; ++l) {
    dexp_momentum.noalias() = Eigen::Map<const Matrix<N, N>>(dexp_derivative_[l].data(), n, n).transpose() * momentum;
    jacobian_.template block<N, 1>(0, (s_ - 1) * n + l, n, 1).noalias() += inverse_T * dexp_momentum;
  }
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
