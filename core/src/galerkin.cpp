#include "varia/core/galerkin.hpp"

#include "galerkin_equations.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace varia {

namespace {

// l_nu(tau) and l'_nu(tau) of the Lagrange basis through the control times d.
// (In T: the node iteration's maps are formed in long double.)
template <class T>
void lagrange(const std::vector<double>& d, T tau, T* l, T* dl) {
  const int count = static_cast<int>(d.size());
  for (int nu = 0; nu < count; ++nu) {
    T value = 1.0, derivative = 0.0;
    for (int mu = 0; mu < count; ++mu) {
      if (mu == nu) continue;
      const T denominator = T(d[nu]) - T(d[mu]);
      derivative = derivative * (tau - d[mu]) / denominator + value / denominator;
      value *= (tau - d[mu]) / denominator;
    }
    l[nu] = value;
    if (dl != nullptr) dl[nu] = derivative;
  }
}

void check_control_times(const std::vector<double>& d) {
  if (d.size() < 2) throw std::invalid_argument("a Galerkin interpolant needs degree >= 1");
  if (d.front() != 0.0 || d.back() != 1.0)
    throw std::invalid_argument("control times must start at 0 and end at 1");
  for (std::size_t i = 1; i < d.size(); ++i)
    if (!(d[i] > d[i - 1])) throw std::invalid_argument("control times must increase");
}

}  // namespace

std::vector<double> equispaced_control_times(int degree) {
  if (degree < 1) throw std::invalid_argument("a Galerkin interpolant needs degree >= 1");
  std::vector<double> d(degree + 1);
  for (int nu = 0; nu <= degree; ++nu) d[nu] = static_cast<double>(nu) / degree;
  return d;
}

std::vector<double> chebyshev_lobatto_control_times(int degree) {
  if (degree < 1) throw std::invalid_argument("a Galerkin interpolant needs degree >= 1");
  std::vector<double> d(degree + 1);
  for (int nu = 0; 2 * nu <= degree; ++nu) {
    const double half_sine = std::sin(M_PI * nu / (2.0 * degree));  // (1 - cos x) / 2 = sin^2(x / 2)
    d[nu] = half_sine * half_sine;
    d[degree - nu] = 1.0 - d[nu];
  }
  if (degree % 2 == 0) d[degree / 2] = 0.5;
  return d;
}

LagrangeBasis::LagrangeBasis(const std::vector<double>& times, const Quadrature& quadrature)
    : control_times(times) {
  check_control_times(times);
  const int r = quadrature.size(), count = static_cast<int>(times.size());
  phi.resize(count, r);
  dphi.resize(count, r);
  for (int i = 0; i < r; ++i) lagrange(times, quadrature.nodes()[i], phi.col(i).data(), dphi.col(i).data());
}

Eigen::VectorXd lagrange_basis_at(const std::vector<double>& times, double tau) {
  Eigen::VectorXd l(times.size());
  lagrange<double>(times, tau, l.data(), nullptr);
  return l;
}

Eigen::VectorXd LagrangeBasis::at(double tau) const { return lagrange_basis_at(control_times, tau); }

