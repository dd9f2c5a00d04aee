// Whether a model's L(q, v) has the form 1/2 v^T M v - V(q) with a constant mass matrix M, read off
// the model's own expression, so that a model need not declare it (AutodiffLagrangian's
// constant_mass_matrix). The model is evaluated once at VelocityStructure, a scalar that carries,
// instead of a number, which monomials in v an expression may contain: degree 0, 1 or 2 in v, each
// with coefficients that are constants or may depend on q, or "other" (degree above 2, or not
// polynomial in v, as cos v). The rules are those of polynomial arithmetic, taken conservatively
// (a sum may contain every monomial of its terms: a cancellation is never assumed), so "constant"
// is only said of an expression that is of that form for every (q, v). An expression with a
// branch on a value that depends on (q, v) (a comparison of such values) is not read: it may take
// another form on the other side of the branch. Written by hand: forward-mode AD libraries give
// derivatives at a point, not the form of an expression.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "varia/sdk/dual.hpp"

namespace varia::sdk {

class VelocityStructure {
 public:
  // One bit a monomial class: bit 2 d + c for degree d in v (0, 1, 2) with coefficients constant
  // (c = 0) or depending on q (c = 1); kOther for any other term.
  static constexpr unsigned kOther = 1u << 6;

  VelocityStructure() = default;
  VelocityStructure(double c) : value_(c), terms_(c == 0.0 ? 0u : bit(0, false)) {}  // NOLINT: a constant
  static VelocityStructure position(double value) { return {value, bit(0, true)}; }
  static VelocityStructure velocity(double value) { return {value, bit(1, false)}; }

  double value() const { return value_; }
  // Whether the expression is 1/2 v^T M v - V(q), M constant: no term of degree 1, none of
  // degree 2 with a coefficient depending on q, nothing else.
  bool constant_mass_form() const { return (terms_ & ~(bit(0, false) | bit(0, true) | bit(2, false))) == 0; }
  // Whether a comparison read a value depending on (q, v) (the form may differ past the branch).
  static bool& branched() {
    static thread_local bool flag = false;
    return flag;
  }

  friend VelocityStructure operator+(const VelocityStructure& a, const VelocityStructure& b) {
    return {a.value_ + b.value_, a.terms_ | b.terms_};
  }
  friend VelocityStructure operator-(const VelocityStructure& a, const VelocityStructure& b) {
    return {a.value_ - b.value_, a.terms_ | b.terms_};
  }
  friend VelocityStructure operator-(const VelocityStructure& a) { return {-a.value_, a.terms_}; }
  friend VelocityStructure operator*(const VelocityStructure& a, const VelocityStructure& b) {
    return {a.value_ * b.value_, product(a.terms_, b.terms_)};
  }
  // a / b: a times 1/b, which is a function of q alone where b is (any degree 0 term), else other.
  friend VelocityStructure operator/(const VelocityStructure& a, const VelocityStructure& b) {
    return {a.value_ / b.value_, product(a.terms_, of_q_alone(b.terms_))};
  }
  VelocityStructure& operator+=(const VelocityStructure& b) { return *this = *this + b; }
  VelocityStructure& operator-=(const VelocityStructure& b) { return *this = *this - b; }
  VelocityStructure& operator*=(const VelocityStructure& b) { return *this = *this * b; }
  VelocityStructure& operator/=(const VelocityStructure& b) { return *this = *this / b; }

  // f(a) for a function that is not polynomial: a function of q alone where a is, else other.
  friend VelocityStructure apply(double value, const VelocityStructure& a) { return {value, of_q_alone(a.terms_)}; }

  friend bool operator<(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ < b.value_); }
  friend bool operator>(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ > b.value_); }
  friend bool operator<=(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ <= b.value_); }
  friend bool operator>=(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ >= b.value_); }
  friend bool operator==(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ == b.value_); }
  friend bool operator!=(const VelocityStructure& a, const VelocityStructure& b) { return compared(a, b, a.value_ != b.value_); }

 private:
  VelocityStructure(double value, unsigned terms) : value_(value), terms_(terms) {}
  static constexpr unsigned bit(int degree, bool of_q) { return 1u << (2 * degree + (of_q ? 1 : 0)); }
  static unsigned product(unsigned a, unsigned b) {
    if (a == 0 || b == 0) return 0;  // a product with zero is zero
    if ((a | b) & kOther) return kOther;
    unsigned r = 0;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        if ((a >> i & 1u) && (b >> j & 1u)) {
          const int degree = i / 2 + j / 2;
          r |= degree > 2 ? kOther : bit(degree, ((i | j) & 1) != 0);
        }
    return r;
  }
  // The terms of f(a) for a non-polynomial f: constant for a constant, a function of q for a
  // function of q, anything else for an expression in v.
  static unsigned of_q_alone(unsigned a) {
    if ((a & ~(bit(0, false) | bit(0, true))) != 0) return kOther;
    return (a & bit(0, true)) != 0 ? bit(0, true) : bit(0, false);
  }
  static bool compared(const VelocityStructure& a, const VelocityStructure& b, bool result) {
    if (((a.terms_ | b.terms_) & ~bit(0, false)) != 0) branched() = true;
    return result;
  }

  double value_ = 0.0;
  unsigned terms_ = 0;
};

