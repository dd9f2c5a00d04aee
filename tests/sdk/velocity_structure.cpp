// sdk::AutodiffLagrangian reads L = 1/2 v^T M v - V(q) with a constant M off the model's own
// expression (velocity_structure.hpp): a model that declares nothing gets the explicit forms where
// its L has that form, with M from its Hessian, and never where it does not (a mass matrix that
// depends on q, a term linear in v, a term of higher degree or not polynomial in v, a branch on a
// value of (q, v)). And the Galerkin construction's explicit form (Stormer-Verlet) then takes no
// Newton iteration on a Henon-Heiles model written without any declaration.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>

#include "varia/core/galerkin.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/abi/quadrature.hpp"
#include "core/shooting_fixtures.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

using varia::sdk::AutodiffLagrangian;
using varia::sdk::Vec;

// Henon-Heiles as the docs' Duffing example is written: no declaration of any kind.
struct HenonHeiles : AutodiffLagrangian<HenonHeiles> {
  HenonHeiles() : AutodiffLagrangian(2, 2) {}
  template <class T>
  T lagrangian(const Vec<T>& q, const Vec<T>& v) const {
    const T x = q(0), y = q(1);
    return 0.5 * (v(0) * v(0) + v(1) * v(1)) - 0.5 * (x * x + y * y) - x * x * y + y * y * y / 3.0;
  }
};

// The form of L(q, v) = kinetic(v) + rest(q, v) with kinetic = |v|^2/2 on R^2, read at the scalar
// (no model compiled: the adapter's reading is this function, has_constant_mass_form).
template <class Rest>
bool constant_mass_form(Rest&& rest) {
  return varia::sdk::has_constant_mass_form(2, 2, [&](const auto& q, const auto& v) { return 0.5 * v.dot(v) + rest(q, v); });
}

// A chain of 40 unit masses (80 numbers: above the stack's dual numbers), nearest neighbours
// coupled by cosines and their velocities by M(i, i + 1) = 1/4: the mass matrix is read in chunks
// of its vv block alone, across the chunks' boundaries.
struct LongChain : AutodiffLagrangian<LongChain> {
  LongChain() : AutodiffLagrangian(40, 40) {}
  template <class T>
  T lagrangian(const Vec<T>& q, const Vec<T>& v) const {
    using std::cos;
    T L = 0.5 * v.dot(v);
    for (int i = 0; i + 1 < 40; ++i) L += cos(q(i + 1) - q(i)) + 0.25 * v(i) * v(i + 1);
    return L;
  }
};

Eigen::MatrixXd mass_of(varia::Lagrangian& lagrangian, bool& found) {
  const int n = lagrangian.velocity_size();
  Eigen::MatrixXd mass = Eigen::MatrixXd::Constant(n, n, -7.0);
  found = lagrangian.constant_mass_matrix(mass.data());
  return mass;
}

struct Plane final : varia::Manifold {
  int point_size() const noexcept override { return 2; }
  int dim() const noexcept override { return 2; }
  varia::ManifoldStructure structure() const noexcept override { return varia::ManifoldStructure::vector_space; }
  varia::Status retract(const double* q0, const double* xi, double* q) noexcept override {
    for (int i = 0; i < 2; ++i) q[i] = q0[i] + xi[i];
    return nullptr;
  }
  varia::Status local(const double* q0, const double* q, double* xi) noexcept override {
    for (int i = 0; i < 2; ++i) xi[i] = q[i] - q0[i];
    return nullptr;
  }
  bool contains(const double*, char*, int) noexcept override { return true; }
};

struct Trapezoid final : varia::Quadrature {
  int size() const noexcept override { return 2; }
  const double* nodes() const noexcept override { return c; }
  const double* weights() const noexcept override { return b; }
  int degree() const noexcept override { return 1; }
  bool symmetric() const noexcept override { return true; }
  double c[2] = {0.0, 1.0}, b[2] = {0.5, 0.5};
};

}  // namespace