GalerkinDiscreteLagrangian::GalerkinDiscreteLagrangian(Manifold& manifold, Lagrangian& lagrangian,
                                                       Quadrature& quadrature,
                                                       std::vector<double> control_times,
                                                       SolverOptions options,
                                                       std::vector<Force*> forces,
                                                       HolonomicConstraints* constraints)
    : lagrangian_(lagrangian),
      forces_(std::move(forces), manifold.dim(), manifold.dim()),
      basis_(control_times, quadrature),
      weights_(Eigen::Map<const Eigen::VectorXd>(quadrature.weights(), quadrature.size())),
      nodes_(Eigen::Map<const Eigen::VectorXd>(quadrature.nodes(), quadrature.size())),
      options_(options),
      solver_(options),
      n_(manifold.dim()),
      s_(static_cast<int>(control_times.size()) - 1) {
  if (!manifold.is_vector_space())
    throw std::invalid_argument("the Galerkin construction needs a natural chart on this manifold");
  if (lagrangian.position_size() != n_ || lagrangian.velocity_size() != n_)
    throw std::invalid_argument("the Lagrangian's sizes do not match the manifold's dimension");
  if (quadrature.derivative_terms() > 0)
    throw std::invalid_argument(
        "the Galerkin construction takes quadratures without endpoint derivative terms");
  extrapolation_.resize(s_ + 1, s_ + 1);
  for (int nu = 0; nu <= s_; ++nu) extrapolation_.col(nu) = basis_.at(1.0 + control_times[nu]);
  origin_.resize(n_);
  points_.resize(n_, s_ + 1);
  previous_.resize(n_, s_ + 1);
  previous_end_.resize(n_);
  carry_q_ = Eigen::VectorXd::Zero(n_);
  carry_p_ = Eigen::VectorXd::Zero(n_);
  end_p_.resize(n_);
  impulse_.resize(n_);
  change_.resize((s_ + 1) * n_);
  q_.resize(n_);
  v_ = Eigen::VectorXd::Zero(n_);  // the explicit form evaluates dL/dq at v = 0 (it does not depend on v there)
  velocity_ = Eigen::VectorXd::Zero(n_);
  grad_.resize(2 * n_);
  gradient_.resize((s_ + 1) * n_);
  f_.resize(n_);
  force_values_.resize(static_cast<Eigen::Index>(forces_.rows().size()));
  if (lagrangian_.sparse()) {
    sparse_values_.resize(lagrangian_.pattern_size());
    for (int e = 0; e < lagrangian_.pattern_size(); ++e) {
      const int r = lagrangian_.pattern_rows()[e], c = lagrangian_.pattern_cols()[e];
      entries_.push_back(Entry{r % n_, c % n_, r >= n_, c >= n_});
    }
  } else {
    hess_.resize(2 * n_, 2 * n_);
    column_.resize(2 * n_);
    hessian_.resize((s_ + 1) * n_, (s_ + 1) * n_);
    dense_ = DenseLinearization(s_ * n_);
  }
  // The forces' Jacobian [df/dq, df/dv]: rows are equations (weighted by l_nu, never by v).
  for (std::size_t e = 0; e < forces_.rows().size(); ++e)
    entries_.push_back(Entry{forces_.rows()[e], forces_.cols()[e] % n_, false, forces_.cols()[e] >= n_});
  action_ = action_function(n_);
  if (constraints != nullptr && constraints->size() > 0) {  // the exact Newton with multipliers only
    constraints_ = constraints;
    multipliers_ = Eigen::MatrixXd::Zero(constraints->size(), s_);
    position_update_.resize(s_ * n_);
    momentum_.resize(n_);
    step_ = step_function(n_, 0, false);
    return;
  }
  explicit_advance_ = explicit_form(quadrature);
  if (explicit_advance_ != nullptr) return;
  node_iteration_ = simplified_applies();
  step_ = step_function(n_, static_cast<int>(iteration_nodes_.size()), node_iteration_);
}

const EvaluationCounters& GalerkinDiscreteLagrangian::evaluations() const {
  counters_ = lagrangian_.counters();
  counters_.force = forces_.evaluations();
  return counters_;
}

// E(m, j) = l_m(c_j): the Lagrange basis through the times t_m that are not NaN, at the
// iteration's nodes c_j (a zero row for a NaN time).
Eigen::MatrixXd GalerkinDiscreteLagrangian::extrapolation_to_nodes(const std::vector<double>& times) const {
  const int count = static_cast<int>(times.size()), R = static_cast<int>(iteration_nodes_.size());
  std::vector<double> known;
  std::vector<int> rows;
  for (int m = 0; m < count; ++m)
    if (!std::isnan(times[m])) {
      known.push_back(times[m]);
      rows.push_back(m);
    }
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(count, R);
  for (int j = 0; j < R; ++j) {
    const Eigen::VectorXd l = lagrange_basis_at(known, nodes_[iteration_nodes_[j]]);
    for (std::size_t k = 0; k < rows.size(); ++k) E(rows[k], j) = l[static_cast<Eigen::Index>(k)];
  }
  return E;
}

