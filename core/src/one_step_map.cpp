#include "varia/core/one_step_map.hpp"

#include "varia/core/lie_group_field.hpp"

namespace varia {

namespace {

// The Euler-Lagrange field the method integrates: on a Lie group the Euler-Poincare field in
// (g, xi); on R^n in (q, v) for a constant mass matrix, else Hamilton's equations in (q, p)
// (mechanical_field.hpp), where a symplectic Runge-Kutta method is symplectic.
std::unique_ptr<EulerLagrangeField> field_of(Manifold& manifold, LagrangianEvaluator& lagrangian,
                                             const OneStepMethod& method, HolonomicConstraints* constraints) {
  if (constraints != nullptr) {
    if (!manifold.is_vector_space())
      throw ConstraintsRefused("with constraints the one-step construction takes vector spaces only");
    require_vector_space(manifold, lagrangian.plugin(), "the one-step construction");
    auto field = std::make_unique<ConstrainedField>(lagrangian, *constraints);
    if (method.explicit_tableau().stages == 0 && !field->has_jacobian())
      throw ConstraintsRefused(
          "with constraints that do not give the derivative of v^T H_i(q) v in q (Constraint::curvature_derivative) "
          "the one-step construction takes explicit Runge-Kutta methods only (an implicit method's stages need the "
          "constrained field's Jacobian, whose multiplier's derivatives need those third derivatives of g)");
    return field;
  }
  if (!manifold.is_vector_space()) return std::make_unique<LieGroupField>(manifold, lagrangian);
  require_vector_space(manifold, lagrangian.plugin(), "the one-step construction");
  return std::make_unique<MechanicalField>(
      lagrangian, declares_constant_mass(lagrangian.plugin()) ? PhaseSpace::tangent : PhaseSpace::cotangent);
}

}  // namespace

OneStepHamiltonianMap::OneStepHamiltonianMap(Manifold& manifold, Lagrangian& lagrangian,
                                             OneStepMethod& method, SolverOptions options,
                                             HolonomicConstraints* constraints)
    : manifold_(manifold),
      lagrangian_(lagrangian),
      field_(field_of(manifold, lagrangian_, method, constraints)),
      constrained_(constraints != nullptr ? static_cast<ConstrainedField*>(field_.get()) : nullptr),
      method_(method),
      m_(manifold.point_size()),
      n_(manifold.dim()),
      tangent_(!manifold.is_vector_space()),
      options_(options),
      y0_(Eigen::VectorXd::Zero(m_ + n_)),
      y1_(Eigen::VectorXd::Zero(m_ + n_)),
      column_(m_ + n_) {
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
  if (constrained_ != nullptr) constrained_->project(y1_.data(), y1_.data() + m_, options_);
  Eigen::Map<Eigen::VectorXd>(q1, m_) = y1_.head(m_);
  if (field_->constant_mass()) Eigen::Map<Eigen::VectorXd>(p1, n_).noalias() = field_->mass() * y1_.tail(n_);
  else if (tangent_) lagrangian_.legendre(q1, y1_.data() + m_, p1);
  else Eigen::Map<Eigen::VectorXd>(p1, n_) = y1_.tail(n_);
}

std::string OneStepHamiltonianMap::tangent_map_refusal() const {
  if (constrained_ != nullptr && !constrained_->evaluates_at_jets())
    return "the one-step construction's tangent map steps jets through the index-1 field and the projection onto "
           "the constraints, which take quadratic constraints only (Constraint::quadratic)";
  if (!lagrangian_.plugin().evaluates_at_jets())
    return "the one-step construction's tangent map steps jets, and this Lagrangian does not evaluate at jets";
  return {};
}

// On a Lie group: the generators D(g0) (m x n), the chart's inverse at g1, C1 = d local(g1, g)/dg at
// g = g1 (n x m), and for a point-dependent inertia L's Hessian at (g0, xi0) with L_xixi's LU, and
// at (g1, xi1).
void OneStepHamiltonianMap::prepare_group_tangent() {
  const int size = m_ + n_;
  point_jets_.resize(m_);
  generator_jets_.resize(m_ * n_);
  for (int k = 0; k < m_; ++k) point_jets_[k] = Jet2(y0_[k]);
  check(manifold_, manifold_.generators(point_jets_.data(), generator_jets_.data()), "manifold generators");
  generators_.resize(m_, n_);
  for (int k = 0; k < m_; ++k)
    for (int a = 0; a < n_; ++a) generators_(k, a) = generator_jets_[k * n_ + a].value;
  local_value_.resize(n_);
  chart_inverse_.resize(m_, n_);  // column r holds dlocal_r/dg (the plugin's n x m, row-major)
  local_hessian_.resize(static_cast<std::size_t>(n_) * m_ * m_);
  check(manifold_, manifold_.local_derivatives(y1_.data(), y1_.data(),
                                               {local_value_.data(), chart_inverse_.data(), local_hessian_.data()}),
        "manifold local_derivatives");
  if (field_->constant_mass()) return;
  gradient_.resize(size);
  for (Eigen::MatrixXd* H : {&hessian0_, &hessian1_}) H->resize(size, size);
  lagrangian_.hessian(y0_.data(), y0_.data() + m_, gradient_.data(), hessian0_.data());
  lagrangian_.hessian(y1_.data(), y1_.data() + m_, gradient_.data(), hessian1_.data());
  inertia_lu_.compute(hessian0_.bottomRightCorner(n_, n_));
}

// A direction dx = (dq; dp) as the state's derivative (into column_). On R^n y = (q, w), w = M^{-1} p
// (a constant mass matrix) or p. On a Lie group y = (g, xi) in the embedding and dq is in the natural
// chart at g0, the curve g0 exp(e dq): dg0 = D(g0) dq, and xi0 = (dL/dxi)^{-1}(g0, p0) moves by
// L_xixi^{-1} (dp - L_xig dg0) (J^{-1} dp for a constant inertia).
void OneStepHamiltonianMap::seed(const double* dx) {
  Eigen::Map<const Eigen::VectorXd> dq(dx, n_), dp(dx + n_, n_);
  auto dy = column_.head(m_);
  auto dw = column_.tail(n_);
  if (tangent_) dy.noalias() = generators_ * dq;
  else dy = dq;
  if (field_->constant_mass()) field_->inverse_mass(dx + n_, dw.data());
  else if (!tangent_) dw = dp;
  else dw = inertia_lu_.solve(dp - hessian0_.bottomLeftCorner(n_, m_) * dy);
}

// The state's derivative (column_) as an image (dq1; dp1) in the directions' coordinates: on a Lie
// group dq1 = C1 dg1 and dp1 = L_xig dg1 + L_xixi dxi1 (the Legendre transform's derivative at
// (g1, xi1); J dxi1 for a constant inertia); on R^n dp1 = M dw1 or dw1.
void OneStepHamiltonianMap::image(double* out) const {
  Eigen::Map<Eigen::VectorXd> dq(out, n_), dp(out + n_, n_);
  const auto dy = column_.head(m_);
  const auto dw = column_.tail(n_);
  if (tangent_) dq.noalias() = chart_inverse_.transpose() * dy;
  else dq = dy;
  if (field_->constant_mass()) dp.noalias() = field_->mass() * dw;
  else if (!tangent_) dp = dw;
  else dp.noalias() = hessian1_.bottomLeftCorner(n_, m_) * dy + hessian1_.bottomRightCorner(n_, n_) * dw;
}

void OneStepHamiltonianMap::take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                              double* p1, int count, const double* directions, double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  if (tangent_) prepare_group_tangent();
  const int size = m_ + n_, capacity = field_->jet_variables();
  jets0_.resize(size);
  jets1_.resize(size);
  for (int first = 0; first < count; first += capacity) {
    const int k = std::min(capacity, count - first);
    for (int r = 0; r < size; ++r) {
      jets0_[r] = Jet2::variable(y0_[r], k, 0);
      jets0_[r].gradient.setZero();
    }
    for (int j = 0; j < k; ++j) {
      seed(directions + static_cast<std::ptrdiff_t>(first + j) * 2 * n_);
      for (int r = 0; r < size; ++r) jets0_[r].gradient[j] = column_[r];
    }
    field_->step(method_, h, jets0_.data(), jets1_.data(), tangent_stages_);
    if (constrained_ != nullptr) constrained_->project(jets1_.data(), jets1_.data() + m_, options_);
    for (int j = 0; j < k; ++j) {
      for (int r = 0; r < size; ++r) column_[r] = jets1_[r].constant() ? 0.0 : jets1_[r].gradient[j];
      image(images + static_cast<std::ptrdiff_t>(first + j) * 2 * n_);
    }
  }
}

}  // namespace varia
