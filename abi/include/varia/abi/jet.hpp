// A second-order jet: the value, gradient and Hessian of a quantity as a function of at most
// kMaxJetVariables independent variables, carried through arithmetic by the chain rule. The
// shooting construction (paper, sec. 3) propagates jets in (q0, v0) through the one-step method,
// so that the action S and the end point q^n come out with the first derivatives that D1 L_d and
// D2 L_d need and the second derivatives that the exact Newton Jacobian of the shooting solve
// needs. Derivative storage has a fixed capacity: jet arithmetic allocates nothing.
//
// A jet with an empty gradient is a constant (its derivatives are zero); arithmetic mixes
// constants and variables freely, and doubles convert to constants implicitly.
//
// FixedJet<N> is the same jet over exactly N variables, stored in N + N^2 numbers: the SDK
// evaluates a model at dual numbers over it when a shooting step's jets are few (jets of the
// plugin interface are Jet2). FixedJet<N, C> carries only the Hessian's last C columns, those in
// the last C variables (N + N C numbers): the second derivatives that a shooting Newton's
// Jacobian takes are those in w0, the last n of the 2n variables (eta, w0) (shooting.hpp), and the
// chain rule gives each column from the same column of its operands. Both share one arithmetic (JetArithmetic: the chain rule written
// once, as hidden friends, so that a double converts to a constant jet in mixed expressions).
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <cmath>
#include <compare>
#include <cstring>

