// The Galerkin construction's discrete action (galerkin.hpp): S(q^0..q^s) = h sum_i b_i L(q(c_i h),
// qdot(c_i h)) of the control points, its gradient and Hessian (dense, or the sparse Newton
// Jacobian's entries), and the forces' discrete terms; compiled for n <= 4 at fixed sizes, here, once.
#include "varia/core/galerkin.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "varia/core/fixed_size.hpp"

namespace varia {

// q_i = q^0 + sum_nu l_nu(c_i) (q^nu - q^0) (sum_nu l_nu = 1), v_i = (1/h) sum_nu l'_nu(c_i) (q^nu - q^0),
// into q and v (n numbers each).
// Plain loops over contiguous arrays: at small n a matrix-vector product's setup would cost more
// than its arithmetic. For a fixed N the sums run in local accumulators (registers) and are
// stored once: summed in q's and v's memory, each addition waited for the store before it (at
// s = 6 the stores were half of the action's time). Inlined into both callers (a call added 12%
// to the s = 2 Gauss step).
template <int N, int S>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::interpolate(int i, double h, double* __restrict q,
                                                                            double* __restrict v) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const double* __restrict a = basis_.phi.col(i).data();
  const double* __restrict da = basis_.dphi.col(i).data();
  const double* __restrict points = points_.data();
  std::array<double, N == Eigen::Dynamic ? 1 : N> q_sum{}, v_sum{};
  double* qs = N == Eigen::Dynamic ? q : q_sum.data();
  double* vs = N == Eigen::Dynamic ? v : v_sum.data();
  for (int r = 0; r < n; ++r) {
    qs[r] = 0.0;
    vs[r] = 0.0;
  }
  for (int nu = 0; nu <= fixed_or<S>(s_); ++nu)
    for (int r = 0; r < n; ++r) {
      qs[r] += a[nu] * points[nu * n + r];
      vs[r] += da[nu] * points[nu * n + r];
    }
  for (int r = 0; r < n; ++r) {
    q[r] = qs[r] + origin_[r];
    v[r] = vs[r] / h;
  }
}

double GalerkinDiscreteLagrangian::weight(int i, int nu, bool by_v, double h) const {
  return by_v ? basis_.dphi(nu, i) / h : basis_.phi(nu, i);
}

// S = h sum_i b_i L(q_i, v_i), q_i = sum_nu l_nu(c_i) q^nu, v_i = (1/h) sum_nu l'_nu(c_i) q^nu
// (paper, sec. 2), and by the chain rule
//   dS/dq^nu = sum_i b_i (h l_nu L_q + l'_nu L_v),
//   d2S/dq^nu dq^mu = sum_i b_i (h l_nu l_mu L_qq + l_nu l'_mu L_qv + l'_nu l_mu L_vq
//                                + l'_nu l'_mu L_vv / h).
// With the gradient, impulse_ = h sum_i b_i (L_q + f)(c_i) = sum_nu (dS/dq^nu + f_d^nu), since
// sum_nu l_nu = 1 and sum_nu l'_nu = 0: the momentum change of the step (see step()).
template <int N>
double GalerkinDiscreteLagrangian::action_for(double h, Order order, bool forced) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const bool sparse = lagrangian_.sparse();
  double S = 0.0;
  if (order != Order::value) {
    for (int k = 0; k < (s_ + 1) * n; ++k) gradient_[k] = 0.0;
    for (int c = 0; c < n; ++c) impulse_[c] = 0.0;
  }
  if (order == Order::hessian && sparse) sparse_.matrix.coeffs().setZero();
  if (order == Order::hessian && !sparse) hessian_.setZero();
  for (int i = 0, j = 0; i < basis_.phi.cols(); ++i) {
    if (weights_[i] == 0.0) continue;
    interpolate<N>(i, h, q_.data(), v_.data());
    double L = 0.0;
    if (order == Order::hessian && sparse)
      L = lagrangian_.sparse_hessian(q_.data(), v_.data(), grad_.data(), sparse_values_.data());
    else if (order == Order::hessian)
      L = lagrangian_.hessian(q_.data(), v_.data(), grad_.data(), hess_.data());
    else if (order == Order::value_and_gradient)
      L = lagrangian_.value_and_gradient(q_.data(), v_.data(), grad_.data());
    else if (order == Order::gradient)
      lagrangian_.gradient(q_.data(), v_.data(), grad_.data());
    else
      L = lagrangian_.value(q_.data(), v_.data());
    const double b = weights_[i];
    S += h * b * L;
    if (order == Order::value) continue;
    for (int c = 0; c < n; ++c) impulse_[c] += (h * b) * grad_[c];
    if (node_iteration_) inverse_mass_times<Eigen::Dynamic>(grad_.data(), node_accelerations_.data() + j * n);
    ++j;
    if (forced) add_forces(i, h, order);
    if (order == Order::hessian && sparse)
      add_sparse_entries(i, h, 0, sparse_values_.data(), static_cast<int>(sparse_values_.size()), h * b);
    add_gradient<N>(i, h, b, grad_.data(), gradient_.data(), 0, s_ + 1);
    if (order == Order::hessian && !sparse) add_hessian<N>(i, h, b);
  }
  return S;
}

