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
      update_(n_),
      hessian_(m_ + n_, m_ + n_),
      lu_(n_) {
  pattern_size_ = lagrangian_.hessian_pattern(&pattern_rows_, &pattern_cols_);
  if (pattern_size_ >= 0) sparse_values_.resize(pattern_size_);
}

void LagrangianEvaluator::check_finite(const double* values, int count, const char* what) const {
  for (int i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw NumericalFailure(std::string("the Lagrangian's ") + what + " is not finite",
                             std::nan(""));
}

double LagrangianEvaluator::value(const double* q, const double* v) {
  double L = 0.0;
  check(lagrangian_.evaluate(q, v, &L, nullptr, nullptr), "Lagrangian evaluation");
  ++counters_.lagrangian;
  check_finite(&L, 1, "value");
  return L;
}

double LagrangianEvaluator::gradient(const double* q, const double* v, double* gradient) {
  double L = 0.0;
  check(lagrangian_.evaluate(q, v, &L, gradient, nullptr), "Lagrangian gradient");
  ++counters_.gradient;
  check_finite(gradient, m_ + n_, "gradient");
  return L;
}

double LagrangianEvaluator::hessian(const double* q, const double* v, double* gradient,
                                    double* hessian) {
  double L = 0.0;
  const int k = m_ + n_;
  if (pattern_size_ < 0) {
    check(lagrangian_.evaluate(q, v, &L, gradient, hessian), "Lagrangian Hessian");
  } else {
    check(lagrangian_.evaluate(q, v, &L, gradient, sparse_values_.data()), "Lagrangian Hessian");
    Eigen::Map<Eigen::MatrixXd> H(hessian, k, k);
    H.setZero();
    for (int e = 0; e < pattern_size_; ++e) H(pattern_rows_[e], pattern_cols_[e]) = sparse_values_[e];
  }
  ++counters_.hessian;
  check_finite(gradient, k, "gradient");
  check_finite(hessian, k * k, "Hessian");
  return L;
}

void LagrangianEvaluator::gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) {
  check(lagrangian_.gradient_jet(q, v, value, gradient), "Lagrangian gradient at jets");
  ++counters_.hessian;
  bool finite = value == nullptr || isfinite(*value);
  for (int i = 0; i < m_ + n_; ++i) finite = finite && isfinite(gradient[i]);
  if (!finite) throw NumericalFailure("the Lagrangian's gradient at jets is not finite", std::nan(""));
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
    hessian(q, v, gradient_.data(), hessian_.data());
    residual_ = gradient_.tail(n_) - momentum;
    residual_norm = residual_.lpNorm<Eigen::Infinity>();
    if (residual_norm <= options.tolerance * (1.0 + momentum.lpNorm<Eigen::Infinity>())) return;
    lu_.compute(hessian_.bottomRightCorner(n_, n_));
    update_.noalias() = lu_.solve(residual_);
    velocity -= update_;
    if (update_.lpNorm<Eigen::Infinity>() <=
        options.tolerance * (1.0 + velocity.lpNorm<Eigen::Infinity>()))
      return;
  }
  throw NumericalFailure("the inverse Legendre transform did not converge", residual_norm);
}

double LagrangianEvaluator::energy(const double* q, const double* v) {
  const double L = gradient(q, v, gradient_.data());
  return gradient_.tail(n_).dot(Eigen::Map<const Eigen::VectorXd>(v, n_)) - L;
}

}  // namespace varia
