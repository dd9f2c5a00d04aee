// A Lagrangian written once, templated on its scalar, with exact derivatives by forward-mode
// automatic differentiation (dual.hpp: Eigen's AutoDiffScalar; nested once for the Hessian). The
// model class derives from AutodiffLagrangian<Model> and defines
//
//   template <class T> T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const;
//
// Any number m + n of positions and velocities. Up to kStackVariables (18) the derivatives are
// taken in one pass by dual numbers on the stack, so an evaluation allocates nothing; for the common
// sizes m + n = 2, 4, 6, 12 (Rn of dim 1, 2, 3; SO3) they have a fixed size, so the arithmetic
// is unrolled and a second-order scalar holds (k+1)^2 doubles instead of 19^2. Above it the
// Hessian is dense all the same, and forward mode runs in chunks of kChunkDirections directions
// over workspace vectors sized once: k/8 passes of the model for the gradient, one pass per pair
// of chunks for the Hessian, so a Hessian costs about k^2/64 evaluations of the model at 81-double
// scalars. A large system whose L is a sum of terms over few numbers each is better written as a
// TermwiseLagrangian (termwise_lagrangian.hpp): linear cost and a sparse Hessian. The same model,
// evaluated at dual numbers over second-order jets (kJetDirections derivative directions at a
// time), gives gradient_jet, for up to kStackVariables numbers (the shooting construction's jets
// hold fewer variables than that). Forward mode over forward mode at jet values (jet_tangent.hpp)
// gives hessian_jet at jets of up to 6 variables, which the shooting construction's lagrangian
// form needs for a configuration-dependent mass matrix (it propagates in passes of at most that
// many variables: any dimension up to kStackVariables / 2). The same first-order pass, inlined into
// one loop, gives the gradients at several points in one call (gradients) and runs the Galerkin
// explicit form's Stormer-Verlet steps inside the plugin (verlet_steps, stormer_verlet.hpp).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "varia/core/lagrangian.hpp"
#include "varia/core/stormer_verlet.hpp"
#include "varia/sdk/dual.hpp"
#include "varia/sdk/jet_tangent.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

