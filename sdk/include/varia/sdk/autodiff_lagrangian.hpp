// A Lagrangian written once, templated on its scalar, with exact derivatives by forward-mode
// automatic differentiation (dual.hpp: Eigen's AutoDiffScalar; nested once for the Hessian). The
// model class derives from AutodiffLagrangian<Model> (sizes read at run time: m and n given to the
// constructor) or AutodiffLagrangian<Model, M, N> (sizes known when it is compiled, as Ceres'
// AutoDiffCostFunction takes them) and defines
//
//   template <class T> T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const;
//
// The model is compiled once per scalar type that its sizes need, and no more: with sizes given
// at compile time (M + N <= kMaxFixedVariables) the dual numbers have that fixed size, so the
// arithmetic is unrolled; with sizes read at run time one family of capacity-bounded dual numbers
// serves every size up to kStackVariables (18), on the stack, so an evaluation allocates nothing.
// Above it forward mode runs in chunks of kChunkDirections directions over workspace vectors sized
// at their first use: k/8 passes of the model for the gradient, one pass per pair of chunks for
// the dense Hessian (about k^2/64 evaluations at 81-double scalars). A large system whose L is a
// sum of terms over few numbers each is better written as a TermwiseLagrangian
// (termwise_lagrangian.hpp): linear cost and a sparse Hessian. The same model at dual numbers over
// second-order jets (kJetDirections directions at a time) gives gradient_jet at any size; forward
// over forward mode at jet values (jet_tangent.hpp) gives hessian_jet at jets of up to 6 variables
// and any size, which shooting's lagrangian form needs for a configuration-dependent mass matrix;
// at constants above the stack size hessian_jet forms the products alone, a Hessian-vector product
// in (m + n) / 8 passes (ChunkProductDual), which shooting's step on the shot's adjoint takes.
// The first-order pass, inlined into one loop, gives the gradients at several points in one call
// (gradients) and runs the Galerkin explicit form's Stormer-Verlet steps inside the plugin
// (kernel::StormerVerletSteps); a model that asks for it (inline_shot) runs the shooting
// construction's shot inside the plugin too (kernel::ExplicitShot, docs/writing-plugins.md).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <optional>
#include <vector>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "varia/core/explicit_shot.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/core/stormer_verlet.hpp"
#include "varia/sdk/dual.hpp"
#include "varia/sdk/jet_tangent.hpp"
#include "varia/sdk/plugin.hpp"
#include "varia/sdk/velocity_structure.hpp"

namespace varia::sdk {

// The most numbers m + n that a model with sizes given at compile time is differentiated at in
// fixed-size dual numbers (SO(3): 9 + 3); above it the capacity-bounded ones serve it too.
inline constexpr int kMaxFixedVariables = 12;

template <class Model, int Positions = Eigen::Dynamic, int Velocities = Positions>
class AutodiffLagrangian : public Lagrangian {
  // Sizes known at compile time (and small enough for fixed-size duals): the one shape compiled.
  static constexpr bool kFixed = Positions != Eigen::Dynamic && Velocities != Eigen::Dynamic && Positions + Velocities <= kMaxFixedVariables;
  static constexpr int kShapeM = kFixed ? Positions : Eigen::Dynamic;
  using FirstDual = std::conditional_t<kFixed, FixedDual<kFixed ? Positions + Velocities : 1>, Dual>;
  using SecondDual = std::conditional_t<kFixed, FixedDual2<kFixed ? Positions + Velocities : 1>, Dual2>;
  // Jets of 2n variables (a shooting step's (eta, w0) on R^n) at a fixed size, for n <= 3.
  static constexpr int kFixedJetVariables = kFixed && Positions == Velocities && 2 * Velocities <= kMaxHessianJetVariables ? 2 * Velocities : 0;

 public:
  AutodiffLagrangian()
    requires(Positions != Eigen::Dynamic && Velocities != Eigen::Dynamic)
      : AutodiffLagrangian(Positions, Velocities) {}
  AutodiffLagrangian(int position_size, int velocity_size)
      : m_(position_size), n_(velocity_size), q_(position_size), v_(velocity_size) {
    if ((Positions != Eigen::Dynamic && m_ != Positions) || (Velocities != Eigen::Dynamic && n_ != Velocities))
      throw std::logic_error("an AutodiffLagrangian<Model, Positions, Velocities> is constructed with m = Positions and n = Velocities");
  }
  int position_size() const noexcept final { return m_; }
  int velocity_size() const noexcept final { return n_; }

