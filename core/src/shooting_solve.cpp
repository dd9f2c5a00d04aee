// The shooting construction's equations and their solve (shooting.hpp): the shot's first
// derivatives, the residual of the target (the momentum for a step, the boundary or lambda for L_d)
// with its Jacobian in w0, Newton's method on it, the step with its warm start and compensated
// sums, and L_d; compiled for n <= 4 at fixed sizes, here, once (step_function).
#include "varia/core/shooting.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "varia/core/compensated.hpp"
#include "varia/core/fixed_size.hpp"
#include "varia/core/lie_group_field.hpp"

namespace varia {

namespace {

template <int N>
using Vector = Eigen::Matrix<double, N, 1>;
template <int N>
using Square = Eigen::Matrix<double, N, N>;

}  // namespace

// The shot from (q0, w0): the propagation's values, the first derivatives of G, W and B with
// lambda and D1 from them (first_derivatives), and, where the solve needs them, Phi's second
// derivatives (second_derivatives), over the passes (plan_passes; every pass has the same values).
template <int N>
void ShootingDiscreteLagrangian::shoot(const double* q0, const double* w0, double h) {
  bool first = false;  // lambda and D1 known
  for (const Pass& pass : passes_) {
    if (!pass.first_order && !second_order_) continue;
    propagate(q0, w0, h, pass);
    if (pass.first_order) gather(pass);
    if (!pass.second_order || !second_order_) continue;
    if (!first) first_derivatives<N>();
    first = true;
    second_derivatives(pass);
  }
  if (!first) first_derivatives<N>();
}

// lambda = B_w^{-T} alpha_w, D1 = alpha_q - B_q^T lambda.
// With offsets (on a vector space, Type I forms) B_q = I + Bq_, and the momentum change of the
// step is D1 + D2 = alpha_q - Bq_^T lambda: small terms, each to its own relative precision.
template <int N>
void ShootingDiscreteLagrangian::first_derivatives() {
  const int n = fixed_or<N>(n_);
  const Eigen::Map<const Square<N>> Bq(Bq_.data(), n, n), Bw(Bw_.data(), n, n);
  Eigen::Map<Vector<N>> lambda(lambda_.data(), n), D1(D1_.data(), n);
  BwT_solver_.compute(Bw.transpose());
  BwT_solver_.solve(Eigen::Map<const Vector<N>>(alpha_.data() + n, n), lambda);
  D1 = Eigen::Map<const Vector<N>>(alpha_.data(), n);
  D1.noalias() -= Bq.transpose() * lambda;
  if (type_2())  // G = <p^n, offset^n> - S leaves out <p^n, q0 + eta>, whose eta-derivative is p^n
    for (int r = 0; r < n; ++r) D1[r] += boundary_[r].value;
  if (offsets()) {
    Eigen::Map<Vector<N>>(momentum_change_.data(), n) = D1;
    D1 -= lambda;
  }
}

// residual_ and its Jacobian in w0, jacobian_, for the target:
//   momentum: dD1/dw0 = Phi_qw - B_q^T B_w^{-T} Phi_ww;
//   boundary: B_w;
//   lambda:   dlambda/dw0 = B_w^{-T} Phi_ww.
template <int N>
void ShootingDiscreteLagrangian::residual(Target target, const double* data) {
  const int n = fixed_or<N>(n_);
  const Eigen::Map<const Vector<N>> given(data, n), D1(D1_.data(), n), lambda(lambda_.data(), n);
  const Eigen::Map<const Square<N>> Bq(Bq_.data(), n, n);
  Eigen::Map<Vector<N>> F(residual_.data(), n);
  Eigen::Map<Square<N>> jacobian(jacobian_.data(), n, n), lambda_jacobian(lambda_jacobian_.data(), n, n);
  const auto phi_ww = phi_.template block<N, N>(n, n, n, n);
  switch (target) {
    case Target::momentum:
      F = D1;
      if (type_2()) F -= given;
      else F += given;
      BwT_solver_.solve(phi_ww, lambda_jacobian);
      jacobian = phi_.template block<N, N>(0, n, n, n);
      jacobian.noalias() -= Bq.transpose() * lambda_jacobian;
      if (offsets()) jacobian -= lambda_jacobian;
      if (type_2()) jacobian += Eigen::Map<const Square<N>>(Bw_.data(), n, n);  // d p^n / dw0
      break;
    case Target::boundary:
      for (int r = 0; r < n; ++r) F[r] = boundary_[r].value - given[r];
      jacobian = Eigen::Map<const Square<N>>(Bw_.data(), n, n);
      break;
    case Target::lambda:
      F = lambda - given;
      BwT_solver_.solve(phi_ww, jacobian);
      break;
  }
}

// The shooting equations in w0 (residual(): the target's), as a system for NewtonSolver
// (solve/newton.hpp), with the exact Jacobian.
template <int N>
struct ShootingDiscreteLagrangian::Equations {
  ShootingDiscreteLagrangian& s;
  const double* q0;
  double h;
  Target target;
  const double* data;
  int n = fixed_or<N>(s.n_);

