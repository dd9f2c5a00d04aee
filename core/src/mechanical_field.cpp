#include "varia/core/mechanical_field.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace varia {

void require_vector_space(const Manifold& manifold, const Lagrangian& lagrangian,
                          const char* construction) {
  if (!manifold.is_vector_space())
    throw std::invalid_argument(std::string(construction) + " needs a vector-space manifold (Rn)");
  const int n = manifold.dim();
  if (lagrangian.position_size() != n || lagrangian.velocity_size() != n)
    throw std::invalid_argument("the Lagrangian's sizes do not match the manifold's dimension");
}

EulerLagrangeField::EulerLagrangeField(LagrangianEvaluator& lagrangian)
    : lagrangian_(lagrangian), n_(lagrangian.velocity_size()), mass_(n_, n_) {
  constant_mass_ = lagrangian.plugin().constant_mass_matrix(mass_.data());
  if (constant_mass_) inverse_mass_ = mass_.inverse();
}

bool declares_constant_mass(const Lagrangian& lagrangian) {
  Eigen::MatrixXd mass(lagrangian.velocity_size(), lagrangian.velocity_size());
  return lagrangian.constant_mass_matrix(mass.data());
}

MechanicalField::MechanicalField(LagrangianEvaluator& lagrangian, PhaseSpace space, Forces* forces)
    : EulerLagrangeField(lagrangian),
      space_(space),
      forces_(forces != nullptr && !forces->empty() ? forces : nullptr),
      force_(n_),
      force_jacobian_(forces_ ? static_cast<Eigen::Index>(forces_->rows().size()) : 0),
      position_(n_),
      absolute_(n_),
      absolute_jet_(n_),
      force_jet_(n_),
      v_(Eigen::VectorXd::Zero(n_)),  // the inverse Legendre transform's first start
      gradient_(2 * n_),
      hessian_(2 * n_, 2 * n_),
      velocity_q_(n_, n_),
      identity_(Eigen::MatrixXd::Identity(n_, n_)),
      rhs_(n_),
      mass_lu_(n_),
      v_jet_(n_),
      gradient_jet_(2 * n_),
      legendre_residual_(2 * n_),
      velocity_hessian_jet_(general_tangent() ? n_ : 0, general_tangent() ? n_ : 0),  // the general tangent form's
      seed_(2 * n_),
      acceleration_jet_(n_),
      correction_jet_(n_),
      acceleration_solve_(general_tangent() ? n_ : 0),
      hessian_jet_variables_(lagrangian.plugin().hessian_jet_variables()) {
  if (general_tangent() && hessian_jet_variables_ < 2)
    throw std::invalid_argument(
        "the tangent form (q, v) of the Euler-Lagrange field with a configuration-dependent mass matrix needs "
        "the Lagrangian's Hessian at jets of at least 2 variables (Lagrangian::hessian_jet: the acceleration "
        "M^{-1} (L_q - L_vq v) and its second-order jets need L's derivatives to fourth order); this one has "
        "no constant mass matrix and gives no Hessian at jets (models derived from sdk::AutodiffLagrangian give "
        "it at every size; sdk::TermwiseLagrangian and hand-written ones may not, docs/shooting.md). "
        "Integrate in (q, p): the shooting construction's \"form\": \"hamiltonian\"");
  v_.setZero();
}

VelocityHessianJet::VelocityHessianJet(int m, int n)
    : m_(m),
      n_(n),
      directions_(static_cast<std::size_t>(n + 1) * (m + n), Jet2(0.0)),
      out_(static_cast<std::size_t>(n) * (n + 1)) {
  for (int j = 0; j < n; ++j) directions_[static_cast<std::size_t>(j) * (m + n) + m + j] = Jet2(1.0);
}

void VelocityHessianJet::evaluate(LagrangianEvaluator& lagrangian, const Jet2* q, const Jet2* v, const Jet2* u) {
  std::copy(u, u + m_, directions_.begin() + static_cast<std::ptrdiff_t>(n_) * (m_ + n_));
  lagrangian.hessian_jet(q, v, m_, n_, n_ + 1, directions_.data(), out_.data());
}

