// The Galerkin construction's explicit form (galerkin.hpp): degree 1 with nodes at 0 and 1 only and
// a constant mass matrix, whose IDEL equations are explicit (Stormer-Verlet for the trapezoid rule),
// stepped without Newton; its fixed-size steps (n <= 4) are instantiated here, once.
#include "varia/core/galerkin.hpp"

#include <algorithm>
#include <array>

#include "varia/core/fixed_size.hpp"
#include "varia/core/stormer_verlet.hpp"

namespace varia {

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
  const std::vector<Eigen::Triplet<double>> triplets = constant_mass_entries(lagrangian_, q);
  sparse_mass_.resize(n_, n_);
  sparse_mass_.setFromTriplets(triplets.begin(), triplets.end());
  diagonal_mass_ = sparse_mass_.nonZeros() == n_;
  for (int k = 0; k < n_ && diagonal_mass_; ++k)
    diagonal_mass_ = sparse_mass_.outerIndexPtr()[k] == k && sparse_mass_.innerIndexPtr()[k] == k;
  sparse_mass_solver_.compute(sparse_mass_);
  if (sparse_mass_solver_.info() != Eigen::Success)
    throw NumericalFailure("the Lagrangian's constant mass matrix (its Hessian's velocity block) is not positive "
                           "definite: the Lagrangian is not regular",
                           NAN);
}

}  // namespace varia