  int size() const { return s.n_; }
  // F's round-off yardstick: the largest of its terms, the given data and D1 (momentum) or B.
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    s.shoot<N>(q0, s.w_.data(), h);
    s.residual<N>(target, data);
    F = Eigen::Map<const Vector<N>>(s.residual_.data(), n);
    double yardstick = Eigen::Map<const Vector<N>>(data, n).template lpNorm<Eigen::Infinity>();
    if (target == Target::momentum)
      return std::max(yardstick, Eigen::Map<const Vector<N>>(s.D1_.data(), n).template lpNorm<Eigen::Infinity>());
    for (int r = 0; r < n; ++r) yardstick = std::max(yardstick, std::abs(s.boundary_[r].value));
    return yardstick;
  }
  void factorize() { s.jacobian_solver_.compute(Eigen::Map<const Square<N>>(s.jacobian_.data(), n, n)); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) {
    Eigen::Map<Vector<N>> x(update.data(), n);
    s.jacobian_solver_.solve(Eigen::Map<const Vector<N>>(F.data(), n), x);
  }
  double apply(const Eigen::VectorXd& update) {
    Eigen::Map<Vector<N>> w(s.w_.data(), n);
    w -= Eigen::Map<const Vector<N>>(update.data(), n);
    return w.template lpNorm<Eigen::Infinity>();
  }
  // The step's outcome at the updated w0, to first order from the last shot (no propagation):
  // the state's values by their w0-derivatives, lambda by dlambda/dw0 = B_w^{-T} Phi_ww, the
  // momentum change by dD1/dw0 + dlambda/dw0, the residual by its Jacobian.
  // The point is read from B (step_at, step_on_constraint), whose w0-derivatives every pass plan
  // gives.
  void finish(const Eigen::VectorXd& update_vector) {
    if (target != Target::momentum) return;
    const Eigen::Map<const Vector<N>> update(update_vector.data(), n);
    const Eigen::Map<const Square<N>> Bw(s.Bw_.data(), n, n), jacobian(s.jacobian_.data(), n, n),
        lambda_jacobian(s.lambda_jacobian_.data(), n, n);
    for (int r = 0; r < n; ++r) s.boundary_[r].value -= Bw.row(r).dot(update);
    Eigen::Map<Vector<N>>(s.lambda_.data(), n).noalias() -= lambda_jacobian * update;
    if (s.offsets()) {
      Eigen::Map<Vector<N>> change(s.momentum_change_.data(), n);
      change.noalias() -= jacobian * update;
      change.noalias() -= lambda_jacobian * update;
    }
    Eigen::Map<Vector<N>>(s.residual_.data(), n).noalias() -= jacobian * update;
  }
};

// Newton's method with the exact Jacobian on w0 (starting from w_); the last shot stays in the
// workspace for the outputs, brought to the solution to first order (Equations::finish).
template <int N>
void ShootingDiscreteLagrangian::solve(const double* q0, double h, Target target,
                                       const double* data) {
  Equations<N> equations{*this, q0, h, target, data};
  second_order_ = target != Target::boundary;
  require_converged(solver_.solve(equations, statistics_), "the shooting equations");
}

