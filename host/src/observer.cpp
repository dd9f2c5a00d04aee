#include "observer.hpp"

#include <Eigen/Core>
#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <string>

namespace varia::host {

Observer::Observer(const Observe& observe, const Manifold& manifold, Lagrangian& lagrangian,
                   const Eigen::VectorXd& v0, const SolverOptions& options, HolonomicConstraints* constraints,
                   const ChaosIndicators* chaos)
    : what_(observe), manifold_(manifold), lagrangian_(lagrangian), evaluator_(lagrangian), options_(options),
      v_(v0.size() == lagrangian.velocity_size() ? v0 : Eigen::VectorXd::Zero(lagrangian.velocity_size())),
      constraints_(constraints),
      chaos_(chaos) {
  if (what_.momentum) momentum_size_ = lagrangian.momentum_size();
}

std::vector<std::string> Observer::columns() const {
  std::vector<std::string> names;
  if (what_.energy) names.emplace_back("energy");
  for (int i = 0; i < momentum_size_; ++i) names.push_back("momentum" + std::to_string(i));
  if (what_.orthogonality) names.emplace_back("orthogonality");
  if (what_.constraint) names.emplace_back("constraint");
  if (what_.constraint_velocity) names.emplace_back("constraint_velocity");
  if (what_.megno) names.emplace_back("megno");
  if (what_.lyapunov) names.emplace_back("lyapunov");
  return names;
}

double Observer::energy(const double* q, const double* p) {
  evaluator_.inverse_legendre(q, p, v_.data(), options_);  // warm-started from the last v
  return evaluator_.energy(q, v_.data(), p);
}

void Observer::observe(const double* q, const double* p) {
  values_.clear();
  if (what_.energy) values_.push_back(energy(q, p));
  else if (what_.momentum || what_.constraint_velocity) evaluator_.inverse_legendre(q, p, v_.data(), options_);
  if (what_.momentum) {
    values_.resize(values_.size() + momentum_size_);
    check(lagrangian_, lagrangian_.momentum(q, v_.data(), values_.data() + values_.size() - momentum_size_), "momentum");
  }
  if (what_.orthogonality) values_.push_back(manifold_.constraint_error(q));  // ||I - R^T R||_F on SO3 and SE3
  if (what_.constraint) values_.push_back(constraints_->residual(q));
  if (what_.constraint_velocity) values_.push_back(constraints_->velocity_residual(q, v_.data()));
  if (what_.megno) values_.push_back(chaos_->megno());
  if (what_.lyapunov) values_.push_back(chaos_->lyapunov());
  if (initial_.empty()) set_scales(q, p);
  update_errors();
}

void Observer::check_energy_range(const double* q, const double* p) {
  const double E = what_.energy ? values_.front() : energy(q, p);
  const int n = static_cast<int>(v_.size());
  if (range_scale_ < 0.0) {
    range_energy_ = E;
    range_scale_ = std::abs(Eigen::Map<const Eigen::VectorXd>(p, n).dot(v_)) + std::abs(evaluator_.value(q, v_.data()));
  }
  if (const double error = std::abs(E - range_energy_); range_scale_ > 0.0 && !(error <= range_scale_))
    throw NumericalFailure(
        fmt::format("the energy error |E - E0| = {:.3g} exceeds the energy's scale |<p0, v0>| + |L(q0, v0)| = {:.3g}: "
                    "the run left every sane range (a step too large for the method, or step equations whose roots "
                    "are not continuous in h); take a smaller step",
                    error, range_scale_),
        error);
}

void Observer::set_scales(const double* q, const double* p) {
  double L = 0.0;  // unchecked, as the energy: an overflow there is the energy's to report
  if (what_.energy && lagrangian_.evaluate(q, v_.data(), &L, nullptr, nullptr) == nullptr)
    energy_scale_ = std::abs(Eigen::Map<const Eigen::VectorXd>(p, v_.size()).dot(v_)) + std::abs(L);
  for (int k = 0; k < momentum_size_; ++k)
    momentum_scale_ = std::max(momentum_scale_, std::abs(values_[(what_.energy ? 1 : 0) + k]));
}

void Observer::update_errors() {
  if (initial_.empty()) initial_ = values_;
  std::size_t i = 0;  // values_ is laid out as columns()
  const auto grow = [&](double& error) {
    error = std::max(error, std::abs(values_[i] - initial_[i]));
    ++i;
  };
  if (what_.energy) grow(energy_error_);
  for (int k = 0; k < momentum_size_; ++k) grow(momentum_error_);
  if (what_.orthogonality) grow(orthogonality_error_);
  if (what_.constraint) constraint_error_ = std::max(constraint_error_, values_[i++]);
  if (what_.constraint_velocity) constraint_velocity_error_ = std::max(constraint_velocity_error_, values_[i++]);
}

}  // namespace varia::host
