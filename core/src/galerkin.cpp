#include "varia/core/galerkin.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "varia/core/compensated.hpp"
#include "varia/core/fixed_size.hpp"
#include "varia/core/stormer_verlet.hpp"

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

// f(N, R) with N = n and R = the number of nodes as compile-time constants for n <= 4 and R <= 7
// (s Gauss-Legendre or s + 1 Lobatto points for s <= 6: the node iteration's loops then have
// fixed lengths and unroll), Eigen::Dynamic otherwise.
template <class F>
auto for_shape(int n, int s, F f) {
  return for_dimension(n, [&](auto N) {
    using Dynamic = std::integral_constant<int, Eigen::Dynamic>;
    if constexpr (decltype(N)::value == Eigen::Dynamic) return f(N, Dynamic{});
    else switch (s) {
      case 1: return f(N, std::integral_constant<int, 1>{});
      case 2: return f(N, std::integral_constant<int, 2>{});
      case 3: return f(N, std::integral_constant<int, 3>{});
      case 4: return f(N, std::integral_constant<int, 4>{});
      case 5: return f(N, std::integral_constant<int, 5>{});
      case 6: return f(N, std::integral_constant<int, 6>{});
      case 7: return f(N, std::integral_constant<int, 7>{});
      default: return f(N, Dynamic{});
    }
  });
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
                                                       std::vector<Force*> forces)
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
  action_ = for_dimension(n_, [](auto N) -> ActionFunction { return &GalerkinDiscreteLagrangian::action_for<decltype(N)::value>; });
  explicit_advance_ = explicit_form(quadrature);
  if (explicit_advance_ != nullptr) return;
  node_iteration_ = simplified_applies();
  step_ = node_iteration_
              ? for_shape(n_, static_cast<int>(iteration_nodes_.size()), [](auto N, auto R) -> StepFunction {
                  return &GalerkinDiscreteLagrangian::step_at<decltype(N)::value, decltype(R)::value>;
                })
              : for_dimension(n_, [](auto N) -> StepFunction {
                  return &GalerkinDiscreteLagrangian::step_at<decltype(N)::value, Eigen::Dynamic>;
                });
}

const EvaluationCounters& GalerkinDiscreteLagrangian::evaluations() const {
  counters_ = lagrangian_.counters();
  counters_.force = forces_.evaluations();
  return counters_;
}

// The explicit form's steps where its equations are explicit: degree 1, nodes at 0 and 1 only,
// no forces (f(v) makes them implicit), a constant mass matrix M, symmetric positive definite (the
// Lagrangian hyperregular). explicit_advance<N> for a dense Lagrangian (M from
// constant_mass_matrix, M^{-1} formed once); sparse_explicit_advance for a sparse one that
// declares has_constant_mass_matrix (M factorized at the first step); else null.
GalerkinDiscreteLagrangian::AdvanceFunction GalerkinDiscreteLagrangian::explicit_form(Quadrature& quadrature) {
  if (!forces_.empty() || s_ != 1) return nullptr;
  for (int i = 0; i < quadrature.size(); ++i) {
    const double c = quadrature.nodes()[i], b = quadrature.weights()[i];
    if (b == 0.0) continue;
    if (c == 0.0)
      b0_ += b;
    else if (c == 1.0)
      b1_ += b;
    else
      return nullptr;
  }
  force_.resize(n_);
  increment_.resize(n_);
  last_q_.resize(n_);
  last_p_.resize(n_);
  if (lagrangian_.sparse())
    return lagrangian_.plugin().has_constant_mass_matrix() ? &GalerkinDiscreteLagrangian::sparse_explicit_advance
                                                           : nullptr;
  mass_matrix_.resize(n_, n_);
  if (!lagrangian_.plugin().constant_mass_matrix(mass_matrix_.data())) return nullptr;
  const Eigen::LLT<Eigen::MatrixXd> mass(mass_matrix_);
  if (mass.info() != Eigen::Success) return nullptr;
  inverse_mass_ = mass.solve(Eigen::MatrixXd::Identity(n_, n_));
  kick_.resize(n_, n_);
  verlet_start_.resize(3 * n_);
  kernel::StormerVerletSteps verlet;
  plugin_runs_steps_ = lagrangian_.plugin().offers(kernel::call(verlet));
  return for_dimension(
      n_, [](auto N) -> AdvanceFunction { return &GalerkinDiscreteLagrangian::explicit_advance<decltype(N)::value>; });
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

// A constant mass matrix, no forces (f(v) would add to the kinetic part), a dense Jacobian; M
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
  if (!forces_.empty() || lagrangian_.sparse()) return false;
  mass_matrix_.resize(n_, n_);
  if (!lagrangian_.plugin().constant_mass_matrix(mass_matrix_.data())) return false;
  const Eigen::LLT<Eigen::MatrixXd> mass(mass_matrix_);
  if (mass.info() != Eigen::Success) return false;
  inverse_mass_ = mass.solve(Eigen::MatrixXd::Identity(n_, n_));
  // In long double (64-bit mantissa on x86, else double): K's block is ill-conditioned at larger s,
  // and a map's rounding is a change of the method, the same at every step (formed in double, the
  // s = 6 Gauss steps of the pendulum ended 5.0e-14 from gni_irk2's over 2000 steps, against 2.7e-15).
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
  // h alpha_s u0 + ... walked by an ulp of h u0 a step (with the maps in double, the s = 4 Gauss
  // steps of the pendulum ended 3.5e-14 from gni_irk2's over 4000 steps without this, 3.7e-15 with
  // it; in long double without it, the s = 6 steps parted from exact Newton's by 4e-14, 1e-14 with).
  const Eigen::VectorXd line = Eigen::Map<const Eigen::VectorXd>(basis_.control_times.data() + 1, s_);
  control_map_ = control.cast<double>();
  node_map_ = (interpolation * control).cast<double>();
  if ((control_map_.col(0) - line).lpNorm<Eigen::Infinity>() <= 1e-12) {
    control_map_.col(0) = line;
    for (int j = 0; j < R; ++j) node_map_(j, 0) = nodes_[iteration_nodes_[j]];
  }
  mass_norm_ = mass_matrix_.cwiseAbs().rowwise().sum().maxCoeff();
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
  return true;
}

