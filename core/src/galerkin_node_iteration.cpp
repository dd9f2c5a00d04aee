// The Galerkin construction's step (galerkin.hpp): the simplified Newton iteration in the nodes'
// coordinates for a constant mass matrix, the exact Newton's warm start, and the step with its
// compensated sums; the fixed-size steps (n <= 4, R <= 7 nodes) are instantiated here, once.
#include "varia/core/galerkin.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "varia/core/compensated.hpp"
#include "varia/core/fixed_size.hpp"

namespace varia {

namespace {

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

// a = M^{-1} g (n numbers each, apart): by M^{-1} in a loop of fixed length where n is small, or by
// the sparse Cholesky factor of M in place (natural order: no permutation, no temporary; a
// diagonal M divides). A sparse M is factorized at the first step (solve_at_nodes); before it, the
// action's accelerations (used by steps only) are not formed.
void GalerkinDiscreteLagrangian::sparse_inverse_mass_times(const double* g, double* a) {
  if (sparse_mass_.rows() == 0) return;
  Eigen::Map<Eigen::VectorXd> x(a, n_);
  const Eigen::Map<const Eigen::VectorXd> b(g, n_);
  if (diagonal_mass_) {  // particles: one rounding, g / m
    x.array() = b.array() / sparse_mass_.coeffs().array();
    return;
  }
  x = b;
  sparse_mass_solver_.matrixL().solveInPlace(x);
  sparse_mass_solver_.matrixU().solveInPlace(x);
}

template <int N>
[[gnu::always_inline]] inline void GalerkinDiscreteLagrangian::inverse_mass_times(const double* __restrict g,
                                                                                  double* __restrict a) {
  if (lagrangian_.sparse()) return sparse_inverse_mass_times(g, a);  // out of line: the dense loop stays small
  const int n = fixed_or<N>(n_);
  const double* __restrict M_inverse = inverse_mass_.data();
  for (int c = 0; c < n; ++c) {
    double sum = 0.0;
    for (int d = 0; d < n; ++d) sum += M_inverse[c + d * n] * g[d];
    a[c] = sum;
  }
}
template void GalerkinDiscreteLagrangian::inverse_mass_times<Eigen::Dynamic>(const double*, double*);

// The fixed point's residual at the nodes' offsets D (node_offsets_): the forces g_j = dL/dq at
// q0 + D_j in one plugin call (Lagrangian::gradients; v = 0: for this Lagrangian L_q does not
// depend on v), kept with M^{-1} g_j, the offsets D' that the step's equations give for those
// forces (into next_offsets_), and F = (D - D') / (h w) (R n), with 1/h and |u0| given (once a
// step), and 1 / (h w) formed at the solve's first evaluation (`scale`, 0 until then: the iterates
// change w by less than the warm start's error, and a division per pass lengthens the chain from
// one pass to the next). (D - D') / h is M^{-1} times the equations' residual (at X, with X' the control points of
// D', the residual of equation nu is (1/h) M sum_mu K_numu (X^mu - X'^mu)): in velocity units every
// coordinate counts alike whatever its mass. w, its yardstick, is the size of the velocities the
// equations sum, |u0| and |D'| / h, so F is relative and the stopping rule means the same in any
// system of units (in momentum units with the solver's tolerance (1 + yardstick), the outer solar
// system's planets, in days, AU and solar masses, stopped tens of eps short of the fixed point:
// bench/README.md, "Measured design choices").
template <int N, int R>
[[gnu::always_inline]] inline double GalerkinDiscreteLagrangian::node_residual(double h, double inverse_h, double speed,
                                                                               double& scale, double* __restrict F) {
  const int n = fixed_or<N>(n_), nodes = fixed_or<R>(static_cast<int>(iteration_nodes_.size()));
  const double* __restrict q0 = origin_.data();
  const double* __restrict D = node_offsets_.data();
  double* __restrict z = node_points_.data();
  double* __restrict gradients = node_gradients_.data();
  double* __restrict accelerations = node_accelerations_.data();
  double* __restrict next = next_offsets_.data();
  for (int j = 0; j < nodes; ++j)
    for (int c = 0; c < n; ++c) z[2 * n * j + c] = q0[c] + D[j * n + c];
  lagrangian_.gradients(nodes, z, gradients);
  for (int j = 0; j < nodes; ++j) inverse_mass_times<N>(gradients + 2 * n * j, accelerations + j * n);
  offsets_from_forces<N, R, R>(node_map_, h, accelerations, next);
  if (scale == 0.0) {
    double largest = 0.0;
    for (int k = 0; k < nodes * n; ++k) largest = std::max(largest, std::abs(next[k]));
    const double yardstick = std::max(speed, largest * inverse_h);
    scale = yardstick > 0.0 ? inverse_h / yardstick : inverse_h;
  }
  for (int k = 0; k < nodes * n; ++k) F[k] = (D[k] - next[k]) * scale;
  return 0.0;
}

// The fixed point D = D'(g(q0 + D)) as a NewtonSolver system with the Jacobian M / h at every node
// (the simplified Newton's of the control points, the kinetic part, carried to the nodes: the
// same iterates): solve()'s update is h M^{-1} F = D - D', and apply() moves to D' (which is
// D - update before rounding).
template <int N, int R>
struct GalerkinDiscreteLagrangian::NodeIteration {
  GalerkinDiscreteLagrangian& g;
  double h, inverse_h;
  double speed, origin;  // |u0|, |q0|
  double scale = 0.0;     // 1 / (h w), node_residual's