  Status evaluate(const double* q, const double* v, double* value, double* gradient,
                  double* hessian) noexcept final {
    return guarded(error_, [&] {
      if (gradient == nullptr && hessian == nullptr) {
        if (value == nullptr) return;
        q_ = Eigen::Map<const Vec<double>>(q, m_);
        v_ = Eigen::Map<const Vec<double>>(v, n_);
        *value = model().lagrangian(q_, v_);
      } else if (above_stack()) {
        if constexpr (!kFixed) {
          if (hessian != nullptr) chunked_second_order(q, v, value, gradient, hessian);
          else chunked_first_order(q, v, value, gradient);
        }
      } else if (hessian != nullptr)
        second_order<SecondDual>(q, v, value, gradient, hessian);
      else if (value != nullptr)
        first_order<FirstDual, kShapeM, true>(q, v, value, gradient);
      else
        first_order<FirstDual, kShapeM, false>(q, v, value, gradient);
    });
  }

  // The gradients at several points through one loop with the model inlined (first_order at each).
  Status gradients(int count, const double* points, double* gradients) noexcept final {
    return guarded(error_, [&] {
      const int k = m_ + n_;
      if constexpr (!kFixed)
        if (above_stack()) {
          for (int i = 0; i < count; ++i)
            chunked_first_order(points + i * k, points + i * k + m_, nullptr, gradients + i * k);
          return;
        }
      gradients_loop<FirstDual, kShapeM>(count, points, gradients);
    });
  }

  // The kernels (abi/kernels.hpp) with the model inlined: Galerkin's explicit form's
  // Stormer-Verlet steps, for m = n and m + n <= kStackVariables (the dual numbers of
  // first_order); the shooting construction's shot, for a model that asks for it
  // (`static constexpr bool inline_shot = true;`: it is the largest function the model is compiled
  // into), sizes given at compile time, m = n up to kMaxShotDimension, and explicit methods of up
  // to kMaxShotStages stages (other models take the core's run of the same recurrences).
  bool offers(const KernelCall& call) const noexcept final {
    if (kernel::arguments<kernel::StormerVerletSteps>(call) != nullptr) return runs_verlet_steps();
    if (const auto* shot = kernel::arguments<kernel::ExplicitShot>(call); shot != nullptr && shot->plan != nullptr)
      return runs_shot(*shot->plan);
    return false;
  }
  Status run(const KernelCall& call) noexcept final {
    return guarded(error_, [&] {
      if (!offers(call)) throw std::invalid_argument("a kernel call that this Lagrangian does not offer");
      if (const auto* verlet = kernel::arguments<kernel::StormerVerletSteps>(call)) {
        if constexpr (!kFixed || Positions == Velocities)
          verlet_loop<FirstDual, kShapeM>(verlet->q, verlet->d, verlet->f, verlet->K, verlet->steps);
      } else if (const auto* shot = kernel::arguments<kernel::ExplicitShot>(call)) {
        if constexpr (inlines_shot())
          fixed_shot<Velocities>(*shot->plan, shot->q0, shot->w0, shot->h, shot->action, shot->offsets);
      }
    });
  }

  // L = 1/2 v^T M v - V(q) with a constant M, read off the model's expression
  // (velocity_structure.hpp), so that no model need declare it: M is then L's Hessian's vv block,
  // the same at every point (here (q, v) = (1/2, ..., 0)); above kStackVariables only that block is
  // formed (n^2 numbers, not (m + n)^2). A model may still override this (as its own declaration,
  // or to refuse the explicit forms); the conformance suite checks a declared M against the Hessian.
  bool constant_mass_matrix(double* mass) const noexcept override {
    if (!has_constant_mass_form()) return false;
    auto* self = const_cast<AutodiffLagrangian*>(this);  // keeps no state between calls but its workspace
    const int k = m_ + n_;
    std::vector<double> q(m_, 0.5), v(n_, 0.0);
    if (above_stack()) {
      if constexpr (!kFixed)
        if (guarded(self->error_, [&] { self->chunked_second_order(q.data(), v.data(), nullptr, nullptr, mass, m_); }))
          return false;
    } else {
      std::vector<double> hessian(k * k);
      if (self->evaluate(q.data(), v.data(), nullptr, nullptr, hessian.data()) != nullptr) return false;
      for (int j = 0; j < n_; ++j)
        for (int i = 0; i < n_; ++i) mass[j * n_ + i] = hessian[(m_ + j) * k + m_ + i];
    }
    return std::all_of(mass, mass + n_ * n_, [](double entry) { return std::isfinite(entry); });
  }

