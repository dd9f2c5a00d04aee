#include "varia/core/constrained_field.hpp"

#include <cmath>
#include <stdexcept>

namespace varia {

ConstrainedField::ConstrainedField(LagrangianEvaluator& lagrangian, HolonomicConstraints& constraints)
    : EulerLagrangeField(lagrangian),
      constraints_(constraints),
      m_(constraints.size()),
      W_(n_, m_),
      S_(m_, m_),
      S_factor_(m_),
      gradient_(2 * n_),
      lambda_(m_),
      rhs_(m_),
      unit_(Eigen::VectorXd::Zero(m_)),
      g_(m_),
      curvature_(n_) {
  if (!constant_mass_)
    throw std::invalid_argument("constraints need a Lagrangian with a constant mass matrix");
}

void ConstrainedField::factor(const double* q) {
  constraints_.evaluate_jacobian(q, g_.data());
  W_.noalias() = inverse_mass_ * constraints_.jacobian().transpose();
  S_.noalias() = constraints_.jacobian() * W_;
  S_factor_.compute(S_);
  if (S_factor_.info() != Eigen::Success)
    throw NumericalFailure("G M^-1 G^T is singular: the constraints' Jacobian has lost its rank", std::nan(""));
}

// f = (v, a), a = M^-1 L_q - W lambda with S lambda = G M^-1 L_q + c.
Status ConstrainedField::eval(const double* y, double* f) noexcept {
  return guard([&] {
    const Eigen::Map<const Eigen::VectorXd> v(y + n_, n_);
    Eigen::Map<Eigen::VectorXd>(f, n_) = v;
    Eigen::Map<Eigen::VectorXd> a(f + n_, n_);
    lagrangian_.gradient(y, y + n_, gradient_.data());
    a.noalias() = inverse_mass_ * gradient_.head(n_);
    factor(y);
    rhs_.noalias() = constraints_.jacobian() * a;
    for (int i = 0; i < m_; ++i) {
      unit_[i] = 1.0;
      constraints_.evaluate_hessian(y, unit_.data());
      curvature_.noalias() = constraints_.hessian() * v;
      rhs_[i] += v.dot(curvature_);
      unit_[i] = 0.0;
    }
    lambda_ = S_factor_.solve(rhs_);
    a.noalias() -= W_ * lambda_;
  });
}

void ConstrainedField::project(double* q, double* v, const SolverOptions& options) {
  Eigen::Map<Eigen::VectorXd> position(q, n_), velocity(v, n_);
  double residual = INFINITY;
  for (int k = 0; k <= options.max_iterations; ++k) {
    factor(q);
    residual = g_.lpNorm<Eigen::Infinity>();
    if (residual <= options.tolerance) break;
    if (k == options.max_iterations)
      throw NumericalFailure("the projection onto the constraint did not converge", residual);
    lambda_ = S_factor_.solve(g_);
    position.noalias() -= W_ * lambda_;
  }
  rhs_.noalias() = constraints_.jacobian() * velocity;
  lambda_ = S_factor_.solve(rhs_);
  velocity.noalias() -= W_ * lambda_;
}

}  // namespace varia