namespace varia {

inline constexpr int kMaxJetVariables = 12;

template <int N, int C = N>
struct FixedJet;

namespace jet {

// f(a), given f(a.value) and f', f'' there: g = f' a_g, H = f' a_H + f'' a_g a_g^T.
// Plain loops over the n (at most kMaxJetVariables) variables, one pass over the Hessian: jets
// are small, and a generic product's setup would cost more than its arithmetic.
template <class J>
J unary(const J& a, double f, double d1, double d2) {
  J r(f);
  if (a.constant() || (d1 == 0.0 && d2 == 0.0)) return r;
  const int n = static_cast<int>(a.gradient.size());
  r.resize(n);
  const double* __restrict g = a.gradient.data();
  const double* __restrict H = a.hessian.data();
  double* __restrict rg = r.gradient.data();
  double* __restrict rH = r.hessian.data();
  for (int i = 0; i < n; ++i) rg[i] = d1 * g[i];
  if (d2 == 0.0) {  // no outer product: 0 * an infinite gradient would make NaN
    for (int k = 0; k < n * n; ++k) rH[k] = d1 * H[k];
    return r;
  }
  for (int j = 0; j < n; ++j) {
    const double c = d2 * g[j];
    for (int i = 0; i < n; ++i) rH[j * n + i] = d1 * H[j * n + i] + c * g[i];
  }
  return r;
}

// The partial derivatives of F(a, b) at the values.
struct Partials {
  double a, b, aa, ab, bb;
};

// F(a, b) by the second-order chain rule:
// g = F_a a_g + F_b b_g,
// H = F_a a_H + F_b b_H + F_aa a_g a_g^T + F_ab (a_g b_g^T + b_g a_g^T) + F_bb b_g b_g^T
//   = F_a a_H + F_b b_H + u a_g^T + w b_g^T,  u = F_aa a_g + F_ab b_g,  w = F_ab a_g + F_bb b_g,
// in one pass over H (the second-order terms only where a second partial is not zero).
template <class J>
J binary(const J& a, const J& b, double f, const Partials& d) {
  if (a.constant()) return unary(b, f, d.b, d.bb);
  if (b.constant()) return unary(a, f, d.a, d.aa);
  assert(a.gradient.size() == b.gradient.size());
  const int n = static_cast<int>(a.gradient.size());
  J r(f);
  r.resize(n);
  const double* __restrict ga = a.gradient.data();
  const double* __restrict gb = b.gradient.data();
  const double* __restrict Ha = a.hessian.data();
  const double* __restrict Hb = b.hessian.data();
  double* __restrict rg = r.gradient.data();
  double* __restrict rH = r.hessian.data();
  for (int i = 0; i < n; ++i) rg[i] = d.a * ga[i] + d.b * gb[i];
  if (d.aa == 0.0 && d.ab == 0.0 && d.bb == 0.0) {
    for (int k = 0; k < n * n; ++k) rH[k] = d.a * Ha[k] + d.b * Hb[k];
    return r;
  }
  double u[kMaxJetVariables], w[kMaxJetVariables];
  for (int i = 0; i < n; ++i) {
    u[i] = d.aa * ga[i] + d.ab * gb[i];
    w[i] = d.ab * ga[i] + d.bb * gb[i];
  }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      rH[j * n + i] = d.a * Ha[j * n + i] + d.b * Hb[j * n + i] + u[i] * ga[j] + w[i] * gb[j];
  return r;
}

// The same chain rule at a fixed number N of variables, inlined into each operation: there the
// sizes are constants, so that it is a few fixed-size loops the compiler unrolls (the outer
// products as loops: as Eigen expressions GCC left their assignment out of line, a quarter of a
// shot), and where the partials are constants (a sum's 1, 1, 0, 0, 0) the terms they zero go. A
// constant operand (FixedJet::is_constant) is skipped as Jet2's is. The terms are those of the
// loops above, summed in the same order, so that both give the same numbers; the zero ones are
// skipped as there (0 * an infinite gradient would make NaN). The loops above, inlined instead,
// are slower (bench/README.md, "Measured design choices").
template <int N, int C>
[[gnu::always_inline]] inline FixedJet<N, C> unary(const FixedJet<N, C>& a, double f, double d1, double d2) {
  if (a.constant() || (d1 == 0.0 && d2 == 0.0)) return FixedJet<N, C>(f);
  FixedJet<N, C> r;
  r.is_constant = false;
  r.value = f;
  r.gradient = d1 * a.gradient;
  if (d2 == 0.0) {
    r.hessian = d1 * a.hessian;
    return r;
  }
  for (int j = 0; j < C; ++j) {
    const double c = d2 * a.gradient[N - C + j];
    for (int i = 0; i < N; ++i) r.hessian(i, j) = d1 * a.hessian(i, j) + c * a.gradient[i];
  }
  return r;
}
template <int N, int C>
[[gnu::always_inline]] inline FixedJet<N, C> binary(const FixedJet<N, C>& a, const FixedJet<N, C>& b, double f,
                                                   const Partials& d) {
  if (a.constant()) return unary(b, f, d.b, d.bb);
  if (b.constant()) return unary(a, f, d.a, d.aa);
  FixedJet<N, C> r;
  r.is_constant = false;
  r.value = f;
  r.gradient = d.a * a.gradient + d.b * b.gradient;
  if (d.aa == 0.0 && d.ab == 0.0 && d.bb == 0.0) {
    r.hessian = d.a * a.hessian + d.b * b.hessian;
    return r;
  }
  double u[N], w[N];
  for (int i = 0; i < N; ++i) {
    u[i] = d.aa * a.gradient[i] + d.ab * b.gradient[i];
    w[i] = d.ab * a.gradient[i] + d.bb * b.gradient[i];
  }
  for (int j = 0; j < C; ++j)
    for (int i = 0; i < N; ++i)
      r.hessian(i, j) =
          d.a * a.hessian(i, j) + d.b * b.hessian(i, j) + u[i] * a.gradient[N - C + j] + w[i] * b.gradient[N - C + j];
  return r;
}

}  // namespace jet

// The arithmetic and elementary functions of a jet type J, by the chain rule (jet::unary,
// jet::binary). Hidden friends: found by argument-dependent lookup for J, and not templates, so
// that a double converts to a constant J in mixed expressions.
template <class J>
struct JetArithmetic {
  friend J operator+(const J& a, const J& b) { return jet::binary(a, b, a.value + b.value, {1, 1, 0, 0, 0}); }
  friend J operator-(const J& a, const J& b) { return jet::binary(a, b, a.value - b.value, {1, -1, 0, 0, 0}); }
  friend J operator*(const J& a, const J& b) {
    return jet::binary(a, b, a.value * b.value, {b.value, a.value, 0, 1, 0});
  }
  friend J operator/(const J& a, const J& b) {
    const double r = 1.0 / b.value, f = a.value * r;
    return jet::binary(a, b, f, {r, -f * r, 0, -r * r, 2 * f * r * r});
  }
  friend J operator-(const J& a) { return jet::unary(a, -a.value, -1, 0); }
  friend J operator+(const J& a) { return a; }
  friend J& operator+=(J& a, const J& b) { return a = a + b; }
  friend J& operator-=(J& a, const J& b) { return a = a - b; }
  friend J& operator*=(J& a, const J& b) { return a = a * b; }
  friend J& operator/=(J& a, const J& b) { return a = a / b; }
  // Comparisons see the values only (branches in a model pick a smooth piece).
  friend bool operator==(const J& a, const J& b) { return a.value == b.value; }
  friend std::partial_ordering operator<=>(const J& a, const J& b) { return a.value <=> b.value; }

