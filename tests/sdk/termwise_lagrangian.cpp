// sdk::TermwiseLagrangian: a sum of small terms over index sets of (q, v), each differentiated at
// its own size, gives the L, gradient, Hessian and jet gradient of the same sum written as one
// dense model; its Hessian pattern is the union of the terms' blocks and nothing else; a term that
// names a number outside (q, v) is refused when it is added.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "varia/sdk/autodiff_lagrangian.hpp"
#include "varia/sdk/termwise_lagrangian.hpp"

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using varia::sdk::TermVec;

constexpr int kSize = 5;  // m = n = 5

// The terms, over (q, v) numbers that overlap and mix positions with velocities.
struct Inertia {  // v_0^2 (1 + q_0^2) / 2 - cos(q_0 - q_1): over (q_0, q_1, v_0)
  template <class T>
  T operator()(const TermVec<T, 3>& x) const {
    using std::cos;
    return 0.5 * x(2) * x(2) * (1.0 + x(0) * x(0)) - cos(x(0) - x(1));
  }
};
struct Coupling {  // c sin(q_i) q_{i+1}^2: over (q_i, q_{i+1})
  double c;
  template <class T>
  T operator()(const TermVec<T, 2>& x) const {
    using std::sin;
    return c * sin(x(0)) * x(1) * x(1);
  }
};
struct Kinetic {  // w v_i^2 / 2
  double w;
  template <class T>
  T operator()(const TermVec<T, 1>& x) const {
    return 0.5 * w * x(0) * x(0);
  }
};

class Sum final : public varia::sdk::TermwiseLagrangian {
 public:
  Sum() : TermwiseLagrangian(kSize, kSize) {
    add_term(Inertia{}, {position(0), position(1), velocity(0)});
    for (int i = 0; i + 1 < kSize; ++i) add_term(Coupling{0.3 + 0.1 * i}, {position(i), position(i + 1)});
    for (int i = 1; i < kSize; ++i) add_term(Kinetic{1.0 + i}, {velocity(i)});
    // The same number twice in one term: the term is a function of (q_3, q_3).
    add_term(
        []<class T>(const TermVec<T, 2>& x) -> T {
          using std::exp;
          return x(0) * exp(0.5 * x(1));
        },
        {position(3), position(3)});
  }
  // A term naming a number that (q, v) does not have.
  void add_outside() { add_term(Kinetic{1.0}, {velocity(kSize)}); }
};

// The same L as one dense model.
struct DenseSum : varia::sdk::AutodiffLagrangian<DenseSum> {
  DenseSum() : varia::sdk::AutodiffLagrangian<DenseSum>(kSize, kSize) {}
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    using std::exp;
    using std::sin;
    T L = 0.5 * v(0) * v(0) * (1.0 + q(0) * q(0)) - cos(q(0) - q(1));
    for (int i = 0; i + 1 < kSize; ++i) L += (0.3 + 0.1 * i) * sin(q(i)) * q(i + 1) * q(i + 1);
    for (int i = 1; i < kSize; ++i) L += 0.5 * (1.0 + i) * v(i) * v(i);
    return L + q(3) * exp(0.5 * q(3));
  }
};

VectorXd point(double phase) {
  VectorXd x(kSize);
  for (int i = 0; i < kSize; ++i) x(i) = 0.8 * std::sin(1.1 * i + phase);
  return x;
}

}  // namespace

TEST_CASE("a term-wise Lagrangian gives the L, gradient and Hessian of the same sum as one dense model, "
          "through its sparse pattern") {
  Sum termwise;
  DenseSum dense;
  const VectorXd q = point(0.3), v = point(1.9);
  const int k = 2 * kSize;
  const int *rows = nullptr, *cols = nullptr;
  const int entries = termwise.hessian_pattern(&rows, &cols);
  double L = 0.0, L_dense = 0.0;
  VectorXd g(k), g_dense(k), values(entries);
  MatrixXd H_dense(k, k);
  REQUIRE(termwise.evaluate(q.data(), v.data(), &L, g.data(), values.data()) == nullptr);
  REQUIRE(dense.evaluate(q.data(), v.data(), &L_dense, g_dense.data(), H_dense.data()) == nullptr);
  MatrixXd H = MatrixXd::Zero(k, k);
  for (int e = 0; e < entries; ++e) H(rows[e], cols[e]) = values(e);
  CHECK(L == doctest::Approx(L_dense).epsilon(1e-15));
  CHECK((g - g_dense).lpNorm<Eigen::Infinity>() <= 1e-15 * g_dense.lpNorm<Eigen::Infinity>());
  CHECK((H - H_dense).lpNorm<Eigen::Infinity>() <= 1e-15 * H_dense.lpNorm<Eigen::Infinity>());

  // The value alone and the gradient alone agree with the Hessian's pass.
  double L_alone = 0.0;
  VectorXd g_alone(k);
  REQUIRE(termwise.evaluate(q.data(), v.data(), &L_alone, nullptr, nullptr) == nullptr);
  REQUIRE(termwise.evaluate(q.data(), v.data(), nullptr, g_alone.data(), nullptr) == nullptr);
  CHECK(L_alone == doctest::Approx(L).epsilon(1e-15));
  CHECK(g_alone == g);
}