template <int N>
void ShootingDiscreteLagrangian::step_at(const double* q0, const double* p0, double h, double* q1, double* p1) {
  const int n = fixed_or<N>(n_), m = fixed_or<N>(m_);  // N is fixed on R^n only, where m = n
  const Eigen::Map<const Vector<N>> start(q0, m), momentum(p0, n);
  Eigen::Map<Vector<N>> end_q(end_q_.data(), m), end_p(end_p_.data(), n), guess(guess_.data(), n);
  const bool continues = continuing_ && end_q == start && end_p == momentum;
  if (form_ == ShootingForm::lagrangian && field_->constant_mass())
    guess.noalias() = Eigen::Map<const Square<N>>(field_->inverse_mass().data(), n, n) * momentum;
  else if (form_ == ShootingForm::lagrangian && mechanical_ != nullptr) mechanical_->velocity_of(q0, p0, guess_.data());
  else if (form_ == ShootingForm::lagrangian) lagrangian_.inverse_legendre(q0, p0, guess_.data(), options_);  // a group
  else guess = momentum;
  warm_start<N>(continues && h == previous_h_);
  target_is_end_ = true;
  if (adjoint_ == nullptr || !solve_by_adjoint(q0, h, p0)) solve<N>(q0, h, Target::momentum, p0);
  record_correction<N>(h);
  Eigen::Map<Vector<N>> p(p1, n);
  if (mechanical_ != nullptr) {  // a vector space: q1 - q0 is the offset B (type-2: lambda)
    Eigen::Map<Vector<N>> carry_q(carry_q_.data(), n), carry_p(carry_p_.data(), n),
        offset(offset_.data(), n), change(momentum_change_.data(), n);
    if (!continues) {
      carry_q.setZero();
      carry_p.setZero();
    }
    if (type_2()) offset = Eigen::Map<const Vector<N>>(lambda_.data(), n);
    else for (int r = 0; r < n; ++r) offset[r] = boundary_[r].value;
    end_q = start;
    compensated_add(end_q, offset, carry_q);
    if (type_2()) {  // p1 = p^n, as propagated
      for (int r = 0; r < n; ++r) end_p[r] = boundary_[r].value;
    } else {
      change -= Eigen::Map<const Vector<N>>(residual_.data(), n);
      end_p = momentum;
      compensated_add(end_p, change, carry_p);
    }
    Eigen::Map<Vector<N>>(q1, n) = end_q;
    p = end_p;
  } else {  // a Lie group: q1 = c exp(B), c = q^n's value at the last shot
    for (int r = 0; r < n; ++r) v_values_[r] = boundary_[r].value;
    check(manifold_, manifold_.retract(target_.data(), v_values_.data(), q1), "manifold retract");
    p = Eigen::Map<const Vector<N>>(lambda_.data(), n);  // with forces p1 = D2 L_d + f_d^+
    end_q = Eigen::Map<const Vector<N>>(q1, m);
    end_p = p;
  }
  continuing_ = true;
}

// The step in the charts of Q (shooting.hpp): p0 as N0^T p0, the guess w0 = N0^T M^-1 p0 (the
// velocity of p0, tangent), the shot from (q0, w0) solved until D1 = -N0^T p0, q1 = q^n and
// p1 = N1 lambda taken onto the cotangent space. No warm start: the bases change from step to step.
void ShootingDiscreteLagrangian::step_on_constraint(const double* q0, const double* p0, double h, double* q1,
                                                    double* p1) {
  start_basis_ = tangent_basis_->at(q0);
  const Eigen::Map<const Eigen::VectorXd> momentum(p0, m_);
  chart_momentum_.noalias() = start_basis_.transpose() * momentum;
  velocity_.noalias() = field_->inverse_mass() * momentum;
  w_.noalias() = start_basis_.transpose() * velocity_;
  target_is_end_ = true;
  solve<Eigen::Dynamic>(q0, h, Target::momentum, chart_momentum_.data());
  // q1 = c + N1 B, c = q^n's value at the last shot (on Q to O(|B|^2), B the last update's size).
  for (int r = 0; r < n_; ++r) v_values_[r] = boundary_[r].value;
  Eigen::Map<Eigen::VectorXd>(q1, m_) = Eigen::Map<const Eigen::VectorXd>(target_.data(), m_);
  Eigen::Map<Eigen::VectorXd>(q1, m_).noalias() += end_basis_ * v_values_;
  embedded_momentum_.noalias() = end_basis_ * lambda_;
  velocity_.noalias() = field_->inverse_mass() * embedded_momentum_;
  constrained_->project_velocity(q1, velocity_.data());
  Eigen::Map<Eigen::VectorXd>(p1, m_).noalias() = field_->mass() * velocity_;
}

