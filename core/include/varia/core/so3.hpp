// SO(3), the rotations of R^3, as 3x3 matrices: the group of the paper's rigid-body examples
// (sec. 2, "Example: Lie group velocity Verlet"). Invariant: a point R satisfies R^T R = I and
// det R = 1 to round-off; the functions below map onto the group exactly in exact arithmetic
// (Rodrigues, Cayley) and never project back onto it. The Lie algebra so(3) is R^3 through the hat
// map, hat(w) x = w x x; tangents and momenta are left-trivialized, Rdot = R hat(Omega).
//
// Everything is templated on the scalar T, so jets and autodiff scalars pass through; branches
// are chosen on the real part. The coefficient functions take x = theta^2, theta = |w|, and use
// their Taylor series for x < kSeriesBound, where the closed forms lose digits to cancellation
// (and divide by zero at theta = 0); the series are summed to below round-off there.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <concepts>
#include <type_traits>

#include "varia/abi/jet.hpp"

namespace varia::so3 {

template <class T>
using Vector3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;

inline constexpr double kSeriesBound = 0.25;  // theta < 1/2

// The real part of a scalar (nested autodiff scalars expose value(), Jet2 the member value).
template <class T>
double real(const T& x) {
  if constexpr (std::is_arithmetic_v<T>)
    return static_cast<double>(x);
  else if constexpr (requires { x.value(); })
    return real(x.value());
  else
    return x.value;
}

template <class T>
Matrix3<T> hat(const Vector3<T>& w) {
  Matrix3<T> W;
  W << T(0), -w(2), w(1), w(2), T(0), -w(0), -w(1), w(0), T(0);
  return W;
}

// The inverse of hat on skew matrices; vee(M) = (M32, M13, M21), so vee(M - M^T) / 2 is the
// axial vector of the skew part of any M.
template <class T>
Vector3<T> vee(const Matrix3<T>& M) {
  return Vector3<T>(M(2, 1), M(0, 2), M(1, 0));
}

// sum_k c[k] x^k by Horner's rule.
template <class T, std::size_t N>
T series(const T& x, const double (&c)[N]) {
  T sum = T(c[N - 1]);
  for (std::size_t k = N - 1; k-- > 0;) sum = sum * x + T(c[k]);
  return sum;
}

// A second-order jet type (Jet2, FixedJet<N>): value, gradient and Hessian as members.
template <class J>
concept SecondOrderJet = requires(const J& x) {
  { x.value } -> std::convertible_to<double>;
  x.gradient;
  x.hessian;
};

// The same series of a jet: one chain-rule step (jet::unary) with the value and the first two
// derivatives of the polynomial summed in double at x's value (Horner's rule for p, p', p''),
// instead of 2(N-1) jet operations with their Hessians.
template <SecondOrderJet J, std::size_t N>
J series(const J& x, const double (&c)[N]) {
  double p = c[N - 1], d1 = 0.0, d2 = 0.0;
  for (std::size_t k = N - 1; k-- > 0;) {
    d2 = d2 * x.value + 2.0 * d1;
    d1 = d1 * x.value + p;
    p = p * x.value + c[k];
  }
  return jet::unary(x, p, d1, d2);
}

// sin(theta)/theta.
template <class T>
T sinc(const T& x) {
  using std::sin;
  using std::sqrt;
  static constexpr double c[] = {1.0, -1.0 / 6, 1.0 / 120, -1.0 / 5040, 1.0 / 362880,
                                 -1.0 / 39916800, 1.0 / 6227020800, -1.0 / 1307674368000};
  if (real(x) < kSeriesBound) return series(x, c);
  const T theta = sqrt(x);
  return sin(theta) / theta;
}

// (1 - cos theta)/theta^2 = sinc(theta/2)^2 / 2, free of cancellation.
template <class T>
T cosc(const T& x) {
  const T half = sinc(T(x / 4.0));
  return half * half / 2.0;
}

// (theta - sin theta)/theta^3.
template <class T>
T sinc3(const T& x) {
  using std::sin;
  using std::sqrt;
  static constexpr double c[] = {1.0 / 6,        -1.0 / 120,        1.0 / 5040,
                                 -1.0 / 362880,  1.0 / 39916800,    -1.0 / 6227020800,
                                 1.0 / 1307674368000, -1.0 / 355687428096000};
  if (real(x) < kSeriesBound) return series(x, c);
  const T theta = sqrt(x);
  return (theta - sin(theta)) / (x * theta);
}

// (1 - (theta/2) cot(theta/2))/theta^2, the coefficient of dexp^{-1}; singular at theta = 2 pi.
template <class T>
T cotc(const T& x) {
  using std::sqrt;
  using std::tan;
  static constexpr double c[] = {1.0 / 12,         1.0 / 720,        1.0 / 30240,
                                 1.0 / 1209600,    1.0 / 47900160,   691.0 / 1307674368000,
                                 1.0 / 74724249600, 3617.0 / 10670622842880000};
  if (real(x) < kSeriesBound) return series(x, c);
  const T half = sqrt(x) / 2.0;
  return (T(1.0) - half / tan(half)) / x;
}

// exp(hat(w)) - I by Rodrigues' formula (paper, eq. rodc): sinc hat(w) + cosc hat(w)^2. Kept
// apart from I so that updates R + R (exp - I) can be summed with compensation.
template <class T>
Matrix3<T> expm1(const Vector3<T>& w) {
  const T x = w.squaredNorm();
  const Matrix3<T> W = hat(w);
  return sinc(x) * W + cosc(x) * (W * W);
}

template <class T>
Matrix3<T> exp(const Vector3<T>& w) {
  return Matrix3<T>::Identity() + expm1(w);
}

// The rotation angle theta in [0, pi] and the axial vector s = sin(theta) n of R = exp(theta n).
template <class T>
Vector3<T> axial(const Matrix3<T>& R) {
  return vee(Matrix3<T>(R - R.transpose())) / 2.0;
}

// The unit axis n of a rotation R by theta with cos theta = cosine < 0, from the symmetric part
// R + R^T = 2 cos theta I + 2 (1 - cos theta) n n^T (its largest diagonal entry), with the sign of
// the axial vector s = sin(theta) n: near pi, s has lost its digits but not its sign.
template <class T>
Vector3<T> axis_past_half_turn(const Matrix3<T>& R, const T& cosine, const Vector3<T>& s) {
  using std::sqrt;
  const Matrix3<T> nn = (R + R.transpose() - 2.0 * cosine * Matrix3<T>::Identity()) /
                        (2.0 * (1.0 - cosine));
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (real(nn(i, i)) > real(nn(k, k))) k = i;
  Vector3<T> n = nn.col(k) / sqrt(nn(k, k));
  if (real(n.dot(s)) < 0.0) n = -n;
  return n;
}

// log R, the w with |w| <= pi and exp(hat(w)) = R. With s = sin(theta) n from axial(R) and
// cos theta = (tr R - 1)/2: w = (theta / sin theta) s, theta = atan2(|s|, cos theta), accurate at
// every angle, and summed as the series of asin(y)/y in y^2 = |s|^2 near theta = 0. Near pi
// (cos theta < 0) s loses its digits, and the axis n comes from the symmetric part
// (axis_past_half_turn).
template <class T>
Vector3<T> log(const Matrix3<T>& R) {
  using std::atan2;
  using std::sqrt;
  static constexpr double asin_over[] = {1.0, 1.0 / 6, 3.0 / 40, 5.0 / 112, 35.0 / 1152};
  constexpr double kSmallSine2 = 1e-4;  // below it, the series' next term is under 1e-21
  const Vector3<T> s = axial(R);
  const T cosine = (R.trace() - 1.0) / 2.0, sine2 = s.squaredNorm();
  if (real(cosine) >= 0.0) {
    if (real(sine2) < kSmallSine2) return series(sine2, asin_over) * s;
    const T sine = sqrt(sine2);
    return (atan2(sine, cosine) / sine) * s;
  }
  return atan2(sqrt(sine2), cosine) * axis_past_half_turn(R, cosine, s);
}

// dexp_w = sum_n ad_w^n/(n+1)! = I + cosc hat(w) + sinc3 hat(w)^2 (paper, sec. 2: T_w exp =
// dexp_w exp(w) in right trivialization); the left-trivialized velocity of exp(xi(t)) is
// dexp_{-xi} xi'.
template <class T>
Matrix3<T> dexp(const Vector3<T>& w) {
  const T x = w.squaredNorm();
  const Matrix3<T> W = hat(w);
  return Matrix3<T>::Identity() + cosc(x) * W + sinc3(x) * (W * W);
}

// dexp_w^{-1} = I - hat(w)/2 + cotc hat(w)^2, for |w| < 2 pi.
template <class T>
Matrix3<T> dexp_inverse(const Vector3<T>& w) {
  const T x = w.squaredNorm();
  const Matrix3<T> W = hat(w);
  return Matrix3<T>::Identity() - 0.5 * W + cotc(x) * (W * W);
}

// cay(f) - I for cay(f) = (I + hat f)(I - hat f)^{-1} (paper, eq. FCay), which is
// I + 2/(1 + |f|^2) (hat f + hat f^2), the rotation by 2 atan|f| about f.
template <class T>
Matrix3<T> cayley_minus_identity(const Vector3<T>& f) {
  const Matrix3<T> W = hat(f);
  return (2.0 / (1.0 + f.squaredNorm())) * (W + W * W);
}

template <class T>
Matrix3<T> cayley(const Vector3<T>& f) {
  return Matrix3<T>::Identity() + cayley_minus_identity(f);
}

// cay^{-1}(F) = tan(theta/2) n for the rotation F by theta < pi about n: vee(F - F^T)/(1 + tr F)
// = sin(theta) n / (2 (1 + cos theta)). Past a half turn (cos theta < 0) 1 + tr F loses its digits
// (it is (pi - theta)^2 near pi, where the result's own condition is 1/(pi - theta)), and
// tan(theta/2) = (1 - cos theta)/sin theta with n from the symmetric part is used instead.
template <class T>
Vector3<T> cayley_inverse(const Matrix3<T>& F) {
  using std::sqrt;
  const Vector3<T> s = axial(F);
  const T cosine = (F.trace() - 1.0) / 2.0;
  if (real(cosine) >= 0.0) return s / (1.0 + cosine);
  return ((1.0 - cosine) / sqrt(s.squaredNorm())) * axis_past_half_turn(F, cosine, s);
}

// The left-trivialized gradient at R of a function with embedding gradient G = df/dR:
// tau . eta = <G, R hat(eta)> for all eta, i.e. tau = vee(R^T G - G^T R).
template <class T>
Vector3<T> trivialize(const Matrix3<T>& R, const Matrix3<T>& G) {
  const Matrix3<T> A = R.transpose() * G;
  return vee(Matrix3<T>(A - A.transpose()));
}

// ||I - R^T R||_F, the distance of R from the orthogonal matrices that the paper plots.
template <class T>
T orthogonality_error(const Matrix3<T>& R) {
  return (Matrix3<T>::Identity() - R.transpose() * R).norm();
}

// The value, first and second derivatives of a 3 x 3 matrix function M(w): value, d[l] = dM/dw_l,
// dd[l][m] = d2M/dw_l dw_m.
struct MatrixJet3 {
  Matrix3<double> value, d[3], dd[3][3];
};

// The value and first two derivatives of a coefficient function c(x) of x = theta^2, from c at a
// jet in the one variable x (FixedJet<1>: two numbers of derivatives, nothing to copy beyond them).
struct Coefficient {
  double value, d1, d2;
  template <class F>
  static Coefficient at(double x, F&& c) {
    const FixedJet<1> y = c(FixedJet<1>::variable(x, 1, 0));
    return {y.value, y.gradient(0), y.hessian(0, 0)};
  }
};

// M(w) = I + a(x) W + b(x) W^2 (W = hat(w), x = |w|^2: exp, dexp and their inverses have this
// form) with its derivatives in w, in doubles from a, b and their first two derivatives in x:
// with dx/dw_l = 2 w_l, H_l = hat(e_l) = dW/dw_l and S_l = H_l W + W H_l = dW^2/dw_l (outer
// products, from hat(a) hat(b) = b a^T - (a . b) I),
//   dM/dw_l = a_l W + a H_l + b_l W^2 + b S_l,   a_l = 2 a' w_l,
//   d2M/dw_l dw_m = a_lm W + a_l H_m + a_m H_l + b_lm W^2 + b_l S_m + b_m S_l + b (H_l H_m + H_m H_l),
//   a_lm = 4 a'' w_l w_m + 2 a' delta_lm (b's alike).
// A few hundred flops, where the same function at 3-variable jets costs thousands. Without
// `second`, dd is left unset.
template <class A, class B>
MatrixJet3 quadratic_in_hat(const Vector3<double>& w, A&& a_of, B&& b_of, bool second = true) {
  const double x = w.squaredNorm();
  const Coefficient a = Coefficient::at(x, a_of), b = Coefficient::at(x, b_of);
  const Matrix3<double> W = hat(w), W2 = W * W;
  Matrix3<double> H[3], S[3];
  double al[3], bl[3];
  for (int l = 0; l < 3; ++l) {
    H[l] = hat(Vector3<double>(Vector3<double>::Unit(l)));
    S[l].setZero();  // w e_l^T + e_l w^T - 2 w_l I, entry by entry (not as outer products of unit vectors)
    S[l].col(l) += w;
    S[l].row(l) += w.transpose();
    S[l].diagonal().array() -= 2.0 * w(l);
    al[l] = 2.0 * a.d1 * w(l);
    bl[l] = 2.0 * b.d1 * w(l);
  }
  MatrixJet3 M;
  M.value = Matrix3<double>::Identity() + a.value * W + b.value * W2;
  for (int l = 0; l < 3; ++l) {
    M.d[l] = al[l] * W + a.value * H[l] + bl[l] * W2 + b.value * S[l];
    for (int m = 0; second && m <= l; ++m) {
      const double alm = 4.0 * a.d2 * w(l) * w(m) + (l == m ? 2.0 * a.d1 : 0.0);
      const double blm = 4.0 * b.d2 * w(l) * w(m) + (l == m ? 2.0 * b.d1 : 0.0);
      M.dd[l][m] = alm * W + al[l] * H[m] + al[m] * H[l] + blm * W2 + bl[l] * S[m] + bl[m] * S[l];
      M.dd[l][m](l, m) += b.value;  // b (H_l H_m + H_m H_l) = b (e_m e_l^T + e_l e_m^T - 2 delta_lm I)
      M.dd[l][m](m, l) += b.value;
      if (l == m) M.dd[l][m].diagonal().array() -= 2.0 * b.value;
      M.dd[m][l] = M.dd[l][m];
    }
  }
  return M;
}

// `jet` set to a value in 6 variables, in place; the caller fills gradient and Hessian.
inline Jet2& jet6(Jet2& jet, double value) {
  jet.value = value;
  jet.resize(6);
  return jet;
}

// The natural chart at R0 to second order (the SO3 manifold's chart; paper, sec. 2 "Natural charts"):
// R0 exp(eta) exp(xi) at eta = 0 as 9 row-major jets in the variables (eta, xi), and the
// left-trivialized velocity dexp_{-xi}(xi_dot) as 3 jets in (xi, xi_dot). Either output may be
// null; without point_second (velocity_second) that output's Hessians are left unset.
// exp(xi) and dexp_{-xi} come with their derivatives in xi from quadratic_in_hat (in doubles; at
// 3-variable jets they would dominate a Lie group Galerkin step), and the rest is assembled from
// them with double 3 x 3 products:
//  - eta enters through exp(eta) = I + hat(eta) + hat(eta)^2/2 + O(|eta|^3), so with E = exp(xi),
//    B = R0, H_k = hat(e_k): dR/deta_k = B H_k E, d2R/deta_k deta_l = B (H_k H_l + H_l H_k)/2 E,
//    d2R/deta_k dxi_l = B H_k dE/dxi_l, and the xi derivatives are B's multiples of E's;
//  - xi_dot enters linearly in Omega = D xi_dot, D = dexp_{-xi}: dOmega/dxi_dot_l = D e_l,
//    d2Omega/dxi dxi_dot_l = dD/dxi e_l, d2Omega/dxi_dot^2 = 0.
inline void chart_jets(const double* R0, const double* xi, const double* xi_dot, Jet2* point, Jet2* velocity,
                       bool point_second = true, bool velocity_second = true) {
  const Vector3<double> w(xi[0], xi[1], xi[2]);
  if (point != nullptr) {
    const MatrixJet3 E = quadratic_in_hat(
        w, [](const auto& x) { return sinc(x); }, [](const auto& x) { return cosc(x); }, point_second);
    const Matrix3<double> B = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R0);
    const Matrix3<double> R = B * E.value;
    Matrix3<double> BH[3];  // B H_k, H_k = hat(e_k)
    for (int k = 0; k < 3; ++k) BH[k] = B * hat(Vector3<double>(Vector3<double>::Unit(k)));
    Matrix3<double> by[6], by2[6][6];  // the derivatives in the 6 variables (eta, xi)
    for (int k = 0; k < 3; ++k) {
      by[k] = BH[k] * E.value;
      by[3 + k] = B * E.d[k];
      for (int l = 0; point_second && l < 3; ++l) {
        // B (H_k H_l + H_l H_k)/2 E with H_k H_l = e_l e_k^T - delta_kl I: outer products.
        by2[k][l] = (B.col(l) * E.value.row(k) + B.col(k) * E.value.row(l)) / 2.0;
        if (k == l) by2[k][l] -= R;
        by2[k][3 + l] = BH[k] * E.d[l];
        by2[3 + l][k] = by2[k][3 + l];
        by2[3 + k][3 + l] = B * E.dd[k][l];
      }
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        Jet2& jet = jet6(point[3 * r + c], R(r, c));
        for (int a = 0; a < 6; ++a) {
          jet.gradient(a) = by[a](r, c);
          for (int b = 0; point_second && b < 6; ++b) jet.hessian(a, b) = by2[a][b](r, c);
        }
      }
  }
  if (velocity != nullptr) {
    // dexp_{-xi} = I - cosc hat(xi) + sinc3 hat(xi)^2.
    const MatrixJet3 D = quadratic_in_hat(
        w, [](const auto& x) { return -cosc(x); }, [](const auto& x) { return sinc3(x); }, velocity_second);
    const Eigen::Map<const Vector3<double>> rate(xi_dot);
    const Vector3<double> omega = D.value * rate;
    for (int i = 0; i < 3; ++i) {
      Jet2& jet = jet6(velocity[i], omega(i));
      if (velocity_second) jet.hessian.setZero();
      for (int k = 0; k < 3; ++k) {
        jet.gradient(k) = D.d[k].row(i).dot(rate);
        jet.gradient(3 + k) = D.value(i, k);
        for (int m = 0; velocity_second && m < 3; ++m) {
          jet.hessian(k, m) = D.dd[k][m].row(i).dot(rate);
          jet.hessian(k, 3 + m) = jet.hessian(3 + m, k) = D.d[k](i, m);
        }
      }
    }
  }
}

// The natural chart's inverse (Manifold::local, and at jets with T a jet): xi = log(R0^{-1} R)
// for R given as 9 row-major numbers. R0^{-1} rather than R0^T: the same for a rotation, but for
// a point that carries round-off it keeps local the exact inverse of retract (R0 exp(xi)), which
// the shooting construction's boundary condition needs (with R0^T the discrete momentum drifted
// 30 times faster, tests/core/shooting_so3.cpp).
template <class T>
void chart_local(const double* R0, const T* q, T* xi) {
  Matrix3<T> R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = q[3 * r + c];
  const Matrix3<double> inverse = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R0).inverse();
  const Vector3<T> w = log(Matrix3<T>(inverse.template cast<T>() * R));
  for (int i = 0; i < 3; ++i) xi[i] = w(i);
}

// Row-major 9-number buffers <-> matrices (the spec's layout of a point).
inline Matrix3<double> from_row_major(const double* q) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(q);
}
inline void to_row_major(const Matrix3<double>& R, double* q) {
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{q} = R;
}

}  // namespace varia::so3