  friend J sin(const J& a) {
    const double s = std::sin(a.value);
    return jet::unary(a, s, std::cos(a.value), -s);
  }
  friend J cos(const J& a) {
    const double c = std::cos(a.value);
    return jet::unary(a, c, -std::sin(a.value), -c);
  }
  friend J tan(const J& a) {
    const double t = std::tan(a.value), d = 1 + t * t;
    return jet::unary(a, t, d, 2 * t * d);
  }
  friend J exp(const J& a) {
    const double e = std::exp(a.value);
    return jet::unary(a, e, e, e);
  }
  friend J log(const J& a) { return jet::unary(a, std::log(a.value), 1 / a.value, -1 / (a.value * a.value)); }
  friend J sqrt(const J& a) {
    const double s = std::sqrt(a.value);
    return jet::unary(a, s, 0.5 / s, -0.25 / (s * a.value));
  }
  // atan2(y, x): F_y = x/r2, F_x = -y/r2, F_yy = -2xy/r2^2 = -F_xx, F_xy = (y^2 - x^2)/r2^2.
  friend J atan2(const J& y, const J& x) {
    const double r2 = x.value * x.value + y.value * y.value, r4 = r2 * r2;
    const double cross = 2 * x.value * y.value / r4;
    return jet::binary(y, x, std::atan2(y.value, x.value),
                       {x.value / r2, -y.value / r2, -cross, (y.value * y.value - x.value * x.value) / r4, cross});
  }
  friend J abs(const J& a) { return a.value < 0 ? -a : a; }
  // a^b; with a constant exponent only the a-derivatives enter (a may then be negative).
  friend J pow(const J& a, const J& b) {
    const double f = std::pow(a.value, b.value);
    const double fa = b.value * std::pow(a.value, b.value - 1);
    const double faa = b.value * (b.value - 1) * std::pow(a.value, b.value - 2);
    if (b.constant()) return jet::unary(a, f, fa, faa);
    const double l = std::log(a.value);
    return jet::binary(a, b, f, {fa, f * l, faa, fa * l + f / a.value, f * l * l});
  }
  friend bool isfinite(const J& a) {
    return std::isfinite(a.value) && a.gradient.allFinite() && a.hessian.allFinite();
  }
};

struct Jet2 : JetArithmetic<Jet2> {
  using Gradient = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJetVariables, 1>;
  using Hessian = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJetVariables,
                                kMaxJetVariables>;

  Jet2() = default;
  Jet2(double constant) : value(constant) {}  // NOLINT: constants convert implicitly
  Jet2(const Jet2& other) : value(other.value) { copy_derivatives(other); }
  Jet2& operator=(const Jet2& other) {
    value = other.value;
    if (this != &other) copy_derivatives(other);
    return *this;
  }
  // The independent variable `index` of `count`, at `x`.
  static Jet2 variable(double x, int count, int index) {
    Jet2 jet(x);
    jet.gradient = Gradient::Unit(count, index);
    jet.hessian = Hessian::Zero(count, count);
    return jet;
  }
  bool constant() const { return gradient.size() == 0; }
  // Gives the result r of an operation on jets of n variables its derivatives' size.
  void resize(int n) {
    gradient.resize(n);
    hessian.resize(n, n);
  }

  double value = 0.0;
  Gradient gradient;
  Hessian hessian;