// L_d = h (b0 L(q0, v) + b1 L(q1, v)), v = (q1 - q0)/h, L = v.Mv/2 - V(q):
//   p0 = -D1 L_d = M v - h b0 dL/dq(q0)  =>  v = M^{-1} (p0 + h b0 dL/dq(q0)), q1 = q0 + h v,
//   p1 =  D2 L_d = M v + h b1 dL/dq(q1)
// (paper, sec. 2: degree 1 with the trapezoidal rule is Stormer-Verlet), `steps` times in place.
// The loop carries the position increment h v instead of p: the next step's is
//   h v' = h M^{-1} (p1 + h b0 dL/dq(q1)) = h v + h^2 (b0 + b1) M^{-1} dL/dq(q1),
// (stormer_verlet.hpp) and p = M (h v) / h - h b0 dL/dq(q) is formed for the caller at the end.
// The same steps, with round-off of the same size (1e-13 to 1e-12 after 10^6 pendulum steps
// against a long double run, as for the form above); the chain of dependent operations from one
// force to the next is three shorter, and the loop's speed is that chain's latency
// (bench/README.md). The increment and dL/dq are kept for the next call: one that continues from
// this one's output (q, p and h as left) takes the same steps as one call for both, to the bit,
// and evaluates no gradient at q.
// Where the plugin runs the steps itself (kernel::StormerVerletSteps: the SDK's autodiff
// Lagrangians), the loop crosses the plugin boundary once for all the steps, with the model's
// dL/dq inlined in it: the same recurrence, the same numbers. Else, or to find the step whose
// gradient is not finite, the loop here calls the plugin once a step.
// N is n, or Dynamic. For a fixed N the state (q, h v, dL/dq) is held in local fixed-size vectors
// across the steps, and the plugin reads q and writes [dL/dq, dL/dv] in one small local array
// (`io`): a step is a few registers' arithmetic and one plugin call, with no load from the class's
// heap vectors (bench/README.md, "Measured design choices"). The dynamic form works on the
// caller's arrays and the class's workspace; neither allocates.
template <int N>
void GalerkinDiscreteLagrangian::explicit_advance(double* q, double* p, double h, long steps) {
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;
  if (steps <= 0) return;  // (q, p) as given, not p formed again from the increment
  const Eigen::Map<const Matrix> mass(mass_matrix_.data(), n_, n_), inverse(inverse_mass_.data(), n_, n_);
  Eigen::Map<Vector> position(q, n_), momentum(p, n_), force(force_.data(), n_), increment(increment_.data(), n_),
      last_q(last_q_.data(), n_), last_p(last_p_.data(), n_);
  const bool same_q = has_force_ && last_q == position;
  if (!same_q) {
    lagrangian_.gradient(q, v_.data(), grad_.data());  // dL/dq does not depend on v here
    force = grad_.head(n_);
  }
  const double kick0 = h * b0_, kick1 = h * b1_;
  if (!(same_q && last_p == momentum && previous_h_ == h)) {
    velocity_ = momentum + kick0 * force;  // M v (workspace)
    increment.noalias() = h * (inverse * velocity_);
  }
  Eigen::Map<Matrix> kick(kick_.data(), n_, n_);
  kick = (h * (kick0 + kick1)) * inverse;  // K = h^2 (b0 + b1) M^{-1}
  // Steps from qk with dk = h v and f = dL/dq(qk), and sets pk at the end; `at` holds q, v (any:
  // dL/dq does not depend on it) and receives the gradient at `gradient`.
  auto run = [&](const auto& M, const auto& K, auto& qk, auto& pk, auto& f, auto& dk, auto& at, double* v,
                 double* gradient) {
    const Eigen::Map<const Vector> dLdq(gradient, n_);  // the head of [dL/dq, dL/dv]
    // The plugin's steps; where a result is not finite, (q, h v, dL/dq) as they were for the retake.
    const auto in_plugin = [&] {
      if (!plugin_runs_steps_) return false;
      Eigen::Map<Vector> q0(verlet_start_.data(), n_), d0(verlet_start_.data() + n_, n_),
          f0(verlet_start_.data() + 2 * n_, n_);
      q0 = qk, d0 = dk, f0 = f;
      if (lagrangian_.verlet_steps(qk.data(), dk.data(), f.data(), K.data(), steps)) return true;
      qk = q0, dk = d0, f = f0;
      return false;
    };
    if (!in_plugin()) {
      stormer_verlet_steps(qk, dk, f, K, steps, [&](const auto& x, auto& g) {
        at = x;
        lagrangian_.gradient(at.data(), v, gradient);
        g = dLdq;
      });
    }
    pk.noalias() = M * dk;
    pk /= h;
    pk -= kick0 * f;
  };
  if constexpr (N == Eigen::Dynamic) {
    Eigen::Map<Vector> at(q_.data(), n_);
    run(mass, kick, position, momentum, force, increment, at, v_.data(), grad_.data());
  } else {
    alignas(64) std::array<double, 4 * N> io{};  // q, v = 0, then [dL/dq, dL/dv]
    Eigen::Map<Vector> at(io.data());
    const Matrix M = mass, K = kick;
    Vector qk = position, pk = momentum, f = force, dk = increment;
    run(M, K, qk, pk, f, dk, at, io.data() + N, io.data() + 2 * N);
    position = qk;
    momentum = pk;
    force = f;
    increment = dk;
  }
  keep_explicit_state(q, p, h, steps);
}