  int size() const { return static_cast<int>(g.node_offsets_.size()); }
  bool simplified() const { return true; }
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) { return g.node_residual<N, R>(h, inverse_h, speed, scale, F.data()); }
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
  if (lagrangian_.sparse() && sparse_mass_.rows() == 0) factorize_sparse_mass(origin_.data());
  inverse_mass_times<N>(p0, velocity0_.data());
  double speed = 0.0, origin = 0.0;
  for (int c = 0; c < n; ++c) {
    speed = std::max(speed, std::abs(velocity0_[c]));
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
  NodeIteration<N, R> iteration{*this, h, 1.0 / h, speed, origin};
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
  step_at_nodes_ = node_iteration_ && solve_at_nodes<N, R>(p0, h, continues);
  if (!step_at_nodes_) {
    warm_start(q0, p0, h, continues);
    newton(h, 1, 0, s_, p0, !forces_.empty());
    if (constraints_ != nullptr) project_momentum(p0);
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

void GalerkinDiscreteLagrangian::control_points_of_step(const double* q0, const double* q1, double h) {
  origin_ = Eigen::Map<const Eigen::VectorXd>(q0, n_);
  points_.col(0).setZero();
  if (explicit_advance_ != nullptr)  // degree 1: the control points are the end points
    points_.col(1) = Eigen::Map<const Eigen::VectorXd>(q1, n_) - origin_;
  else if (step_at_nodes_)  // q^1..q^s from the converged forces, as solve_at_nodes formed q^s
    offsets_from_forces<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>(control_map_, h, node_accelerations_.data(),
                                                                        points_.col(1).data());
}

GalerkinDiscreteLagrangian::StepFunction GalerkinDiscreteLagrangian::step_function(int n, int nodes,
                                                                                   bool node_iteration) {
  if (node_iteration)
    return for_shape(n, nodes, [](auto N, auto R) -> StepFunction {
      return &GalerkinDiscreteLagrangian::step_at<decltype(N)::value, decltype(R)::value>;
    });
  return for_dimension(n, [](auto N) -> StepFunction {
    return &GalerkinDiscreteLagrangian::step_at<decltype(N)::value, Eigen::Dynamic>;
  });
}

}  // namespace varia
