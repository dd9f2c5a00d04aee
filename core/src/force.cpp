#include "varia/abi/force.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "varia/core/discrete_hamiltonian_map.hpp"

namespace varia {

Forces::Forces(std::vector<Force*> forces, int position_size, int velocity_size)
    : forces_(std::move(forces)), one_(velocity_size) {
  for (std::size_t k = 0; k < forces_.size(); ++k) {
    Force& force = *forces_[k];
    if (force.position_size() != position_size || force.velocity_size() != velocity_size)
      throw std::invalid_argument("force " + std::to_string(k) + " does not fit the system's sizes");
    const int *rows = nullptr, *cols = nullptr;
    const int entries = force.jacobian_pattern(&rows, &cols);
    offsets_.push_back(static_cast<int>(rows_.size()));
    rows_.insert(rows_.end(), rows, rows + entries);
    cols_.insert(cols_.end(), cols, cols + entries);
  }
}

void Forces::evaluate(double t, const double* q, const double* v, double* force, double* jacobian) {
  const int n = static_cast<int>(one_.size());
  std::fill(force, force + n, 0.0);
  for (std::size_t k = 0; k < forces_.size(); ++k) {
    check(*forces_[k], forces_[k]->evaluate(t, q, v, one_.data(), jacobian ? jacobian + offsets_[k] : nullptr),
          "force evaluation");
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(one_[i])) throw NumericalFailure("a force is not finite", std::nan(""), forces_[k]->origin());
    for (int i = 0; i < n; ++i) force[i] += one_[i];
  }
  ++evaluations_;
}

}  // namespace varia