// The explicit form's steps for a sparse Lagrangian: explicit_advance's recurrence (q += h v,
// f = dL/dq(q), h v += h^2 (b0 + b1) M^{-1} f, then p = M (h v) / h - h b0 f), with M^{-1} f by
// the sparse Cholesky factor of M: linear in M's entries per step, no Newton iteration (a chain
// of N particles: M diagonal). M is read at the first step from the Hessian's velocity block
// (constant, so any point gives it) and factorized once, in natural order: no permutation, which
// a solve would apply through a temporary.
void GalerkinDiscreteLagrangian::sparse_explicit_advance(double* q, double* p, double h, long steps) {
  if (steps <= 0) return;
  if (sparse_mass_.rows() == 0) factorize_sparse_mass(q);
  Eigen::Map<Eigen::VectorXd> position(q, n_), momentum(p, n_);
  const bool same_q = has_force_ && last_q_ == position;
  if (!same_q) {
    lagrangian_.gradient(q, v_.data(), grad_.data());  // dL/dq does not depend on v here
    force_ = grad_.head(n_);
  }
  const double kick0 = h * b0_, kick = h * h * (b0_ + b1_);
  if (!(same_q && last_p_ == momentum && previous_h_ == h)) {
    velocity_ = momentum + kick0 * force_;  // M v
    increment_ = sparse_mass_solver_.solve(velocity_);
    increment_ *= h;
  }
  for (long k = 0; k < steps; ++k) {
    position += increment_;
    lagrangian_.gradient(q, v_.data(), grad_.data());
    force_ = grad_.head(n_);
    velocity_ = sparse_mass_solver_.solve(force_);  // M^{-1} dL/dq (workspace)
    increment_ += kick * velocity_;
  }
  momentum.noalias() = sparse_mass_ * increment_;
  momentum /= h;
  momentum -= kick0 * force_;
  keep_explicit_state(q, p, h, steps);
}

// The explicit form's state after `steps` steps of h ending at (q, p): a call that continues from
// there reuses dL/dq and the increment (force_, increment_).
void GalerkinDiscreteLagrangian::keep_explicit_state(const double* q, const double* p, double h, long steps) {
  last_q_ = Eigen::Map<const Eigen::VectorXd>(q, n_);
  last_p_ = Eigen::Map<const Eigen::VectorXd>(p, n_);
  previous_h_ = h;
  has_force_ = true;
  statistics_.solves += steps;  // explicit: no Newton iterations
}

void GalerkinDiscreteLagrangian::factorize_sparse_mass(const double* q) {
  lagrangian_.sparse_hessian(q, v_.data(), grad_.data(), sparse_values_.data());
  std::vector<Eigen::Triplet<double>> triplets;
  for (int e = 0; e < lagrangian_.pattern_size(); ++e)
    if (entries_[e].row_v && entries_[e].col_v) triplets.emplace_back(entries_[e].row, entries_[e].col, sparse_values_[e]);
  sparse_mass_.resize(n_, n_);
  sparse_mass_.setFromTriplets(triplets.begin(), triplets.end());
  sparse_mass_solver_.compute(sparse_mass_);
  if (sparse_mass_solver_.info() != Eigen::Success)
    throw NumericalFailure("the Lagrangian's constant mass matrix (its Hessian's velocity block) is not positive "
                           "definite: the Lagrangian is not regular",
                           NAN);
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

// q_i = q^0 + sum_nu l_nu(c_i) (q^nu - q^0) (sum_nu l_nu = 1), v_i = (1/h) sum_nu l'_nu(c_i) (q^nu - q^0),
// into q and v (n numbers each).
// Plain loops over contiguous arrays: at small n a matrix-vector product's setup would cost more
// than its arithmetic. For a fixed N the sums run in local accumulators (registers) and are
// stored once: summed in q's and v's memory, each addition waited for the store before it (at
// s = 6 the stores were half of the action's time). Inlined into both callers (a call added 12%
// to the s = 2 Gauss step).
template <int N, int S>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::interpolate(int i, double h, double* __restrict q,
                                                                            double* __restrict v) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const double* __restrict a = basis_.phi.col(i).data();
  const double* __restrict da = basis_.dphi.col(i).data();
  const double* __restrict points = points_.data();
  std::array<double, N == Eigen::Dynamic ? 1 : N> q_sum{}, v_sum{};
  double* qs = N == Eigen::Dynamic ? q : q_sum.data();
  double* vs = N == Eigen::Dynamic ? v : v_sum.data();
  for (int r = 0; r < n; ++r) {
    qs[r] = 0.0;
    vs[r] = 0.0;
  }
  for (int nu = 0; nu <= fixed_or<S>(s_); ++nu)
    for (int r = 0; r < n; ++r) {
      qs[r] += a[nu] * points[nu * n + r];
      vs[r] += da[nu] * points[nu * n + r];
    }
  for (int r = 0; r < n; ++r) {
    q[r] = qs[r] + origin_[r];
    v[r] = vs[r] / h;
  }
}

