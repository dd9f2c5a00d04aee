// The shooting construction's shot as one fixed recurrence, where it is one: an explicit
// Runge-Kutta method Psi (Butcher tableau a, b, c with a strictly lower triangular), a Lagrangian
// L = 1/2 v^T M v - V(q) with a constant mass matrix M on R^n, and no forces. The Euler-Lagrange
// field is then (q, v)' = (v, M^{-1} L_q(q, v)), and the shot from q^0 = q0 + eta, v^0 = w0 is
//   S = h sum_i b_i L(q^i, v^i),  (q^{i+1}, v^{i+1}) = Psi_{(c_{i+1} - c_i) h}(q^i, v^i)
// (paper, sec. 3: the shooting-based discrete Lagrangian), carried as second-order jets in the 2n
// variables x = (eta, w0) as shooting.hpp describes, the positions as offsets q^i - (q0 + eta)
// from the origin q0 + eta, so that the far end's offset (the boundary quantity B) is formed to
// its own precision. An explicit method's first stage is at the start of its step, so that the
// evaluation at a node gives L there and L_q, the next step's first stage: s - 1 evaluations a
// step of Psi and one a node.
//
// One piece of code for the places that run it: the SDK inside a Lagrangian's plugin with the
// model inlined (kernel::ExplicitShot, kernels.hpp: the plugin boundary crossed once a shot instead of once a
// stage and a node), and the conformance suite, which checks a plugin's shot against it with the
// plugin's gradient_jet (sdk/conformance/lagrangian.hpp). Its Runge-Kutta step is the SDK's
// explicit methods' step (runge_kutta.hpp), at doubles and jets alike.
#pragma once

#include <type_traits>
#include <utility>

#include "varia/core/fixed_size.hpp"
#include "varia/abi/jet.hpp"
#include "varia/abi/kernels.hpp"

namespace varia {

// out = start + terms(): a small T (a double, a FixedJet) summed in a local, which stays in
// registers (summed in place, every term would store and reload it); a Jet2 (1.3 kB) in place,
// where a local is one more copy (bench/README.md, "Measured design choices").
template <class T, class Terms>
void linear_combination(T& out, const T& start, Terms&& terms) {
  if constexpr (std::is_same_v<T, Jet2>) {
    terms(out = start);
  } else {
    T sum = start;
    terms(sum);
    out = sum;
  }
}

// Y = y0 + h sum_{j < count} a_ij K_j for N numbers (K: the stages, blocks of N); the zero a_ij skipped.
template <class T>
void runge_kutta_stage_point(const RungeKuttaTableau& t, double h, int i, int count, int N, const T* y0,
                             const T* K, T* Y) {
  for (int r = 0; r < N; ++r)
    linear_combination(Y[r], y0[r], [&](T& sum) {
      for (int j = 0; j < count; ++j)
        if (t.at(i, j) != 0.0) add_scaled(sum, h * t.at(i, j), K[j * N + r]);
    });
}

// y1 = y0 + h sum_i b_i K_i, the zero b_i skipped.
template <class T>
void runge_kutta_combination(const RungeKuttaTableau& t, double h, int N, const T* y0, const T* K, T* y1) {
  for (int r = 0; r < N; ++r)
    linear_combination(y1[r], y0[r], [&](T& sum) {
      for (int i = 0; i < t.stages; ++i)
        if (t.b[i] != 0.0) add_scaled(sum, h * t.b[i], K[i * N + r]);
    });
}

// One step y1 = Psi_h(y0) of an explicit method on N numbers: f(y, k) writes the field at y; K holds
// s blocks of N, Y one. With first_given, K's first block already holds f(y0).
template <class T, class Field>
void explicit_runge_kutta_step(const RungeKuttaTableau& t, double h, int N, const T* y0, T* y1, T* K, T* Y,
                               Field&& f, bool first_given = false) {
  for (int i = first_given ? 1 : 0; i < t.stages; ++i) {
    runge_kutta_stage_point(t, h, i, i, N, y0, K, Y);
    f(static_cast<const T*>(Y), K + i * N);
  }
  runge_kutta_combination(t, h, N, y0, K, y1);
}

// The model's evaluations in a shot: one at every node but a last one of zero weight, and s - 1
// in every step of Psi.
inline int shot_evaluations(const ShotPlan& plan) {
  const int last = plan.weight[plan.nodes - 1] != 0.0 ? 1 : 0;
  return plan.nodes - 1 + last + (plan.nodes - 1) * (plan.method.stages - 1);
}

// The jets of J a shot needs as workspace.
inline int shot_workspace(const ShotPlan& plan) { return 10 * plan.n + 2 * plan.n * plan.method.stages; }

// The shot from (q0, w0) at step h: S and the end's offsets q^n - (q0 + eta), jets in x = (eta, w0).
// model(q, v, L, L_q) writes L (where L is not null) and dL/dq at jets (q, v); J is Jet2,
// FixedJet<2n> or FixedJet<2n, n> (the Hessians' columns in w0 only); work holds shot_workspace(plan) jets. Nothing is allocated.
// Dimension, where it is not Eigen::Dynamic, is plan.n known at compile time (the loops over
// the state then have fixed lengths).
template <int Dimension = Eigen::Dynamic, class J, class Model>
void explicit_shot(const ShotPlan& plan, const double* q0, const double* w0, double h, J& S, J* offsets, J* work,
                   Model&& model) {
  const int n = fixed_or<Dimension>(plan.n), N = 2 * n, s = plan.method.stages;
  J* origin = work;
  J* y = origin + n;  // (offsets, v)
  J* next = y + N;
  J* K = next + N;
  J* Y = K + s * N;
  J* q = Y + N;
  J* Lq = q + n;
  for (int r = 0; r < n; ++r) {
    origin[r] = J::variable(q0[r], N, r);
    y[r] = J(0.0);
    y[n + r] = J::variable(w0[r], N, n + r);
  }
  // The field at z = (offsets, v) into k, with L at z where L is not null.
  const auto field = [&](const J* z, J* k, J* L) {
    for (int r = 0; r < n; ++r) add_scaled(q[r] = origin[r], 1.0, z[r]);
    model(static_cast<const J*>(q), z + n, L, Lq);
    for (int r = 0; r < n; ++r) {
      k[r] = z[n + r];
      J& a = k[n + r] = J(0.0);
      for (int c = 0; c < n; ++c)
        if (const double m = plan.inverse_mass[c * n + r]; m != 0.0) add_scaled(a, m, Lq[c]);
    }
  };
  S = J(0.0);
  J L;
  for (int i = 0; i < plan.nodes; ++i) {
    const bool last = i + 1 == plan.nodes;
    if (last && plan.weight[i] == 0.0) break;
    field(y, K, &L);
    if (plan.weight[i] != 0.0) add_scaled(S, h * plan.weight[i], L);
    if (last) break;
    explicit_runge_kutta_step(
        plan.method, (plan.node[i + 1] - plan.node[i]) * h, N, static_cast<const J*>(y), next, K, Y,
        [&](const J* z, J* k) { field(z, k, nullptr); }, true);
    std::swap(y, next);
  }
  for (int r = 0; r < n; ++r) offsets[r] = y[r];
}

}  // namespace varia
