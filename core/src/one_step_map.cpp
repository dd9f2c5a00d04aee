#include "varia/core/one_step_map.hpp"

#include "varia/core/lie_group_field.hpp"

namespace varia {

namespace {

// The Euler-Lagrange field the method integrates: on a Lie group the Euler-Poincare field in
// (g, xi); on R^n in (q, v) for a constant mass matrix, else Hamilton's equations in (q, p)
// (mechanical_field.hpp), where a symplectic Runge-Kutta method is symplectic.
std::unique_ptr<EulerLagrangeField> field_of(Manifold& manifold, LagrangianEvaluator& lagrangian) {
  if (!manifold.is_vector_space()) return std::make_unique<LieGroupField>(manifold, lagrangian);
  require_vector_space(manifold, lagrangian.plugin(), "the one-step construction");
  return std::make_unique<MechanicalField>(
      lagrangian, declares_constant_mass(lagrangian.plugin()) ? PhaseSpace::tangent : PhaseSpace::cotangent);
}

}  // namespace

OneStepHamiltonianMap::OneStepHamiltonianMap(Manifold& manifold, Lagrangian& lagrangian,
                                             OneStepMethod& method, SolverOptions options)
    : lagrangian_(lagrangian),
      field_(field_of(manifold, lagrangian_)),
      method_(method),
      m_(manifold.point_size()),
      n_(manifold.dim()),
      tangent_(!manifold.is_vector_space()),
      options_(options),
      y0_(Eigen::VectorXd::Zero(m_ + n_)),
      y1_(Eigen::VectorXd::Zero(m_ + n_)) {
  method_.set_solver(options.tolerance, options.max_iterations);
}

void OneStepHamiltonianMap::take_step(const double* q0, const double* p0, double /*t0*/, double h, double* q1,
                                      double* p1) {
  y0_.head(m_) = Eigen::Map<const Eigen::VectorXd>(q0, m_);
  if (field_->constant_mass()) {
    field_->inverse_mass(p0, y0_.data() + m_);
  } else if (tangent_) {  // from the last step's xi, the solution where the steps continue
    y0_.tail(n_) = y1_.tail(n_);
    lagrangian_.inverse_legendre(q0, p0, y0_.data() + m_, options_);
  } else {
    y0_.tail(n_) = Eigen::Map<const Eigen::VectorXd>(p0, n_);
  }
  field_->step(method_, h, y0_.data(), y1_.data(), statistics_);
  Eigen::Map<Eigen::VectorXd>(q1, m_) = y1_.head(m_);
  if (field_->constant_mass()) Eigen::Map<Eigen::VectorXd>(p1, n_).noalias() = field_->mass() * y1_.tail(n_);
  else if (tangent_) lagrangian_.legendre(q1, y1_.data() + m_, p1);
  else Eigen::Map<Eigen::VectorXd>(p1, n_) = y1_.tail(n_);
}

}  // namespace varia