double GalerkinDiscreteLagrangian::weight(int i, int nu, bool by_v, double h) const {
  return by_v ? basis_.dphi(nu, i) / h : basis_.phi(nu, i);
}

// S = h sum_i b_i L(q_i, v_i), q_i = sum_nu l_nu(c_i) q^nu, v_i = (1/h) sum_nu l'_nu(c_i) q^nu
// (paper, sec. 2), and by the chain rule
//   dS/dq^nu = sum_i b_i (h l_nu L_q + l'_nu L_v),
//   d2S/dq^nu dq^mu = sum_i b_i (h l_nu l_mu L_qq + l_nu l'_mu L_qv + l'_nu l_mu L_vq
//                                + l'_nu l'_mu L_vv / h).
// With the gradient, impulse_ = h sum_i b_i (L_q + f)(c_i) = sum_nu (dS/dq^nu + f_d^nu), since
// sum_nu l_nu = 1 and sum_nu l'_nu = 0: the momentum change of the step (see step()).
template <int N>
double GalerkinDiscreteLagrangian::action_for(double h, Order order, bool forced) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const bool sparse = lagrangian_.sparse();
  double S = 0.0;
  if (order != Order::value) {
    for (int k = 0; k < (s_ + 1) * n; ++k) gradient_[k] = 0.0;
    for (int c = 0; c < n; ++c) impulse_[c] = 0.0;
  }
  if (order == Order::hessian && sparse) sparse_.matrix.coeffs().setZero();
  if (order == Order::hessian && !sparse) hessian_.setZero();
  for (int i = 0, j = 0; i < basis_.phi.cols(); ++i) {
    if (weights_[i] == 0.0) continue;
    interpolate<N>(i, h, q_.data(), v_.data());
    double L = 0.0;
    if (order == Order::hessian && sparse)
      L = lagrangian_.sparse_hessian(q_.data(), v_.data(), grad_.data(), sparse_values_.data());
    else if (order == Order::hessian)
      L = lagrangian_.hessian(q_.data(), v_.data(), grad_.data(), hess_.data());
    else if (order == Order::value_and_gradient)
      L = lagrangian_.value_and_gradient(q_.data(), v_.data(), grad_.data());
    else if (order == Order::gradient)
      lagrangian_.gradient(q_.data(), v_.data(), grad_.data());
    else
      L = lagrangian_.value(q_.data(), v_.data());
    const double b = weights_[i];
    S += h * b * L;
    if (order == Order::value) continue;
    for (int c = 0; c < n; ++c) impulse_[c] += (h * b) * grad_[c];
    if (node_iteration_) node_accelerations_.segment(j * n, n).noalias() = inverse_mass_ * grad_.head(n);
    ++j;
    if (forced) add_forces(i, h, order);
    if (order == Order::hessian && sparse)
      add_sparse_entries(i, h, 0, sparse_values_.data(), static_cast<int>(sparse_values_.size()), h * b);
    add_gradient<N>(i, h, b, grad_.data(), gradient_.data(), 0, s_ + 1);
    if (order == Order::hessian && !sparse) add_hessian<N>(i, h, b);
  }
  return S;
}

// out ((nu - first) n + r) += b (h l_nu L_q + l'_nu L_v)(r) at node i (see action()), for the
// control points nu in [first, first + count), dL = [L_q; L_v].
template <int N>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::add_gradient(int i, double h, double b, const double* __restrict dL,
                                              double* __restrict out, int first, int count) {
  const int n = N == Eigen::Dynamic ? n_ : N;
  const double* __restrict a = basis_.phi.col(i).data() + first;
  const double* __restrict da = basis_.dphi.col(i).data() + first;
  for (int nu = 0; nu < count; ++nu) {
    const double x = b * h * a[nu], y = b * da[nu];
    for (int r = 0; r < n; ++r) out[nu * n + r] += x * dL[r] + y * dL[n + r];
  }
}

