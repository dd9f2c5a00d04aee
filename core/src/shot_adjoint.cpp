#include "varia/core/shot_adjoint.hpp"

namespace varia {

ShotAdjoint::ShotAdjoint(LagrangianEvaluator& lagrangian, const Eigen::MatrixXd& inverse_mass,
                         const RungeKuttaTableau& tableau, const std::vector<double>& nodes,
                         const std::vector<double>& weights, bool cotangent)
    : lagrangian_(lagrangian),
      inverse_mass_(inverse_mass),
      tableau_(tableau),
      nodes_(nodes),
      weights_(weights),
      cotangent_(cotangent),
      n_(static_cast<int>(inverse_mass.rows())),
      stages_(tableau.stages),
      intervals_(static_cast<int>(nodes.size()) - 1) {
  const Eigen::Index N = 2 * n_;
  // intervals_ + 1 blocks of stages: the last holds the final node (its stage 0) only.
  points_.resize((intervals_ + 1) * stages_ * N);
  gradients_.resize((intervals_ + 1) * stages_ * N);
  K_.resize(stages_ * N);
  Kbar_.resize(N);
  Ybar_.resize(stages_ * N);
  for (auto* x : {&y_, &ybar_, &u_, &product_}) x->resize(N);
  for (auto* x : {&eta_bar_, &q_, &v_, &end_offset_, &end_w_}) x->resize(n_);
  u_.setZero();  // (u, 0): its tail stays zero
}

void ShotAdjoint::take_point(const double* y) {
  for (int r = 0; r < n_; ++r) q_[r] = q0_[r] + y[r];
  if (cotangent_) v_.noalias() = inverse_mass_ * Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
  else v_ = Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
}

double ShotAdjoint::evaluate(const double* y, double* gradient) {
  take_point(y);
  return lagrangian_.value_and_gradient(q_.data(), v_.data(), gradient);
}

void ShotAdjoint::field(const double* y, const double* gradient, double* f) const {
  Eigen::Map<Eigen::VectorXd> rate(f, n_), acceleration(f + n_, n_);
  const Eigen::Map<const Eigen::VectorXd> w(y + n_, n_), Lq(gradient, n_);
  if (cotangent_) {
    rate.noalias() = inverse_mass_ * w;
    acceleration = Lq;
  } else {
    rate = w;
    acceleration.noalias() = inverse_mass_ * Lq;
  }
}

// With u = M^{-1} k_v (lagrangian) or k_p (hamiltonian) and (a, b) = L's Hessian times (u, 0),
// i.e. (L_qq u, L_vq u): the field's transposed Jacobian gives (a, k_q + b) or (a, M^{-1} (k_q + b)).
void ShotAdjoint::transposed_jacobian(const double* y, const double* k, double* out) {
  const Eigen::Map<const Eigen::VectorXd> kq(k, n_), kw(k + n_, n_);
  if (cotangent_) u_.head(n_) = kw;
  else u_.head(n_).noalias() = inverse_mass_ * kw;
  take_point(y);
  lagrangian_.hessian_product(q_.data(), v_.data(), u_.data(), product_.data());
  Eigen::Map<Eigen::VectorXd> position(out, n_), rest(out + n_, n_);
  position = product_.head(n_);
  if (cotangent_) rest.noalias() = inverse_mass_ * (kq + product_.tail(n_));
  else rest = kq + product_.tail(n_);
}

void ShotAdjoint::add_node(double weight, const double* gradient, double* ybar) {
  if (weight == 0.0) return;
  const Eigen::Map<const Eigen::VectorXd> Lq(gradient, n_), Lv(gradient + n_, n_);
  Eigen::Map<Eigen::VectorXd> position(ybar, n_), rest(ybar + n_, n_);
  position += weight * Lq;
  eta_bar_ += weight * Lq;
  if (cotangent_) rest.noalias() += weight * (inverse_mass_ * Lv);
  else rest += weight * Lv;
}

// An explicit method's first stage is at the start of its step: the node's evaluation gives L
// there and the first stage's field.
void ShotAdjoint::forward(const double* q0, const double* w0, double h) {
  q0_ = q0;
  h_ = h;
  const int N = 2 * n_;
  y_.head(n_).setZero();
  y_.tail(n_) = Eigen::Map<const Eigen::VectorXd>(w0, n_);
  action_ = 0.0;
  for (int k = 0;; ++k) {
    std::copy_n(y_.data(), N, point(k, 0));
    const bool last = k == intervals_;
    if (last && weights_[k] == 0.0) break;
    const double L = evaluate(y_.data(), gradient(k, 0));
    action_ += h * weights_[k] * L;
    if (last) break;
    const double dt = (nodes_[k + 1] - nodes_[k]) * h;
    field(y_.data(), gradient(k, 0), K_.data());
    for (int i = 1; i < stages_; ++i) {
      double* Y = point(k, i);
      std::copy_n(y_.data(), N, Y);
      for (int j = 0; j < i; ++j)
        if (const double a = tableau_.at(i, j); a != 0.0)
          Eigen::Map<Eigen::VectorXd>(Y, N) += dt * a * K_.segment(j * N, N);
      evaluate(Y, gradient(k, i));
      field(Y, gradient(k, i), K_.data() + i * N);
    }
    for (int i = 0; i < stages_; ++i)
      if (tableau_.b[i] != 0.0) y_ += dt * tableau_.b[i] * K_.segment(i * N, N);
  }
  end_offset_ = y_.head(n_);
  end_w_ = y_.tail(n_);
}

// Backwards through the nodes: the adjoint of a step y' = y + dt sum_i b_i K_i, K_i = f(Y_i),
// Y_i = y + dt sum_{j<i} a_ij K_j, from y'bar: Kbar_i = dt (b_i y'bar + sum_{l>i} a_li Ybar_l),
// Ybar_i = f'(Y_i)^T Kbar_i (i from the last stage down), ybar = y'bar + sum_i Ybar_i.
void ShotAdjoint::reverse(const double* lambda, double* change, double* dw) {
  const int N = 2 * n_;
  ybar_.head(n_) = -Eigen::Map<const Eigen::VectorXd>(lambda, n_);
  ybar_.tail(n_).setZero();
  eta_bar_.setZero();
  for (int k = intervals_;; --k) {
    add_node(h_ * weights_[k], gradient(k, 0), ybar_.data());
    if (k == 0) break;
    const int interval = k - 1;
    const double dt = (nodes_[k] - nodes_[interval]) * h_;
    for (int i = stages_ - 1; i >= 0; --i) {
      Kbar_ = dt * tableau_.b[i] * ybar_;
      for (int l = i + 1; l < stages_; ++l)
        if (const double a = tableau_.at(l, i); a != 0.0) Kbar_ += dt * a * Ybar_.segment(l * N, N);
      transposed_jacobian(point(interval, i), Kbar_.data(), Ybar_.data() + i * N);
      eta_bar_ += Ybar_.segment(i * N, n_);
    }
    for (int i = 0; i < stages_; ++i) ybar_ += Ybar_.segment(i * N, N);
  }
  Eigen::Map<Eigen::VectorXd>(change, n_) = eta_bar_;
  Eigen::Map<Eigen::VectorXd>(dw, n_) = ybar_.tail(n_);
}

}  // namespace varia