// out ((nu - first) n + r) += b (h l_nu L_q + l'_nu L_v)(r) at node i (see action()), for the
// control points nu in [first, first + count), dL = [L_q; L_v].
template <int N>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::add_gradient(int i, double h, double b, const double* __restrict dL,
                                              double* __restrict out, int first, int count) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const double* __restrict a = basis_.phi.col(i).data() + first;
  const double* __restrict da = basis_.dphi.col(i).data() + first;
  for (int nu = 0; nu < count; ++nu) {
    const double x = b * h * a[nu], y = b * da[nu];
    for (int r = 0; r < n; ++r) out[nu * n + r] += x * dL[r] + y * dL[n + r];
  }
}

// hessian_(nu n + r, mu n + c) += b (l_nu (h l_mu L_qq + l'_mu L_qv) + l'_nu (l_mu L_vq + l'_mu L_vv / h))(r, c)
// at node i: the same sum as above, factored by column so that each entry costs two products
// (this runs (s+1)^2 n^2 times per node and Newton iteration). Column (mu, c) of the update is
// l_nu g_q + l'_nu g_v over (nu, r) for the column's two n-vectors g = column_.
template <int N>
void GalerkinDiscreteLagrangian::add_hessian(int i, double h, double b) {
  const int n = N == Eigen::Dynamic ? n_ : N, k = 2 * n, size = (s_ + 1) * n;
  const double* __restrict H = hess_.data();  // the 2n x 2n Hessian of L in (q, v), column-major
  const double* __restrict a = basis_.phi.col(i).data();
  const double* __restrict da = basis_.dphi.col(i).data();
  double* __restrict column_q = column_.data();
  double* __restrict column_v = column_.data() + n;
  double* __restrict hessian = hessian_.data();
  for (int mu = 0; mu <= s_; ++mu) {
    const double cq = b * h * a[mu], dcq = b * da[mu], cv = b * a[mu], dcv = b * da[mu] / h;
    for (int col = 0; col < n; ++col) {
      const double* by_q = H + col * k;        // d/dq_col of [L_q; L_v]
      const double* by_v = H + (n + col) * k;  // d/dv_col of [L_q; L_v]
      for (int r = 0; r < n; ++r) {
        column_q[r] = cq * by_q[r] + dcq * by_v[r];
        column_v[r] = cv * by_q[n + r] + dcv * by_v[n + r];
      }
      double* target = hessian + (mu * n + col) * size;
      for (int nu = 0; nu <= s_; ++nu)
        for (int r = 0; r < n; ++r) target[nu * n + r] += a[nu] * column_q[r] + da[nu] * column_v[r];
    }
  }
}