// The step's equations on the shot's adjoint (shot_adjoint.hpp) in the unknowns (w0, lambda):
//   D1 + p0 = dF/deta - lambda + p0 = 0,   dF/dw0 / h = (G_w - B_w^T lambda) / h = 0,
// the second making lambda = B_w^{-T} G_w = D2 L_d (shooting.hpp), scaled by 1/h so that both are
// of the size of a momentum (the stopping rule's yardstick). Simplified Newton (solve/newton.hpp)
// with the Jacobian of the flow to first order in h: q^n - q0 = h V w0 + O(h^2) and
// G = h L(q0, V w0) + O(h^2), V = I (lagrangian) or M^{-1} (hamiltonian: w0 = p^0), so that
//   A = [0, -I; V^T M V, -V^T]   (columns w0, lambda),
// with the exact Jacobian's other terms O((omega h)^2) relative for a frequency omega of the
// motion: the contraction. A's inverse is closed-form (solve()).
struct ShootingDiscreteLagrangian::AdjointEquations {
  ShootingDiscreteLagrangian& s;
  const double* q0;
  double h;
  const double* p0;
  bool first = true;

  bool hamiltonian() const { return s.form_ == ShootingForm::hamiltonian; }
  int size() const { return 2 * s.n_; }
  bool simplified() const { return true; }
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    const int n = s.n_;
    ShotAdjoint& shot = *s.adjoint_;
    shot.forward(q0, s.w_.data(), h);
    // lambda's guess: the far end's momentum less the start's correction w0 - guess, which moves it
    // by about M dw0 (the end momentum of the flow from the guess, D2 L_d to the method's order),
    // with the warm start's correction.
    if (first) {
      s.adjoint_scratch_ = shot.end_w() - s.w_ + s.guess_;
      if (hamiltonian()) s.lambda_guess_ = s.adjoint_scratch_;
      else s.lambda_guess_.noalias() = s.field_->mass() * s.adjoint_scratch_;
      s.lambda_ = s.lambda_guess_;
      s.add_extrapolation<Eigen::Dynamic>(n, s.lambda_.data());
      first = false;
    }
    shot.reverse(s.lambda_.data(), s.momentum_change_.data(), F.data() + n);
    const Eigen::Map<const Eigen::VectorXd> momentum(p0, n);
    F.head(n) = s.momentum_change_ - s.lambda_ + momentum;
    F.tail(n) /= h;
    return std::max({momentum.lpNorm<Eigen::Infinity>(), s.momentum_change_.lpNorm<Eigen::Infinity>(),
                     s.lambda_.lpNorm<Eigen::Infinity>()});
  }
  void factorize() {}
  // A [x; y] = [a; b]: y = -a, V^T M V x = b - V^T a: x = M^{-1} (b - a), or x = M b - a.
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) {
    const int n = s.n_;
    update.tail(n) = -F.head(n);
    if (hamiltonian()) {
      update.head(n).noalias() = s.field_->mass() * F.tail(n);
      update.head(n) -= F.head(n);
    } else {
      s.adjoint_scratch_ = F.tail(n) - F.head(n);
      update.head(n).noalias() = s.field_->inverse_mass() * s.adjoint_scratch_;
    }
  }
  double apply(const Eigen::VectorXd& update) {
    const int n = s.n_;
    s.w_ -= update.head(n);
    s.lambda_ -= update.tail(n);
    return std::max(s.w_.lpNorm<Eigen::Infinity>(), s.lambda_.lpNorm<Eigen::Infinity>());
  }
  // The outputs at the updated unknowns, to first order by A: lambda is one; the far end's offset
  // moves by -h V dw0; D1 + p0 goes to zero by A's first row, which leaves dF/deta (the momentum
  // change) as it was.
  void finish(const Eigen::VectorXd& update) {
    const int n = s.n_;
    if (hamiltonian()) s.adjoint_scratch_.noalias() = s.field_->inverse_mass() * update.head(n);
    else s.adjoint_scratch_ = update.head(n);
    for (int r = 0; r < n; ++r) s.boundary_[r].value = s.adjoint_->end_offset()[r] - h * s.adjoint_scratch_[r];
    s.residual_.setZero();
  }
};

