// A Lie group manifold written once, in the style of manif's minimal API: the plugin author gives
// the group's operations templated on the scalar, and LieGroupManifold<Group> derives everything
// the Manifold interface asks of a group (varia/abi/manifold.hpp): the natural chart
// q0 exp(xi) and its inverse log(q0^{-1} q) (paper, sec. 2 "Natural charts"), and their first and
// second derivatives as plain arrays.
//
// The Group class defines
//   static constexpr int point_size, dim;
//   template <class T> static void compose(const T* a, const T* b, T* ab);   // a b
//   static void inverse(const double* a, double* a_inverse);
//   template <class T> static void exp(const T* xi, T* g);                   // exp: algebra -> group
//   template <class T> static void log(const T* g, T* xi);                   // its inverse near e
//   template <class T> static void bracket(const T* a, const T* b, T* ab);   // [a, b] = ad_a b
// with xi in the left-trivialized coordinates of the Lie algebra (g' = g xi for the curve
// g exp(t xi)). The adapter derives from them
//   dexp_{-xi} v = sum_k (-1)^k / (k+1)! ad_xi^k v, the left-trivialized velocity of exp(xi(t))
//   with xi' = v (the series of (1 - e^{-x}) / x, entire: it converges for every xi);
//   the coadjoint action ad*_xi mu = (ad_xi)^T mu (coadjoint below);
//   at jets, the translation q exp(xi) and the generators D(q) e_a = compose(q, e + E_a) - q, with
//   e = exp(0) and E_a = d exp(t e_a)/dt at t = 0: exact when the composition is affine in its
//   second factor in the point's numbers, as for a matrix group (SO(3): R1 R2) or a semidirect
//   product written (R, x) (SE(3): (R1 R2, x1 + R1 x2)). The Lie group conformance suite
//   (varia/sdk/conformance/manifold.hpp) checks D(q) against retract by a Taylor test, so a group
//   for which this fails is refused there.
// Derivatives come from the templated operations evaluated at second-order jets (Jet2), and the
// chart's (exp, compose, bracket) at first-order dual numbers (Eigen::AutoDiffScalar,
// differentiate_first_order) when no Hessian is asked: those operations must compile at both
// scalars. (Not log: Eigen's atan2 of an AutoDiffScalar allocates.) A jet
// holds at most kMaxJetVariables variables; a quantity of more variables is differentiated in
// blocks of half that many, one evaluation per pair of blocks (each pair gives its blocks of the
// gradient and the Hessian), so the group's dimension is not limited by the jet's capacity.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "varia/abi/jet.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

// The size of a scalar and its derivatives (for the series' stopping rule).
inline double magnitude(double x) { return std::abs(x); }
template <class Derivatives>
double magnitude(const Eigen::AutoDiffScalar<Derivatives>& x) {
  return std::max(std::abs(x.value()), x.derivatives().template lpNorm<Eigen::Infinity>());
}
inline double magnitude(const Jet2& x) {
  double m = std::abs(x.value);
  if (!x.constant())
    m = std::max({m, x.gradient.lpNorm<Eigen::Infinity>(), x.hessian.lpNorm<Eigen::Infinity>()});
  return m;
}

// dexp_{-xi} v (left-trivialized velocity of exp(xi(t)) with xi' = v) from the bracket: the terms
// t_0 = v, t_k = -[xi, t_{k-1}] / (k+1), summed until two terms in a row are below round-off of
// the sum in value and derivatives.
template <class Group, class T>
void dexp_series(const T* xi, const T* v, T* out) {
  constexpr int n = Group::dim;
  std::array<T, n> term, next;
  for (int i = 0; i < n; ++i) out[i] = term[i] = v[i];
  int small = 0;
  for (int k = 1; k < 200 && small < 2; ++k) {
    Group::bracket(xi, term.data(), next.data());
    double size = 0.0, total = 0.0;
    for (int i = 0; i < n; ++i) {
      term[i] = next[i] * (-1.0 / (k + 1));
      out[i] += term[i];
      size = std::max(size, magnitude(term[i]));
      total = std::max(total, magnitude(out[i]));
    }
    small = size <= 1e-17 * total ? small + 1 : 0;
  }
}

// Up to this many variables, first derivatives alone are taken at first-order duals on the stack
// ((V + K)(V + 1) numbers); a larger group's are read off jets.
inline constexpr int kMaxFirstOrderVariables = 32;

// Value and gradient (Derivatives' layout, no Hessian) of f: R^V -> R^K at x, at first-order
// dual numbers over exactly V variables: V + 1 numbers a scalar instead of a second-order jet's
// 1 + V + V^2 (a chart asked for first derivatives only, as in a simplified Newton iteration).
template <int V, int K, class F>
void differentiate_first_order(F&& f, const double* x, Derivatives out) {
  using Dual = Eigen::AutoDiffScalar<Eigen::Matrix<double, V, 1>>;
  std::array<Dual, V> xs;
  std::array<Dual, K> ys;
  for (int i = 0; i < V; ++i) xs[i] = Dual(x[i], V, i);
  f(static_cast<const Dual*>(xs.data()), ys.data());
  for (int k = 0; k < K; ++k) {
    if (out.value != nullptr) out.value[k] = ys[k].value();
    if (out.gradient != nullptr)
      for (int i = 0; i < V; ++i) out.gradient[k * V + i] = ys[k].derivatives()[i];
  }
}