// hessian_(nu n + r, mu n + c) += b (l_nu (h l_mu L_qq + l'_mu L_qv) + l'_nu (l_mu L_vq + l'_mu L_vv / h))(r, c)
// at node i: the same sum as above, factored by column so that each entry costs two products
// (this runs (s+1)^2 n^2 times per node and Newton iteration). Column (mu, c) of the update is
// l_nu g_q + l'_nu g_v over (nu, r) for the column's two n-vectors g = column_.
template <int N>
void GalerkinDiscreteLagrangian::add_hessian(int i, double h, double b) {
  const int n = N == Eigen::Dynamic ? n_ : N, k = 2 * n, size = (s_ + 1) * n;
  const double* __restrict H = hess_.data();  // the 2n x 2n Hessian of L in (q, v), column-major
  const double* __restrict a = basis_.phi.col(i).data();
  const double* __restrict da = basis_.dphi.col(i).data();
  double* __restrict column_q = column_.data();
  double* __restrict column_v = column_.data() + n;
  double* __restrict hessian = hessian_.data();
  for (int mu = 0; mu <= s_; ++mu) {
    const double cq = b * h * a[mu], dcq = b * da[mu], cv = b * a[mu], dcv = b * da[mu] / h;
    for (int col = 0; col < n; ++col) {
      const double* by_q = H + col * k;        // d/dq_col of [L_q; L_v]
      const double* by_v = H + (n + col) * k;  // d/dv_col of [L_q; L_v]
      for (int r = 0; r < n; ++r) {
        column_q[r] = cq * by_q[r] + dcq * by_v[r];
        column_v[r] = cv * by_q[n + r] + dcv * by_v[n + r];
      }
      double* target = hessian + (mu * n + col) * size;
      for (int nu = 0; nu <= s_; ++nu)
        for (int r = 0; r < n; ++r) target[nu * n + r] += a[nu] * column_q[r] + da[nu] * column_v[r];
    }
  }
}

// f_d^nu += h b_i l_nu(c_i) f(t + c_i h, q_i, v_i) (Marsden & West 2001, sec. 3.2, through the
// quadrature), and d f_d^nu / dq^mu += h b_i l_nu (l_mu df/dq + l'_mu/h df/dv).
void GalerkinDiscreteLagrangian::add_forces(int i, double h, Order order) {
  const bool jacobian = order == Order::hessian;
  forces_.evaluate(t_ + nodes_[i] * h, q_.data(), v_.data(), f_.data(),
                   jacobian ? force_values_.data() : nullptr);
  const double w = h * weights_[i];
  for (int nu = 0; nu <= s_; ++nu) gradient_.segment(nu * n_, n_) += w * basis_.phi(nu, i) * f_;
  impulse_ += w * f_;
  if (!jacobian) return;
  const int first = static_cast<int>(entries_.size() - force_values_.size());
  if (lagrangian_.sparse())
    return add_sparse_entries(i, h, first, force_values_.data(), static_cast<int>(force_values_.size()), w);
  for (Eigen::Index k = 0; k < force_values_.size(); ++k) {
    const Entry& e = entries_[first + k];
    for (int nu = 0; nu <= s_; ++nu)
      for (int mu = 0; mu <= s_; ++mu)
        hessian_(nu * n_ + e.row, mu * n_ + e.col) +=
            w * force_values_[k] * weight(i, nu, e.row_v, h) * weight(i, mu, e.col_v, h);
  }
}

void GalerkinDiscreteLagrangian::add_sparse_entries(int i, double h, int first_entry,
                                                    const double* values, int count, double w) {
  const int blocks = sparse_.blocks;
  double* coefficients = sparse_.matrix.valuePtr();
  for (int k = 0; k < count; ++k) {
    const Entry& e = entries_[first_entry + k];
    const int* slot = &sparse_.slots[static_cast<std::size_t>(first_entry + k) * blocks * blocks];
    for (int nu = 0; nu < blocks; ++nu) {
      const double row = w * values[k] * weight(i, sparse_.first_equation + nu, e.row_v, h);
      for (int mu = 0; mu < blocks; ++mu)
        coefficients[slot[nu * blocks + mu]] += row * weight(i, sparse_.first_unknown + mu, e.col_v, h);
    }
  }
}

// The structure: every entry in every block (nu, mu) of the equations and unknowns, summed where
// entries coincide; slots_ records where each (entry, nu, mu) landed in the compressed matrix.
void GalerkinDiscreteLagrangian::prepare_sparse(int first_unknown, int first_equation, int blocks) {
  if (sparse_.first_unknown == first_unknown && sparse_.first_equation == first_equation &&
      sparse_.blocks == blocks)
    return;
  sparse_.first_unknown = first_unknown;
  sparse_.first_equation = first_equation;
  sparse_.blocks = blocks;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(entries_.size() * blocks * blocks);
  for (const Entry& e : entries_)
    for (int nu = 0; nu < blocks; ++nu)
      for (int mu = 0; mu < blocks; ++mu) triplets.emplace_back(nu * n_ + e.row, mu * n_ + e.col, 0.0);
  sparse_.matrix.resize(blocks * n_, blocks * n_);
  sparse_.matrix.setFromTriplets(triplets.begin(), triplets.end());
  sparse_.matrix.makeCompressed();
  sparse_.slots.resize(triplets.size());
  const int* outer = sparse_.matrix.outerIndexPtr();
  const int* inner = sparse_.matrix.innerIndexPtr();
  for (std::size_t k = 0; k < triplets.size(); ++k) {
    const int col = triplets[k].col(), row = triplets[k].row();
    sparse_.slots[k] = static_cast<int>(std::lower_bound(inner + outer[col], inner + outer[col + 1], row) - inner);
  }
  sparse_.analyzed = false;
}

// ---- simplified Newton for a constant mass matrix, in the nodes' coordinates (galerkin.hpp) --
// Plain loops over a handful of numbers, n and R fixed where small: at these sizes a dynamic-size
// product's setup costs more than its arithmetic.

