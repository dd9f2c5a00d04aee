#include "varia/core/one_step_map.hpp"

#include <stdexcept>

namespace varia {

OneStepHamiltonianMap::OneStepHamiltonianMap(Manifold& manifold, Lagrangian& lagrangian,
                                             OneStepMethod& method, SolverOptions options)
    : lagrangian_((require_vector_space(manifold, lagrangian, "the one-step construction"), lagrangian)),
      field_(lagrangian_, PhaseSpace::tangent),
      method_(method),
      n_(manifold.dim()),
      y0_(2 * n_),
      y1_(2 * n_) {
  method_.set_solver(options.tolerance, options.max_iterations);
}

void OneStepHamiltonianMap::step(const double* q0, const double* p0, double h, double* q1,
                                 double* p1) {
  y0_.head(n_) = Eigen::Map<const Eigen::VectorXd>(q0, n_);
  field_.inverse_mass(p0, y0_.data() + n_);
  field_.step(method_, h, y0_.data(), y1_.data(), statistics_);
  Eigen::Map<Eigen::VectorXd>(q1, n_) = y1_.head(n_);
  Eigen::Map<Eigen::VectorXd>(p1, n_).noalias() = field_.mass() * y1_.tail(n_);
}

}  // namespace varia