  // At jets the model runs at dual numbers over jets, kJetDirections numbers of (q, v) at a time:
  // on the stack for sizes given at compile time, else over the workspace's inputs (any size).
  bool evaluates_at_jets() const noexcept final { return true; }
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept final {
    return guarded(error_, [&] {
      if constexpr (kFixed) {
        if constexpr (kFixedJetVariables > 0)
          if (jet_variables(q, v) == kFixedJetVariables) return at_fixed_jets<kFixedJetVariables>(q, v, value, gradient);
        at_stack_jets(q, v, value, gradient);
      } else {
        jet_q_.resize(m_), jet_v_.resize(n_);
        at_jets(jet_q_, jet_v_, q, v, value, gradient);
      }
    });
  }
  int hessian_jet_variables() const noexcept final { return kMaxHessianJetVariables; }
  Status hessian_jet(const Jet2* q, const Jet2* v, int first, int count, int directions, const Jet2* U,
                     Jet2* out) noexcept final {
    return guarded(error_, [&] {
      const int variables = jet_variables(q, v, directions, U);
      const HessianRows rows{first, count, directions, U, out};
      if (variables == 0) return hessian_at_constants(q, v, rows);
      if (variables > kMaxHessianJetVariables)
        throw std::length_error("an autodiff Lagrangian gives its Hessian at jets of at most " +
                                std::to_string(kMaxHessianJetVariables) + " variables (hessian_jet_variables())");
      if constexpr (kFixed) {
        if constexpr (kFixedJetVariables > 0 && kFixedJetVariables < kMaxHessianJetVariables)
          if (variables <= kFixedJetVariables) return hessian_at_stack_jets<kFixedJetVariables>(q, v, variables, rows);
        hessian_at_stack_jets<kMaxHessianJetVariables>(q, v, variables, rows);
      } else {
        hessian_jet_q_.resize(m_), hessian_jet_v_.resize(n_);
        hessian_at_jets(hessian_jet_q_, hessian_jet_v_, q, v, variables, rows);
      }
    });
  }

 protected:
  std::string error_;  // the message of the last failed call (see guarded)

 private:
  const Model& model() const { return static_cast<const Model&>(*this); }
  bool runs_verlet_steps() const { return m_ == n_ && m_ + n_ <= kStackVariables; }
  bool runs_shot(const ShotPlan& plan) const {
    return inlines_shot() && plan.n == n_ && plan.method.stages <= kMaxShotStages;
  }
  // Whether the shot kernel is compiled: the model asks for it (inline_shot) and its sizes allow it.
  static constexpr bool inlines_shot() {
    if constexpr (requires { Model::inline_shot; })
      return Model::inline_shot && kFixed && Positions == Velocities && Velocities <= kMaxShotDimension;
    return false;
  }
  // Whether the model's L is 1/2 v^T M v - V(q) with M constant, read once from its expression.
  bool has_constant_mass_form() const {
    if (!constant_mass_form_)
      constant_mass_form_ = sdk::has_constant_mass_form(
          m_, n_, [&](const Vec<VelocityStructure>& q, const Vec<VelocityStructure>& v) { return model().lagrangian(q, v); });
    return *constant_mass_form_;
  }
  // Whether (q, v) has more numbers than dual numbers on the stack take (the chunked passes).
  bool above_stack() const { return !kFixed && m_ + n_ > kStackVariables; }
  // Number k of (q, v), q having m numbers.
  template <class T>
  static const T& at(const T* q, const T* v, int m, int k) { return k < m ? q[k] : v[k - m]; }
  template <class T>
  T& input(Vec<T>& q, Vec<T>& v, int k) const { return k < m_ ? q(k) : v(k - m_); }