// f_d^nu += h b_i l_nu(c_i) f(t + c_i h, q_i, v_i) (Marsden & West 2001, sec. 3.2, through the
// quadrature), and d f_d^nu / dq^mu += h b_i l_nu (l_mu df/dq + l'_mu/h df/dv).
void GalerkinDiscreteLagrangian::add_forces(int i, double h, Order order) {
  const bool jacobian = order == Order::hessian;
  forces_.evaluate(t_ + nodes_[i] * h, q_.data(), v_.data(), f_.data(),
                   jacobian ? force_values_.data() : nullptr);
  const double w = h * weights_[i];
  for (int nu = 0; nu <= s_; ++nu) gradient_.segment(nu * n_, n_) += w * basis_.phi(nu, i) * f_;
  impulse_ += w * f_;
  if (!jacobian) return;
  const int first = static_cast<int>(entries_.size() - force_values_.size());
  if (lagrangian_.sparse())
    return add_sparse_entries(i, h, first, force_values_.data(), static_cast<int>(force_values_.size()), w);
  for (Eigen::Index k = 0; k < force_values_.size(); ++k) {
    const Entry& e = entries_[first + k];
    for (int nu = 0; nu <= s_; ++nu)
      for (int mu = 0; mu <= s_; ++mu)
        hessian_(nu * n_ + e.row, mu * n_ + e.col) +=
            w * force_values_[k] * weight(i, nu, e.row_v, h) * weight(i, mu, e.col_v, h);
  }
}

void GalerkinDiscreteLagrangian::add_sparse_entries(int i, double h, int first_entry,
                                                    const double* values, int count, double w) {
  const int blocks = sparse_.blocks;
  double* coefficients = sparse_.matrix.valuePtr();
  for (int k = 0; k < count; ++k) {
    const Entry& e = entries_[first_entry + k];
    const int* slot = &sparse_.slots[static_cast<std::size_t>(first_entry + k) * blocks * blocks];
    for (int nu = 0; nu < blocks; ++nu) {
      const double row = w * values[k] * weight(i, sparse_.first_equation + nu, e.row_v, h);
      for (int mu = 0; mu < blocks; ++mu)
        coefficients[slot[nu * blocks + mu]] += row * weight(i, sparse_.first_unknown + mu, e.col_v, h);
    }
  }
}

// The structure: every entry in every block (nu, mu) of the equations and unknowns, summed where
// entries coincide; slots_ records where each (entry, nu, mu) landed in the compressed matrix.
void GalerkinDiscreteLagrangian::prepare_sparse(int first_unknown, int first_equation, int blocks) {
  if (sparse_.first_unknown == first_unknown && sparse_.first_equation == first_equation &&
      sparse_.blocks == blocks)
    return;
  sparse_.first_unknown = first_unknown;
  sparse_.first_equation = first_equation;
  sparse_.blocks = blocks;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(entries_.size() * blocks * blocks);
  for (const Entry& e : entries_)
    for (int nu = 0; nu < blocks; ++nu)
      for (int mu = 0; mu < blocks; ++mu) triplets.emplace_back(nu * n_ + e.row, mu * n_ + e.col, 0.0);
  sparse_.matrix.resize(blocks * n_, blocks * n_);
  sparse_.matrix.setFromTriplets(triplets.begin(), triplets.end());
  sparse_.matrix.makeCompressed();
  sparse_.slots.resize(triplets.size());
  const int* outer = sparse_.matrix.outerIndexPtr();
  const int* inner = sparse_.matrix.innerIndexPtr();
  for (std::size_t k = 0; k < triplets.size(); ++k) {
    const int col = triplets[k].col(), row = triplets[k].row();
    sparse_.slots[k] = static_cast<int>(std::lower_bound(inner + outer[col], inner + outer[col + 1], row) - inner);
  }
  sparse_.analyzed = false;
}

GalerkinDiscreteLagrangian::ActionFunction GalerkinDiscreteLagrangian::action_function(int n) {
  return for_dimension(n, [](auto N) -> ActionFunction { return &GalerkinDiscreteLagrangian::action_for<decltype(N)::value>; });
}

}  // namespace varia