TEST_CASE("a constant mass matrix is read off the model's expression, with M from its Hessian") {
  HenonHeiles henon_heiles;
  bool found = false;
  CHECK(mass_of(henon_heiles, found) == Eigen::MatrixXd::Identity(2, 2));
  CHECK(found);
  LongChain chain;
  Eigen::MatrixXd coupled = Eigen::MatrixXd::Identity(40, 40);
  for (int i = 0; i + 1 < 40; ++i) coupled(i, i + 1) = coupled(i + 1, i) = 0.25;
  CHECK(mass_of(chain, found) == coupled);
  CHECK(found);
  // A Kepler potential, and masses coupled by a constant off-diagonal entry.
  using std::cos;
  using std::sqrt;
  CHECK(constant_mass_form([](const auto& q, const auto&) { return 1.0 / sqrt(q.dot(q)); }));
  CHECK(constant_mass_form([](const auto& q, const auto& v) { return 0.25 * v(0) * v(1) - cos(q(0) - q(1)); }));
}

TEST_CASE("a Lagrangian not of the form 1/2 v^T M v - V(q) with M constant is never taken for one") {
  using std::cos;
  // Through the adapter: the double pendulum's mass matrix depends on q1 - q2.
  varia::testing::DoublePendulum double_pendulum;
  bool found = true;
  mass_of(double_pendulum, found);
  CHECK_FALSE(found);
  CHECK_FALSE(constant_mass_form([](const auto& q, const auto& v) { return cos(q(0) - q(1)) * v(0) * v(1); }));
  CHECK_FALSE(constant_mass_form([](const auto& q, const auto& v) { return 0.5 * v(0) - q.dot(q); }));  // linear in v
  CHECK_FALSE(constant_mass_form([](const auto&, const auto& v) { return v(0) * v(0) * v(1) * v(1); }));
  CHECK_FALSE(constant_mass_form([](const auto&, const auto& v) { return cos(v(0)); }));
  // A branch on q: the branch taken at the point read (q0 = 1/2 > 0) has the form, the other not.
  CHECK_FALSE(constant_mass_form(
      [](const auto& q, const auto& v) { return q(0) > 0.0 ? 0.0 * q(0) : q(0) * q(0) * v.dot(v); }));
  // A comparison of constants (at the scalar) is no branch on (q, v).
  CHECK(constant_mass_form([](const auto& q, const auto&) {
    const auto c = 0.0 * q(0) + 2.0;
    return c > 1.0 ? cos(q(0)) : cos(q(1));
  }));
}

TEST_CASE("Henon-Heiles written without any declaration: Galerkin degree 1 with the trapezoid rule is "
          "Stormer-Verlet, 0 Newton iterations") {
  HenonHeiles model;
  Plane plane;
  Trapezoid rule;
  varia::GalerkinDiscreteLagrangian galerkin(plane, model, rule, varia::equispaced_control_times(1), {});
  Eigen::Vector2d q(0.1, -0.2), p(0.3, 0.1), q1, p1;
  for (int k = 0; k < 100; ++k) {
    galerkin.step(q.data(), p.data(), 0.0, 0.1, q1.data(), p1.data());
    q = q1, p = p1;
  }
  CHECK(galerkin.solver_statistics().max_iterations == 0);
  // Against Stormer-Verlet written out: p += h/2 F(q); q += h p; p += h/2 F(q).
  const auto force = [](const Eigen::Vector2d& x) {
    return Eigen::Vector2d(-x(0) - 2 * x(0) * x(1), -x(1) - x(0) * x(0) + x(1) * x(1));
  };
  Eigen::Vector2d x(0.1, -0.2), y(0.3, 0.1);
  for (int k = 0; k < 100; ++k) {
    y += 0.05 * force(x);
    x += 0.1 * y;
    y += 0.05 * force(x);
  }
  CHECK((q - x).lpNorm<Eigen::Infinity>() <= 1e-14);
  CHECK((p - y).lpNorm<Eigen::Infinity>() <= 1e-14);
}