  // L and its gradient by forward mode: one derivative direction per number of (q, v). For a
  // fixed-size D the loop runs to the compile-time size, so that it unrolls and each seed e_i is
  // stored whole (not a zero vector then one coefficient, which the next whole-vector load has
  // to wait for); with m fixed too (M >= 0) every index is a constant, and the compiler keeps the
  // seeds in registers instead of storing and reloading them.
  // Without the value (WithValue false), what only L needs is dead code once the model is inlined
  // (flatten: the model and Eigen's dual arithmetic are inlined here; noinline: the frame stays
  // this function's, not evaluate's with every other path in it). Math functions are pure, since
  // varia builds with -fno-math-errno (the evaluator checks finiteness instead), so that a model
  // written c * cos(q) with a double c costs sin q alone (written T(c) * cos(q), the derivative
  // multiplies c's zero derivatives by cos q, and IEEE arithmetic keeps that: sincos).
  // GCC warns of uninitialized reads in the fixed-size seeding that it cannot follow.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  template <class D, int M, bool WithValue>
  [[gnu::noinline, gnu::flatten]] void first_order(const double* q, const double* v, double* value,
                                                   double* gradient) const {
    first_order_inline<D, M, WithValue>(q, v, value, gradient);
  }
  template <class D, int M, bool WithValue>
  [[gnu::always_inline]] void first_order_inline(const double* q, const double* v, double* value,
                                                 double* gradient) const {
    constexpr int fixed = D::DerType::SizeAtCompileTime;
    const int k = fixed > 0 ? fixed : m_ + n_;
    const int m = M >= 0 ? M : m_;
    Vec<D> qd(m), vd(k - m);
    for (int i = 0; i < k; ++i) {
      D& z = i < m ? qd(i) : vd(i - m);
      z.value() = at(q, v, m, i);
      z.derivatives() = D::DerType::Unit(k, i);
    }
    const D r = model().lagrangian(qd, vd);
    if constexpr (WithValue) *value = r.value();
    for (int i = 0; i < k; ++i) gradient[i] = r.derivatives().size() ? r.derivatives()(i) : 0.0;
  }

  template <class D, int M>
  [[gnu::noinline, gnu::flatten]] void gradients_loop(int count, const double* points, double* gradients) const {
    const int k = m_ + n_;
    for (int i = 0; i < count; ++i)
      first_order_inline<D, M, false>(points + i * k, points + i * k + m_, nullptr, gradients + i * k);
  }

  // The Stormer-Verlet kernel with n = M (or m_, for M = Dynamic): the recurrence of stormer_verlet.hpp with
  // the model's dL/dq inlined (flatten), read at (q, v = 0) from one small local array, as the
  // core does a step at a time. For a fixed n the state stays in fixed-size vectors.
  template <class D, int M>
  [[gnu::noinline, gnu::flatten]] void verlet_loop(double* q, double* d, double* f, const double* K,
                                                   long steps) const {
    using Vector = Eigen::Matrix<double, M, 1>;
    using Matrix = Eigen::Matrix<double, M, M>;
    const int n = M >= 0 ? M : m_;
    alignas(64) std::array<double, 2 * kStackVariables> io{}, gradient{};  // (q, v = 0), [dL/dq, dL/dv]
    auto force = [&](const auto& x, auto& g) {
      for (int i = 0; i < n; ++i) io[i] = x(i);
      first_order_inline<D, M, false>(io.data(), io.data() + n, nullptr, gradient.data());
      g = Eigen::Map<const Vector>(gradient.data(), n);
    };
    const Eigen::Map<const Matrix> kick(K, n, n);
    if constexpr (M == Eigen::Dynamic) {
      Eigen::Map<Vector> position(q, n), increment(d, n), dLdq(f, n);
      stormer_verlet_steps(position, increment, dLdq, kick, steps, force);
    } else {
      Eigen::Map<Vector> q_out(q), d_out(d), f_out(f);
      Vector position = q_out, increment = d_out, dLdq = f_out;
      const Matrix k = kick;
      stormer_verlet_steps(position, increment, dLdq, k, steps, force);
      q_out = position;
      d_out = increment;
      f_out = dLdq;
    }
  }
#pragma GCC diagnostic pop

