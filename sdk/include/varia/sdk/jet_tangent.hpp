// First derivatives over jets: the inner level of L's Hessian at jets (Lagrangian::hessian_jet,
// autodiff_lagrangian.hpp). The Hessian is forward mode over forward mode with jet values, i.e.
// Eigen's AutoDiffScalar (outer) over JetTangent (inner) over a jet J. Eigen's AutoDiffScalar
// nested over itself does not take a double in mixed expressions (its Real is an AutoDiffScalar,
// two conversions away from a double), so that models written `0.5 * v(0)` would not compile;
// this inner type converts from a double and from J in one step, as a jet does, and Eigen treats
// it as a real scalar. Hand-written because no library dual number nests over a user's jet type
// with that conversion; the chain rule is the textbook one, f(a + e d) = f(a) + e f'(a) d.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <compare>

#include "varia/abi/jet.hpp"

namespace varia::sdk {

template <class J, int K>
struct JetTangent {
  // Default-constructed its value is uninitialized, as a double and a FixedJet are (Eigen
  // constructs every element of its vectors of dual numbers' derivatives), a constant whose
  // derivatives are not stored. JetTangent(0.0) is the zero.
  JetTangent() : constant(true) {}
  JetTangent(double c) : value(c), constant(true) {}  // NOLINT: constants convert implicitly
  JetTangent(const J& x) : value(x), constant(true) {}            // NOLINT: as a double does
  // x with the derivatives d[0..K-1] along this level's directions.
  JetTangent(const J& x, const std::array<J, K>& d) : value(x), derivatives(d), constant(false) {}
  // A constant's derivatives are not stored, and not copied.
  JetTangent(const JetTangent& other) : value(other.value), constant(other.constant) {
    if (!constant) derivatives = other.derivatives;
  }
  JetTangent& operator=(const JetTangent& other) {
    value = other.value;
    constant = other.constant;
    if (!constant) derivatives = other.derivatives;
    return *this;
  }

  J value;
  // Along the K directions of this level; not stored (zero) where `constant`: a double of the model
  // (a mass, a body vector) converts to a JetTangent at every use, and zeroing and multiplying its
  // K derivative jets was most of L's Hessian at jets (bench/README.md).
  std::array<J, K> derivatives;
  bool constant;

  // The derivative along direction i.
  const J& derivative(int i) const { return constant ? kZero : derivatives[i]; }

  // f(a) from f(a.value) and f'(a.value).
  static JetTangent chain(const JetTangent& a, const J& f, const J& slope) {
    if (a.constant) return JetTangent(f);
    JetTangent r = varying(f);
    for (int i = 0; i < K; ++i) r.derivatives[i] = slope * a.derivatives[i];
    return r;
  }

  friend JetTangent operator+(const JetTangent& a, const JetTangent& b) {
    if (b.constant) return a.constant ? JetTangent(a.value + b.value) : JetTangent(a.value + b.value, a.derivatives);
    if (a.constant) return JetTangent(a.value + b.value, b.derivatives);
    JetTangent r = varying(a.value + b.value);
    for (int i = 0; i < K; ++i) r.derivatives[i] = a.derivatives[i] + b.derivatives[i];
    return r;
  }
  friend JetTangent operator-(const JetTangent& a, const JetTangent& b) {
    if (b.constant) return a.constant ? JetTangent(a.value - b.value) : JetTangent(a.value - b.value, a.derivatives);
    JetTangent r = varying(a.value - b.value);
    for (int i = 0; i < K; ++i) r.derivatives[i] = a.constant ? -b.derivatives[i] : a.derivatives[i] - b.derivatives[i];
    return r;
  }
  friend JetTangent operator*(const JetTangent& a, const JetTangent& b) {
    if (a.constant && b.constant) return JetTangent(a.value * b.value);
    JetTangent r = varying(a.value * b.value);
    for (int i = 0; i < K; ++i)
      r.derivatives[i] = a.constant   ? a.value * b.derivatives[i]
                         : b.constant ? a.derivatives[i] * b.value
                                      : a.derivatives[i] * b.value + a.value * b.derivatives[i];
    return r;
  }
  friend JetTangent operator/(const JetTangent& a, const JetTangent& b) {
    if (a.constant && b.constant) return JetTangent(a.value / b.value);
    JetTangent r = varying(a.value / b.value);
    for (int i = 0; i < K; ++i)
      r.derivatives[i] = a.constant   ? -(r.value * b.derivatives[i]) / b.value
                         : b.constant ? a.derivatives[i] / b.value
                                      : (a.derivatives[i] - r.value * b.derivatives[i]) / b.value;
    return r;
  }
  friend JetTangent operator-(const JetTangent& a) { return chain(a, -a.value, J(-1.0)); }
  friend JetTangent operator+(const JetTangent& a) { return a; }
  friend JetTangent& operator+=(JetTangent& a, const JetTangent& b) { return a = a + b; }
  friend JetTangent& operator-=(JetTangent& a, const JetTangent& b) { return a = a - b; }
  friend JetTangent& operator*=(JetTangent& a, const JetTangent& b) { return a = a * b; }
  friend JetTangent& operator/=(JetTangent& a, const JetTangent& b) { return a = a / b; }
  friend bool operator==(const JetTangent& a, const JetTangent& b) { return a.value == b.value; }
  friend std::partial_ordering operator<=>(const JetTangent& a, const JetTangent& b) { return a.value <=> b.value; }