TEST_CASE("a term-wise Lagrangian's Hessian pattern is the union of its terms' blocks, each entry once") {
  Sum termwise;
  const int *rows = nullptr, *cols = nullptr;
  const int entries = termwise.hessian_pattern(&rows, &cols);
  std::set<std::pair<int, int>> pattern;
  for (int e = 0; e < entries; ++e) pattern.insert({rows[e], cols[e]});
  CHECK(static_cast<int>(pattern.size()) == entries);
  const int v0 = kSize;
  std::set<std::pair<int, int>> expected;
  for (int a : {0, 1, v0})
    for (int b : {0, 1, v0}) expected.insert({a, b});
  for (int i = 0; i + 1 < kSize; ++i)
    for (int a : {i, i + 1})
      for (int b : {i, i + 1}) expected.insert({a, b});
  for (int i = 1; i < kSize; ++i) expected.insert({v0 + i, v0 + i});
  CHECK(pattern == expected);
  // Not dense: q_0 and q_2 share no term.
  CHECK(pattern.count({0, 2}) == 0);
}

TEST_CASE("a term-wise Lagrangian at jet inputs gives the jets of the dense model's gradient") {
  Sum termwise;
  DenseSum dense;
  const VectorXd q = point(0.7), v = point(2.4);
  // Jets in 2 variables: q_i and v_i move along (1, i/5) and (i/7, 1).
  std::vector<varia::Jet2> qj(kSize), vj(kSize), g(2 * kSize), g_dense(2 * kSize);
  for (int i = 0; i < kSize; ++i) {
    qj[i] = varia::Jet2::variable(q(i), 2, 0) + (i / 5.0) * varia::Jet2::variable(0.0, 2, 1);
    vj[i] = (i / 7.0) * varia::Jet2::variable(v(i), 2, 0) + varia::Jet2::variable(0.0, 2, 1);
  }
  varia::Jet2 L, L_dense;
  REQUIRE(termwise.gradient_jet(qj.data(), vj.data(), &L, g.data()) == nullptr);
  REQUIRE(dense.gradient_jet(qj.data(), vj.data(), &L_dense, g_dense.data()) == nullptr);
  const auto gap = [](const varia::Jet2& a, const varia::Jet2& b) {
    return std::max({std::abs(a.value - b.value), (a.gradient - b.gradient).lpNorm<Eigen::Infinity>(),
                     (a.hessian - b.hessian).lpNorm<Eigen::Infinity>()});
  };
  CHECK(gap(L, L_dense) <= 1e-14);
  for (int i = 0; i < 2 * kSize; ++i) CHECK(gap(g[i], g_dense[i]) <= 1e-14);
}

TEST_CASE("a term naming a number outside (q, v) is refused when it is added, naming it") {
  Sum termwise;
  try {
    termwise.add_outside();
    FAIL("the term was accepted");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()) == "a term names velocity 5 of 5");
  }
}

namespace {

// L = sum_i (1 + i) v_i^2 / 2 + 0.25 v_0 v_1 + sum_i c_i sin(q_i) q_{i+1}^2: a constant mass matrix
// (with a coupling of v_0 and v_1), declared nowhere; `branch` adds a term that branches on q_0.
class Separable final : public varia::sdk::TermwiseLagrangian {
 public:
  explicit Separable(bool branch = false) : TermwiseLagrangian(kSize, kSize) {
    for (int i = 0; i < kSize; ++i) add_term(Kinetic{1.0 + i}, {velocity(i)});
    add_term([]<class T>(const TermVec<T, 2>& x) -> T { return 0.25 * x(0) * x(1); }, {velocity(0), velocity(1)});
    for (int i = 0; i + 1 < kSize; ++i) add_term(Coupling{0.3 + 0.1 * i}, {position(i), position(i + 1)});
    if (branch) add_term([]<class T>(const TermVec<T, 1>& x) -> T { return x(0) > 0.0 ? x(0) : -x(0); }, {position(0)});
  }
};

}  // namespace

TEST_CASE("a term-wise Lagrangian's constant mass matrix is read off its terms, declared nowhere (issue #39: a "
          "term-wise model that did not declare it stepped Stormer-Verlet by Newton's method)") {
  Separable separable;
  REQUIRE(separable.has_constant_mass_matrix());
  MatrixXd mass(kSize, kSize), expected = MatrixXd::Zero(kSize, kSize);
  REQUIRE(separable.constant_mass_matrix(mass.data()));
  for (int i = 0; i < kSize; ++i) expected(i, i) = 1.0 + i;
  expected(0, 1) = expected(1, 0) = 0.25;
  CHECK((mass - expected).cwiseAbs().maxCoeff() < 1e-15);
  // A mass depending on q (Inertia in Sum), or a term that branches on q: not read as constant.
  Sum varying;
  CHECK_FALSE(varying.has_constant_mass_matrix());
  CHECK_FALSE(varying.constant_mass_matrix(mass.data()));
  Separable branching(true);
  CHECK_FALSE(branching.has_constant_mass_matrix());
}