  // A shot at n = N (jets of 2N variables carrying their Hessians' N columns in w0, FixedJet<2N, N>:
  // those that the shooting Newton reads): the recurrence of explicit_shot.hpp at the fixed size N
  // with the model inlined (flatten) at dual numbers over the jets in the N directions of q, which give L
  // and dL/dq together (the velocities' directions, which the field of a constant mass matrix does
  // not use, are not taken). The model reads only the first N inputs of its vectors (as at_fixed_jets).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  template <int N>
  [[gnu::noinline, gnu::flatten]] void fixed_shot(const ShotPlan& plan, const double* q0, const double* w0, double h,
                                                  Jet2* action, Jet2* offsets) const {
    using J = FixedJet<2 * N, N>;  // the Hessians' columns in w0 only (kernel::ExplicitShot)
    using D = JetDual<N, J>;
    std::array<J, 10 * N + 2 * N * kMaxShotStages> work;
    std::array<J, N> end;
    J S;
    explicit_shot<N>(plan, q0, w0, h, S, end.data(), work.data(), [&](const J* q, const J* v, J* L, J* Lq) {
      Vec<D> qd(N), vd(N);
      for (int r = 0; r < N; ++r) {
        qd(r).value() = q[r];
        vd(r).value() = v[r];
        for (int d = 0; d < N; ++d) {
          qd(r).derivatives()(d) = J(d == r ? 1.0 : 0.0);
          vd(r).derivatives()(d) = J(0.0);
        }
      }
      const D result = model().lagrangian(qd, vd);
      if (L != nullptr) *L = result.value();
      for (int r = 0; r < N; ++r) Lq[r] = result.derivatives()(r);
    });
    S.to_jet2(*action);
    for (int r = 0; r < N; ++r) end[r].to_jet2(offsets[r]);
  }
#pragma GCC diagnostic pop

  // The number of variables of the jets (q, v) (0 when all are constants), or of the directions U.
  int jet_variables(const Jet2* q, const Jet2* v) const {
    for (int i = 0; i < m_ + n_; ++i)
      if (const Jet2& z = at(q, v, m_, i); !z.constant()) return static_cast<int>(z.gradient.size());
    return 0;
  }
  int jet_variables(const Jet2* q, const Jet2* v, int directions, const Jet2* U) const {
    if (const int variables = jet_variables(q, v); variables > 0) return variables;
    for (int i = 0; i < directions * (m_ + n_); ++i)
      if (!U[i].constant()) return static_cast<int>(U[i].gradient.size());
    return 0;
  }
  // gradient_jet at jets of N variables: the model at dual numbers over FixedJet<N> (N + N^2
  // numbers each, every loop of the chain rule of a fixed length), converted from and to Jet2.
  // A shooting pass's jets have up to twice the manifold's dimension in variables (shooting.hpp).
  // The model reads only the first m + n inputs, which are set; GCC cannot see that, and warns of
  // the others (uninitialized FixedJet's, jet.hpp). Filling them would cost a large part of the
  // evaluation.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  template <int N>
  void at_fixed_jets(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) const {
    std::array<FixedJet<N>, kStackVariables> inputs, outputs;
    FixedJet<N> fixed_value;
    for (int i = 0; i < m_ + n_; ++i) inputs[i] = FixedJet<N>(at(q, v, m_, i));
    at_stack_jets(inputs.data(), inputs.data() + m_, value != nullptr ? &fixed_value : nullptr, outputs.data());
    if (value != nullptr) fixed_value.to_jet2(*value);
    for (int i = 0; i < m_ + n_; ++i) outputs[i].to_jet2(gradient[i]);
  }
  // At jets J (sizes given at compile time), over dual numbers on the stack: one pass of forward
  // mode over every number of (q, v) up to two of them, else one per block of kJetDirections.
  template <class J>
  void at_stack_jets(const J* q, const J* v, J* value, J* gradient) const {
    constexpr int K = Positions + Velocities <= 2 ? 2 : kJetDirections;
    Vec<JetDual<K, J>> qd(m_), vd(n_);
    at_jets(qd, vd, q, v, value, gradient);
  }
  // At jets J over the dual inputs qd, vd: one pass of forward mode per block of their directions.
  template <class JD, class J>
  void at_jets(Vec<JD>& qd, Vec<JD>& vd, const J* q, const J* v, J* value, J* gradient) const {
    for (int first = 0; first < m_ + n_; first += JD::DerType::MaxRowsAtCompileTime)
      jet_first_order(qd, vd, q, v, first, first == 0 ? value : nullptr, gradient);
  }
  // L (if value is not null) and the derivatives in the numbers first .. first + K - 1 of (q, v)
  // (those that exist, K the dual numbers' directions) at jet inputs: forward mode over the jets,
  // one derivative direction per number of the block, over the dual inputs qd, vd.
  template <class JD, class J>
  void jet_first_order(Vec<JD>& qd, Vec<JD>& vd, const J* q, const J* v, int first, J* value, J* gradient) const {
    constexpr int K = JD::DerType::MaxRowsAtCompileTime;
    const int k = m_ + n_, last = std::min(first + K, k);
    for (int i = 0; i < k; ++i) seed(input(qd, vd, i), at(q, v, m_, i), K, i - first);
    const JD r = model().lagrangian(qd, vd);
    if (value != nullptr) *value = r.value();
    for (int i = first; i < last; ++i) gradient[i] = derivative(r, i - first);
  }
#pragma GCC diagnostic pop