int MechanicalField::jet_variables() const {
  return general_tangent() ? std::min(kMaxJetVariables, hessian_jet_variables_) : kMaxJetVariables;
}

void EulerLagrangeField::inverse_mass(const double* w, double* x) const {
  Eigen::Map<Eigen::VectorXd>(x, n_).noalias() =
      inverse_mass_ * Eigen::Map<const Eigen::VectorXd>(w, n_);
}

namespace {

// y = A x, A of doubles, x and y (distinct) of jets; A's zero entries are skipped.
void multiply(const Eigen::MatrixXd& A, const Jet2* x, Jet2* y) {
  for (Eigen::Index r = 0; r < A.rows(); ++r) {
    y[r] = Jet2(0.0);
    for (Eigen::Index c = 0; c < A.cols(); ++c)
      if (A(r, c) != 0.0) add_scaled(y[r], A(r, c), x[c]);
  }
}

}  // namespace

JetLinearSolve::JetLinearSolve(int n)
    : n_(n), inverse_(n, n), identity_(Eigen::MatrixXd::Identity(n, n)), lu_(n), residual_(n), correction_(n) {}

void JetLinearSolve::solve(const Jet2* M, int stride, const Jet2* b, Jet2* x) {
  for (int r = 0; r < n_; ++r)
    for (int c = 0; c < n_; ++c) inverse_(r, c) = M[c * stride + r].value;
  lu_.compute(inverse_);
  inverse_.noalias() = lu_.solve(identity_);  // inverse() would allocate
  multiply(inverse_, b, x);
  for (int iteration = 0; iteration < 2; ++iteration) {
    for (int r = 0; r < n_; ++r) {
      Jet2& residual = residual_[r] = b[r];
      for (int c = 0; c < n_; ++c) residual -= M[c * stride + r] * x[c];
    }
    multiply(inverse_, residual_.data(), correction_.data());
    for (int r = 0; r < n_; ++r) x[r] += correction_[r];
  }
}

void EulerLagrangeField::inverse_mass(const Jet2* w, Jet2* x) const { multiply(inverse_mass_, w, x); }

// v(q, p) at jets. With a constant mass matrix M^{-1} p; otherwise Newton's method at jets on
// dL/dv (q, v) = p from the value v(q.value, p.value), with the constant matrix L_vv there: the
// iteration's error has no value part, and each iteration multiplies it by I - L_vv^{-1} L_vv(q,v),
// whose value part is zero, so two iterations make the first and second derivatives exact.
const Jet2* MechanicalField::velocity(const Jet2* y) {
  const Jet2* w = y + n_;
  if (space_ == PhaseSpace::tangent) return w;
  Jet2* v = v_jet_.data();
  if (constant_mass_) {
    inverse_mass(w, v);
    return v;
  }
  const Jet2* q = point(y);
  for (int r = 0; r < n_; ++r) {
    position_[r] = q[r].value;
    force_[r] = w[r].value;  // p's values (force_ as workspace)
  }
  velocity_of_momentum(position_.data(), force_.data());
  lagrangian_.hessian(position_.data(), v_.data(), gradient_.data(), hessian_.data());
  mass_lu_.compute(hessian_.bottomRightCorner(n_, n_));
  velocity_q_.noalias() = mass_lu_.solve(identity_);  // M^{-1} at the values (inverse() would allocate)
  for (int r = 0; r < n_; ++r) v[r] = Jet2(v_[r]);
  for (int iteration = 0; iteration < 2; ++iteration) {
    lagrangian_.gradient_jet(q, v, nullptr, legendre_residual_.data());
    for (int r = 0; r < n_; ++r) legendre_residual_[n_ + r] -= w[r];
    multiply(velocity_q_, legendre_residual_.data() + n_, correction_jet_.data());
    for (int r = 0; r < n_; ++r) v[r] -= correction_jet_[r];
  }
  return v;
}

