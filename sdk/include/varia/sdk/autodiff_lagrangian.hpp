// A Lagrangian written once, templated on its scalar, with exact derivatives by forward-mode
// automatic differentiation (Eigen's AutoDiffScalar; nested once for the Hessian). The model
// class derives from AutodiffLagrangian<Model> and defines
//
//   template <class T> T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const;
//
// Derivative vectors have a fixed capacity, so an evaluation allocates nothing; for the common
// sizes m + n = 2, 4, 6, 12 (Rn of dim 1, 2, 3; SO3) they have a fixed size, so the arithmetic
// is unrolled and a second-order scalar holds (k+1)^2 doubles instead of 17^2. The same model,
// evaluated at dual numbers over second-order jets (kJetDirections derivative directions at a
// time), gives gradient_jet for every size.
#pragma once

#include <Eigen/Core>
#include <string>
#include <algorithm>
#include <type_traits>
#include <unsupported/Eigen/AutoDiff>

#include "varia/core/lagrangian.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

inline constexpr int kMaxAutodiffVariables = 18;  // m + n of an autodiff Lagrangian (SE(3): 12 + 6)
// First derivatives at jet inputs (Lagrangian::gradient_jet) are taken kJetDirections numbers of
// (q, v) at a time, one evaluation per block: a dual number over jets then holds 1 + 4 jets, and
// a Vec of them (18 x 5 x 1.3 kB) stays within Eigen's stack allocation limit (128 kB).
inline constexpr int kJetDirections = 4;
template <class T>
using Vec = Eigen::Matrix<T, Eigen::Dynamic, 1, 0, kMaxAutodiffVariables, 1>;
using Dual = Eigen::AutoDiffScalar<Vec<double>>;
using Dual2 = Eigen::AutoDiffScalar<Vec<Dual>>;
// The fixed-size counterparts for m + n = K (Eigen's AutoDiffScalar takes any derivative vector).
template <int K>
using FixedDual = Eigen::AutoDiffScalar<Eigen::Matrix<double, K, 1>>;
template <int K>
using FixedDual2 = Eigen::AutoDiffScalar<Eigen::Matrix<FixedDual<K>, K, 1>>;
// A dual number over jets with K derivative directions.
template <int K>
using JetDual = Eigen::AutoDiffScalar<Eigen::Matrix<Jet2, K, 1>>;

template <class Model>
class AutodiffLagrangian : public Lagrangian {
 public:
  AutodiffLagrangian(int position_size, int velocity_size) : m_(position_size), n_(velocity_size) {
    if (m_ + n_ > kMaxAutodiffVariables)
      throw std::invalid_argument("an autodiff Lagrangian takes at most " +
                                  std::to_string(kMaxAutodiffVariables) +
                                  " position and velocity numbers together");
  }
  int position_size() const noexcept final { return m_; }
  int velocity_size() const noexcept final { return n_; }

  Status evaluate(const double* q, const double* v, double* value, double* gradient,
                  double* hessian) noexcept final {
    return guarded(error_, [&] {
      if (hessian != nullptr)
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
      else if (value != nullptr)
        *value = model().lagrangian(Vec<double>(Eigen::Map<const Vec<double>>(q, m_)),
                                    Vec<double>(Eigen::Map<const Vec<double>>(v, n_)));
    });
  }

  bool evaluates_at_jets() const noexcept final { return true; }
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept final {
    return guarded(error_, [&] {
      if (m_ + n_ <= 2) return jet_first_order<2>(q, v, 0, value, gradient);
      for (int first = 0; first < m_ + n_; first += kJetDirections)
        jet_first_order<kJetDirections>(q, v, first, first == 0 ? value : nullptr, gradient);
    });
  }

 protected:
  std::string error_;  // the message of the last failed call (see guarded)

 private:
  const Model& model() const { return static_cast<const Model&>(*this); }
  // Number k of (q, v), q having m numbers.
  template <class T>
  static const T& at(const T* q, const T* v, int m, int k) { return k < m ? q[k] : v[k - m]; }

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
#pragma GCC diagnostic pop

  // L (if value is not null) and the derivatives in the numbers first .. first + K - 1 of (q, v)
  // (those that exist) at jet inputs: forward mode over the jets, one derivative direction per
  // number of the block.
  template <int K>
  void jet_first_order(const Jet2* q, const Jet2* v, int first, Jet2* value, Jet2* gradient) const {
    using JD = JetDual<K>;
    const int k = m_ + n_, last = std::min(first + K, k);
    Vec<JD> qd(m_), vd(n_);
    for (int i = 0; i < k; ++i) {
      JD& z = i < m_ ? qd(i) : vd(i - m_);
      z.value() = at(q, v, m_, i);
      z.derivatives().setConstant(Jet2(0.0));
      if (i >= first && i < last) z.derivatives()(i - first) = Jet2(1.0);
    }
    const JD r = model().lagrangian(qd, vd);
    if (value != nullptr) *value = r.value();
    for (int i = first; i < last; ++i) gradient[i] = r.derivatives().size() ? r.derivatives()(i - first) : Jet2();
  }

  // L, gradient and Hessian by forward mode nested once (derivatives of derivatives).
  template <class D2>
  void second_order(const double* q, const double* v, double* value, double* gradient,
                    double* hessian) const {
    using D = typename D2::Scalar;
    using Inner = typename D::DerType;
    const int k = m_ + n_;
    Vec<D2> qd(m_), vd(n_);
    for (int i = 0; i < k; ++i) {
      D2 z;
      z.value() = D(at(q, v, m_, i), k, i);
      z.derivatives().resize(k);
      for (int j = 0; j < k; ++j) z.derivatives()(j) = D(i == j ? 1.0 : 0.0, Inner::Zero(k));
      (i < m_ ? qd(i) : vd(i - m_)) = z;
    }
    const D2 r = model().lagrangian(qd, vd);
    if (value != nullptr) *value = r.value().value();
    const bool has_first = r.value().derivatives().size() == k;
    const bool has_second = r.derivatives().size() == k;
    for (int i = 0; i < k; ++i) {
      if (gradient != nullptr) gradient[i] = has_first ? r.value().derivatives()(i) : 0.0;
      for (int j = 0; j < k; ++j) {
        const bool has = has_second && r.derivatives()(j).derivatives().size() == k;
        hessian[j * k + i] = has ? r.derivatives()(j).derivatives()(i) : 0.0;
      }
    }
  }

  int m_, n_;
};

}  // namespace varia::sdk
