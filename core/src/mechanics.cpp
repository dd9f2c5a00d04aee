#include "varia/core/mechanics.hpp"

#include <cmath>
#include <string>

namespace varia {

LagrangianEvaluator::LagrangianEvaluator(Lagrangian& lagrangian)
    : lagrangian_(lagrangian),
      m_(lagrangian.position_size()),
      n_(lagrangian.velocity_size()),
      gradient_(m_ + n_),
      residual_(n_),
      update_(n_) {
  pattern_size_ = lagrangian_.hessian_pattern(&pattern_rows_, &pattern_cols_);
  if (pattern_size_ >= 0) {
    sparse_values_.resize(pattern_size_);
    velocity_block_.resize(n_, n_);
  } else {
    hessian_.resize(m_ + n_, m_ + n_);
    lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
  }
}

// Out of line, so that the inline check that runs on every evaluation is a loop of scalar loads
// and well-predicted branches.
void LagrangianEvaluator::not_finite(const char* what) const {
  throw NumericalFailure(std::string("the Lagrangian's ") + what + " is not finite", std::nan(""),
                         lagrangian_.origin());
}

double LagrangianEvaluator::value(const double* q, const double* v) {
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, nullptr, nullptr), "Lagrangian evaluation");
  ++counters_.lagrangian;
  check_finite(&L, 1, "value");
  return L;
}

double LagrangianEvaluator::value_and_gradient(const double* q, const double* v, double* gradient) {
  double L = 0.0;
  evaluate_gradient(q, v, &L, gradient);
  return L;
}

double LagrangianEvaluator::hessian(const double* q, const double* v, double* gradient,
                                    double* hessian) {
  const int k = m_ + n_;
  if (pattern_size_ >= 0) {
    const double L = sparse_hessian(q, v, gradient, sparse_values_.data());
    Eigen::Map<Eigen::MatrixXd> H(hessian, k, k);
    H.setZero();
    for (int e = 0; e < pattern_size_; ++e) H(pattern_rows_[e], pattern_cols_[e]) = sparse_values_[e];
    return L;
  }
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, gradient, hessian), "Lagrangian Hessian");
  ++counters_.hessian;
  check_finite(gradient, k, "gradient");
  check_finite(hessian, k * k, "Hessian");
  return L;
}

double LagrangianEvaluator::sparse_hessian(const double* q, const double* v, double* gradient,
                                           double* values) {
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, gradient, values), "Lagrangian Hessian");
  ++counters_.hessian;
  check_finite(gradient, m_ + n_, "gradient");
  check_finite(values, pattern_size_, "Hessian");
  return L;
}

void LagrangianEvaluator::gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) {
  check(lagrangian_, lagrangian_.gradient_jet(q, v, value, gradient), "Lagrangian gradient at jets");
  ++counters_.hessian;
  bool finite = value == nullptr || isfinite(*value);
  for (int i = 0; i < m_ + n_; ++i) finite = finite && isfinite(gradient[i]);
  if (!finite)
    throw NumericalFailure("the Lagrangian's gradient at jets is not finite", std::nan(""), lagrangian_.origin());
}

void LagrangianEvaluator::legendre(const double* q, const double* v, double* p) {
  gradient(q, v, gradient_.data());
  Eigen::Map<Eigen::VectorXd>(p, n_) = gradient_.tail(n_);
}

// Newton's method on dL/dv (q, v) - p = 0 with the exact Jacobian d2L/dv2; L is assumed
// hyperregular (paper, sec. 3 "Implementation issues": the initial guess for shooting).
void LagrangianEvaluator::inverse_legendre(const double* q, const double* p, double* v,
                                           const SolverOptions& options) {
  Eigen::Map<Eigen::VectorXd> velocity(v, n_);
  const Eigen::Map<const Eigen::VectorXd> momentum(p, n_);
  double residual_norm = 0.0;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    velocity_newton_update(q, v, p);
    residual_norm = residual_.lpNorm<Eigen::Infinity>();
    if (options.converged(residual_norm, momentum.lpNorm<Eigen::Infinity>())) return;
    velocity -= update_;
    if (options.converged(update_.lpNorm<Eigen::Infinity>(), velocity.lpNorm<Eigen::Infinity>())) return;
  }
  throw NumericalFailure("the inverse Legendre transform did not converge", residual_norm);
}

// residual_ = dL/dv (q, v) - p and the Newton update solving d2L/dv2 update = residual_; a sparse
// Lagrangian's velocity block is assembled from its pattern and factorized by sparse LU.
void LagrangianEvaluator::velocity_newton_update(const double* q, const double* v, const double* p) {
  if (pattern_size_ < 0) {
    hessian(q, v, gradient_.data(), hessian_.data());
    lu_.compute(hessian_.bottomRightCorner(n_, n_));
  } else {
    sparse_hessian(q, v, gradient_.data(), sparse_values_.data());
    triplets_.clear();
    for (int e = 0; e < pattern_size_; ++e)
      if (pattern_rows_[e] >= m_ && pattern_cols_[e] >= m_)
        triplets_.emplace_back(pattern_rows_[e] - m_, pattern_cols_[e] - m_, sparse_values_[e]);
    velocity_block_.setFromTriplets(triplets_.begin(), triplets_.end());
    sparse_lu_.compute(velocity_block_);
  }
  residual_ = gradient_.tail(n_) - Eigen::Map<const Eigen::VectorXd>(p, n_);
  if (pattern_size_ < 0)
    update_.noalias() = lu_.solve(residual_);
  else
    update_ = sparse_lu_.solve(residual_);
}

double LagrangianEvaluator::energy(const double* q, const double* v) {
  const double L = value_and_gradient(q, v, gradient_.data());
  return gradient_.tail(n_).dot(Eigen::Map<const Eigen::VectorXd>(v, n_)) - L;
}

}  // namespace varia
