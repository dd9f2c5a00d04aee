// Small in-process models for testing core/ without loading plugins.
#pragma once

#include <cmath>
#include <vector>

#include "varia/abi/manifold.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/so3.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"
#include "varia/sdk/groups/so3.hpp"
#include "varia/sdk/termwise_lagrangian.hpp"

namespace varia::testing {

struct FlatSpace : Manifold {
  explicit FlatSpace(int n) : n(n) {}
  int point_size() const noexcept override { return n; }
  int dim() const noexcept override { return n; }
  ManifoldStructure structure() const noexcept override { return ManifoldStructure::vector_space; }
  Status retract(const double* q0, const double* xi, double* q) noexcept override {
    for (int i = 0; i < n; ++i) q[i] = q0[i] + xi[i];
    return nullptr;
  }
  Status local(const double* q0, const double* q, double* xi) noexcept override {
    for (int i = 0; i < n; ++i) xi[i] = q[i] - q0[i];
    return nullptr;
  }
  bool contains(const double*, char*, int) noexcept override { return true; }
  int n;
};

// A fixed rule given by its nodes and weights on [0, 1].
struct FixedRule : Quadrature {
  FixedRule(std::vector<double> c, std::vector<double> b, int degree)
      : c(std::move(c)), b(std::move(b)), exact_degree(degree) {}
  int size() const noexcept override { return static_cast<int>(c.size()); }
  const double* nodes() const noexcept override { return c.data(); }
  const double* weights() const noexcept override { return b.data(); }
  int degree() const noexcept override { return exact_degree; }
  bool symmetric() const noexcept override { return true; }
  std::vector<double> c, b;
  int exact_degree;
};

inline FixedRule trapezoid() { return FixedRule({0.0, 1.0}, {0.5, 0.5}, 1); }
inline FixedRule lobatto3() { return FixedRule({0.0, 0.5, 1.0}, {1.0 / 6, 4.0 / 6, 1.0 / 6}, 3); }
// The s-point Gauss-Legendre rule on [0, 1] (tests/fixtures.cpp).
FixedRule gauss_legendre(int s);

// L = v^2/2 - q^2/2 (unit oscillator) or v^2/2 + cos q (unit pendulum) on R^1.
struct Oscillator : sdk::AutodiffLagrangian<Oscillator, 1, 1> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    return 0.5 * v(0) * v(0) - 0.5 * q(0) * q(0);
  }
  // Refuses the explicit forms (the SDK would read its constant mass matrix off L): the tests take
  // Newton's paths with it, and declare M where they want the explicit ones (MassOscillator).
  bool constant_mass_matrix(double* /*mass*/) const noexcept override { return false; }
};

struct Pendulum : sdk::AutodiffLagrangian<Pendulum, 1, 1> {
  static constexpr bool inline_shot = true;  // SeparablePendulum's shots with L inlined at each stage
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::cos;
    return 0.5 * v(0) * v(0) + cos(q(0));
  }
  // Refuses the explicit forms (the SDK would read its constant mass matrix off L): the tests take
  // Newton's paths with it, and declare M where they want the explicit ones (SeparablePendulum).
  bool constant_mass_matrix(double* /*mass*/) const noexcept override { return false; }
};

// n uncoupled pendulums with masses 1..n, declaring their constant mass matrix: at degree 1 the
// Galerkin explicit form applies, at a fixed size (n <= 4) or the dynamic size (n > 4). With
// Size given, the model's sizes are known when it is compiled (the SDK's fixed-size duals).
template <int Size = Eigen::Dynamic>
struct Pendulums : sdk::AutodiffLagrangian<Pendulums<Size>, Size, Size> {
  explicit Pendulums(int n = Size) : sdk::AutodiffLagrangian<Pendulums<Size>, Size, Size>(n, n), n_(n) {}
  static constexpr bool inline_shot = true;  // the shot kernel's test (tests/core/shooting.cpp)
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::cos;
    T L = T(0.0);
    for (int i = 0; i < n_; ++i) L += (0.5 * (i + 1)) * v(i) * v(i) + (i + 1.0) * cos(q(i));
    return L;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    Eigen::Map<Eigen::MatrixXd>(mass, n_, n_) = Eigen::VectorXd::LinSpaced(n_, 1, n_).asDiagonal();
    return true;
  }
  int n_;
};

// SO(3) in process (varia/sdk/groups/so3.hpp, as the SO3 plugin): points are row-major rotation
// matrices.
struct Rotations : sdk::groups::RotationGroup {};

// A top with principal moments J and weight w = m g at the body offset chi (w = 0: the free rigid
// body): L = 1/2 Omega . J Omega - w e3 . (R chi), R row-major in q.
struct Top : sdk::AutodiffLagrangian<Top, 9, 3> {
  Top(Eigen::Vector3d J, double w, Eigen::Vector3d chi) : J(J), w(w), chi(chi) {}
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    T L = T(0.0);
    for (int i = 0; i < 3; ++i) L += T(0.5 * J(i)) * v(i) * v(i) - T(w * chi(i)) * q(6 + i);
    return L;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    Eigen::Map<Eigen::Matrix3d>{mass} = J.asDiagonal();
    return true;
  }
  Eigen::Vector3d J;
  double w;
  Eigen::Vector3d chi;
};

}  // namespace varia::testing

// The models' derivatives are compiled once, in tests/fixtures.cpp (the test_fixtures library),
// not in every test file that includes this header.
extern template class varia::sdk::AutodiffLagrangian<varia::testing::Oscillator, 1, 1>;
extern template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulum, 1, 1>;
extern template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulums<>, Eigen::Dynamic, Eigen::Dynamic>;
extern template class varia::sdk::AutodiffLagrangian<varia::testing::Top, 9, 3>;

namespace varia::testing {

// The unit pendulum declaring its constant mass matrix, which enables explicit forms.
struct SeparablePendulum : Pendulum {
  bool constant_mass_matrix(double* mass) const noexcept override {
    mass[0] = 1.0;
    return true;
  }
};

// n unit masses on a line, neighbours joined by anharmonic springs (V = d^2/2 + d^4/4, d the
// stretch past length 1), written term-wise: a sparse Lagrangian (the Hessian's pattern from the
// terms). Declared (has_constant_mass_matrix) or not, to compare the explicit form with Newton.
// Its constant mass matrix is read off the terms (TermwiseLagrangian), or refused (explicit_forms
// false: the implicit forms' Newton solves).
struct SparseChain : sdk::TermwiseLagrangian {
  SparseChain(int n, bool explicit_forms) : TermwiseLagrangian(n, n), explicit_forms_(explicit_forms) {
    for (int i = 0; i < n; ++i)
      add_term([]<class T>(const sdk::TermVec<T, 1>& x) -> T { return 0.5 * x(0) * x(0); }, {velocity(i)});
    for (int i = 0; i + 1 < n; ++i)
      add_term(
          []<class T>(const sdk::TermVec<T, 2>& x) -> T {
            const T d = x(1) - x(0) - 1.0;
            return -(0.5 * d * d + 0.25 * d * d * d * d);
          },
          {position(i), position(i + 1)});
  }
  bool has_constant_mass_matrix() const noexcept override {
    return explicit_forms_ && TermwiseLagrangian::has_constant_mass_matrix();
  }

 private:
  bool explicit_forms_;
};

}  // namespace varia::testing