template <class Model>
class AutodiffLagrangian : public Lagrangian {
 public:
  AutodiffLagrangian(int position_size, int velocity_size)
      : m_(position_size), n_(velocity_size), q_(position_size), v_(velocity_size) {
    if (m_ + n_ > kStackVariables) {
      chunk_q_.resize(m_), chunk_v_.resize(n_);
      chunk2_q_.resize(m_), chunk2_v_.resize(n_);
    }
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
      } else if (m_ + n_ > kStackVariables) {
        if (hessian != nullptr) chunked_second_order(q, v, value, gradient, hessian);
        else chunked_first_order(q, v, value, gradient);
      } else if (hessian != nullptr)
        dispatch([&](auto, auto second, auto) {
          second_order<typename decltype(second)::type>(q, v, value, gradient, hessian);
        });
      else if (gradient != nullptr && value != nullptr)
        dispatch([&](auto first, auto, auto m) {
          first_order<typename decltype(first)::type, decltype(m)::value, true>(q, v, value, gradient);
        });
      else if (gradient != nullptr)
        dispatch([&](auto first, auto, auto m) {
          first_order<typename decltype(first)::type, decltype(m)::value, false>(q, v, value, gradient);
        });
    });
  }

  // The gradients at several points through one loop with the model inlined (first_order at each).
  Status gradients(int count, const double* points, double* gradients) noexcept final {
    return guarded(error_, [&] {
      const int k = m_ + n_;
      if (k > kStackVariables) {
        for (int i = 0; i < count; ++i) chunked_first_order(points + i * k, points + i * k + m_, nullptr, gradients + i * k);
        return;
      }
      dispatch([&](auto first, auto, auto m) {
        gradients_loop<typename decltype(first)::type, decltype(m)::value>(count, points, gradients);
      });
    });
  }

  // The explicit form's Stormer-Verlet steps with the model inlined in the loop: for m = n and
  // m + n <= kStackVariables (the dual numbers of first_order).
  bool runs_verlet_steps() const noexcept final { return m_ == n_ && m_ + n_ <= kStackVariables; }
  Status verlet_steps(double* q, double* d, double* f, const double* K, long steps) noexcept final {
    return guarded(error_, [&] {
      if (!runs_verlet_steps())
        throw std::length_error("an autodiff Lagrangian runs Stormer-Verlet steps for m = n and at most " +
                                std::to_string(kStackVariables) + " position and velocity numbers together");
      dispatch([&](auto first, auto, auto m) {
        verlet_loop<typename decltype(first)::type, decltype(m)::value>(q, d, f, K, steps);
      });
    });
  }

  // The shooting construction's shot with the model inlined (explicit_shot.hpp): for m = n up to
  // kMaxShotDimension and explicit methods of up to kMaxShotStages stages.
  bool runs_shots(const ShotPlan& plan) const noexcept final {
    return m_ == n_ && plan.n == n_ && n_ <= kMaxShotDimension && plan.method.stages <= kMaxShotStages;
  }
  Status shoot(const ShotPlan& plan, const double* q0, const double* w0, double h, Jet2* action,
               Jet2* offsets) noexcept final {
    return guarded(error_, [&] {
      if (!runs_shots(plan))
        throw std::length_error("an autodiff Lagrangian runs shots for m = n <= " + std::to_string(kMaxShotDimension) +
                                " and explicit methods of at most " + std::to_string(kMaxShotStages) + " stages");
      switch (n_) {
        case 1: return fixed_shot<1>(plan, q0, w0, h, action, offsets);
        case 2: return fixed_shot<2>(plan, q0, w0, h, action, offsets);
        default: return fixed_shot<3>(plan, q0, w0, h, action, offsets);
      }
    });
  }

  // At jets the model runs at dual numbers on the stack: up to kStackVariables numbers (q, v). Above
  // that the shooting construction refuses the Lagrangian when it is built (validate, exit 2).
  bool evaluates_at_jets() const noexcept final { return m_ + n_ <= kStackVariables; }
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept final {
    return guarded(error_, [&] {
      if (m_ + n_ > kStackVariables)
        throw std::length_error("an autodiff Lagrangian evaluates at jets with at most " +
                                 std::to_string(kStackVariables) + " position and velocity numbers together");
      switch (jet_variables(q, v)) {
        case 2: return at_fixed_jets<2>(q, v, value, gradient);
        case 4: return at_fixed_jets<4>(q, v, value, gradient);
        case 6: return at_fixed_jets<6>(q, v, value, gradient);
        default: return at_jets(q, v, value, gradient);
      }
    });
  }
  int hessian_jet_variables() const noexcept final { return m_ + n_ <= kStackVariables ? kMaxHessianJetVariables : 0; }
  Status hessian_jet(const Jet2* q, const Jet2* v, Jet2* hessian) noexcept final {
    return guarded(error_, [&] {
      if (m_ + n_ > kStackVariables)
        throw std::length_error("an autodiff Lagrangian gives its Hessian at jets for at most " +
                                std::to_string(kStackVariables) + " position and velocity numbers together");
      const int variables = jet_variables(q, v);
      if (variables == 0) return hessian_at_constants(q, v, hessian);
      if (variables <= 2) return hessian_at_fixed_jets<2>(q, v, variables, hessian);
      if (variables <= 4) return hessian_at_fixed_jets<4>(q, v, variables, hessian);
      if (variables <= kMaxHessianJetVariables) return hessian_at_fixed_jets<6>(q, v, variables, hessian);
      throw std::length_error("an autodiff Lagrangian gives its Hessian at jets of at most " +
                              std::to_string(kMaxHessianJetVariables) + " variables (hessian_jet_variables())");
    });
  }

 protected:
  std::string error_;  // the message of the last failed call (see guarded)

 private:
  const Model& model() const { return static_cast<const Model&>(*this); }
  // Number k of (q, v), q having m numbers.
  template <class T>
  static const T& at(const T* q, const T* v, int m, int k) { return k < m ? q[k] : v[k - m]; }
  template <class T>
  T& input(Vec<T>& q, Vec<T>& v, int k) const { return k < m_ ? q(k) : v(k - m_); }

  // Calls f with tags (std::type_identity) of the first- and second-order scalar types for
  // k = m + n, and m as a compile-time constant (Shape): fixed-size types where k is one of the
  // common sizes, with m fixed too for the common shapes (R^1..R^3: m = n; SO(3): 9 + 3), so that
  // every index of the first-order seeding is known at compile time; else the capacity-bounded
  // dynamic types and m = Eigen::Dynamic (read at run time).
  template <class T>
  using Tag = std::type_identity<T>;
  template <int M>
  using Shape = std::integral_constant<int, M>;
  template <class F>
  void dispatch(F&& f) const {
    switch (m_ + n_) {
      case 2: return common_shape<2, 1>(f);
      case 4: return common_shape<4, 2>(f);
      case 6: return common_shape<6, 3>(f);
      case 12: return common_shape<12, 9>(f);
      default: return f(Tag<Dual>(), Tag<Dual2>(), Shape<Eigen::Dynamic>());
    }
  }
  template <int K, int M, class F>
  void common_shape(F& f) const {
    if (m_ == M) return f(Tag<FixedDual<K>>(), Tag<FixedDual2<K>>(), Shape<M>());
    return f(Tag<FixedDual<K>>(), Tag<FixedDual2<K>>(), Shape<Eigen::Dynamic>());
  }

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
  // The model is compiled for every common shape, also those it never runs with (an SO(3) model
  // at m = 1, whose q(6) would read past the size): GCC's warnings of uninitialized reads there
  // are about code that never runs.
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

  // verlet_steps with n = M (or m_, for M = Dynamic): the recurrence of stormer_verlet.hpp with
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
    using J = FixedJet<2 * N, N>;  // the Hessians' columns in w0 only (Lagrangian::shoot)
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

  // The number of variables of the jets (q, v) (0 when all are constants).
  int jet_variables(const Jet2* q, const Jet2* v) const {
    for (int i = 0; i < m_ + n_; ++i)
      if (const Jet2& z = at(q, v, m_, i); !z.constant()) return static_cast<int>(z.gradient.size());
    return 0;
  }
  // gradient_jet at jets of N variables: the model at dual numbers over FixedJet<N> (N + N^2
  // numbers each, every loop of the chain rule of a fixed length), converted from and to Jet2.
  // A shooting pass's jets have up to twice the manifold's dimension in variables (shooting.hpp).
  // The model reads only the first m + n inputs, which are set; GCC cannot see that, and warns of
  // the others (uninitialized FixedJet's, jet.hpp). Filling them took a sixth of the evaluation.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
  template <int N>
  void at_fixed_jets(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) const {
    std::array<FixedJet<N>, kStackVariables> inputs, outputs;
    FixedJet<N> fixed_value;
    for (int i = 0; i < m_ + n_; ++i) inputs[i] = FixedJet<N>(at(q, v, m_, i));
    at_jets(inputs.data(), inputs.data() + m_, value != nullptr ? &fixed_value : nullptr, outputs.data());
    if (value != nullptr) fixed_value.to_jet2(*value);
    for (int i = 0; i < m_ + n_; ++i) outputs[i].to_jet2(gradient[i]);
  }
  // At jets J: one pass of forward mode over every number of (q, v) up to two of them, else one
  // per block of kJetDirections.
  template <class J>
  void at_jets(const J* q, const J* v, J* value, J* gradient) const {
    if (m_ + n_ <= 2) return jet_first_order<2>(q, v, 0, value, gradient);
    for (int first = 0; first < m_ + n_; first += kJetDirections)
      jet_first_order<kJetDirections>(q, v, first, first == 0 ? value : nullptr, gradient);
  }
  // L (if value is not null) and the derivatives in the numbers first .. first + K - 1 of (q, v)
  // (those that exist) at jet inputs: forward mode over the jets, one derivative direction per
  // number of the block.
  template <int K, class J>
  void jet_first_order(const J* q, const J* v, int first, J* value, J* gradient) const {
    using JD = JetDual<K, J>;
    const int k = m_ + n_, last = std::min(first + K, k);
    Vec<JD> qd(m_), vd(n_);
    for (int i = 0; i < k; ++i) seed(input(qd, vd, i), at(q, v, m_, i), K, i - first);
    const JD r = model().lagrangian(qd, vd);
    if (value != nullptr) *value = r.value();
    for (int i = first; i < last; ++i) gradient[i] = derivative(r, i - first);
  }