// A constant mass matrix, no forces (f(v) would add to the kinetic part); a dense Lagrangian's M
// symmetric positive definite (the Lagrangian hyperregular), and the stiffness matrix's block for
// the step's equations invertible (it is: K's kernel is the constants, and its rows sum to 0).
// The maps (see the top of galerkin.hpp): with the forces g_j at the R nodes of nonzero weight
// given, the step's equations
//   p0 delta_nu0 + (1/h) M sum_{mu=1..s} K_numu X^mu + h sum_j b_j l_nu(c_j) g_j = 0, nu < s,
// in the offsets X^mu = q^mu - q^0 are linear, solved by the inverse of K's block:
//   X^mu = h (alpha_mu u0 + h sum_j P_muj M^{-1} g_j), alpha_mu = -(K^{-1})_{mu 0},
//   P_muj = -b_j sum_nu (K^{-1})_{mu nu} l_nu(c_j),   u0 = M^{-1} p0,
// and the nodes' offsets are the interpolant's there, sum_mu l_mu(c_i) X^mu.
bool GalerkinDiscreteLagrangian::simplified_applies() {
  if (!forces_.empty()) return false;
  if (lagrangian_.sparse()) {
    // M from the Hessian's velocity block, factorized at the first step (inverse_mass_times)
    if (!lagrangian_.plugin().has_constant_mass_matrix()) return false;
  } else {
    mass_matrix_.resize(n_, n_);
    if (!lagrangian_.plugin().constant_mass_matrix(mass_matrix_.data())) return false;
    const Eigen::LLT<Eigen::MatrixXd> mass(mass_matrix_);
    if (mass.info() != Eigen::Success) return false;
    inverse_mass_ = mass.solve(Eigen::MatrixXd::Identity(n_, n_));
  }
  // In long double (64-bit mantissa on x86, else double): K's block is ill-conditioned at larger s,
  // and a map's rounding is a change of the method, the same at every step (bench/README.md,
  // "Measured design choices").
  using Extended = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  const int r = static_cast<int>(nodes_.size());
  Extended phi(s_ + 1, r), dphi(s_ + 1, r), stiffness = Extended::Zero(s_ + 1, s_ + 1);
  for (int i = 0; i < r; ++i) {
    lagrange<long double>(basis_.control_times, nodes_[i], phi.col(i).data(), dphi.col(i).data());
    stiffness.noalias() += static_cast<long double>(weights_[i]) * dphi.col(i) * dphi.col(i).transpose();
  }
  const Eigen::FullPivLU<Extended> block(stiffness.block(0, 1, s_, s_));
  if (!block.isInvertible()) return false;
  const Extended K_inverse = block.inverse();  // row mu - 1 (X^mu), column nu (equation)
  iteration_nodes_.clear();
  for (int i = 0; i < r; ++i)
    if (weights_[i] != 0.0) iteration_nodes_.push_back(i);
  const int R = static_cast<int>(iteration_nodes_.size());
  Extended control(s_, 1 + R), interpolation(R, s_);  // interpolation: l_mu(c_j), mu = 1..s
  control.col(0) = -K_inverse.col(0);
  for (int j = 0; j < R; ++j) {
    const int i = iteration_nodes_[j];
    control.col(1 + j) = -static_cast<long double>(weights_[i]) * K_inverse * phi.col(i).head(s_);
    interpolation.row(j) = phi.col(i).tail(s_).transpose();
  }
  // The straight line X^mu = d_mu h u0 solves the equations without forces where the quadrature
  // integrates l'_nu exactly (sum_mu K_numu d_mu = l_nu(1) - l_nu(0)): then alpha_mu = d_mu, and
  // the nodes' coefficient of u0 is c_j. Where alpha agrees with that to rounding, the exact values
  // are taken: through K^{-1} alpha_s is off by an ulp, the same at every step, and q1 - q0 =
  // h alpha_s u0 + ... walked by an ulp of h u0 a step (bench/README.md, "Measured design choices").
  const Eigen::VectorXd line = Eigen::Map<const Eigen::VectorXd>(basis_.control_times.data() + 1, s_);
  control_map_ = control.cast<double>();
  node_map_ = (interpolation * control).cast<double>();
  if ((control_map_.col(0) - line).lpNorm<Eigen::Infinity>() <= 1e-12) {
    control_map_.col(0) = line;
    for (int j = 0; j < R; ++j) node_map_(j, 0) = nodes_[iteration_nodes_[j]];
  }
  prepare_node_iteration();
  return true;
}

// The node iteration's workspace (galerkin_node_iteration.cpp) and its warm start's extrapolations of the
// nodes' accelerations from the last steps, once the maps are formed.
void GalerkinDiscreteLagrangian::prepare_node_iteration() {
  const int R = static_cast<int>(iteration_nodes_.size());
  end_map_ = control_map_.bottomRows(1);
  velocity0_.resize(n_);
  for (Eigen::VectorXd* v : {&node_offsets_, &next_offsets_, &node_accelerations_, &predicted_accelerations_})
    v->resize(R * n_);
  node_points_ = Eigen::VectorXd::Zero(2 * n_ * R);  // the velocities stay 0 (L_q does not depend on v)
  node_gradients_.resize(2 * n_ * R);
  acceleration_history_ = Eigen::MatrixXd::Zero(n_, 2 * R);
  // The history's times, in steps from the next step's start: the last step's nodes c_j - 1, the
  // step's before c_j - 2 (NaN: not used).
  std::vector<double> last(2 * R, NAN), two_back(2 * R, NAN);
  for (int j = 0; j < R; ++j) last[j] = two_back[j] = nodes_[iteration_nodes_[j]] - 1.0;
  for (int j = R - 1, taken = 0; j >= 0 && taken < 2; --j) {
    const double t = nodes_[iteration_nodes_[j]] - 2.0;
    const bool repeated = std::any_of(last.begin(), last.end(), [&](double u) { return std::abs(u - t) < 1e-12; });
    if (!repeated) two_back[R + j] = t, ++taken;
  }
  acceleration_extrapolation_[0] = extrapolation_to_nodes(last);
  acceleration_extrapolation_[1] = extrapolation_to_nodes(two_back);
  for (int k = 0; k < 2; ++k) {  // the nodes' offsets from the history: [u0's | W E_k^T]
    prediction_map_[k].resize(R, 1 + 2 * R);
    prediction_map_[k].col(0) = node_map_.col(0);
    prediction_map_[k].rightCols(2 * R).noalias() = node_map_.rightCols(R) * acceleration_extrapolation_[k].transpose();
  }
}

