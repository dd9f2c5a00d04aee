// A particle drawn into a wall at q = 1, beyond which its potential sqrt(1 - q) is not defined:
// L = v^2/2 - sqrt(1 - q), whose dL/dq = 1 / (2 sqrt(1 - q)) is NaN past q = 1 (the explicit
// Stormer-Verlet form's gradient there: a NumericalFailure at that step).
#pragma once

#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::testing {

struct Wall : sdk::AutodiffLagrangian<Wall, 1, 1> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::sqrt;
    return 0.5 * v(0) * v(0) - sqrt(1.0 - q(0));
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    mass[0] = 1.0;
    return true;
  }
};

}  // namespace varia::testing
