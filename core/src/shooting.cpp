#include "varia/core/shooting.hpp"

#include <cmath>
#include <stdexcept>

#include "varia/core/compensated.hpp"
#include "varia/core/fixed_size.hpp"
#include "varia/core/lie_group_field.hpp"

namespace varia {

namespace {

template <int N>
using Vector = Eigen::Matrix<double, N, 1>;
template <int N>
using Square = Eigen::Matrix<double, N, N>;

PhaseSpace phase_space(ShootingForm form) {
  return form == ShootingForm::lagrangian ? PhaseSpace::tangent : PhaseSpace::cotangent;
}

Lagrangian& checked(const Manifold& manifold, Lagrangian& lagrangian, ShootingForm form) {
  if (manifold.is_vector_space())
    require_vector_space(manifold, lagrangian, "the shooting construction");
  else if (form != ShootingForm::lagrangian)
    throw std::invalid_argument("the shooting construction on a Lie group takes the lagrangian form "
                                "(the Euler-Lagrange field on TQ) only");
  if (!lagrangian.evaluates_at_jets())
    throw std::invalid_argument("the shooting construction propagates jets through the Euler-Lagrange field, and "
                                "this Lagrangian does not evaluate at jets (Lagrangian::gradient_jet: models "
                                "derived from sdk::AutodiffLagrangian or sdk::TermwiseLagrangian do, and a "
                                "composite Lagrangian whose effects all do: Effect::gradient_jet)");
  return lagrangian;
}

// The Euler-Lagrange field of the manifold's phase space: on R^n in (q, v) or (q, p), with the
// forces; on a Lie group in (g, xi) (the Euler-Poincare field, lie_group_field.hpp).
std::unique_ptr<EulerLagrangeField> field_of(Manifold& manifold, LagrangianEvaluator& lagrangian,
                                            ShootingForm form, Forces& forces) {
  if (manifold.is_vector_space())
    return std::make_unique<MechanicalField>(lagrangian, phase_space(form), &forces);
  if (!forces.empty())
    throw std::invalid_argument("the shooting construction takes forces on vector spaces only");
  return std::make_unique<LieGroupField>(manifold, lagrangian);
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
                                                       SolverOptions options, std::vector<Force*> forces,
                                                       int jet_capacity)
    : manifold_(manifold),
      lagrangian_(checked(manifold, lagrangian, form)),
      forces_(std::move(forces), manifold.point_size(), manifold.dim()),
      field_(field_of(manifold, lagrangian_, form, forces_)),
      mechanical_(dynamic_cast<MechanicalField*>(field_.get())),
      method_(method),
      form_(form),
      options_(options),
      solver_(options),
      m_(manifold.point_size()),
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
  if (!forces_.empty() && type_2())
    throw std::invalid_argument("the shooting construction takes forces in the lagrangian and "
                                "hamiltonian forms (Type I generating functions), not type-2");
  if ((!forces_.empty() || mechanical_ == nullptr || !field_->constant_mass()) &&
      (start_correction_ != 0.0 || end_correction_ != 0.0))
    throw std::invalid_argument("the shooting construction takes end-derivative quadratures on vector spaces "
                                "without forces, for a Lagrangian with a constant mass matrix, only");
  state_.resize(field_->size());
  next_.resize(field_->size());
  target_.resize(m_);
  force_.resize(n_);
  alpha_.resize(2 * n_);
  zero_.assign(std::max(m_, n_), 0.0);
  slot_.resize(2 * n_);
  if (jet_capacity < 2 || jet_capacity > kMaxJetVariables)
    throw std::invalid_argument("the shooting construction's jets hold 2 to " + std::to_string(kMaxJetVariables) +
                                " variables");
  plan_passes(std::min(jet_capacity, field_->jet_variables()));
  acceleration_.resize(n_);
  gradient_.resize(m_ + n_);
  boundary_.resize(n_);
  end_.resize(m_);
  chart_value_.resize(m_);
  chart_gradient_.resize(2 * m_ * n_);
  chart_hessian_.resize(4 * m_ * n_ * n_);
  local_value_.resize(n_);
  local_gradient_.resize(n_ * m_);
  local_hessian_.resize(n_ * m_ * m_);
  w_.resize(n_);
  v_values_.resize(n_);
  lambda_.resize(n_);
  D1_.resize(n_);
  residual_.resize(n_);
  lambda_jacobian_.resize(n_, n_);
  offset_.resize(n_);
  momentum_change_.resize(n_);
  carry_q_ = Eigen::VectorXd::Zero(n_);
  carry_p_ = Eigen::VectorXd::Zero(n_);
  end_q_.resize(m_);
  end_p_.resize(n_);
  guess_.resize(n_);
  corrections_history_.resize(n_, kCorrections);
  origin_.resize(n_);
  if (mechanical_ != nullptr) mechanical_->set_origin(origin_.data());
  Bq_.resize(n_, n_);
  Bw_.resize(n_, n_);
  phi_.resize(2 * n_, 2 * n_);
  jacobian_.resize(n_, n_);
  BwT_solver_ = SmallDenseSolver(n_);
  jacobian_solver_ = SmallDenseSolver(n_);
  const RungeKuttaTableau tableau = method_.explicit_tableau();
  if (offsets() && form_ == ShootingForm::lagrangian && field_->constant_mass() && forces_.empty() &&
      start_correction_ == 0.0 && end_correction_ == 0.0 && tableau.stages > 0 && passes_.size() == 1) {
    shot_plan_ = {tableau, static_cast<int>(nodes_.size()), nodes_.data(), weights_.data(), n_,
                  field_->inverse_mass().data()};
    kernel::ExplicitShot shot;
    shot.plan = &shot_plan_;
    plugin_shoots_ = lagrangian.offers(kernel::call(shot));
  }
  step_ = manifold_.is_vector_space()
              ? for_dimension(n_, [](auto N) -> StepFunction { return &ShootingDiscreteLagrangian::step_at<decltype(N)::value>; })
              : &ShootingDiscreteLagrangian::step_at<Eigen::Dynamic>;
}

// The passes of a propagation. When the jets hold all 2n numbers of x = (eta, w0), one pass gives
// every derivative (dimensions 1..6). Otherwise (n > capacity / 2), the first
// derivatives come from passes over consecutive blocks of `capacity` numbers, and Phi's columns in
// w0, the only second derivatives the solve needs (shooting.hpp), from passes over a block of
// eta with a block of w0 and over two blocks of w0 (capacity / 2 numbers each): of the order of
// (n / (capacity / 2))^2 propagations, each of jets of `capacity` variables, instead of one of
// jets of 2n (2n + 4n^2 numbers each).
void ShootingDiscreteLagrangian::plan_passes(int capacity) {
  const int V = 2 * n_;
  const auto block = [](int first, int count) {
    std::vector<int> variables(count);
    for (int j = 0; j < count; ++j) variables[j] = first + j;
    return variables;
  };
  jet_size_ = std::min(V, capacity);  // every pass's jets alike: a method's workspace keeps its size
  if (V <= capacity) {
    passes_.push_back({block(0, V), true, true});
    return;
  }
  for (int first = 0; first < V; first += capacity)
    passes_.push_back({block(first, std::min(capacity, V - first)), true, false});
  const int half = capacity / 2;
  std::vector<std::vector<int>> eta, w0;
  for (int first = 0; first < n_; first += half) {
    eta.push_back(block(first, std::min(half, n_ - first)));
    w0.push_back(block(n_ + first, std::min(half, n_ - first)));
  }
  const auto joined = [](std::vector<int> a, const std::vector<int>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  for (const auto& a : eta)
    for (const auto& b : w0) passes_.push_back({joined(a, b), false, true});
  for (std::size_t b = 0; b < w0.size(); ++b)
    for (std::size_t c = b + 1; c < w0.size(); ++c) passes_.push_back({joined(w0[b], w0[c]), false, true});
}

// Every number of the state carries the pass's variables, with zero derivatives where it does not
// depend on them: a one-step method reads the variables of its derivatives off the state's jets
// (one_step.hpp), and on R^n those in eta enter through the field's origin, not the state.
Jet2 ShootingDiscreteLagrangian::seeded(double value, int variable) const {
  const int slot = variable < 0 ? -1 : slot_[variable];
  Jet2 jet(value);
  jet.resize(jet_size_);
  jet.gradient.setZero();
  jet.hessian.setZero();
  if (slot >= 0) jet.gradient[slot] = 1.0;
  return jet;
}

const Jet2* ShootingDiscreteLagrangian::position() {
  return mechanical_ != nullptr ? mechanical_->point(state_.data()) : state_.data();
}

// The quadrature's contribution at node i: h b_i L(q^i, v^i), plus the Euler-Maclaurin end
// correction h^2 a_1 dL/dt at t = 0 or h^2 z_1 dL/dt at t = h, where along the Euler-Lagrange
// flow dL/dt = <L_q, v> + <L_v, a>, a = M^{-1} L_q (the prolongation, paper, sec. 3).
void ShootingDiscreteLagrangian::accumulate(int node, double h, Jet2& S) {
  const bool first = node == 0, last = node + 1 == static_cast<int>(nodes_.size());
  const double correction = first ? start_correction_ : last ? end_correction_ : 0.0;
  if (weights_[node] == 0.0 && correction == 0.0) return;
  const Jet2* v = mechanical_ != nullptr ? mechanical_->velocity(state_.data()) : state_.data() + m_;
  Jet2 L;
  lagrangian_.gradient_jet(position(), v, &L, gradient_.data());
  add_scaled(S, h * weights_[node], L);
  if (forced_) add_work(h * weights_[node], v);
  if (correction == 0.0) return;
  field_->inverse_mass(gradient_.data(), acceleration_.data());
  Jet2 rate;
  for (int r = 0; r < n_; ++r) rate += gradient_[r] * v[r] + gradient_[n_ + r] * acceleration_[r];
  add_scaled(S, h * h * correction, rate);
}

// The virtual work of the forces at node i, weight = h b_i: W_x += weight q^i_x^T f_i and
// dW_x/dx += weight (sum_r f_ir q^i_r,xx + q^i_x^T f_i,x), f_i = f(t + c_i h, q^i, v^i) at jets
// (Marsden & West 2001, sec. 3.2, through the quadrature; see shooting.hpp).
void ShootingDiscreteLagrangian::add_work(double weight, const Jet2* v) {
  mechanical_->force(state_.data(), v, force_.data());
  const Jet2* point = position();
  for (int r = 0; r < n_; ++r) {
    const Jet2& q = point[r];
    if (q.constant()) continue;
    const double f = weight * force_[r].value;
    work_gradient_ += f * q.gradient;
    work_jacobian_ += f * q.hessian;
    if (!force_[r].constant()) work_jacobian_.noalias() += weight * q.gradient * force_[r].gradient.transpose();
  }
}

// q^0 = q0 exp(eta) at eta = 0 as jets in x = (eta, w0), the natural chart at q0 (paper, sec. 2
// "Natural charts"): eta carries D1 L_d, left-trivialized on a Lie group. On a vector space the
// chart is q0 + eta, held as the field's origin, and the state's positions are the offsets
// q^i - (q0 + eta), starting at 0 (position()). Otherwise the manifold's chart gives
// q0 exp(eta) exp(xi) in (eta, xi), whose xi-derivatives (xi = 0) are dropped: the variables
// n..2n-1 are w0 here.
void ShootingDiscreteLagrangian::start_point(const double* q0) {
  if (manifold_.is_vector_space()) {
    for (int r = 0; r < n_; ++r) {
      origin_[r] = seeded(q0[r], r);
      state_[r] = seeded(0.0, -1);
    }
    return;
  }
  const int V = 2 * n_;
  check(manifold_, manifold_.chart(q0, zero_.data(), zero_.data(),
                        {chart_value_.data(), chart_gradient_.data(), chart_hessian_.data()}, {}),
        "manifold chart");
  for (int r = 0; r < m_; ++r) {
    Jet2& q = state_[r] = seeded(chart_value_[r], -1);
    for (int a = 0; a < n_; ++a) {
      if (slot_[a] < 0) continue;
      q.gradient(slot_[a]) = chart_gradient_[r * V + a];
      for (int b = 0; b < n_; ++b)
        if (slot_[b] >= 0) q.hessian(slot_[a], slot_[b]) = chart_hessian_[(r * V + a) * V + b];
    }
  }
}

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

// Propagates (q^0, w^0) = (q0 exp(eta), w0) as jets in the pass's numbers of x = (eta, w0) through
// the nodes, then forms the generating function G and the boundary quantity B of the form.
void ShootingDiscreteLagrangian::propagate(const double* q0, const double* w0, double h, const Pass& pass) {
  work_gradient_.setZero(jet_size_);
  work_jacobian_.setZero(jet_size_, jet_size_);
  if (plugin_shoots_) {
    lagrangian_.shoot(shot_plan_, q0, w0, h, &generating_, boundary_.data());
    return;
  }
  std::fill(slot_.begin(), slot_.end(), -1);
  for (std::size_t j = 0; j < pass.variables.size(); ++j) slot_[pass.variables[j]] = static_cast<int>(j);
  start_point(q0);
  for (int r = 0; r < n_; ++r) state_[m_ + r] = seeded(w0[r], n_ + r);
  if (mechanical_ != nullptr && mechanical_->clock()) state_[2 * n_] = Jet2(t_);
  if (mechanical_ != nullptr) mechanical_->set_forced(forced_);
  Jet2 S;
  accumulate(0, h, S);
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    field_->step(method_, (nodes_[i] - nodes_[i - 1]) * h, state_.data(), next_.data(), stages_);
    std::swap(state_, next_);
    accumulate(static_cast<int>(i), h, S);
  }
  if (type_2()) {
    generating_ = -S;  // H_d^+ = <p^n, q^n> - S
    const Jet2* point = position();
    for (int r = 0; r < n_; ++r) generating_ += state_[n_ + r] * point[r];
    std::copy_n(state_.begin() + n_, n_, boundary_.begin());
  } else {
    generating_ = S;
    boundary();
  }
}

// B = local(q1, q^n), the natural chart at the far end (paper, sec. 2 "Natural charts"): at
// B = 0, lambda = dG/dB is D2 L_d left-trivialized at q1 (q1 exp(B) = q^n). The chart is at the
// given q1 when evaluating L_d, and at q^n's own value in a step (where q1 is the outcome), so
// that B = 0 there; its second derivatives enter Phi. On a vector space B = q^n - q1, taken as
// the offset q^n - (q0 + eta) (the targets subtract q1 - q0; B's derivative in eta is then the
// offset's plus I, see differentiate()).
void ShootingDiscreteLagrangian::boundary() {
  if (manifold_.is_vector_space()) {
    std::copy_n(state_.begin(), n_, boundary_.begin());
    return;
  }
  if (target_is_end_)
    for (int r = 0; r < m_; ++r) target_[r] = state_[r].value;
  for (int r = 0; r < m_; ++r) end_[r] = state_[r].value;
  check(manifold_, manifold_.local_derivatives(target_.data(), end_.data(),
                                    {local_value_.data(), local_gradient_.data(), local_hessian_.data()}),
        "manifold local_derivatives");
  // The chain rule from the point's jets: B_r = sum_k dB_r/dq_k q_k (first and second order).
  for (int r = 0; r < n_; ++r) {
    Jet2& b = boundary_[r] = seeded(local_value_[r], -1);
    for (int k = 0; k < m_; ++k) {
      const Jet2& q = state_[k];
      if (q.constant()) continue;
      const double d = local_gradient_[r * m_ + k];
      b.gradient += d * q.gradient;
      b.hessian += d * q.hessian;
      for (int l = 0; l < m_; ++l) {
        const double dd = local_hessian_[(r * m_ + k) * m_ + l];
        if (dd != 0.0 && !state_[l].constant()) b.hessian.noalias() += dd * q.gradient * state_[l].gradient.transpose();
      }
    }
  }
}

namespace {

// A jet's first and second derivatives in its variables i, j (zero for a constant).
double first(const Jet2& x, int i) { return x.constant() ? 0.0 : x.gradient[i]; }
double second(const Jet2& x, int i, int j) { return x.constant() ? 0.0 : x.hessian(i, j); }

}  // namespace

// The pass's first derivatives: alpha = G_x + W_x and B_x (B_x = [Bq_, Bw_]) in its numbers of x.
void ShootingDiscreteLagrangian::gather(const Pass& pass) {
  for (std::size_t j = 0; j < pass.variables.size(); ++j) {
    const int x = pass.variables[j], i = static_cast<int>(j);
    alpha_[x] = first(generating_, i) + work_gradient_[i];
    for (int r = 0; r < n_; ++r) (x < n_ ? Bq_(r, x) : Bw_(r, x - n_)) = first(boundary_[r], i);
  }
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
  if (offsets()) {
    Eigen::Map<Vector<N>>(momentum_change_.data(), n) = D1;
    D1 -= lambda;
  }
}

// Phi = d alpha/dx - sum_r lambda_r Hess B_r in pairs of the pass's numbers of x (alpha = G_x, + W_x
// with forces; Phi's rows are alpha's components, its columns the variables), in its columns in
// w0, the only ones the solve's Jacobians take (residual()).
void ShootingDiscreteLagrangian::second_derivatives(const Pass& pass) {
  const int k = static_cast<int>(pass.variables.size());
  for (int j = 0; j < k; ++j) {
    if (pass.variables[j] < n_) continue;
    for (int i = 0; i < k; ++i) {
      double phi = second(generating_, i, j) + work_jacobian_(i, j);
      for (int r = 0; r < n_; ++r) phi -= lambda_[r] * second(boundary_[r], i, j);
      phi_(pass.variables[i], pass.variables[j]) = phi;
    }
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
  // On a Lie group the point is the state's (one pass, whose variables are x = (eta, w0)); on a
  // vector space it is read from B.
  void finish(const Eigen::VectorXd& update_vector) {
    if (target != Target::momentum) return;
    const Eigen::Map<const Vector<N>> update(update_vector.data(), n);
    if (!s.manifold_.is_vector_space())
      for (int r = 0; r < s.m_; ++r)
        if (!s.state_[r].constant()) s.state_[r].value -= s.state_[r].gradient.tail(n).dot(update);
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

// The paper's shooting-based implementation: w0 = v0 from the inverse Legendre transform
// v0 = M^{-1} p0 (Lagrangian form), or w0 = p^0 guessed as p0 (Hamiltonian forms), corrected by
// the extrapolated corrections of the last steps (warm_start).
// On a vector space in a Type I form, q1 = q0 + (q^n - q0) and p1 = p0 + (D1 L_d + D2 L_d) - r
// (r = p0 + D1 L_d, the residual left; with forces D1 and D2 include f_d^-, f_d^+), the
// increments summed with Kahan's compensation across steps (compensated.hpp) while each step
// continues from the last one's output, as the Galerkin construction does.
void ShootingDiscreteLagrangian::take_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                      double* p1) {
  forced_ = !forces_.empty();
  t_ = t0;
  (this->*step_)(q0, p0, h, q1, p1);
}

template <int N>
void ShootingDiscreteLagrangian::step_at(const double* q0, const double* p0, double h, double* q1, double* p1) {
  const int n = fixed_or<N>(n_), m = fixed_or<N>(m_);  // N is fixed on R^n only, where m = n
  const Eigen::Map<const Vector<N>> start(q0, m), momentum(p0, n);
  Eigen::Map<Vector<N>> end_q(end_q_.data(), m), end_p(end_p_.data(), n), guess(guess_.data(), n);
  const bool continues = continuing_ && end_q == start && end_p == momentum;
  if (form_ == ShootingForm::lagrangian && field_->constant_mass())
    guess.noalias() = Eigen::Map<const Square<N>>(field_->inverse_mass().data(), n, n) * momentum;
  else if (form_ == ShootingForm::lagrangian) mechanical_->velocity_of(q0, p0, guess_.data());
  else guess = momentum;
  warm_start<N>(continues && h == previous_h_);
  target_is_end_ = true;
  solve<N>(q0, h, Target::momentum, p0);
  record_correction<N>(h);
  Eigen::Map<Vector<N>> p(p1, n);
  if (offsets()) {
    Eigen::Map<Vector<N>> carry_q(carry_q_.data(), n), carry_p(carry_p_.data(), n),
        offset(offset_.data(), n), change(momentum_change_.data(), n);
    if (!continues) {
      carry_q.setZero();
      carry_p.setZero();
    }
    for (int r = 0; r < n; ++r) offset[r] = boundary_[r].value;
    change -= Eigen::Map<const Vector<N>>(residual_.data(), n);
    end_q = start;
    compensated_add(end_q, offset, carry_q);
    end_p = momentum;
    compensated_add(end_p, change, carry_p);
    Eigen::Map<Vector<N>>(q1, n) = end_q;
    p = end_p;
  } else {
    if (type_2()) {
      for (int r = 0; r < n; ++r) p[r] = boundary_[r].value;
      Eigen::Map<Vector<N>>(q1, n) = Eigen::Map<const Vector<N>>(lambda_.data(), n);
    } else {
      for (int r = 0; r < m; ++r) q1[r] = state_[r].value;
      p = Eigen::Map<const Vector<N>>(lambda_.data(), n);  // with forces p1 = D2 L_d + f_d^+
    }
    end_q = Eigen::Map<const Vector<N>>(q1, m);
    end_p = p;
  }
  continuing_ = true;
}

// The warm start: w0 = guess + c, the correction c = w0 - guess of the step extrapolated from the
// last steps' (while the steps continue one another at the same h) by the polynomial through up to
// three of them. The correction is a smooth function of the state along the motion, of the
// size of the method's local error (the inverse Legendre transform is exact for the exact flow),
// so that the first shot's residual is of that size times h^k, k the corrections used. With the
// guess alone the first residual of the pendulum at h = 0.005 (SVIRK4) was 1e-12 and every step
// took two shots; from the extrapolation the first update is at round-off and the step one shot
// (Newton's stopping rule, solve/newton.hpp: the error left is of the update's square).
template <int N>
void ShootingDiscreteLagrangian::warm_start(bool continues) {
  if (!continues) corrections_ = 0;
  static constexpr double kExtrapolation[3][3] = {{1.0, 0.0, 0.0}, {2.0, -1.0, 0.0}, {3.0, -3.0, 1.0}};
  const int n = fixed_or<N>(n_);
  Eigen::Map<Vector<N>> w(w_.data(), n);
  w = Eigen::Map<const Vector<N>>(guess_.data(), n);
  if (corrections_ == 0) return;
  const double* c = kExtrapolation[corrections_ - 1];
  for (int k = 0; k < corrections_; ++k) w += c[k] * Eigen::Map<const Vector<N>>(&corrections_history_(0, k), n);
}

// The converged step's correction w0 - guess joins the history (newest first).
template <int N>
void ShootingDiscreteLagrangian::record_correction(double h) {
  const int n = fixed_or<N>(n_);
  const auto correction = [&](int k) { return Eigen::Map<Vector<N>>(&corrections_history_(0, k), n); };
  for (int k = kCorrections - 1; k > 0; --k) correction(k) = correction(k - 1);
  correction(0) = Eigen::Map<const Vector<N>>(w_.data(), n) - Eigen::Map<const Vector<N>>(guess_.data(), n);
  corrections_ = std::min(corrections_ + 1, kCorrections);
  previous_h_ = h;
}

const EvaluationCounters& ShootingDiscreteLagrangian::evaluations() const {
  counters_ = lagrangian_.counters();
  counters_.force = forces_.evaluations();
  return counters_;
}

// From the velocity local(q0, q1)/h of the chart's straight line (times M for a momentum).
void ShootingDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h,
                                          double* Ld, double* D1, double* D2) {
  forced_ = false;  // L_d alone: the forces are not part of it
  check(manifold_, manifold_.local(q0, q1, w_.data()), "manifold chart");
  w_ /= h;
  if (form_ != ShootingForm::lagrangian) {  // p0's guess: the momentum of that velocity at q0
    v_values_ = w_;
    mechanical_->momentum(q0, v_values_.data(), w_.data());
  }
  target_is_end_ = false;
  std::copy_n(q1, m_, target_.begin());
  // On a vector space B = q^n - q0 against q1 - q0 (type-2: lambda against q1); through the chart
  // at q1, B = local(q1, q^n) against 0.
  if (type_2()) {
    solve<Eigen::Dynamic>(q0, h, Target::lambda, q1);
  } else if (offsets()) {
    offset_ = Eigen::Map<const Eigen::VectorXd>(q1, n_) - Eigen::Map<const Eigen::VectorXd>(q0, n_);
    solve<Eigen::Dynamic>(q0, h, Target::boundary, offset_.data());
  } else {
    solve<Eigen::Dynamic>(q0, h, Target::boundary, zero_.data());
  }
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