  // Lagrangian::hessian_jet's request: rows first .. first + count - 1 of L's Hessian times the
  // directions U_0 .. U_{d-1} (m + n jets each), into out[j count + r].
  struct HessianRows {
    int first, count, directions;
    const Jet2* U;
    Jet2* out;
  };
  // Those products at jets of `variables` <= N variables (held as FixedJet<N>, padded with zero
  // derivatives): forward over forward mode with jet values, the outer level Eigen's
  // AutoDiffScalar seeded with the rows' unit vectors, the inner a JetTangent (jet_tangent.hpp)
  // seeded with the directions, kHessianJetDirections of each a pass: one pass of the model per
  // block of rows and block of directions, whose second derivatives are H(rows, :) U. Sizes given
  // at compile time: over dual inputs on the stack; read at run time: over the workspace's (any
  // size).
  template <int N>
  void hessian_at_stack_jets(const Jet2* q, const Jet2* v, int variables, const HessianRows& rows) {
    Vec<HessianJetDual<N>> qd(m_), vd(n_);
    hessian_at_jets(qd, vd, q, v, variables, rows);
  }
  template <int N>
  static FixedJet<N> padded(const Jet2& x, int variables) {
    FixedJet<N> z(x.value);
    if (x.constant()) return z;
    z.is_constant = false;
    z.gradient.head(variables) = x.gradient;
    z.hessian.topLeftCorner(variables, variables) = x.hessian;
    return z;
  }
  template <class Outer>
  void hessian_at_jets(Vec<Outer>& qd, Vec<Outer>& vd, const Jet2* q, const Jet2* v, int variables,
                       const HessianRows& rows) {
    constexpr int K = kHessianJetDirections;
    using Inner = typename Outer::Scalar;
    using J = std::remove_cvref_t<decltype(std::declval<Inner>().value)>;
    constexpr int N = decltype(J::gradient)::RowsAtCompileTime;
    const int k = m_ + n_;
    auto& z = hessian_jet_workspace<J>();
    z.resize(static_cast<std::size_t>(k) * (1 + rows.directions));  // (q, v), then the directions
    for (int i = 0; i < k; ++i) z[i] = padded<N>(at(q, v, m_, i), variables);
    for (int i = 0; i < k * rows.directions; ++i) z[k + i] = padded<N>(rows.U[i], variables);
    for (int a = 0; a < rows.count; a += K)
      for (int b = 0; b < rows.directions; b += K) {
        for (int i = 0; i < k; ++i) {
          Outer& x = input(qd, vd, i);
          x.value() = inner_seed<Inner>(z, k, i, b, rows.directions);
          x.derivatives().resize(K);
          for (int j = 0; j < K; ++j) x.derivatives()(j) = Inner(i == rows.first + a + j ? 1.0 : 0.0);
        }
        const Outer r = model().lagrangian(qd, vd);
        for (int j = 0; j < K && a + j < rows.count; ++j)
          for (int i = 0; i < K && b + i < rows.directions; ++i)
            rows.out[(b + i) * rows.count + a + j] = truncated(derivative(r, j).derivative(i), variables);
      }
  }
  // Input i's inner dual number: its jet z[i] with the directions b .. b + K - 1 (those of the
  // `directions` that exist), z[k + j k + i] for direction j; a constant where all of them are zero
  // (a unit direction is zero but in one input), so that its derivatives are not carried.
  template <class Inner, class J>
  static Inner inner_seed(const std::vector<J>& z, int k, int i, int b, int directions) {
    constexpr int K = kHessianJetDirections;
    std::array<J, K> d;
    bool zero = true;
    for (int j = 0; j < K; ++j) {
      d[j] = b + j < directions ? z[k + (b + j) * k + i] : J(0.0);
      zero = zero && d[j].constant() && d[j].value == 0.0;
    }
    return zero ? Inner(z[i]) : Inner(z[i], d);
  }
  // The padded jets of (q, v) and the directions, for jets J: a workspace per jet size, sized at its
  // first use.
  template <class J>
  std::vector<J>& hessian_jet_workspace() {
    if constexpr (std::is_same_v<J, FixedJet<kMaxHessianJetVariables>>) return hessian_jet_z_;
    else return hessian_jet_small_z_;
  }
  template <int N>
  static Jet2 truncated(const FixedJet<N>& x, int variables) {
    Jet2 jet(x.value);
    jet.gradient = x.gradient.head(variables);
    jet.hessian = x.hessian.topLeftCorner(variables, variables);
    return jet;
  }
  // Constant inputs and directions: the Hessian at their values (evaluate's) times the directions'
  // values, as constant jets; above kStackVariables the products alone (chunked_hessian_products).
  void hessian_at_constants(const Jet2* q, const Jet2* v, const HessianRows& rows) {
    if constexpr (!kFixed)
      if (above_stack()) return chunked_hessian_products(q, v, rows);
    const int k = m_ + n_;
    at_constants_.resize(k), hessian_at_constants_.resize(static_cast<std::size_t>(k) * k);
    for (int i = 0; i < k; ++i) at_constants_[i] = at(q, v, m_, i).value;
    if (const Status status = evaluate(at_constants_.data(), at_constants_.data() + m_, nullptr, nullptr,
                                       hessian_at_constants_.data()))
      throw std::runtime_error(status);
    for (int j = 0; j < rows.directions; ++j)
      for (int r = 0; r < rows.count; ++r) {
        double sum = 0.0;
        for (int c = 0; c < k; ++c)
          sum += hessian_at_constants_[static_cast<std::size_t>(c) * k + rows.first + r] * rows.U[j * k + c].value;
        rows.out[j * rows.count + r] = Jet2(sum);
      }
  }