void MechanicalField::momentum(const double* q, const double* v, double* p) {
  if (constant_mass_) {
    Eigen::Map<Eigen::VectorXd>(p, n_).noalias() = mass_ * Eigen::Map<const Eigen::VectorXd>(v, n_);
    return;
  }
  lagrangian_.legendre(q, v, p);
}

void MechanicalField::velocity_of_momentum(const double* q, const double* p) {
  if (constant_mass_) return inverse_mass(p, v_.data());
  lagrangian_.inverse_legendre(q, p, v_.data(), legendre_options_);
}

const double* MechanicalField::point(const double* y) {
  if (origin_ == nullptr) return y;
  for (int r = 0; r < n_; ++r) absolute_[r] = origin_[r].value + y[r];
  return absolute_.data();
}

const Jet2* MechanicalField::point(const Jet2* y) {
  if (origin_ == nullptr) return y;
  for (int r = 0; r < n_; ++r) add_scaled(absolute_jet_[r] = origin_[r], 1.0, y[r]);
  return absolute_jet_.data();
}

void MechanicalField::add_forces(const double* y, const double* q, bool jacobian) {
  forces_->evaluate(y[2 * n_], q, v_.data(), force_.data(), jacobian ? force_jacobian_.data() : nullptr);
  gradient_.head(n_) += force_;
  if (!jacobian) return;
  for (std::size_t e = 0; e < forces_->rows().size(); ++e)
    hessian_(forces_->rows()[e], forces_->cols()[e]) += force_jacobian_[static_cast<Eigen::Index>(e)];
}

void MechanicalField::force(const Jet2* state, const Jet2* v, Jet2* f) {
  force_at(point(state), v, state[2 * n_].value, f);
}

void MechanicalField::force_at(const Jet2* y, const Jet2* v, double t, Jet2* f) {
  for (int r = 0; r < n_; ++r) {
    position_[r] = y[r].value;
    v_[r] = v[r].value;
  }
  forces_->evaluate(t, position_.data(), v_.data(), force_.data(), force_jacobian_.data());
  for (int r = 0; r < n_; ++r) f[r] = Jet2(force_[r]);
  for (std::size_t e = 0; e < forces_->rows().size(); ++e) {
    const int col = forces_->cols()[e];
    const Jet2& x = col < n_ ? y[col] : v[col - n_];
    if (!x.constant()) f[forces_->rows()[e]] += force_jacobian_[static_cast<Eigen::Index>(e)] * (x - x.value);
  }
}

Status MechanicalField::eval(const double* y, double* f) noexcept {
  return guard([&] {
    const double* q = point(y);
    if (space_ == PhaseSpace::cotangent) velocity_of_momentum(q, y + n_);
    else v_ = Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
    if (general_tangent()) lagrangian_.hessian(q, v_.data(), gradient_.data(), hessian_.data());
    else lagrangian_.gradient(q, v_.data(), gradient_.data());
    if (forced_) add_forces(y, q, false);
    Eigen::Map<Eigen::VectorXd>(f, n_) = v_;
    if (space_ == PhaseSpace::cotangent) Eigen::Map<Eigen::VectorXd>(f + n_, n_) = gradient_.head(n_);
    else if (constant_mass_) inverse_mass(gradient_.data(), f + n_);
    else acceleration(f + n_);
    if (clock()) f[2 * n_] = 1.0;
  });
}

Status MechanicalField::eval(const Jet2* y, Jet2* f) noexcept {
  return guard([&] {
    const Jet2* v = velocity(y);
    lagrangian_.gradient_jet(point(y), v, nullptr, gradient_jet_.data());
    if (forced_) {
      force(y, v, force_jet_.data());
      for (int r = 0; r < n_; ++r) gradient_jet_[r] += force_jet_[r];
    }
    std::copy_n(v, n_, f);
    if (space_ == PhaseSpace::cotangent) std::copy_n(gradient_jet_.begin(), n_, f + n_);
    else if (constant_mass_) inverse_mass(gradient_jet_.data(), f + n_);
    else acceleration(point(y), v, f + n_);
    if (clock()) f[2 * n_] = Jet2(1.0);
  });
}