void GalerkinDiscreteLagrangian::take_steps(double* q, double* p, double t0, double h, long steps, double* q1,
                                            double* p1) {
  if (explicit_advance_ != nullptr) return (this->*explicit_advance_)(q, p, h, steps);
  repeat_steps(  // by step_, without a virtual call a step
      [this](const double* q0, const double* p0, double t, double step, double* q_end, double* p_end) {
        t_ = t;
        (this->*step_)(q0, p0, step, q_end, p_end);
      },
      q, p, t0, h, steps, q1, p1);
}

// Eigen's SparseLU: the symbolic analysis (COLAMD ordering) once per structure, the numerical
// factorization when the solver asks for it.
void GalerkinDiscreteLagrangian::factorize_sparse() {
  if (!sparse_.analyzed) {
    sparse_.lu.analyzePattern(sparse_.matrix);
    sparse_.analyzed = true;
  }
  sparse_.lu.factorize(sparse_.matrix);
  if (sparse_.lu.info() != Eigen::Success)
    throw NumericalFailure("the Galerkin Newton Jacobian is singular: " + sparse_.lu.lastErrorMessage(),
                           std::nan(""));
}

// Newton's method with the exact Jacobian (solve/newton.hpp: its stopping rule, and the update
// from the last residual always applied).
void GalerkinDiscreteLagrangian::newton(double h, int first_unknown, int first_equation,
                                        int blocks, const double* p0, bool forced) {
  if (lagrangian_.sparse()) prepare_sparse(first_unknown, first_equation, blocks);
  if (constraints_ != nullptr) return constrained_newton(h, first_unknown, first_equation, blocks, p0, forced);
  const int size = blocks * n_;
  if (!lagrangian_.sparse() && dense_.jacobian.rows() != size) dense_ = DenseLinearization(size);
  Equations equations{*this, h, first_unknown, first_equation, blocks, p0, forced};
  require_converged(solver_.solve(equations, statistics_), "the Galerkin equations");
}

// The gradient (and impulse_) at the points just updated. Dense: from the Hessian at hand, to
// first order in the update (dS/dq^nu -= sum_mu d2S/dq^nu dq^mu update^mu); the update is at
// round-off here, so the neglected O(|update|^2) term is far below it and no evaluation is made.
// Sparse: the Jacobian holds only the equations' rows, so the gradient is evaluated again.
void GalerkinDiscreteLagrangian::gradient_after_update(double h, int first_unknown,
                                                       Eigen::Ref<const Eigen::VectorXd> update, bool forced) {
  if (lagrangian_.sparse()) {
    action(h, Order::gradient, forced);
    return;
  }
  change_.noalias() = hessian_.middleCols(first_unknown * n_, update.size()) * update;
  gradient_ -= change_;
  for (int nu = 0; nu <= s_; ++nu) impulse_ -= change_.segment(nu * n_, n_);
}

void GalerkinDiscreteLagrangian::take_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                           double* p1) {
  if (explicit_advance_ != nullptr) {
    std::copy_n(q0, n_, q1);
    std::copy_n(p0, n_, p1);
    return (this->*explicit_advance_)(q1, p1, h, 1);
  }
  t_ = t0;
  (this->*step_)(q0, p0, h, q1, p1);
}

void GalerkinDiscreteLagrangian::evaluate(const double* q0, const double* q1, double h, double* Ld,
                                          double* D1, double* D2) {
  const Eigen::Map<const Eigen::VectorXd> a(q0, n_), b(q1, n_);
  origin_ = a;
  for (int nu = 0; nu <= s_; ++nu) points_.col(nu) = basis_.control_times[nu] * (b - a);
  if (s_ > 1) newton(h, 1, 1, s_ - 1, nullptr, false);
  const double S = action(h, Order::value_and_gradient);
  if (Ld != nullptr) *Ld = S;
  if (D1 != nullptr) Eigen::Map<Eigen::VectorXd>(D1, n_) = gradient_.head(n_);
  if (D2 != nullptr) Eigen::Map<Eigen::VectorXd>(D2, n_) = gradient_.segment(s_ * n_, n_);
}

}  // namespace varia