  friend JetTangent sin(const JetTangent& a) { return chain(a, sin(a.value), cos(a.value)); }
  friend JetTangent cos(const JetTangent& a) { return chain(a, cos(a.value), -sin(a.value)); }
  friend JetTangent tan(const JetTangent& a) {
    const J t = tan(a.value);
    return chain(a, t, 1.0 + t * t);
  }
  friend JetTangent exp(const JetTangent& a) {
    const J e = exp(a.value);
    return chain(a, e, e);
  }
  friend JetTangent log(const JetTangent& a) { return chain(a, log(a.value), 1.0 / a.value); }
  friend JetTangent sqrt(const JetTangent& a) {
    const J s = sqrt(a.value);
    return chain(a, s, 0.5 / s);
  }
  friend JetTangent abs(const JetTangent& a) { return a.value < J(0.0) ? -a : a; }
  friend JetTangent atan2(const JetTangent& y, const JetTangent& x) {
    if (y.constant && x.constant) return JetTangent(atan2(y.value, x.value));
    const J squared = x.value * x.value + y.value * y.value;
    JetTangent r = varying(atan2(y.value, x.value));
    for (int i = 0; i < K; ++i) r.derivatives[i] = (x.value * y.derivative(i) - y.value * x.derivative(i)) / squared;
    return r;
  }
  // a^b = exp(b log a): d = b a^(b-1) da + a^b log(a) db, the second term where log a exists (a
  // varying exponent of a base <= 0 has no derivative).
  friend JetTangent pow(const JetTangent& a, const JetTangent& b) {
    JetTangent r = chain(a, pow(a.value, b.value), b.value * pow(a.value, b.value - 1.0));
    if (b.constant || !(a.value > J(0.0))) return r;
    const J log_a = log(a.value);
    for (int i = 0; i < K; ++i) {
      const J term = r.value * log_a * b.derivatives[i];
      r.derivatives[i] = r.constant ? term : r.derivatives[i] + term;
    }
    r.constant = false;
    return r;
  }
  friend bool isfinite(const JetTangent& a) {
    bool finite = isfinite(a.value);
    if (a.constant) return finite;
    for (const J& d : a.derivatives) finite = finite && isfinite(d);
    return finite;
  }

 private:
  // A result whose value is f and whose derivatives the operation writes next, every one.
  static JetTangent varying(const J& f) {
    JetTangent r;
    r.value = f;
    r.constant = false;
    return r;
  }
  static inline const J kZero = J(0.0);
};

}  // namespace varia::sdk

namespace Eigen {

// A real scalar for Eigen, as the jets are (jet.hpp).
template <class J, int K>
struct NumTraits<varia::sdk::JetTangent<J, K>> : JetNumTraits<varia::sdk::JetTangent<J, K>> {};
template <class J, int K, typename BinaryOp>
struct ScalarBinaryOpTraits<varia::sdk::JetTangent<J, K>, double, BinaryOp> {
  using ReturnType = varia::sdk::JetTangent<J, K>;
};
template <class J, int K, typename BinaryOp>
struct ScalarBinaryOpTraits<double, varia::sdk::JetTangent<J, K>, BinaryOp> {
  using ReturnType = varia::sdk::JetTangent<J, K>;
};

}  // namespace Eigen