bool ShootingDiscreteLagrangian::solve_by_adjoint(const double* q0, double h, const double* p0) {
  AdjointEquations equations{*this, q0, h, p0};
  adjoint_guess_ = w_;
  last_solver_ = &adjoint_solver_;
  if (adjoint_solver_.solve(equations, statistics_).converged()) return true;
  w_ = adjoint_guess_;
  last_solver_ = &solver_;
  return false;
}

// The warm start: w0 = guess + c, the correction c = w0 - guess of the step extrapolated from the
// last steps' (while the steps continue one another at the same h) by the polynomial through up to
// three of them. The correction is a smooth function of the state along the motion, of the
// size of the method's local error (the inverse Legendre transform is exact for the exact flow),
// so that the first shot's residual is of that size times h^k, k the corrections used. With the
// guess alone the first residual of the pendulum at h = 0.005 (SVIRK4) was 1e-12 and every step
// took two shots; from the extrapolation the first update is at round-off and the step one shot
// (Newton's stopping rule, solve/newton.hpp: the error left is of the update's square).
// On the shot's adjoint lambda's guess (the far end's momentum, less the start's correction) is
// corrected the same way, its correction lambda - guess in the history's rows n..2n-1: on the
// 60-DOF chain at h = 0.05, 4.33 iterations a step instead of 4.70 (bench/README.md).
template <int N>
void ShootingDiscreteLagrangian::warm_start(bool continues) {
  if (!continues) corrections_ = 0;
  const int n = fixed_or<N>(n_);
  Eigen::Map<Vector<N>>(w_.data(), n) = Eigen::Map<const Vector<N>>(guess_.data(), n);
  add_extrapolation<N>(0, w_.data());
}