// The elementary functions a model may call (found by argument-dependent lookup, as `using std::cos;
// cos(x)` finds them): each a function of q alone where its argument is one.
#define VARIA_VELOCITY_STRUCTURE_UNARY(f) \
  inline VelocityStructure f(const VelocityStructure& a) { return apply(std::f(a.value()), a); }
VARIA_VELOCITY_STRUCTURE_UNARY(sin)
VARIA_VELOCITY_STRUCTURE_UNARY(cos)
VARIA_VELOCITY_STRUCTURE_UNARY(tan)
VARIA_VELOCITY_STRUCTURE_UNARY(asin)
VARIA_VELOCITY_STRUCTURE_UNARY(acos)
VARIA_VELOCITY_STRUCTURE_UNARY(atan)
VARIA_VELOCITY_STRUCTURE_UNARY(sinh)
VARIA_VELOCITY_STRUCTURE_UNARY(cosh)
VARIA_VELOCITY_STRUCTURE_UNARY(tanh)
VARIA_VELOCITY_STRUCTURE_UNARY(exp)
VARIA_VELOCITY_STRUCTURE_UNARY(log)
VARIA_VELOCITY_STRUCTURE_UNARY(sqrt)
VARIA_VELOCITY_STRUCTURE_UNARY(cbrt)
VARIA_VELOCITY_STRUCTURE_UNARY(abs)
#undef VARIA_VELOCITY_STRUCTURE_UNARY
inline VelocityStructure abs2(const VelocityStructure& a) { return a * a; }
inline VelocityStructure atan2(const VelocityStructure& y, const VelocityStructure& x) {
  return apply(std::atan2(y.value(), x.value()), y + x);
}
inline VelocityStructure hypot(const VelocityStructure& x, const VelocityStructure& y) {
  return apply(std::hypot(x.value(), y.value()), x + y);
}
// a^k: a polynomial in a for a whole k >= 0, else a function like the others.
inline VelocityStructure pow(const VelocityStructure& a, double k) {
  if (k >= 0 && k <= 8 && k == std::floor(k)) {
    VelocityStructure r(1.0);
    for (int i = 0; i < static_cast<int>(k); ++i) r *= a;
    return r;
  }
  return apply(std::pow(a.value(), k), a);
}
inline VelocityStructure pow(const VelocityStructure& a, const VelocityStructure& k) {
  return apply(std::pow(a.value(), k.value()), a + k);
}

// A Vec of them holds any number of inputs (the form is read once, for a model of any size).
template <>
struct OnStack<VelocityStructure> : std::false_type {};

}  // namespace varia::sdk

namespace Eigen {

template <>
struct NumTraits<varia::sdk::VelocityStructure> : GenericNumTraits<double> {
  using Real = varia::sdk::VelocityStructure;
  using NonInteger = varia::sdk::VelocityStructure;
  using Literal = varia::sdk::VelocityStructure;
  using Nested = varia::sdk::VelocityStructure;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1, AddCost = 1, MulCost = 1 };
  static Real epsilon() { return Real(GenericNumTraits<double>::epsilon()); }
  static Real dummy_precision() { return Real(GenericNumTraits<double>::dummy_precision()); }
  static Real highest() { return Real(GenericNumTraits<double>::highest()); }
  static Real lowest() { return Real(GenericNumTraits<double>::lowest()); }
};
template <class BinaryOp>
struct ScalarBinaryOpTraits<varia::sdk::VelocityStructure, double, BinaryOp> {
  using ReturnType = varia::sdk::VelocityStructure;
};
template <class BinaryOp>
struct ScalarBinaryOpTraits<double, varia::sdk::VelocityStructure, BinaryOp> {
  using ReturnType = varia::sdk::VelocityStructure;
};

}  // namespace Eigen

namespace varia::sdk {

// Whether the expression that evaluate() computes from inputs of VelocityStructure (seeded by the
// caller: position() for q, velocity() for v) is 1/2 v^T M v - V(q) with M constant. False where it
// branches on a value of (q, v) or throws.
template <class F>
bool constant_mass_form_of(F&& evaluate) {
  try {
    VelocityStructure::branched() = false;
    const VelocityStructure L = evaluate();
    return L.constant_mass_form() && !VelocityStructure::branched();
  } catch (...) {
    return false;
  }
}

// Whether lagrangian(q, v), a model written for any scalar (called here with Vec<VelocityStructure>
// of m and n numbers), is 1/2 v^T M v - V(q) with M constant, read off its expression.
template <class Model>
bool has_constant_mass_form(int m, int n, const Model& lagrangian) {
  return constant_mass_form_of([&] {
    Vec<VelocityStructure> q(m), v(n);
    for (int i = 0; i < m; ++i) q(i) = VelocityStructure::position(0.5);
    for (int i = 0; i < n; ++i) v(i) = VelocityStructure::velocity(0.5);
    return lagrangian(q, v);
  });
}

}  // namespace varia::sdk