// offsets(j) = h (map(j, 0) u0 + h sum_i map(j, 1 + i) a_i) for the rows j of map, with
// u0 = velocity0_ and a_i = M^{-1} g_i the forces' accelerations at C points (n each): the R nodes,
// or the 2R of the history.
// Offsets from q0, numbers of size h |v|: q0 + offset rounds to eps |q0|, where forming the
// positions themselves would add eps |q0| at every step (docs/hard-cases.md, Kepler).
// The sum over points runs in four accumulators (points i mod 4): it is on the chain from one
// pass's forces to the next pass's, and one accumulator would make it a chain of C dependent
// additions.
template <int N, int Rows, int C>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::offsets_from_forces(const Eigen::MatrixXd& map, double h,
                                                                                  const double* __restrict accelerations,
                                                                                  double* __restrict offsets) const {
  const int n = fixed_or<N>(n_), nodes = fixed_or<C>(static_cast<int>(map.cols()) - 1),
            rows = fixed_or<Rows>(static_cast<int>(map.rows()));
  const double* __restrict W = map.data();
  const double* __restrict u0 = velocity0_.data();
  for (int j = 0; j < rows; ++j)
    for (int c = 0; c < n; ++c) {
      double sum[4] = {0.0, 0.0, 0.0, 0.0};
      for (int i = 0; i < nodes; ++i) sum[i % 4] += W[j + (1 + i) * rows] * accelerations[i * n + c];
      offsets[j * n + c] = h * (W[j] * u0[c] + h * ((sum[0] + sum[1]) + (sum[2] + sum[3])));
    }
}

// The fixed point's residual at the nodes' offsets D (node_offsets_): the forces g_j = dL/dq at
// q0 + D_j in one plugin call (Lagrangian::gradients; v = 0: for this Lagrangian L_q does not
// depend on v), kept with M^{-1} g_j, the offsets D' that the step's equations give for those
// forces (into next_offsets_), and F = M (D - D') / h (R n), with 1/h and |p0| given (once a step). F is the equations' residual in their
// own units, momentum (at X, with X' the control points of D', the residual of equation nu is
// (1/h) M sum_mu K_numu (X^mu - X'^mu)): the stopping rule's tolerance means what it means for
// the equations, and its yardstick is theirs, |p0| and the kinetic terms |M D'| / h. (The
// offsets' difference itself is smaller by h / |M|: at tolerance (1 + yardstick) in positions the
// rule stopped with systematic errors h^-1 times larger, and the s = 6 Gauss steps of the
// pendulum ended 1.6e-13 from gni_irk2's instead of 2e-15.)
template <int N, int R>
[[gnu::always_inline]] inline double GalerkinDiscreteLagrangian::node_residual(double h, double inverse_h, double momentum,
                                                                               double* __restrict F) {
  const int n = fixed_or<N>(n_), nodes = fixed_or<R>(static_cast<int>(iteration_nodes_.size()));
  const double* __restrict q0 = origin_.data();
  const double* __restrict D = node_offsets_.data();
  const double* __restrict M = mass_matrix_.data();
  const double* __restrict M_inverse = inverse_mass_.data();
  double* __restrict z = node_points_.data();
  double* __restrict gradients = node_gradients_.data();
  double* __restrict accelerations = node_accelerations_.data();
  double* __restrict next = next_offsets_.data();
  for (int j = 0; j < nodes; ++j)
    for (int c = 0; c < n; ++c) z[2 * n * j + c] = q0[c] + D[j * n + c];
  lagrangian_.gradients(nodes, z, gradients);
  for (int j = 0; j < nodes; ++j) {
    const double* g = gradients + 2 * n * j;
    for (int c = 0; c < n; ++c) {
      double a = 0.0;
      for (int d = 0; d < n; ++d) a += M_inverse[c + d * n] * g[d];
      accelerations[j * n + c] = a;
    }
  }
  offsets_from_forces<N, R, R>(node_map_, h, accelerations, next);
  double largest = 0.0;
  for (int j = 0; j < nodes; ++j)
    for (int c = 0; c < n; ++c) {
      double f = 0.0;
      for (int d = 0; d < n; ++d) f += M[c + d * n] * (D[j * n + d] - next[j * n + d]);
      F[j * n + c] = f * inverse_h;
      largest = std::max(largest, std::abs(next[j * n + c]));
    }
  return std::max(momentum, mass_norm_ * largest * inverse_h);
}

// The fixed point D = D'(g(q0 + D)) as a NewtonSolver system with the Jacobian M / h at every node
// (the simplified Newton's of the control points, the kinetic part, carried to the nodes: the
// same iterates): solve()'s update is h M^{-1} F = D - D', and apply() moves to D' (which is
// D - update before rounding).
template <int N, int R>
struct GalerkinDiscreteLagrangian::NodeIteration {
  GalerkinDiscreteLagrangian& g;
  double h, inverse_h;
  double momentum, origin;  // |p0|, |q0|

  int size() const { return static_cast<int>(g.node_offsets_.size()); }
  bool simplified() const { return true; }
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) { return g.node_residual<N, R>(h, inverse_h, momentum, F.data()); }
  void factorize() {}
  void solve(const Eigen::VectorXd&, Eigen::VectorXd& update) {
    const int size = fixed_or<R>(static_cast<int>(g.iteration_nodes_.size())) * fixed_or<N>(g.n_);
    for (int k = 0; k < size; ++k) update[k] = g.node_offsets_[k] - g.next_offsets_[k];
  }
  double apply(const Eigen::VectorXd&) {
    const int n = fixed_or<N>(g.n_), size = fixed_or<R>(static_cast<int>(g.iteration_nodes_.size())) * n;
    double largest = 0.0;
    for (int k = 0; k < size; ++k) {
      g.node_offsets_[k] = g.next_offsets_[k];
      largest = std::max(largest, std::abs(g.node_offsets_[k]));
    }
    return origin + largest;
  }
  void finish(const Eigen::VectorXd&) {}
};