// Value, gradient and Hessian (Derivatives' layout) of f: R^V -> R^K at x, f templated on the
// scalar as f(const T* x, T* y). Work buffers are the caller's: xs (V jets), ys (K jets).
template <class F>
void differentiate(F&& f, const double* x, int V, int K, Derivatives out, Jet2* xs, Jet2* ys) {
  const int block = V <= kMaxJetVariables ? V : kMaxJetVariables / 2;
  const int blocks = (V + block - 1) / block;
  const auto run = [&](int a, int b) {  // the variables of blocks a and b (a == b: one block)
    const auto chosen = [&](int i) { return i / block == a || i / block == b; };
    int count = 0;
    for (int i = 0; i < V; ++i) count += chosen(i) ? 1 : 0;
    for (int i = 0, c = 0; i < V; ++i) xs[i] = chosen(i) ? Jet2::variable(x[i], count, c++) : Jet2(x[i]);
    f(static_cast<const Jet2*>(xs), ys);
    for (int k = 0; k < K; ++k) {
      if (out.value != nullptr) out.value[k] = ys[k].value;
      const bool constant = ys[k].constant();
      for (int i = 0, ci = 0; i < V; ++i) {
        if (!chosen(i)) continue;
        if (out.gradient != nullptr) out.gradient[k * V + i] = constant ? 0.0 : ys[k].gradient(ci);
        if (out.hessian != nullptr)
          for (int j = 0, cj = 0; j < V; ++j) {
            if (!chosen(j)) continue;
            out.hessian[(k * V + i) * V + j] = constant ? 0.0 : ys[k].hessian(ci, cj);
            ++cj;
          }
        ++ci;
      }
    }
  };
  if (blocks == 1) return run(0, 0);
  for (int a = 0; a < blocks; ++a)
    for (int b = a + 1; b < blocks; ++b) run(a, b);
}

// K jets in V variables (constants allowed) into Derivatives' layout: for a group that computes
// its chart at jets itself.
inline void store(const Jet2* ys, int K, int V, Derivatives out) {
  for (int k = 0; k < K; ++k) {
    if (out.value != nullptr) out.value[k] = ys[k].value;
    const bool constant = ys[k].constant();
    for (int i = 0; i < V; ++i) {
      if (out.gradient != nullptr) out.gradient[k * V + i] = constant ? 0.0 : ys[k].gradient(i);
      if (out.hessian != nullptr)
        for (int j = 0; j < V; ++j) out.hessian[(k * V + i) * V + j] = constant ? 0.0 : ys[k].hessian(i, j);
    }
  }
}

// For Manifold::contains: writes the reason a point is refused into `why` and returns false.
template <class... Args>
bool explain(char* why, int why_size, const char* format, Args... args) {
  if (why != nullptr && why_size > 0) std::snprintf(why, static_cast<std::size_t>(why_size), format, args...);
  return false;
}

template <class Group>
class LieGroupManifold : public Manifold {
 public:
  static constexpr int m = Group::point_size, n = Group::dim;

  int point_size() const noexcept final { return m; }
  int dim() const noexcept final { return n; }
  ManifoldStructure structure() const noexcept final { return ManifoldStructure::lie_group; }

  Status retract(const double* q0, const double* xi, double* q) noexcept override {
    return guarded(error_, [&] {
      double g[m];
      Group::exp(xi, g);
      Group::compose(q0, g, q);
    });
  }

  Status local(const double* q0, const double* q, double* xi) noexcept override {
    return guarded(error_, [&] {
      double inverse[m], relative[m];
      Group::inverse(q0, inverse);
      Group::compose(inverse, q, relative);
      Group::log(relative, xi);
    });
  }

  // point = q0 exp(eta) exp(xi) in (eta, xi); velocity = dexp_{-xi} xi_dot in (xi, xi_dot).
  Status chart(const double* q0, const double* xi, const double* xi_dot, Derivatives point,
               Derivatives velocity) noexcept override {
    return guarded(error_, [&] {
      if (point.value != nullptr || point.gradient != nullptr || point.hessian != nullptr) {
        for (int i = 0; i < n; ++i) {
          x_[i] = 0.0;
          x_[n + i] = xi[i];
        }
        derivatives<2 * n, m>([&](const auto* y, auto* g) { chart_point(q0, y, g); }, x_.data(), point);
      }
      if (velocity.value != nullptr || velocity.gradient != nullptr || velocity.hessian != nullptr) {
        for (int i = 0; i < n; ++i) {
          x_[i] = xi[i];
          x_[n + i] = xi_dot[i];
        }
        derivatives<2 * n, n>([](const auto* y, auto* v) { chart_velocity(y, v); }, x_.data(), velocity);
      }
    });
  }

