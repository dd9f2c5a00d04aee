// The Lie group Galerkin construction's kernels (galerkin_chart.hpp): one quadrature node of the
// action through the chart's jets, dexp and its derivatives, and the step's equations, as templates
// on the group's dimension and point size, instantiated here once per size that choose_kernels
// picks.
#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <type_traits>

#include "varia/core/galerkin_chart.hpp"

namespace varia {

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
  constexpr int Z = plus(M, N);
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
  chain_to_node<N, M>(with_hessian);
  add_to_action<N>(i, h, with_hessian);
  return h * weights_(i) * L;
}

// The chain rule of add_node: L's gradient and (with_hessian) Hessian in z = (g, Omega), held in
// grad_ and hess_, to the node's variables y = (eta, xi, xi_dot), into node_gradient_ and node_hessian_.
template <int N, int M>
void LieGroupGalerkinDiscreteLagrangian::chain_to_node(bool with_hessian) {
  constexpr int N2 = times(2, N), N3 = times(3, N), Z = plus(M, N);
  const int n = n_, m = m_;
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
}

// The node's derivatives (chain_to_node) carried to the action's unknowns with the quadrature weight.
template <int N>
void LieGroupGalerkinDiscreteLagrangian::add_to_action(int i, double h, bool with_hessian) {
  const int n = n_;
  const Eigen::Map<const Vector<times(3, N)>> node_gradient(node_gradient_.data(), 3 * n);
  const Eigen::Map<const Matrix<times(3, N), times(3, N)>> node_hessian(node_hessian_.data(), 3 * n, 3 * n);
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

}  // namespace varia
