#include "varia/core/shooting.hpp"

#include <cmath>
#include <stdexcept>

namespace varia {

namespace {

PhaseSpace phase_space(ShootingForm form) {
  return form == ShootingForm::lagrangian ? PhaseSpace::tangent : PhaseSpace::cotangent;
}

Lagrangian& checked(const Manifold& manifold, Lagrangian& lagrangian) {
  require_vector_space(manifold, lagrangian, "the shooting construction");
  if (2 * manifold.dim() > kMaxJetVariables)
    throw std::invalid_argument("the shooting construction differentiates the propagation with "
                                "jets of at most " + std::to_string(kMaxJetVariables) +
                                " variables (q0, v0): it takes dim <= " +
                                std::to_string(kMaxJetVariables / 2));
  return lagrangian;
}

}  // namespace

ShootingForm shooting_form(const std::string& name) {
  if (name == "lagrangian") return ShootingForm::lagrangian;
  if (name == "hamiltonian") return ShootingForm::hamiltonian;
  if (name == "type-2") return ShootingForm::type_2;
  throw std::invalid_argument("unknown shooting form '" + name +
                              "'; valid forms are: lagrangian, hamiltonian, type-2");
}

ShootingDiscreteLagrangian::ShootingDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian,
                                                       Quadrature& quadrature,
                                                       OneStepMethod& method, ShootingForm form,
                                                       SolverOptions options)
    : lagrangian_(checked(manifold, lagrangian)),
      field_(lagrangian_, phase_space(form)),
      method_(method),
      form_(form),
      options_(options),
      n_(manifold.dim()) {
  method_.set_solver(options.tolerance, options.max_iterations);
  // The nodes 0 = c_0 < ... < c_n = 1 with zero weights where the rule has no node (paper, sec. 3).
  const double* c = quadrature.nodes();
  const double* b = quadrature.weights();
  const int size = quadrature.size();
  if (size == 0 || c[0] != 0.0) {
    nodes_.push_back(0.0);
    weights_.push_back(0.0);
  }
  nodes_.insert(nodes_.end(), c, c + size);
  weights_.insert(weights_.end(), b, b + size);
  if (nodes_.back() != 1.0) {
    nodes_.push_back(1.0);
    weights_.push_back(0.0);
  }
  for (std::size_t i = 1; i < nodes_.size(); ++i)
    if (!(nodes_[i] > nodes_[i - 1]) || nodes_[i] > 1.0)
      throw std::invalid_argument("the quadrature's nodes must increase within [0, 1]");
  for (int k = 1; k <= quadrature.derivative_terms(); ++k) {
    const double* az = quadrature.derivative_weights(k);
    if (k == 1) {
      start_correction_ = az[0];
      end_correction_ = az[1];
    } else if (az[0] != 0.0 || az[1] != 0.0) {
      throw std::invalid_argument("the shooting construction takes end corrections with the "
                                  "first derivative of the integrand only");
    }
  }
  state_.resize(2 * n_);
  next_.resize(2 * n_);
  v_.resize(n_);
  acceleration_.resize(n_);
  gradient_.resize(2 * n_);
  boundary_.resize(n_);
  w_.resize(n_);
  lambda_.resize(n_);
  D1_.resize(n_);
  residual_.resize(n_);
  update_.resize(n_);
  Bq_.resize(n_, n_);
  Bw_.resize(n_, n_);
  phi_.resize(2 * n_, 2 * n_);
  jacobian_.resize(n_, n_);
  BwT_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
  jacobian_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
  residuals_.reserve(options_.max_iterations + 1);
}

// The quadrature's contribution at node i: h b_i L(q^i, v^i), plus the Euler-Maclaurin end
// correction h^2 a_1 dL/dt at t = 0 or h^2 z_1 dL/dt at t = h, where along the Euler-Lagrange
// flow dL/dt = <L_q, v> + <L_v, a>, a = M^{-1} L_q (the prolongation, paper, sec. 3).
void ShootingDiscreteLagrangian::accumulate(int node, double h, Jet2& S) {
  const bool first = node == 0, last = node + 1 == static_cast<int>(nodes_.size());
  const double correction = first ? start_correction_ : last ? end_correction_ : 0.0;
  if (weights_[node] == 0.0 && correction == 0.0) return;
  field_.velocity(&state_[n_], v_.data());
  Jet2 L;
  lagrangian_.gradient_jet(state_.data(), v_.data(), &L, gradient_.data());
  S += (h * weights_[node]) * L;
  if (correction == 0.0) return;
  field_.inverse_mass(gradient_.data(), acceleration_.data());
  Jet2 rate;
  for (int r = 0; r < n_; ++r) rate += gradient_[r] * v_[r] + gradient_[n_ + r] * acceleration_[r];
  S += (h * h * correction) * rate;
}

// Propagates (q^0, w^0) = (q0, w0) as jets in those 2n variables through the nodes, then forms
// the generating function G and the boundary quantity B of the form.
void ShootingDiscreteLagrangian::shoot(const double* q0, const double* w0, double h) {
  for (int r = 0; r < n_; ++r) {
    state_[r] = Jet2::variable(q0[r], 2 * n_, r);
    state_[n_ + r] = Jet2::variable(w0[r], 2 * n_, n_ + r);
  }
  Jet2 S;
  accumulate(0, h, S);
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    field_.step(method_, (nodes_[i] - nodes_[i - 1]) * h, state_.data(), next_.data(), stages_);
    std::swap(state_, next_);
    accumulate(static_cast<int>(i), h, S);
  }
  if (type_2()) {
    generating_ = -S;  // H_d^+ = <p^n, q^n> - S
    for (int r = 0; r < n_; ++r) generating_ += state_[n_ + r] * state_[r];
    std::copy_n(state_.begin() + n_, n_, boundary_.begin());
  } else {
    generating_ = S;
    std::copy_n(state_.begin(), n_, boundary_.begin());
  }
}