 private:
  // Copies whole 64-byte blocks of the fixed-capacity storage (the gradient's kMaxJetVariables
  // numbers, the Hessian's first n^2 rounded up to 8): constant-size copies the compiler inlines. Eigen copies
  // exactly n and n^2 numbers, by a library call each, which cost more than the copies themselves
  // for the few variables of a jet (a quarter of a shooting step's time went to them).
  void copy_derivatives(const Jet2& other) {
    const auto n = other.gradient.size();
    gradient.resize(n);
    hessian.resize(n, n);
    if (n == 0) return;
    constexpr std::size_t block = 8 * sizeof(double);
    static_assert(kMaxJetVariables * kMaxJetVariables % 8 == 0);
    std::memcpy(gradient.data(), other.gradient.data(), kMaxJetVariables * sizeof(double));
    for (Eigen::Index k = 0; k < n * n; k += 8) std::memcpy(hessian.data() + k, other.hessian.data() + k, block);
  }
};

// r += c x in place (r and x distinct), for doubles and Jet2 (FixedJet below): the linear combinations of a
// Runge-Kutta step and of a matrix of doubles times jets, whose values and derivatives combine
// alike, without the two temporaries and the copy of r = r + c * x (the same numbers: c x
// rounded, then added).
inline void add_scaled(double& r, double c, double x) { r += c * x; }
inline void add_scaled(Jet2& r, double c, const Jet2& x) {
  r.value += c * x.value;
  if (x.constant()) return;
  const auto n = x.gradient.size();
  const double* __restrict g = x.gradient.data();
  const double* __restrict H = x.hessian.data();
  if (r.constant()) {
    r.resize(static_cast<int>(n));
    r.gradient.setZero();
    r.hessian.setZero();
  }
  double* __restrict rg = r.gradient.data();
  double* __restrict rH = r.hessian.data();
  for (Eigen::Index i = 0; i < n; ++i) rg[i] += c * g[i];
  for (Eigen::Index k = 0; k < n * n; ++k) rH[k] += c * H[k];
}

// A jet over exactly N variables; a constant is one whose derivatives are zero.
// Default-constructed it is uninitialized, as a double is: Eigen constructs every element of a
// fixed-capacity vector (the SDK's sdk::Vec of dual numbers over FixedJet holds 18), and zeroing
// them would cost a large part of a shooting step (bench/README.md). Every use assigns first
// (valgrind's memcheck finds no read of one on the shooting and Lie group scenes); FixedJet(0.0)
// is the zero jet.
template <int N, int C>
struct FixedJet : JetArithmetic<FixedJet<N, C>> {
  static_assert(C >= 1 && C <= N);
  FixedJet() {}  // NOLINT: uninitialized, as a double
  FixedJet(double constant)  // NOLINT: constants convert implicitly
      : value(constant),
        gradient(Eigen::Matrix<double, N, 1>::Zero()),
        hessian(Eigen::Matrix<double, N, C>::Zero()),
        is_constant(true) {}
  // Jet2 `jet` of N variables (or a constant) and back, written into `jet` in place. With C < N,
  // to_jet2 fills the Hessian's rows in the last C variables by its symmetry and leaves the block
  // in the first N - C variables zero: that block is not carried.
  explicit FixedJet(const Jet2& jet) : FixedJet(jet.value) {
    if (!jet.constant()) gradient = jet.gradient, hessian = jet.hessian.rightCols(C), is_constant = false;
  }
  void to_jet2(Jet2& jet) const {
    jet.value = value;
    jet.gradient = gradient;
    if constexpr (C == N) {
      jet.hessian = hessian;
    } else {
      jet.hessian.setZero(N, N);
      jet.hessian.rightCols(C) = hessian;
      jet.hessian.bottomLeftCorner(C, N - C) = hessian.topRows(N - C).transpose();
    }
  }
  // The independent variable `index` of `count` (= N), at `x`.
  static FixedJet variable(double x, int /*count*/, int index) {
    FixedJet jet(x);
    jet.gradient[index] = 1.0;
    jet.is_constant = false;
    return jet;
  }
  bool constant() const { return is_constant; }
  void resize(int) {}

  double value;
  Eigen::Matrix<double, N, 1> gradient;
  Eigen::Matrix<double, N, C> hessian;  // columns N - C .. N - 1 of the Hessian
  // Made from a double, with zero derivatives: the chain rule then takes the other operand alone, as
  // for a constant Jet2 (a dual number's seeds over jets are constants). Code that writes the
  // derivatives of a jet made from a double clears it.
  bool is_constant;
};

// r += c x in place, as for Jet2 (the same numbers).
template <int N, int C>
inline void add_scaled(FixedJet<N, C>& r, double c, const FixedJet<N, C>& x) {
  r.value += c * x.value;
  if (x.constant()) return;
  r.gradient += c * x.gradient;
  r.hessian += c * x.hessian;
  r.is_constant = false;
}

// The value of a double or a jet: code written once for both scalars tests it.
inline double value_of(double x) { return x; }
inline double value_of(const Jet2& x) { return x.value; }

}  // namespace varia

namespace Eigen {

// Jets are real scalars for Eigen (as its own AutoDiffScalar is): Real is the jet itself, so that
// norms and dot products of jet vectors stay jets, and a double converts to a constant jet.
template <class J>
struct JetNumTraits : GenericNumTraits<double> {
  using Real = J;
  using NonInteger = J;
  using Nested = J;
  using Literal = double;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1,
         AddCost = 3, MulCost = 3 };
};
template <>
struct NumTraits<varia::Jet2> : JetNumTraits<varia::Jet2> {};
template <int N, int C>
struct NumTraits<varia::FixedJet<N, C>> : JetNumTraits<varia::FixedJet<N, C>> {};

template <typename BinaryOp>
struct ScalarBinaryOpTraits<varia::Jet2, double, BinaryOp> {
  using ReturnType = varia::Jet2;
};
template <typename BinaryOp>
struct ScalarBinaryOpTraits<double, varia::Jet2, BinaryOp> {
  using ReturnType = varia::Jet2;
};
template <int N, int C, typename BinaryOp>
struct ScalarBinaryOpTraits<varia::FixedJet<N, C>, double, BinaryOp> {
  using ReturnType = varia::FixedJet<N, C>;
};
template <int N, int C, typename BinaryOp>
struct ScalarBinaryOpTraits<double, varia::FixedJet<N, C>, BinaryOp> {
  using ReturnType = varia::FixedJet<N, C>;
};

}  // namespace Eigen