  // H(rows, :) U at constants by forward over forward mode: the outer level seeded with the unit
  // vectors of kChunkDirections rows, the inner with the values of one direction, so that the
  // second derivatives are (H U_d)(row) (ChunkProductDual, fixed sizes). One pass a block of rows
  // and a direction: a Hessian-vector product costs (m + n) / 8 passes, where the whole Hessian is
  // ((m + n) / 8)^2 / 2 passes at the chunks' 8 x 8 second-order numbers (bench/README.md).
  void chunked_hessian_products(const Jet2* q, const Jet2* v, const HessianRows& rows) {
    const int k = m_ + n_;
    product_q_.resize(m_), product_v_.resize(n_);
    for (int d = 0; d < rows.directions; ++d)
      for (int a = 0; a < rows.count; a += kChunkDirections) {
        for (int i = 0; i < k; ++i) {
          ChunkProductDual& x = input(product_q_, product_v_, i);
          x.value() = FixedDual<1>(at(q, v, m_, i).value, Eigen::Matrix<double, 1, 1>(rows.U[d * k + i].value));
          for (int j = 0; j < kChunkDirections; ++j)
            x.derivatives()(j) = FixedDual<1>(i == rows.first + a + j ? 1.0 : 0.0, Eigen::Matrix<double, 1, 1>(0.0));
        }
        const ChunkProductDual r = model().lagrangian(product_q_, product_v_);
        for (int j = 0; j < kChunkDirections && a + j < rows.count; ++j)
          rows.out[d * rows.count + a + j] = Jet2(r.derivatives()(j).derivatives()(0));
      }
  }