// lambda = B_w^{-T} G_w, D1 = G_q - B_q^T lambda, Phi = Hess G - sum_r lambda_r Hess B_r.
void ShootingDiscreteLagrangian::differentiate() {
  for (int r = 0; r < n_; ++r) {
    Bq_.row(r) = boundary_[r].gradient.head(n_).transpose();
    Bw_.row(r) = boundary_[r].gradient.tail(n_).transpose();
  }
  BwT_lu_.compute(Bw_.transpose());
  lambda_.noalias() = BwT_lu_.solve(generating_.gradient.tail(n_));
  D1_ = generating_.gradient.head(n_);
  D1_.noalias() -= Bq_.transpose() * lambda_;
  phi_ = generating_.hessian;
  for (int r = 0; r < n_; ++r) phi_ -= lambda_[r] * boundary_[r].hessian;
}

// residual_ and its Jacobian in w0, jacobian_, for the target:
//   momentum: dD1/dw0 = Phi_qw - B_q^T B_w^{-T} Phi_ww;
//   boundary: B_w;
//   lambda:   dlambda/dw0 = B_w^{-T} Phi_ww.
void ShootingDiscreteLagrangian::residual(Target target, const double* data) {
  const Eigen::Map<const Eigen::VectorXd> given(data, n_);
  const auto phi_ww = phi_.bottomRightCorner(n_, n_);
  switch (target) {
    case Target::momentum:
      residual_ = D1_;
      if (type_2()) residual_ -= given;
      else residual_ += given;
      jacobian_ = phi_.topRightCorner(n_, n_);
      jacobian_.noalias() -= Bq_.transpose() * BwT_lu_.solve(phi_ww);
      break;
    case Target::boundary:
      for (int r = 0; r < n_; ++r) residual_[r] = boundary_[r].value - given[r];
      jacobian_ = Bw_;
      break;
    case Target::lambda:
      residual_ = lambda_ - given;
      jacobian_ = BwT_lu_.solve(phi_ww);
      break;
  }
}

// Newton's method with the exact Jacobian on w0 (starting from w_), until the residual or the
// update is at the tolerance; the last shot stays in the workspace for the outputs.
void ShootingDiscreteLagrangian::solve(const double* q0, double h, Target target,
                                       const double* data) {
  residuals_.clear();
  const double scale = Eigen::Map<const Eigen::VectorXd>(data, n_).lpNorm<Eigen::Infinity>();
  bool settled = false;
  for (int iteration = 0;; ++iteration) {
    shoot(q0, w_.data(), h);
    differentiate();
    residual(target, data);
    const double norm = residual_.lpNorm<Eigen::Infinity>();
    residuals_.push_back(norm);
    if (!std::isfinite(norm))
      throw NumericalFailure("the shooting equations have a non-finite residual", norm);
    if (settled || options_.converged(norm, scale)) return statistics_.record(iteration);
    if (iteration == options_.max_iterations)
      throw NumericalFailure("the shooting Newton iteration did not converge in " +
                                 std::to_string(options_.max_iterations) + " iterations",
                             norm);
    jacobian_lu_.compute(jacobian_);
    update_.noalias() = jacobian_lu_.solve(residual_);
    w_ -= update_;
    settled = options_.converged(update_.lpNorm<Eigen::Infinity>(), w_.lpNorm<Eigen::Infinity>());
  }
}

// The paper's shooting-based implementation: w0 = v0 from the inverse Legendre transform
// v0 = M^{-1} p0 (Lagrangian form), or w0 = p^0 guessed as p0 (Hamiltonian forms).
void ShootingDiscreteLagrangian::step(const double* q0, const double* p0, double h, double* q1,
                                      double* p1) {
  if (form_ == ShootingForm::lagrangian) field_.inverse_mass(p0, w_.data());
  else w_ = Eigen::Map<const Eigen::VectorXd>(p0, n_);
  solve(q0, h, Target::momentum, p0);
  Eigen::Map<Eigen::VectorXd> q(q1, n_), p(p1, n_);
  for (int r = 0; r < n_; ++r) (type_2() ? p : q)[r] = boundary_[r].value;
  (type_2() ? q : p) = lambda_;
}

// From the straight line's velocity (q1 - q0)/h (times M for a momentum).
void ShootingDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h,
                                          double* Ld, double* D1, double* D2) {
  const Eigen::Map<const Eigen::VectorXd> a(q0, n_), b(q1, n_);
  w_ = (b - a) / h;
  if (form_ != ShootingForm::lagrangian) w_ = field_.mass() * w_;
  solve(q0, h, type_2() ? Target::lambda : Target::boundary, q1);
  double p1_q1 = 0.0;
  for (int r = 0; r < n_; ++r) p1_q1 += boundary_[r].value * lambda_[r];
  if (Ld != nullptr) *Ld = type_2() ? p1_q1 - generating_.value : generating_.value;
  if (D1 != nullptr) Eigen::Map<Eigen::VectorXd>(D1, n_) = type_2() ? -D1_ : D1_;
  if (D2 == nullptr) return;
  Eigen::Map<Eigen::VectorXd> d2(D2, n_);
  if (type_2())
    for (int r = 0; r < n_; ++r) d2[r] = boundary_[r].value;
  else
    d2 = lambda_;
}

}  // namespace varia
