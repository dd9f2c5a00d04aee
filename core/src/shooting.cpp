#include "varia/core/shooting.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "varia/core/lie_group_field.hpp"

namespace varia {

namespace {

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
// forces; with constraints the constrained field in (q, v) (constrained_field.hpp); on a Lie group
// in (g, xi) (the Euler-Poincare field, lie_group_field.hpp).
std::unique_ptr<EulerLagrangeField> field_of(Manifold& manifold, LagrangianEvaluator& lagrangian,
                                            ShootingForm form, Forces& forces, HolonomicConstraints* constraints) {
  if (constraints != nullptr) {
    if (form != ShootingForm::lagrangian || !forces.empty())
      throw ConstraintsRefused("with constraints the shooting construction takes the lagrangian form and no forces");
    if (!constraints->quadratic())
      throw ConstraintsRefused(
          "with constraints the shooting construction takes quadratic constraints only (Constraint::quadratic, as "
          "rod and S2's): its shot carries the constrained field at second-order jets, which would need the "
          "constraints' third and fourth derivatives");
    return std::make_unique<ConstrainedField>(lagrangian, *constraints);
  }
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
                                                       int jet_capacity, HolonomicConstraints* constraints)
    : manifold_(manifold),
      lagrangian_(checked(manifold, lagrangian, form)),
      forces_(std::move(forces), manifold.point_size(), manifold.dim()),
      field_(field_of(manifold, lagrangian_, form, forces_, constraints)),
      mechanical_(dynamic_cast<MechanicalField*>(field_.get())),
      constrained_(dynamic_cast<ConstrainedField*>(field_.get())),
      constraints_(constraints),
      method_(method),
      form_(form),
      options_(options),
      solver_(options),
      m_(manifold.point_size()),
      n_(manifold.dim() - (constraints != nullptr ? constraints->size() : 0)),
      adjoint_solver_(options) {
  method_.set_solver(options.tolerance, options.max_iterations);
  take_quadrature(quadrature);
  refuse_unsupported();
  if (jet_capacity < 2 || jet_capacity > kMaxJetVariables)
    throw std::invalid_argument("the shooting construction's jets hold 2 to " + std::to_string(kMaxJetVariables) +
                                " variables");
  plan_passes(std::min(jet_capacity, field_->jet_variables()));
  size_workspace();
  if (mechanical_ != nullptr) mechanical_->set_origin(origin_.data());
  offer_explicit_shot(lagrangian);
  offer_adjoint();
  step_ = constrained_ != nullptr ? &ShootingDiscreteLagrangian::step_on_constraint
                                  : step_function(n_, manifold_.is_vector_space());
}

// The nodes 0 = c_0 < ... < c_n = 1 with zero weights where the rule has no node (paper, sec. 3),
// and the rule's end corrections (first derivatives of the integrand at 0 and 1 only).
void ShootingDiscreteLagrangian::take_quadrature(Quadrature& quadrature) {
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
}

// What the construction does not take: forces in the type-2 form, and end corrections anywhere but
// on a vector space without forces for a Lagrangian with a constant mass matrix.
void ShootingDiscreteLagrangian::refuse_unsupported() const {
  if (!forces_.empty() && type_2())
    throw std::invalid_argument("the shooting construction takes forces in the lagrangian and "
                                "hamiltonian forms (Type I generating functions), not type-2");
  if ((!forces_.empty() || mechanical_ == nullptr || !field_->constant_mass()) &&
      (start_correction_ != 0.0 || end_correction_ != 0.0))
    throw std::invalid_argument("the shooting construction takes end-derivative quadratures on vector spaces "
                                "without forces, for a Lagrangian with a constant mass matrix, only");
}

void ShootingDiscreteLagrangian::size_workspace() {
  state_.resize(field_->size());
  next_.resize(field_->size());
  target_.resize(m_);
  force_.resize(n_);
  alpha_.resize(2 * n_);
  zero_.assign(std::max(m_, n_), 0.0);
  slot_.resize(2 * n_);
  acceleration_.resize(n_);
  gradient_.resize(lagrangian_.position_size() + lagrangian_.velocity_size());
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
  guess_ = Eigen::VectorXd::Zero(n_);
  corrections_history_.resize(n_, kCorrections);
  origin_.resize(n_);
  Bq_.resize(n_, n_);
  Bw_.resize(n_, n_);
  phi_.resize(2 * n_, 2 * n_);
  jacobian_.resize(n_, n_);
  BwT_solver_ = SmallDenseSolver(n_);
  jacobian_solver_ = SmallDenseSolver(n_);
  if (constrained_ == nullptr) return;
  start_basis_.resize(m_, n_);
  end_basis_.resize(m_, n_);
  tangent_basis_ = std::make_unique<TangentBasis>(*constraints_);
  chart_momentum_.resize(n_);
  velocity_.resize(m_);
  embedded_momentum_.resize(m_);
}

// Where the step is one recurrence (an explicit method, a constant mass matrix, no forces or end
// corrections, one pass), the plugin is offered to run the shot with its model inlined.
void ShootingDiscreteLagrangian::offer_explicit_shot(Lagrangian& lagrangian) {
  const RungeKuttaTableau tableau = method_.explicit_tableau();
  if (offsets() && form_ == ShootingForm::lagrangian && field_->constant_mass() && forces_.empty() &&
      start_correction_ == 0.0 && end_correction_ == 0.0 && tableau.stages > 0 && passes_.size() == 1) {
    shot_plan_ = {tableau, static_cast<int>(nodes_.size()), nodes_.data(), weights_.data(), n_,
                  field_->inverse_mass().data()};
    kernel::ExplicitShot shot;
    shot.plan = &shot_plan_;
    plugin_shoots_ = lagrangian.offers(kernel::call(shot));
  }
}

// Where the exact Newton Jacobian takes several passes of jets (2n above the jets' capacity) and
// the shot is one explicit recurrence at doubles, the step solves on the shot's adjoint
// (shot_adjoint.hpp): one forward and one reverse sweep an iteration, whatever n.
void ShootingDiscreteLagrangian::offer_adjoint() {
  const RungeKuttaTableau tableau = method_.explicit_tableau();
  if (passes_.size() > 1 && offsets() && field_->constant_mass() && forces_.empty() && start_correction_ == 0.0 &&
      end_correction_ == 0.0 && tableau.stages > 0) {
    adjoint_ = std::make_unique<ShotAdjoint>(lagrangian_, field_->inverse_mass(), tableau, nodes_, weights_,
                                             form_ == ShootingForm::hamiltonian);
    adjoint_guess_.resize(n_);
    adjoint_scratch_.resize(n_);
    lambda_guess_.resize(n_);
    corrections_history_.resize(2 * n_, kCorrections);
  }
}

// The passes of a propagation. When the jets hold all 2n numbers of x = (eta, w0), one pass gives
// every derivative (dimensions 1..6). Otherwise (n > capacity / 2), the first
// derivatives come from passes over consecutive blocks of `capacity` numbers, and Phi's columns in
// w0, the only second derivatives the solve needs (shooting.hpp), from passes over a block of
// eta with a block of w0 and over two blocks of w0 (capacity / 2 numbers each): of the order of
// (n / (capacity / 2))^2 propagations, each of jets of `capacity` variables, instead of one of
// jets of 2n (2n + 4n^2 numbers each).
namespace {

// The numbers [first, first + count) of x.
std::vector<int> block(int first, int count) {
  std::vector<int> variables(count);
  for (int j = 0; j < count; ++j) variables[j] = first + j;
  return variables;
}

std::vector<int> joined(std::vector<int> a, const std::vector<int>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

void ShootingDiscreteLagrangian::plan_passes(int capacity) {
  const int V = 2 * n_;
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
  for (const auto& a : eta)
    for (const auto& b : w0) passes_.push_back({joined(a, b), false, true});
  for (std::size_t b = 0; b < w0.size(); ++b)
    for (std::size_t c = b + 1; c < w0.size(); ++c) passes_.push_back({joined(w0[b], w0[c]), false, true});
  // The tangent map's shot needs Phi's columns in eta too: every pair of blocks of x, after the
  // first-order passes.
  std::vector<std::vector<int>> blocks;
  for (int first = 0; first < V; first += half) blocks.push_back(block(first, std::min(half, V - first)));
  for (const Pass& pass : passes_)
    if (pass.first_order) tangent_passes_.push_back(pass);
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t c = b + 1; c < blocks.size(); ++c)
      tangent_passes_.push_back({joined(blocks[b], blocks[c]), false, true});
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
// n..2n-1 are w0 here. With constraints (x = (a, w0)) q^0 and v^0 are q0 + N0 a and N0 w0
// projected onto the constraint and its hidden constraint: a chart of Q at q0, exact at jets.
void ShootingDiscreteLagrangian::start_point(const double* q0, const double* w0) {
  if (constrained_ != nullptr) {
    for (int r = 0; r < m_; ++r) {
      Jet2& q = state_[r] = seeded(q0[r], -1);
      Jet2& v = state_[m_ + r] = seeded(0.0, -1);
      for (int a = 0; a < n_; ++a) {
        v.value += start_basis_(r, a) * w0[a];
        if (slot_[a] >= 0) q.gradient[slot_[a]] = start_basis_(r, a);
        if (slot_[n_ + a] >= 0) v.gradient[slot_[n_ + a]] = start_basis_(r, a);
      }
    }
    constrained_->project(state_.data(), state_.data() + m_, options_);
    return;
  }
  for (int r = 0; r < n_; ++r) state_[m_ + r] = seeded(w0[r], n_ + r);
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
  start_point(q0, w0);
  if (mechanical_ != nullptr && mechanical_->clock()) state_[2 * n_] = Jet2(t_);
  if (mechanical_ != nullptr) mechanical_->set_forced(forced_);
  Jet2 S;
  accumulate(0, h, S);
  for (std::size_t i = 1; i < nodes_.size(); ++i) {
    field_->step(method_, (nodes_[i] - nodes_[i - 1]) * h, state_.data(), next_.data(), stages_);
    std::swap(state_, next_);
    if (constrained_ != nullptr) constrained_->project(state_.data(), state_.data() + m_, options_);
    accumulate(static_cast<int>(i), h, S);
  }
  if (type_2()) {
    // H_d^+ = <p^n, q^n> - S, formed as G = <p^n, q^n - (q0 + eta)> - S from the state's offsets:
    // its multiplier lambda is then q1 - q0, an increment that the step sums with Kahan's
    // compensation, and D1 gains <p^n, q0 + eta>'s eta-derivative p^n (first_derivatives), the
    // Newton Jacobian its w0-derivative B_w (residual).
    generating_ = -S;
    for (int r = 0; r < n_; ++r) generating_ += state_[n_ + r] * state_[r];
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
  if (target_is_end_ && mechanical_ == nullptr)
    for (int r = 0; r < m_; ++r) target_[r] = state_[r].value;
  if (constrained_ != nullptr) {  // B = N1^T (q^n - c), c the target
    end_basis_ = tangent_basis_->at(target_.data());
    for (int r = 0; r < n_; ++r) {
      Jet2& b = boundary_[r] = seeded(0.0, -1);
      for (int k = 0; k < m_; ++k) {
        add_scaled(b, end_basis_(k, r), state_[k]);
        b.value -= end_basis_(k, r) * target_[k];
      }
    }
    return;
  }
  if (manifold_.is_vector_space()) {
    std::copy_n(state_.begin(), n_, boundary_.begin());
    return;
  }
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

// Phi = d alpha/dx - sum_r lambda_r Hess B_r in pairs of the pass's numbers of x (alpha = G_x, + W_x
// with forces; Phi's rows are alpha's components, its columns the variables), in its columns in
// w0, the only ones the solve's Jacobians take (residual()).
void ShootingDiscreteLagrangian::second_derivatives(const Pass& pass) {
  const int k = static_cast<int>(pass.variables.size());
  for (int j = 0; j < k; ++j) {
    if (pass.variables[j] < n_ && !all_second_derivatives_) continue;
    for (int i = 0; i < k; ++i) {
      double phi = second(generating_, i, j) + work_jacobian_(i, j);
      for (int r = 0; r < n_; ++r) phi -= lambda_[r] * second(boundary_[r], i, j);
      phi_(pass.variables[i], pass.variables[j]) = phi;
    }
  }
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

const EvaluationCounters& ShootingDiscreteLagrangian::evaluations() const {
  counters_ = lagrangian_.counters();
  counters_.force = forces_.evaluations();
  return counters_;
}

}  // namespace varia