  // L, gradient and Hessian by forward mode nested once (derivatives of derivatives).
  template <class D2>
  void second_order(const double* q, const double* v, double* value, double* gradient,
                    double* hessian) const {
    const int k = m_ + n_;
    Vec<D2> qd(m_), vd(n_);
    for (int i = 0; i < k; ++i) seed(input(qd, vd, i), at(q, v, m_, i), k, i, k, i);
    const D2 r = model().lagrangian(qd, vd);
    if (value != nullptr) *value = r.value().value();
    for (int i = 0; i < k; ++i) {
      if (gradient != nullptr) gradient[i] = derivative(r.value(), i);
      for (int j = 0; j < k; ++j) hessian[j * k + i] = second_derivative(r, j, i);
    }
  }

  // Above kStackVariables: L and the gradient by forward mode, kChunkDirections directions of
  // (q, v) per pass of the model.
  void chunked_first_order(const double* q, const double* v, double* value, double* gradient) {
    const int k = m_ + n_;
    chunk_q_.resize(m_), chunk_v_.resize(n_);
    for (int first = 0; first < k; first += kChunkDirections) {
      const int size = std::min(kChunkDirections, k - first);
      for (int i = 0; i < k; ++i) seed(input(chunk_q_, chunk_v_, i), at(q, v, m_, i), size, i - first);
      const ChunkDual r = model().lagrangian(chunk_q_, chunk_v_);
      if (value != nullptr && first == 0) *value = r.value();
      for (int i = 0; i < size; ++i) gradient[first + i] = derivative(r, i);
    }
  }
  // And the Hessian: forward over forward, one pass per pair of chunks (a, b) with b >= a, whose
  // block of second derivatives gives H(a.., b..) and, by symmetry, H(b.., a..). With first > 0,
  // only the block of the numbers first.. of (q, v) (value and gradient null).
  void chunked_second_order(const double* q, const double* v, double* value, double* gradient, double* hessian,
                            int first = 0) {
    const int k = m_ + n_, size = k - first;
    chunk2_q_.resize(m_), chunk2_v_.resize(n_);
    for (int a = first; a < k; a += kChunkDirections) {
      const int inner = std::min(kChunkDirections, k - a);
      for (int b = a; b < k; b += kChunkDirections) {
        const int outer = std::min(kChunkDirections, k - b);
        for (int i = 0; i < k; ++i) seed(input(chunk2_q_, chunk2_v_, i), at(q, v, m_, i), inner, i - a, outer, i - b);
        const ChunkDual2 r = model().lagrangian(chunk2_q_, chunk2_v_);
        if (value != nullptr && a == 0 && b == 0) *value = r.value().value();
        if (gradient != nullptr && a == b)
          for (int i = 0; i < inner; ++i) gradient[a + i] = derivative(r.value(), i);
        for (int j = 0; j < outer; ++j)
          for (int i = 0; i < inner; ++i)
            hessian[(a - first + i) * size + b - first + j] = hessian[(b - first + j) * size + a - first + i] =
                second_derivative(r, j, i);
      }
    }
  }

  int m_, n_;
  mutable std::optional<bool> constant_mass_form_;
  // Workspace: the value's inputs; the others (the chunks' and the jets' dual inputs, the Hessian at
  // constants) are sized at their first use, so a model allocates only what the constructions ask of it.
  Vec<double> q_, v_;
  Vec<ChunkJetDual> jet_q_, jet_v_;
  Vec<ChunkDual> chunk_q_, chunk_v_;
  Vec<ChunkDual2> chunk2_q_, chunk2_v_;
  Vec<ChunkProductDual> product_q_, product_v_;
  Vec<ChunkHessianJetDual> hessian_jet_q_, hessian_jet_v_;
  std::vector<FixedJet<kMaxHessianJetVariables>> hessian_jet_z_;
  std::vector<FixedJet<(kFixedJetVariables > 0 && kFixedJetVariables < kMaxHessianJetVariables ? kFixedJetVariables : 1)>>
      hessian_jet_small_z_;  // hessian_at_stack_jets<kFixedJetVariables>'s
  std::vector<double> at_constants_, hessian_at_constants_;
};

}  // namespace varia::sdk