  Status local_derivatives(const double* q0, const double* q, Derivatives xi) noexcept override {
    return guarded(error_, [&] {
      double inverse[m];
      Group::inverse(q0, inverse);
      differentiate([&](const auto* y, auto* w) { chart_local(inverse, y, w); }, q, m, n, xi, xs_.data(),
                    ys_.data());
    });
  }

  Status translate(const Jet2* q, const Jet2* xi, Jet2* moved) noexcept override {
    return guarded(error_, [&] {
      Group::exp(xi, ys_.data());
      Group::compose(q, ys_.data(), moved);
    });
  }

  Status generators(const Jet2* q, Jet2* D) noexcept override {
    return guarded(error_, [&] {
      if (std::all_of(q, q + m, [](const Jet2& x) { return x.constant(); })) return generators_at_point(q, D);
      for (int a = 0; a < n; ++a) {
        for (int k = 0; k < m; ++k) xs_[k] = Jet2(unit_[k] + tangents_[k * n + a]);
        Group::compose(q, xs_.data(), ys_.data());
        for (int k = 0; k < m; ++k) D[k * n + a] = ys_[k] - q[k];
      }
    });
  }

  // At a point (constant jets: the Euler-Poincare field at doubles, an explicit method's stages) the
  // same compositions in doubles, which give the same values without a jet's derivatives to carry.
  void generators_at_point(const Jet2* q, Jet2* D) const {
    std::array<double, m> point, unit_plus_tangent, moved;
    for (int k = 0; k < m; ++k) point[k] = q[k].value;
    for (int a = 0; a < n; ++a) {
      for (int k = 0; k < m; ++k) unit_plus_tangent[k] = unit_[k] + tangents_[k * n + a];
      Group::compose(point.data(), unit_plus_tangent.data(), moved.data());
      for (int k = 0; k < m; ++k) D[k * n + a] = Jet2(moved[k] - point[k]);
    }
  }

  // ad*_xi mu = (ad_xi)^T mu: component j is <mu, [xi, e_j]>.
  static void coadjoint(const double* xi, const double* mu, double* out) {
    double e[n], b[n];
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) e[i] = i == j ? 1.0 : 0.0;
      Group::bracket(xi, e, b);
      out[j] = 0.0;
      for (int i = 0; i < n; ++i) out[j] += mu[i] * b[i];
    }
  }

 protected:
  std::string error_;

 private:
  // f's derivatives at x into out: first-order duals when no Hessian is asked and the duals fit
  // on the stack (kMaxFirstOrderVariables), else jets in blocks.
  template <int V, int K, class F>
  void derivatives(F&& f, const double* x, Derivatives out) {
    if constexpr (V <= kMaxFirstOrderVariables) {
      if (out.hessian == nullptr) return differentiate_first_order<V, K>(f, x, out);
    }
    differentiate(f, x, V, K, out, xs_.data(), ys_.data());
  }
  template <class T>
  static void chart_point(const double* q0, const T* y, T* point) {
    T a[m], b[m], ab[m];
    Group::exp(y, a);
    Group::exp(y + n, b);
    Group::compose(a, b, ab);
    T base[m];
    for (int i = 0; i < m; ++i) base[i] = T(q0[i]);
    Group::compose(base, ab, point);
  }
  template <class T>
  static void chart_velocity(const T* y, T* velocity) {
    dexp_series<Group>(y, y + n, velocity);
  }
  template <class T>
  static void chart_local(const double* inverse, const T* q, T* xi) {
    T base[m], relative[m];
    for (int i = 0; i < m; ++i) base[i] = T(inverse[i]);
    Group::compose(base, q, relative);
    Group::log(relative, xi);
  }

  // e = exp(0) and E = d exp(xi)/d xi at 0 (m x n, component-major), for generators().
  static std::array<double, m> unit() {
    std::array<double, m> e;
    const double zero[n] = {};
    Group::exp(zero, e.data());
    return e;
  }
  static std::array<double, m * n> tangents() {
    std::array<double, m * n> E;
    std::array<Jet2, std::max(2 * n, m)> xs;
    std::array<Jet2, std::max(n, m)> ys;
    const double zero[n] = {};
    differentiate([](const auto* xi, auto* g) { Group::exp(xi, g); }, zero, n, m, {nullptr, E.data(), nullptr},
                  xs.data(), ys.data());
    return E;
  }

  std::array<double, 2 * n> x_{};
  std::array<Jet2, std::max(2 * n, m)> xs_;
  std::array<Jet2, std::max(n, m)> ys_;
  std::array<double, m> unit_ = unit();
  std::array<double, m * n> tangents_ = tangents();
};

}  // namespace varia::sdk