// The step by the node iteration from its warm start. Converged, the step is that of the forces
// of the last evaluation: q1 - q0 = X^s by end_map_ (into points_' last column), and p1 - p0 =
// impulse_ = h sum_j b_j g_j, the sum of the step's equations (see action()), all of which those
// forces satisfy with the X^mu they give. False when it does not converge (the caller solves the
// step again with the exact Jacobian).
template <int N, int R>
bool GalerkinDiscreteLagrangian::solve_at_nodes(const double* p0, double h, bool continues) {
  const int n = fixed_or<N>(n_), nodes = fixed_or<R>(static_cast<int>(iteration_nodes_.size()));
  double momentum = 0.0, origin = 0.0;
  for (int c = 0; c < n; ++c) {
    double u = 0.0;
    for (int d = 0; d < n; ++d) u += inverse_mass_.data()[c + d * n] * p0[d];
    velocity0_[c] = u;
    momentum = std::max(momentum, std::abs(p0[c]));
    origin = std::max(origin, std::abs(origin_[c]));
  }
  if (continues) {
    constexpr int history = R == Eigen::Dynamic ? Eigen::Dynamic : 2 * R;
    offsets_from_forces<N, R, history>(prediction_map_[two_steps_back_ ? 1 : 0], h, acceleration_history_.data(),
                                    node_offsets_.data());
  } else {  // the straight line with the velocity of the inverse Legendre transform, u0
    for (int j = 0; j < nodes; ++j)
      for (int c = 0; c < n; ++c) node_offsets_[j * n + c] = nodes_[iteration_nodes_[j]] * h * velocity0_[c];
  }
  NodeIteration<N, R> iteration{*this, h, 1.0 / h, momentum, origin};
  if (!solver_.solve(iteration, statistics_).converged()) return false;
  offsets_from_forces<N, 1, R>(end_map_, h, node_accelerations_.data(), points_.col(s_).data());
  for (int c = 0; c < n; ++c) {
    double sum = 0.0;
    for (int j = 0; j < nodes; ++j) sum += weights_[iteration_nodes_[j]] * node_gradients_[2 * n * j + c];
    impulse_[c] = h * sum;
  }
  return true;
}

// The warm start: the forces along the motion are as smooth as the motion, and the polynomial
// through the last steps' forces at their nodes continued to this step's nodes predicts them,
// through the last step's R nodes to O(h^R), through those and two more of the step before (as
// Hairer's gni_irk2 starts from s + 2 forces) to O(h^(R+2)); the offsets they give are off by h^2
// times that. Against O(h^(s+1)) for the last step's interpolant continued (which Newton's method
// with the exact Jacobian starts from). The history holds the accelerations M^{-1} g (M^{-1} is
// linear): the node iteration starts from their offsets, by prediction_map_ (the extrapolation and
// node_map_ in one); this, for the exact Jacobian's start where the iteration did not converge,
// forms the predicted accelerations at the nodes themselves, into predicted_accelerations_.
void GalerkinDiscreteLagrangian::predict_accelerations() {
  const Eigen::MatrixXd& E = acceleration_extrapolation_[two_steps_back_ ? 1 : 0];
  const int n = n_, R = static_cast<int>(E.cols());
  for (int j = 0; j < R; ++j)
    for (int c = 0; c < n; ++c) {
      double a = 0.0;
      for (int m = 0; m < E.rows(); ++m) a += E(m, j) * acceleration_history_(c, m);
      predicted_accelerations_[j * n + c] = a;
    }
}

// The equations dS/dq^nu (+ f_d^nu when forced) = 0, nu in [first_equation, first_equation +
// blocks), in the control points [first_unknown, first_unknown + blocks), with p0 (if not null)
// added to the equation nu = 0 (IDEL: p0 + D1 L_d + f_d^0 = 0), as a system for NewtonSolver
// (solve/newton.hpp), with the exact Jacobian.
struct GalerkinDiscreteLagrangian::Equations {
  GalerkinDiscreteLagrangian& g;
  double h;
  int first_unknown, first_equation, blocks;
  const double* p0;
  bool forced;