// Tangent:   df = [0, I; M^{-1} L_qq, M^{-1} L_qv]; with a configuration-dependent mass matrix
//            general_tangent_jacobian().
// Cotangent: df = [0, M^{-1}; L_qq, L_qv M^{-1}]  (v = M^{-1} p); with a configuration-dependent
// mass matrix M = L_vv (q, v), cotangent_jacobian().
// With forces, L_q + f in place of L_q, and the time's row and column zero: t' = 1 is constant,
// and df/dt (which the Force interface does not give) multiplies only the time's Newton update,
// which is zero once the stages' times are right (after the first update of an implicit stage
// solve; the values at convergence and the jets are exact).
Status MechanicalField::jacobian(const double* y, double* f, double* df) noexcept {
  return guard([&] {
    if (general_tangent()) return general_tangent_jacobian(y, f, df);
    const double* q = point(y);
    if (space_ == PhaseSpace::cotangent) velocity_of_momentum(q, y + n_);
    else v_ = Eigen::Map<const Eigen::VectorXd>(y + n_, n_);
    lagrangian_.hessian(q, v_.data(), gradient_.data(), hessian_.data());
    if (forced_) add_forces(y, q, true);
    const int N = size();
    Eigen::Map<Eigen::VectorXd> rate(f, N);
    Eigen::Map<Eigen::MatrixXd> J(df, N, N);
    J.setZero();
    rate.head(n_) = v_;
    if (space_ == PhaseSpace::cotangent && !constant_mass_) {
      rate.segment(n_, n_) = gradient_.head(n_);
      cotangent_jacobian(J.topLeftCorner(2 * n_, 2 * n_));
    } else if (space_ == PhaseSpace::cotangent) {
      rate.segment(n_, n_) = gradient_.head(n_);
      J.block(0, n_, n_, n_) = inverse_mass_;
      J.block(n_, 0, n_, n_) = hessian_.topLeftCorner(n_, n_);
      J.block(n_, n_, n_, n_).noalias() = hessian_.topRightCorner(n_, n_) * inverse_mass_;
    } else {
      rate.segment(n_, n_).noalias() = inverse_mass_ * gradient_.head(n_);
      J.block(0, n_, n_, n_).setIdentity();
      J.block(n_, 0, n_, n_).noalias() = inverse_mass_ * hessian_.topLeftCorner(n_, n_);
      J.block(n_, n_, n_, n_).noalias() = inverse_mass_ * hessian_.topRightCorner(n_, n_);
    }
    if (clock()) rate[2 * n_] = 1.0;
  });
}

// v = v(q, p) solves L_v(q, v) = p: v_p = M^{-1}, v_q = -M^{-1} L_vq (M = L_vv); the momentum's
// rate g = L_q + f (hessian_'s first n rows hold its derivatives in (q, v)) has
// g_q + g_v v_q and g_v v_p.
void MechanicalField::cotangent_jacobian(Eigen::Ref<Eigen::MatrixXd> J) {
  mass_lu_.compute(hessian_.bottomRightCorner(n_, n_));
  J.block(0, n_, n_, n_).noalias() = mass_lu_.solve(identity_);
  velocity_q_.noalias() = -J.block(0, n_, n_, n_) * hessian_.bottomLeftCorner(n_, n_);
  J.block(0, 0, n_, n_) = velocity_q_;
  J.block(n_, 0, n_, n_) = hessian_.topLeftCorner(n_, n_);
  J.block(n_, 0, n_, n_).noalias() += hessian_.topRightCorner(n_, n_) * velocity_q_;
  J.block(n_, n_, n_, n_).noalias() = hessian_.topRightCorner(n_, n_) * J.block(0, n_, n_, n_);
}

