#include "observer.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

namespace varia::host {

Observer::Observer(const Observe& observe, const Manifold& manifold, Lagrangian& lagrangian,
                   const Eigen::VectorXd& v0, const SolverOptions& options)
    : what_(observe), manifold_(manifold), lagrangian_(lagrangian), evaluator_(lagrangian), options_(options), v_(v0) {
  if (what_.momentum) momentum_size_ = lagrangian.momentum_size();
}

std::vector<std::string> Observer::columns() const {
  std::vector<std::string> names;
  if (what_.energy) names.emplace_back("energy");
  for (int i = 0; i < momentum_size_; ++i) names.push_back("momentum" + std::to_string(i));
  if (what_.orthogonality) names.emplace_back("orthogonality");
  return names;
}

void Observer::observe(const double* q, const double* p) {
  values_.clear();
  if (what_.energy || what_.momentum)
    evaluator_.inverse_legendre(q, p, v_.data(), options_);  // warm-started from the last v
  if (what_.energy) values_.push_back(evaluator_.energy(q, v_.data(), p));
  if (what_.momentum) {
    values_.resize(values_.size() + momentum_size_);
    check(lagrangian_, lagrangian_.momentum(q, v_.data(), values_.data() + values_.size() - momentum_size_), "momentum");
  }
  if (what_.orthogonality) values_.push_back(manifold_.constraint_error(q));  // ||I - R^T R||_F on SO3 and SE3
  update_errors();
}

void Observer::update_errors() {
  if (initial_.empty()) initial_ = values_;
  std::size_t i = 0;  // values_ is laid out as columns(): energy, momentum0.., orthogonality
  const auto grow = [&](double& error) {
    error = std::max(error, std::abs(values_[i] - initial_[i]));
    ++i;
  };
  if (what_.energy) grow(energy_error_);
  for (int k = 0; k < momentum_size_; ++k) grow(momentum_error_);
  if (what_.orthogonality) grow(orthogonality_error_);
}

}  // namespace varia::host