// x += the correction of the history's rows first .. first + n - 1 extrapolated from its
// corrections_ newest columns.
template <int N>
void ShootingDiscreteLagrangian::add_extrapolation(int first, double* x) const {
  static constexpr double kExtrapolation[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
  if (corrections_ == 0) return;
  const int n = fixed_or<N>(n_);
  Eigen::Map<Vector<N>> out(x, n);
  const double* c = kExtrapolation[corrections_ - 1];
  for (int k = 0; k < corrections_; ++k) out += c[k] * Eigen::Map<const Vector<N>>(&corrections_history_(first, k), n);
}

// The converged step's correction w0 - guess (and on the shot's adjoint lambda - its guess) joins
// the history (newest first).
template <int N>
void ShootingDiscreteLagrangian::record_correction(double h) {
  const int n = fixed_or<N>(n_);
  const auto correction = [&](int k) { return Eigen::Map<Vector<N>>(&corrections_history_(0, k), n); };
  for (int k = kCorrections - 1; k > 0; --k) correction(k) = correction(k - 1);
  correction(0) = Eigen::Map<const Vector<N>>(w_.data(), n) - Eigen::Map<const Vector<N>>(guess_.data(), n);
  if (adjoint_ != nullptr) {
    for (int k = kCorrections - 1; k > 0; --k) corrections_history_.col(k).tail(n_) = corrections_history_.col(k - 1).tail(n_);
    corrections_history_.col(0).tail(n_) = lambda_ - lambda_guess_;
  }
  corrections_ = std::min(corrections_ + 1, kCorrections);
  previous_h_ = h;
}

// From the velocity local(q0, q1)/h of the chart's straight line (times M for a momentum). With
// constraints the guess is N0^T (q1 - q0)/h, B = N1^T (q^n - q1) against 0 at N1 = T_q1 Q's basis,
// and D1, D2 the covectors N0 D1, N1 lambda in R^N.
void ShootingDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h,
                                          double* Ld, double* D1, double* D2) {
  forced_ = false;  // L_d alone: the forces are not part of it
  target_is_end_ = false;
  std::copy_n(q1, m_, target_.begin());
  if (constrained_ != nullptr) {
    start_basis_ = tangent_basis_->at(q0);
    velocity_ = (Eigen::Map<const Eigen::VectorXd>(q1, m_) - Eigen::Map<const Eigen::VectorXd>(q0, m_)) / h;
    w_.noalias() = start_basis_.transpose() * velocity_;
    solve<Eigen::Dynamic>(q0, h, Target::boundary, zero_.data());
    if (Ld != nullptr) *Ld = generating_.value;
    if (D1 != nullptr) Eigen::Map<Eigen::VectorXd>(D1, m_).noalias() = start_basis_ * D1_;
    if (D2 != nullptr) Eigen::Map<Eigen::VectorXd>(D2, m_).noalias() = end_basis_ * lambda_;
    return;
  }
  check(manifold_, manifold_.local(q0, q1, w_.data()), "manifold chart");
  w_ /= h;
  if (form_ != ShootingForm::lagrangian) {  // p0's guess: the momentum of that velocity at q0
    v_values_ = w_;
    mechanical_->momentum(q0, v_values_.data(), w_.data());
  }
  // On a vector space B = q^n - q0 against q1 - q0 (type-2: lambda, an offset too, against it);
  // through the chart at q1, B = local(q1, q^n) against 0.
  if (mechanical_ != nullptr) {
    offset_ = Eigen::Map<const Eigen::VectorXd>(q1, n_) - Eigen::Map<const Eigen::VectorXd>(q0, n_);
    solve<Eigen::Dynamic>(q0, h, type_2() ? Target::lambda : Target::boundary, offset_.data());
  } else {
    solve<Eigen::Dynamic>(q0, h, Target::boundary, zero_.data());
  }
  // type-2: L_d = <p1, q1> - H_d^+ with H_d^+ = G + <p1, q0> (G as propagated), so <p1, q1 - q0> - G.
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

// On a Lie group the tangent map below reads the shot's end through the natural chart at g^n, which
// a Runge-Kutta method integrating in the embedding leaves (its g^n is off the group by its local
// error): only a Lie group method's shot has it.
std::string ShootingDiscreteLagrangian::tangent_map_refusal() const {
  if (constrained_ != nullptr)
    return "the shooting construction with constraints has no tangent map (its projected shot's is not derived)";
  if (mechanical_ == nullptr && std::string(method_.equivariance()) != "left")
    return "the shooting construction's tangent map on a Lie group takes a Lie group method (as crouch-grossman), "
           "whose shot stays on the group; a Runge-Kutta method integrates in the embedding and leaves it";
  return {};
}


// With lambda(x) = B_w^{-T} alpha_w and Phi = G + W - <lambda, B> with lambda frozen (shooting.hpp),
// dlambda/dx = B_w^{-T} Phi_wx, and for a direction (dq0, dp0) = (deta, dp0):
// - Type I forms, D1(x) = alpha_eta - (I + B_eta)^T lambda (the offsets' B = q^n - q0 - eta):
//   dD1/dx = Phi_etax - (I + B_eta)^T dlambda/dx, and the step D1 + p0 = 0, q1 = q0 + eta + B,
//   p1 = lambda gives dw0 = -(dD1/dw0)^{-1} (dp0 + dD1/deta dq0), dq1 = (I + B_eta) dq0 + B_w dw0,
//   dp1 = dlambda/deta dq0 + dlambda/dw0 dw0;
// - the type-2 form, D1 H_d^+(x) = alpha_eta - B_eta^T lambda + B (B = p^n): dD1/dx = Phi_etax -
//   B_eta^T dlambda/dx + B_x, and the step D1 - p0 = 0, q1 = q0 + eta + lambda, p1 = B gives
//   dw0 = (dD1/dw0)^{-1} (dp0 - dD1/deta dq0), dq1 = (I + dlambda/deta) dq0 + dlambda/dw0 dw0,
//   dp1 = B_eta dq0 + B_w dw0;
// - on a Lie group (the lagrangian form, B = log(c^{-1} g^n) about c = g^n's value at the solution,
//   D1 = alpha_eta - B_eta^T lambda): moving g0 to g0 exp(e a), the chart's eta at the new base is
//   e a + eta' + (e/2) [a, eta'] + ... (Baker-Campbell-Hausdorff), so D1 gains 1/2 ad_a^T D1 =
//   -1/2 ad_a^T p0; dq1 = B_eta dq0 + B_w dw0 in the chart at g1; and the momentum, left-trivialized
//   at g^n itself, is dexp_{-B}^{-T} lambda, so dp1 = dlambda + 1/2 ad_{dq1}^T lambda.
void ShootingDiscreteLagrangian::take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                                   double* p1, int count, const double* directions, double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  // The shot at the solution w0 again, through the method's plugin, with Phi's columns in eta (the
  // step's shot, and a plugin's kernel, form only those in w0).
  // In passes, those of every pair of blocks of x (plan_passes).
  struct Restore {
    ShootingDiscreteLagrangian& s;
    bool plugin;
    ~Restore() {
      s.plugin_shoots_ = plugin;
      s.all_second_derivatives_ = false;
      if (!s.tangent_passes_.empty()) s.passes_.swap(s.tangent_passes_);
    }
  } restore{*this, plugin_shoots_};
  if (!tangent_passes_.empty()) passes_.swap(tangent_passes_);
  plugin_shoots_ = false;
  all_second_derivatives_ = true;
  second_order_ = true;
  shoot<Eigen::Dynamic>(q0, w_.data(), h);
  const int n = n_;
  using Strided = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  const Strided dq0(directions, n, count, Eigen::OuterStride<>(2 * n));
  const Strided dp0(directions + n, n, count, Eigen::OuterStride<>(2 * n));
  tangent_bw_lu_.compute(Bw_.transpose());
  tangent_lambda_ = tangent_bw_lu_.solve(phi_.bottomRows(n));
  tangent_d1_ = phi_.topRows(n);
  tangent_d1_.noalias() -= Bq_.transpose() * tangent_lambda_;
  const bool group = mechanical_ == nullptr;
  if (type_2()) {
    tangent_d1_.leftCols(n) += Bq_;
    tangent_d1_.rightCols(n) += Bw_;
  } else if (!group) {
    tangent_d1_ -= tangent_lambda_;
  }
  tangent_lu_.compute(tangent_d1_.rightCols(n));
  tangent_rhs_ = dp0;
  if (!type_2()) tangent_rhs_ = -tangent_rhs_;
  tangent_rhs_.noalias() -= tangent_d1_.leftCols(n) * dq0;
  const Eigen::Map<const Eigen::VectorXd> momentum(p0, n);
  const std::vector<double> structure = group ? structure_constants(manifold_, q0) : std::vector<double>{};
  if (group) tangent_rhs_ += 0.5 * coadjoint(structure, dq0, momentum);
  tangent_w_.noalias() = tangent_lu_.solve(tangent_rhs_);
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dq1(images, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dp1(images + n, n, count, Eigen::OuterStride<>(2 * n));
  if (group) {
    dq1.noalias() = Bq_ * dq0;
    dq1.noalias() += Bw_ * tangent_w_;
    dp1.noalias() = tangent_lambda_.leftCols(n) * dq0;
    dp1.noalias() += tangent_lambda_.rightCols(n) * tangent_w_;
    dp1 += 0.5 * coadjoint(structure, dq1, Eigen::Map<const Eigen::VectorXd>(lambda_.data(), n));
    return;
  }
  // Type I: the position's offset is B and the momentum lambda; type 2 the other way round.
  dq1 = dq0;
  if (type_2()) {
    dq1.noalias() += tangent_lambda_.leftCols(n) * dq0;
    dq1.noalias() += tangent_lambda_.rightCols(n) * tangent_w_;
    dp1.noalias() = Bq_ * dq0;
    dp1.noalias() += Bw_ * tangent_w_;
  } else {
    dq1.noalias() += Bq_ * dq0;
    dq1.noalias() += Bw_ * tangent_w_;
    dp1.noalias() = tangent_lambda_.leftCols(n) * dq0;
    dp1.noalias() += tangent_lambda_.rightCols(n) * tangent_w_;
  }
}

ShootingDiscreteLagrangian::StepFunction ShootingDiscreteLagrangian::step_function(int n, bool vector_space) {
  if (!vector_space) return &ShootingDiscreteLagrangian::step_at<Eigen::Dynamic>;
  return for_dimension(n, [](auto N) -> StepFunction { return &ShootingDiscreteLagrangian::step_at<decltype(N)::value>; });
}

}  // namespace varia