// a = M^{-1} (L_q + f - L_vq v) at doubles, M = L_vv, from gradient_ (with the forces) and hessian_.
void MechanicalField::acceleration(double* a) {
  rhs_ = gradient_.head(n_);
  rhs_.noalias() -= hessian_.bottomLeftCorner(n_, n_) * v_;
  mass_lu_.compute(hessian_.bottomRightCorner(n_, n_));
  Eigen::Map<Eigen::VectorXd>(a, n_) = mass_lu_.solve(rhs_);
}

// a = M^{-1} (L_q + f - L_vq v) at jets (L_q + f in gradient_jet_), M = L_vv: the velocity rows of
// L's Hessian at jets give M and L_vq v, and the solve at jets starts from M's values
// (JetLinearSolve, as in velocity()).
void MechanicalField::acceleration(const Jet2* q, const Jet2* v, Jet2* a) {
  velocity_hessian_jet_.evaluate(lagrangian_, q, v, v);
  for (int r = 0; r < n_; ++r) legendre_residual_[r] = gradient_jet_[r] - velocity_hessian_jet_.along(r);
  acceleration_solve_.solve(velocity_hessian_jet_.inertia(), n_, legendre_residual_.data(), a);
}

// The tangent form's Jacobian with a configuration-dependent mass matrix: the acceleration at jets
// whose variables are a block of (q, v)'s own numbers, read off their gradients, in blocks of at
// most jet_variables() numbers; the forces enter through their Jacobian (force_at), the time's
// column is zero as in jacobian().
void MechanicalField::general_tangent_jacobian(const double* y, double* f, double* df) {
  const double* q = point(y);
  const int N = size(), block = jet_variables();
  Eigen::Map<Eigen::MatrixXd> J(df, N, N);
  J.setZero();
  J.block(0, n_, n_, n_).setIdentity();
  for (int first = 0; first < 2 * n_; first += block) {
    const int count = std::min(block, 2 * n_ - first);
    const auto seeded = [&](double x, int index) {
      return index >= first && index < first + count ? Jet2::variable(x, count, index - first) : Jet2(x);
    };
    for (int r = 0; r < n_; ++r) {
      seed_[r] = seeded(q[r], r);
      v_jet_[r] = seeded(y[n_ + r], n_ + r);
    }
    lagrangian_.gradient_jet(seed_.data(), v_jet_.data(), nullptr, gradient_jet_.data());
    if (forced_) {
      force_at(seed_.data(), v_jet_.data(), y[2 * n_], force_jet_.data());
      for (int r = 0; r < n_; ++r) gradient_jet_[r] += force_jet_[r];
    }
    acceleration(seed_.data(), v_jet_.data(), acceleration_jet_.data());
    for (int r = 0; r < n_; ++r)
      if (!acceleration_jet_[r].constant())
        J.row(n_ + r).segment(first, count) = acceleration_jet_[r].gradient.transpose();
  }
  for (int r = 0; r < n_; ++r) {
    f[r] = y[n_ + r];
    f[n_ + r] = acceleration_jet_[r].value;
  }
  if (clock()) f[2 * n_] = 1.0;
}

template <class T>
void EulerLagrangeField::advance(OneStepMethod& method, double h, const T* y0, T* y1,
                              SolverStatistics& stages) {
  StageSolve report;
  pending_ = nullptr;
  if (Status status = method.step(*this, h, y0, y1, &report)) {
    if (pending_) std::rethrow_exception(pending_);
    if (!report.converged) throw NumericalFailure(status, report.residual);
    throw PluginFault(std::string("one-step method: ") + status, method.origin());
  }
  stages.record(report.iterations);
  for (int r = 0; r < size(); ++r)
    if (!std::isfinite(value_of(y1[r])))
      throw NumericalFailure("the one-step method produced a non-finite state", std::nan(""), method.origin());
}

void EulerLagrangeField::step(OneStepMethod& method, double h, const double* y0, double* y1,
                           SolverStatistics& stages) {
  advance(method, h, y0, y1, stages);
}

void EulerLagrangeField::step(OneStepMethod& method, double h, const Jet2* y0, Jet2* y1,
                           SolverStatistics& stages) {
  advance(method, h, y0, y1, stages);
}

}  // namespace varia