  int size() const { return blocks * g.n_; }
  // F's round-off yardstick: the largest of its terms p0 and dS/dq^nu.
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    g.action(h, Order::hessian, forced);
    F = g.gradient_.segment(first_equation * g.n_, size());
    double yardstick = g.gradient_.lpNorm<Eigen::Infinity>();
    if (p0 != nullptr) {
      const Eigen::Map<const Eigen::VectorXd> momentum(p0, g.n_);
      F.head(g.n_) += momentum;
      yardstick = std::max(yardstick, momentum.lpNorm<Eigen::Infinity>());
    }
    return yardstick;
  }
  void factorize() {
    if (g.lagrangian_.sparse()) return g.factorize_sparse();
    g.dense_.jacobian = g.hessian_.block(first_equation * g.n_, first_unknown * g.n_, size(), size());
    g.dense_.factorize();
  }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) {
    if (g.lagrangian_.sparse()) update = g.sparse_.lu.solve(F);
    else g.dense_.solve(F, update);
  }
  // x's round-off yardstick: the control points' size, q^0 + offsets.
  double apply(const Eigen::VectorXd& update) {
    g.points_.middleCols(first_unknown, blocks).reshaped() -= update;
    return g.origin_.lpNorm<Eigen::Infinity>() + g.points_.lpNorm<Eigen::Infinity>();
  }
  // The gradient at the updated points; for the step's equations (p0 given), impulse_ less their
  // residuals there (see take_step).
  void finish(const Eigen::VectorXd& update) {
    g.gradient_after_update(h, first_unknown, update, forced);
    if (p0 == nullptr) return;
    g.impulse_ -= g.gradient_.head(g.n_) + Eigen::Map<const Eigen::VectorXd>(p0, g.n_);
    for (int nu = 1; nu < g.s_; ++nu) g.impulse_ -= g.gradient_.segment(nu * g.n_, g.n_);
  }
};

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
                                                       const Eigen::VectorXd& update, bool forced) {
  if (lagrangian_.sparse()) {
    action(h, Order::gradient, forced);
    return;
  }
  change_.noalias() = hessian_.middleCols(first_unknown * n_, update.size()) * update;
  gradient_ -= change_;
  for (int nu = 0; nu <= s_; ++nu) impulse_ -= change_.segment(nu * n_, n_);
}

// The initial guess: where the node iteration applies, the control points of the forces it
// predicted (see predict_accelerations()) when this step follows the last; else the previous step's
// interpolant continued past its end when this step follows it; otherwise a straight line with
// the velocity of the inverse Legendre transform. Offsets from q0 = the last step's q1:
// q(1 + d_nu) - q1 = sum_mu l_mu(1 + d_nu) (q_prev^mu - q_prev^0) - (q_prev^s - q_prev^0).
void GalerkinDiscreteLagrangian::warm_start(const double* q0, const double* p0, double h, bool continues) {
  if (continues && node_iteration_) {
    predict_accelerations();
    offsets_from_forces<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>(control_map_, h, predicted_accelerations_.data(),
                                                        points_.col(1).data());
  } else if (continues) {
    points_.noalias() = previous_ * extrapolation_;
    points_.colwise() -= previous_.col(s_);
  } else {
    lagrangian_.inverse_legendre(q0, p0, velocity_.data(), options_);
    for (int nu = 0; nu <= s_; ++nu) points_.col(nu) = (basis_.control_times[nu] * h) * velocity_;
  }
  points_.col(0).setZero();
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

// q1 = q0 + (q^s - q^0), and p1 = D2 L_d + f_d^s written as p0 plus its change: the equations
// sum to sum_nu (dS/dq^nu + f_d^nu) = impulse_ (see action()), so
//   p1 - p0 = impulse_ - (dS/dq^0 + f_d^0 + p0) - sum_{0 < nu < s} (dS/dq^nu + f_d^nu),
// the impulse less the residuals of the solved equations (formed by the solve's finish(), where the
// residuals are at hand). Both sums are compensated across steps (compensated.hpp) when a step
// continues from the last one's output.
// At N = n and R nodes of the node iteration where both are small (for_shape), in
// loops of a fixed length: at small n, dynamic-size Eigen expressions spend more on bookkeeping
// than on the solve.
template <int N, int R>
void GalerkinDiscreteLagrangian::step_at(const double* q0, const double* p0, double h, double* q1, double* p1) {
  using Vector = Eigen::Matrix<double, N, 1>;
  const int n = fixed_or<N>(n_);
  bool same_point = has_previous_, same_momentum = has_previous_;
  for (int c = 0; c < n; ++c) {
    same_point = same_point && previous_end_[c] == q0[c];
    same_momentum = same_momentum && end_p_[c] == p0[c];
    origin_[c] = q0[c];
  }
  Eigen::Map<Vector> carry_q(carry_q_.data(), n), carry_p(carry_p_.data(), n);
  if (!(same_point && same_momentum)) {
    carry_q.setZero();
    carry_p.setZero();
  }
  const bool continues = same_point && previous_h_ == h;
  // impulse_ is then p1 - p0, q^s - q^0 that of q1 (solve_at_nodes, or the Equations' finish())
  if (!(node_iteration_ && solve_at_nodes<N, R>(p0, h, continues))) {
    warm_start(q0, p0, h, continues);
    newton(h, 1, 0, s_, p0, !forces_.empty());
  }
  Eigen::Map<Vector> end(previous_end_.data(), n), momentum(end_p_.data(), n);
  end = Eigen::Map<const Vector>(q0, n);
  compensated_add(end, Eigen::Map<const Vector>(points_.col(s_).data(), n), carry_q);
  momentum = Eigen::Map<const Vector>(p0, n);
  compensated_add(momentum, Eigen::Map<const Vector>(impulse_.data(), n), carry_p);
  Eigen::Map<Vector>(q1, n) = end;
  Eigen::Map<Vector>(p1, n) = momentum;
  if (node_iteration_) {  // the history shifts by a step
    const int size = n * fixed_or<R>(static_cast<int>(iteration_nodes_.size()));
    double* __restrict history = acceleration_history_.data();
    for (int k = 0; k < size; ++k) {
      history[size + k] = history[k];
      history[k] = node_accelerations_[k];
    }
    two_steps_back_ = continues;
  } else
    previous_ = points_;
  previous_h_ = h;
  has_previous_ = true;
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