#pragma GCC diagnostic pop

  // L's Hessian at jets of `variables` <= N variables (held as FixedJet<N>, padded with zero
  // derivatives): forward over forward mode with jet values, the outer level
  // Eigen's AutoDiffScalar, the inner a JetTangent (jet_tangent.hpp), kHessianJetDirections
  // directions each: one pass of the model per pair of blocks (a, b), b >= a, whose second
  // derivatives give H(a.., b..) and, by symmetry, H(b.., a..).
  template <int N>
  void hessian_at_fixed_jets(const Jet2* q, const Jet2* v, int variables, Jet2* hessian) const {
    constexpr int K = kHessianJetDirections;
    using Inner = JetTangent<FixedJet<N>, K>;
    using Outer = Eigen::AutoDiffScalar<Eigen::Matrix<Inner, K, 1>>;
    const int k = m_ + n_;
    std::array<FixedJet<N>, kStackVariables> z;
    for (int i = 0; i < k; ++i) {
      const Jet2& x = at(q, v, m_, i);
      z[i] = FixedJet<N>(x.value);
      if (x.constant()) continue;
      z[i].is_constant = false;
      z[i].gradient.head(variables) = x.gradient;
      z[i].hessian.topLeftCorner(variables, variables) = x.hessian;
    }
    Vec<Outer> qd(m_), vd(n_);
    for (int a = 0; a < k; a += K)
      for (int b = a; b < k; b += K) {
        for (int i = 0; i < k; ++i) {
          Outer& x = input(qd, vd, i);
          x.value() = Inner(z[i]);
          if (i >= b && i < b + K) x.value().derivatives[i - b] = FixedJet<N>(1.0);
          for (int j = 0; j < K; ++j) x.derivatives()(j) = Inner(i == a + j ? 1.0 : 0.0);
        }
        const Outer r = model().lagrangian(qd, vd);
        for (int j = 0; j < K && a + j < k; ++j)
          for (int i = 0; i < K && b + i < k; ++i)
            hessian[(a + j) * k + b + i] = hessian[(b + i) * k + a + j] =
                truncated(r.derivatives()(j).derivatives[i], variables);
      }
  }
  template <int N>
  static Jet2 truncated(const FixedJet<N>& x, int variables) {
    Jet2 jet(x.value);
    jet.gradient = x.gradient.head(variables);
    jet.hessian = x.hessian.topLeftCorner(variables, variables);
    return jet;
  }
  // Constant inputs: the Hessian at their values, as constant jets.
  void hessian_at_constants(const Jet2* q, const Jet2* v, Jet2* hessian) {
    const int k = m_ + n_;
    for (int i = 0; i < k; ++i) input(q_, v_, i) = at(q, v, m_, i).value;
    std::array<double, kStackVariables * kStackVariables> values;
    dispatch([&](auto, auto second, auto) {
      second_order<typename decltype(second)::type>(q_.data(), v_.data(), nullptr, nullptr, values.data());
    });
    for (int i = 0; i < k * k; ++i) hessian[i] = Jet2(values[i]);
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
    for (int first = 0; first < k; first += kChunkDirections) {
      const int size = std::min(kChunkDirections, k - first);
      for (int i = 0; i < k; ++i) seed(input(chunk_q_, chunk_v_, i), at(q, v, m_, i), size, i - first);
      const ChunkDual r = model().lagrangian(chunk_q_, chunk_v_);
      if (value != nullptr && first == 0) *value = r.value();
      for (int i = 0; i < size; ++i) gradient[first + i] = derivative(r, i);
    }
  }
  // And the Hessian: forward over forward, one pass per pair of chunks (a, b) with b >= a, whose
  // block of second derivatives gives H(a.., b..) and, by symmetry, H(b.., a..).
  void chunked_second_order(const double* q, const double* v, double* value, double* gradient,
                            double* hessian) {
    const int k = m_ + n_;
    for (int a = 0; a < k; a += kChunkDirections) {
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
            hessian[(a + i) * k + b + j] = hessian[(b + j) * k + a + i] = second_derivative(r, j, i);
      }
    }
  }

  int m_, n_;
  // Workspace, sized once: the value's inputs, and above kStackVariables the chunks' dual inputs.
  Vec<double> q_, v_;
  Vec<ChunkDual> chunk_q_, chunk_v_;
  Vec<ChunkDual2> chunk2_q_, chunk2_v_;
};

}  // namespace varia::sdk
