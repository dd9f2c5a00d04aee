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
      y1_(Eigen::VectorXd::Zero(m_ + n_)),
      deviation_w_(n_) {
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

std::string OneStepHamiltonianMap::tangent_map_refusal() const {
  if (tangent_) return "the one-step construction's tangent map is derived on vector spaces only yet";
  if (!lagrangian_.plugin().evaluates_at_jets())
    return "the one-step construction's tangent map steps jets, and this Lagrangian does not evaluate at jets";
  return {};
}

// y = (q, w) with w = M^{-1} p (a constant mass matrix) or p (mechanical_field.hpp): the directions
// in y are (dq, M^{-1} dp) or (dq, dp), and the images' dp1 = M dw1 or dw1.
void OneStepHamiltonianMap::take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                              double* p1, int count, const double* directions, double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  const int size = m_ + n_, capacity = field_->jet_variables();
  jets0_.resize(size);
  jets1_.resize(size);
  Eigen::VectorXd& w = deviation_w_;
  for (int first = 0; first < count; first += capacity) {
    const int k = std::min(capacity, count - first);
    for (int r = 0; r < size; ++r) {
      jets0_[r] = Jet2::variable(y0_[r], k, 0);
      jets0_[r].gradient.setZero();
    }
    for (int j = 0; j < k; ++j) {
      const double* dx = directions + static_cast<std::ptrdiff_t>(first + j) * size;
      if (field_->constant_mass()) field_->inverse_mass(dx + m_, w.data());
      else w = Eigen::Map<const Eigen::VectorXd>(dx + m_, n_);
      for (int r = 0; r < size; ++r) jets0_[r].gradient[j] = r < m_ ? dx[r] : w[r - m_];
    }
    field_->step(method_, h, jets0_.data(), jets1_.data(), tangent_stages_);
    for (int j = 0; j < k; ++j) {
      double* image = images + static_cast<std::ptrdiff_t>(first + j) * size;
      for (int r = 0; r < size; ++r) image[r] = jets1_[r].constant() ? 0.0 : jets1_[r].gradient[j];
      if (!field_->constant_mass()) continue;
      w = Eigen::Map<const Eigen::VectorXd>(image + m_, n_);
      Eigen::Map<Eigen::VectorXd>(image + m_, n_).noalias() = field_->mass() * w;
    }
  }
}

}  // namespace varia
