// sdk::AutodiffLagrangian at every size: the stack path (m + n <= 18) and the chunked path above
// it give L, the gradient and the Hessian of the hand-written formulas of the planar Morse chain
// (morse_chain.hpp), through every evaluate() path, and at jets (the shooting construction's
// gradient_jet) above the stack size the sum of its bonds' below it.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <malloc.h>

#include "morse_chain.hpp"

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using varia::testing::DenseMorseChain;
using varia::testing::MorseChainFormula;
using varia::testing::MorseChainParameters;

struct Evaluation {
  double value = 0.0;
  VectorXd gradient;
  MatrixXd hessian;
};

Evaluation evaluate(varia::Lagrangian& lagrangian, const VectorXd& q, const VectorXd& v) {
  const int k = lagrangian.position_size() + lagrangian.velocity_size();
  Evaluation e{0.0, VectorXd(k), MatrixXd(k, k)};
  REQUIRE(lagrangian.evaluate(q.data(), v.data(), &e.value, e.gradient.data(), e.hessian.data()) == nullptr);
  return e;
}

// The largest deviations of the model's L, gradient and Hessian from the formula's, relative to
// the size of each (of L: 1 + |L|, as L is a difference of energies of order 1).
struct Deviations {
  double value, gradient, hessian;
};
Deviations deviations(varia::Lagrangian& lagrangian, const MorseChainFormula& formula, const VectorXd& q,
                      const VectorXd& v) {
  const Evaluation e = evaluate(lagrangian, q, v);
  const VectorXd g = formula.gradient(q, v);
  const MatrixXd H = formula.hessian(q);
  return {std::abs(e.value - formula.value(q, v)) / (1 + std::abs(formula.value(q, v))),
          (e.gradient - g).lpNorm<Eigen::Infinity>() / g.lpNorm<Eigen::Infinity>(),
          (e.hessian - H).lpNorm<Eigen::Infinity>() / H.lpNorm<Eigen::Infinity>()};
}

}  // namespace

TEST_CASE("a dense autodiff Lagrangian of any size gives the exact L, gradient and Hessian: the planar Morse "
          "chain of 3 particles (12 numbers, fixed size), 4 (16, stack), 5 (20, chunks) and 30 (120, chunks)") {
  for (int particles : {3, 4, 5, 30}) {
    CAPTURE(particles);
    MorseChainParameters p;
    p.particles = particles;
    p.depth = 1.7;
    p.range = 1.3;
    DenseMorseChain model(p);
    VectorXd q, v;
    varia::testing::morse_chain_state(p, 1, q, v);
    const Deviations d = deviations(model, MorseChainFormula{p}, q, v);
    MESSAGE(particles << " particles: relative deviations L " << d.value << ", gradient " << d.gradient
                      << ", Hessian " << d.hessian);
    CHECK(d.value <= 1e-15);
    CHECK(d.gradient <= 1e-14);
    CHECK(d.hessian <= 1e-14);
  }
}

// At constant inputs above the stack size, hessian_jet forms the products alone (forward over forward
// mode, the outer level over blocks of rows, the inner along one direction): the rows asked for
// times two directions equal the hand-written Hessian's.
TEST_CASE("hessian_jet at constants above the stack size (30 particles, 120 numbers) gives rows of the Hessian "
          "times directions: the hand-written Hessian's products") {
  MorseChainParameters p;
  p.depth = 1.7;
  DenseMorseChain model(p);
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 1, q, v);
  const int k = 4 * p.particles, first = 37, count = 60, directions = 2;
  const MatrixXd H = MorseChainFormula{p}.hessian(q);
  MatrixXd U(k, directions);
  for (int i = 0; i < k; ++i) U(i, 0) = std::sin(0.3 * i), U(i, 1) = std::cos(1.1 * i) * (i % 3);
  std::vector<varia::Jet2> z(k), directions_jets(k * directions), out(count * directions);
  for (int i = 0; i < k; ++i) z[i] = varia::Jet2(i < k / 2 ? q[i] : v[i - k / 2]);
  for (int j = 0; j < directions; ++j)
    for (int i = 0; i < k; ++i) directions_jets[j * k + i] = varia::Jet2(U(i, j));
  REQUIRE(model.hessian_jet(z.data(), z.data() + k / 2, first, count, directions, directions_jets.data(), out.data()) ==
          nullptr);
  const MatrixXd expected = H.middleRows(first, count) * U;
  double worst = 0.0;
  for (int j = 0; j < directions; ++j)
    for (int r = 0; r < count; ++r) worst = std::max(worst, std::abs(out[j * count + r].value - expected(r, j)));
  MESSAGE("largest deviation " << worst << " of products up to " << expected.cwiseAbs().maxCoeff());
  CHECK(worst <= 1e-13 * (1.0 + expected.cwiseAbs().maxCoeff()));
  CHECK(expected.cwiseAbs().maxCoeff() > 0.1);  // not all zeros
}

TEST_CASE("the formula check sees a wrong derivative: a chain of another range differs by far more than the "
          "tolerance") {
  MorseChainParameters p;
  DenseMorseChain model(p);
  MorseChainParameters other = p;
  other.range *= 1.001;
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 1, q, v);
  const Deviations d = deviations(model, MorseChainFormula{other}, q, v);
  CHECK(d.gradient > 1e-4);
  CHECK(d.hessian > 1e-4);
}

TEST_CASE("every evaluate() path of the chunked dense adapter gives the same numbers") {
  MorseChainParameters p;
  p.particles = 13;  // 52 numbers: 6 full chunks and one of 4
  DenseMorseChain model(p);
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 2, q, v);
  const Evaluation all = evaluate(model, q, v);
  const int k = 4 * p.particles;
  double value = 0.0;
  VectorXd gradient(k), gradient_alone(k);
  MatrixXd hessian_alone(k, k);
  // L alone is taken in doubles, with the gradient at first-order duals, with the Hessian at
  // second-order ones: the same operations on the values, rounded alike up to the last bit.
  REQUIRE(model.evaluate(q.data(), v.data(), &value, nullptr, nullptr) == nullptr);
  CHECK(value == doctest::Approx(all.value).epsilon(1e-15));
  REQUIRE(model.evaluate(q.data(), v.data(), &value, gradient.data(), nullptr) == nullptr);
  CHECK(value == doctest::Approx(all.value).epsilon(1e-15));
  CHECK((gradient - all.gradient).lpNorm<Eigen::Infinity>() <= 1e-15 * all.gradient.lpNorm<Eigen::Infinity>());
  REQUIRE(model.evaluate(q.data(), v.data(), nullptr, gradient_alone.data(), nullptr) == nullptr);
  CHECK(gradient_alone == gradient);
  REQUIRE(model.evaluate(q.data(), v.data(), nullptr, nullptr, hessian_alone.data()) == nullptr);
  CHECK(hessian_alone == all.hessian);
  CHECK(all.hessian == all.hessian.transpose());
}

namespace {

// A double pendulum's L = 1/2 v1^2 + 1/2 v2^2 + v1 v2 cos(q1 - q2) + cos q1 (m + n = 4, cross terms in
// q and v) and a pendulum's (m + n = 2), with their gradients written out for jet arithmetic.
struct Coupled : varia::sdk::AutodiffLagrangian<Coupled, 2, 2> {
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    return 0.5 * v(0) * v(0) + 0.5 * v(1) * v(1) + v(0) * v(1) * cos(q(0) - q(1)) + cos(q(0));
  }
  template <class T>
  static std::vector<T> gradient(const T* q, const T* v) {
    using std::cos;
    using std::sin;
    const T s = sin(q[0] - q[1]), c = cos(q[0] - q[1]);
    return {-(v[0] * v[1] * s) - sin(q[0]), v[0] * v[1] * s, v[0] + v[1] * c, v[1] + v[0] * c};
  }
  // Column-major in z = (q1, q2, v1, v2) (symmetric).
  template <class T>
  static std::vector<T> hessian(const T* q, const T* v) {
    using std::cos;
    using std::sin;
    const T s = sin(q[0] - q[1]), c = cos(q[0] - q[1]), w = v[0] * v[1] * c;
    return {-w - cos(q[0]), w,         -(v[1] * s), -(v[0] * s),  //
            w,              -w,        v[1] * s,    v[0] * s,     //
            -(v[1] * s),    v[1] * s,  T(1.0),      c,            //
            -(v[0] * s),    v[0] * s,  c,           T(1.0)};
  }
};
struct Single : varia::sdk::AutodiffLagrangian<Single> {
  Single() : varia::sdk::AutodiffLagrangian<Single>(1, 1) {}
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    using std::sin;
    return 0.5 * v(0) * v(0) * (2.0 + sin(q(0))) + cos(q(0));
  }
  template <class T>
  static std::vector<T> gradient(const T* q, const T* v) {
    using std::cos;
    using std::sin;
    return {0.5 * v[0] * v[0] * cos(q[0]) - sin(q[0]), v[0] * (2.0 + sin(q[0]))};
  }
  template <class T>
  static std::vector<T> hessian(const T* q, const T* v) {
    using std::cos;
    using std::sin;
    const T qv = v[0] * cos(q[0]);
    return {-(0.5 * v[0] * v[0] * sin(q[0])) - cos(q[0]), qv, qv, 2.0 + sin(q[0])};
  }
};

// The largest difference of two jets of N variables (a constant's derivatives are zero).
double jet_distance(const varia::Jet2& a, const varia::Jet2& b, int N) {
  auto gradient = [N](const varia::Jet2& j) { return j.constant() ? Eigen::VectorXd::Zero(N).eval() : Eigen::VectorXd(j.gradient); };
  auto hessian = [N](const varia::Jet2& j) { return j.constant() ? Eigen::MatrixXd::Zero(N, N).eval() : Eigen::MatrixXd(j.hessian); };
  return std::max({std::abs(a.value - b.value), (gradient(a) - gradient(b)).cwiseAbs().maxCoeff(),
                   (hessian(a) - hessian(b)).cwiseAbs().maxCoeff()});
}

// k inputs that are nonlinear functions of N jet variables (so that their Hessians are not zero),
// the last one a constant.
std::vector<varia::Jet2> jet_inputs(int k, int N) {
  std::vector<varia::Jet2> x, z;
  for (int i = 0; i < N; ++i) x.push_back(varia::Jet2::variable(0.3 + 0.2 * i, N, i));
  for (int i = 0; i < k; ++i)
    z.push_back(i == k - 1 ? varia::Jet2(0.7) : sin(x[i % N] * x[(i + 1) % N]) + 0.5 * x[(i + 2) % N] * x[(i + 2) % N]);
  return z;
}

template <class Model>
double jet_deviation(int variables) {
  Model model;
  const int m = model.position_size(), k = m + model.velocity_size(), N = variables;
  const std::vector<varia::Jet2> z = jet_inputs(k, N);
  std::vector<varia::Jet2> gradient(k);
  varia::Jet2 value;
  REQUIRE(model.gradient_jet(z.data(), z.data() + m, &value, gradient.data()) == nullptr);
  const std::vector<varia::Jet2> expected = Model::gradient(z.data(), z.data() + m);
  varia::sdk::Vec<varia::Jet2> q(m), v(k - m);
  for (int i = 0; i < k; ++i) (i < m ? q(i) : v(i - m)) = z[i];
  const varia::Jet2 L = model.template lagrangian<varia::Jet2>(q, v);
  double worst = jet_distance(value, L, N);
  for (int i = 0; i < k; ++i) worst = std::max(worst, jet_distance(gradient[i], expected[i], N));
  return worst;
}

}  // namespace

TEST_CASE("gradient_jet at jets of 2, 4 and 6 variables (dual numbers over fixed-size jets) and of 3 and 5 (over "
          "Jet2) equals jet arithmetic on the written-out gradient (issue #19: a shooting step's time went to dual "
          "numbers over 1.3 kB jets)") {
  for (int variables : {2, 3, 4, 5, 6}) {
    CAPTURE(variables);
    CHECK(jet_deviation<Single>(variables) < 1e-14);
    CHECK(jet_deviation<Coupled>(variables) < 1e-14);
  }
}

namespace {

// L's whole Hessian at jets through Lagrangian::hessian_jet: every row, times the unit directions.
varia::Status whole_hessian_jet(varia::Lagrangian& model, const varia::Jet2* q, const varia::Jet2* v,
                                varia::Jet2* hessian) {
  const int k = model.position_size() + model.velocity_size();
  std::vector<varia::Jet2> identity(static_cast<std::size_t>(k) * k, varia::Jet2(0.0));
  for (int j = 0; j < k; ++j) identity[static_cast<std::size_t>(j) * k + j] = varia::Jet2(1.0);
  return model.hessian_jet(q, v, 0, k, k, identity.data(), hessian);
}

// The largest difference between L's Hessian at jets of N variables (hessian_jet) and jet
// arithmetic on the written-out Hessian.
template <class Model>
double hessian_jet_deviation(int N) {
  Model model;
  const int m = model.position_size(), k = m + model.velocity_size();
  const std::vector<varia::Jet2> z = jet_inputs(k, N);
  std::vector<varia::Jet2> hessian(k * k);
  REQUIRE(whole_hessian_jet(model, z.data(), z.data() + m, hessian.data()) == nullptr);
  const std::vector<varia::Jet2> expected = Model::hessian(z.data(), z.data() + m);
  double worst = 0.0;
  for (int i = 0; i < k * k; ++i) worst = std::max(worst, jet_distance(hessian[i], expected[i], N));
  return worst;
}

}  // namespace

TEST_CASE("hessian_jet at jets of 1 to 6 variables (forward over forward mode with jet values) equals jet "
          "arithmetic on the written-out Hessian, and more are refused with the limit (issue #18: the lagrangian form "
          "of shooting with a configuration-dependent mass matrix)") {
  for (int variables = 1; variables <= 6; ++variables) {
    CAPTURE(variables);
    CHECK(hessian_jet_deviation<Single>(variables) < 1e-14);
    CHECK(hessian_jet_deviation<Coupled>(variables) < 1e-14);
  }
  Coupled model;
  CHECK(model.hessian_jet_variables() == 6);
  std::vector<varia::Jet2> hessian(16);
  const std::vector<varia::Jet2> z = jet_inputs(4, 7);
  const varia::Status status = whole_hessian_jet(model, z.data(), z.data() + 2, hessian.data());
  REQUIRE(status != nullptr);
  CHECK(std::string(status) == "an autodiff Lagrangian gives its Hessian at jets of at most 6 variables "
                               "(hessian_jet_variables())");
  // Constant inputs: the Hessian at doubles.
  const std::vector<varia::Jet2> constants(4, varia::Jet2(0.4));
  REQUIRE(whole_hessian_jet(model, constants.data(), constants.data() + 2, hessian.data()) == nullptr);
  const std::vector<double> at(4, 0.4);
  const std::vector<double> expected = Coupled::hessian(at.data(), at.data() + 2);
  for (int i = 0; i < 16; ++i) {
    CHECK(hessian[i].constant());
    CHECK(hessian[i].value == doctest::Approx(expected[i]).epsilon(1e-15));
  }
}

namespace {

// n coupled pendulums with configuration-dependent masses, L = sum_i [1/2 v_i^2 (2 + sin q_i) + cos q_i]
// + 1/2 sum_i cos(q_i - q_{i+1}), sizes read at run time, with its Hessian written out for jet arithmetic.
struct VaryingMassChain : varia::sdk::AutodiffLagrangian<VaryingMassChain> {
  explicit VaryingMassChain(int n) : varia::sdk::AutodiffLagrangian<VaryingMassChain>(n, n), n_(n) {}
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    using std::sin;
    T L = T(0.0);
    for (int i = 0; i < n_; ++i) L += 0.5 * v(i) * v(i) * (2.0 + sin(q(i))) + cos(q(i));
    for (int i = 0; i + 1 < n_; ++i) L += 0.5 * cos(q(i) - q(i + 1));
    return L;
  }
  // Column-major in z = (q, v).
  template <class T>
  std::vector<T> hessian(const T* q, const T* v) const {
    using std::cos;
    using std::sin;
    const int k = 2 * n_;
    std::vector<T> H(k * k, T(0.0));
    auto add = [&](int r, int c, const T& x) { H[c * k + r] = H[c * k + r] + x; };
    for (int i = 0; i < n_; ++i) {
      add(i, i, -(0.5 * v[i] * v[i] * sin(q[i])) - cos(q[i]));
      add(i, n_ + i, v[i] * cos(q[i]));
      add(n_ + i, i, v[i] * cos(q[i]));
      add(n_ + i, n_ + i, 2.0 + sin(q[i]));
    }
    for (int i = 0; i + 1 < n_; ++i) {
      const T c = 0.5 * cos(q[i] - q[i + 1]);
      add(i, i, -c), add(i + 1, i + 1, -c), add(i, i + 1, c), add(i + 1, i, c);
    }
    return H;
  }
  int n_;
};

}  // namespace

TEST_CASE("hessian_jet above the stack size (a dense model of 10 + 10 numbers with a configuration-dependent mass "
          "matrix, over the workspace's dual numbers) equals jet arithmetic on the written-out Hessian at jets of 1 "
          "to 6 variables and at constants (issue #39: it was refused above 18 numbers)") {
  VaryingMassChain model(10);
  CHECK(model.hessian_jet_variables() == 6);
  const int k = 20;
  for (int N = 1; N <= 6; ++N) {
    CAPTURE(N);
    const std::vector<varia::Jet2> z = jet_inputs(k, N);
    std::vector<varia::Jet2> hessian(k * k);
    REQUIRE(whole_hessian_jet(model, z.data(), z.data() + 10, hessian.data()) == nullptr);
    const std::vector<varia::Jet2> expected = model.hessian(z.data(), z.data() + 10);
    double worst = 0.0;
    for (int i = 0; i < k * k; ++i) worst = std::max(worst, jet_distance(hessian[i], expected[i], N));
    CHECK(worst < 1e-14);
  }
  const std::vector<varia::Jet2> constants(k, varia::Jet2(0.4));
  std::vector<varia::Jet2> hessian(k * k);
  REQUIRE(whole_hessian_jet(model, constants.data(), constants.data() + 10, hessian.data()) == nullptr);
  const std::vector<double> at(k, 0.4);
  const std::vector<double> expected = model.hessian(at.data(), at.data() + 10);
  for (int i = 0; i < k * k; ++i) {
    CHECK(hessian[i].constant());
    CHECK(hessian[i].value == doctest::Approx(expected[i]).epsilon(1e-15));
  }
}

TEST_CASE("hessian_jet gives the rows it is asked for times directions that are themselves jets: the velocity rows "
          "times (v, 0) and the unit velocity directions, as the Euler-Lagrange field asks (ABI 19), equal jet "
          "arithmetic on the written-out Hessian") {
  VaryingMassChain model(10);
  const int n = 10, k = 20;
  for (int N : {1, 4, 6}) {
    CAPTURE(N);
    const std::vector<varia::Jet2> z = jet_inputs(k, N);
    std::vector<varia::Jet2> directions(static_cast<std::size_t>(n + 1) * k, varia::Jet2(0.0));
    for (int j = 0; j < n; ++j) directions[static_cast<std::size_t>(j) * k + n + j] = varia::Jet2(1.0);
    for (int c = 0; c < n; ++c) directions[static_cast<std::size_t>(n) * k + c] = z[n + c];
    std::vector<varia::Jet2> out(static_cast<std::size_t>(n) * (n + 1));
    REQUIRE(model.hessian_jet(z.data(), z.data() + n, n, n, n + 1, directions.data(), out.data()) == nullptr);
    const std::vector<varia::Jet2> H = model.hessian(z.data(), z.data() + n);
    double worst = 0.0;
    for (int r = 0; r < n; ++r) {
      for (int j = 0; j < n; ++j) worst = std::max(worst, jet_distance(out[j * n + r], H[(n + j) * k + n + r], N));
      varia::Jet2 along(0.0);
      for (int c = 0; c < n; ++c) along += H[c * k + n + r] * z[n + c];
      worst = std::max(worst, jet_distance(out[n * n + r], along, N));
    }
    CHECK(worst < 1e-13);
  }
}

namespace {
// The bytes this process holds from malloc (glibc: small blocks and mmapped ones).
std::size_t heap_bytes() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}
}  // namespace

TEST_CASE("a dense model of sizes read at run time allocates at construction only its value's inputs, each "
          "workspace comes at its first use, and the Hessian at constants takes the products' dual numbers, not "
          "an (m + n)^2 workspace (one was allocated at construction: 134 MB for 2048 + 2048 numbers)") {
  const int n = 2048, k = 2 * n;
  const std::size_t before = heap_bytes();
  VaryingMassChain large(n);
  CHECK(heap_bytes() - before < 64 * static_cast<std::size_t>(k));

  // The whole Hessian at constant jets above the stack size: a workspace of m + n dual numbers of the
  // products (each 8 x 2 + 2 doubles), sized at the first call, where the (m + n)^2 Hessian was.
  VaryingMassChain small(100);
  const std::vector<varia::Jet2> constants(200, varia::Jet2(0.4));
  std::vector<varia::Jet2> hessian(200 * 200);
  const std::size_t asked = heap_bytes();
  REQUIRE(whole_hessian_jet(small, constants.data(), constants.data() + 100, hessian.data()) == nullptr);
  CHECK(heap_bytes() - asked > 0);
  CHECK(heap_bytes() - asked < 200 * 200 * sizeof(double) / 4);
  const std::size_t again = heap_bytes();
  REQUIRE(whole_hessian_jet(small, constants.data(), constants.data() + 100, hessian.data()) == nullptr);
  CHECK(heap_bytes() == again);  // sized once
}

TEST_CASE("above the stack size a dense autodiff Lagrangian evaluates at jets (over its workspace's dual numbers): "
          "a Morse chain of 5 particles (20 numbers) gives the sum of its 4 bonds' gradient jets, each a 2-particle "
          "chain of 8 numbers on the stack path, and of the kinetic term's") {
  MorseChainParameters p;
  p.particles = 5;
  p.mass = 1.5;
  DenseMorseChain chain(p);
  MorseChainParameters pair = p;
  pair.particles = 2;
  pair.mass = 0.0;
  DenseMorseChain bond(pair);
  const int n = 2 * p.particles, N = 5;
  VectorXd q0, v0;
  varia::testing::morse_chain_state(p, 2, q0, v0);
  const std::vector<varia::Jet2> wiggle = jet_inputs(2 * n, N);  // nonlinear in the N jet variables
  std::vector<varia::Jet2> q(n), v(n), gradient(2 * n);
  for (int i = 0; i < n; ++i) {
    q[i] = 0.1 * (wiggle[i] - wiggle[i].value) + q0(i);
    v[i] = 0.1 * (wiggle[n + i] - wiggle[n + i].value) + v0(i);
  }
  varia::Jet2 value;
  REQUIRE(chain.evaluates_at_jets());
  REQUIRE(chain.gradient_jet(q.data(), v.data(), &value, gradient.data()) == nullptr);

  varia::Jet2 expected_value;
  std::vector<varia::Jet2> expected(2 * n, varia::Jet2(0.0));
  for (int i = 0; i < n; ++i) {
    expected_value += 0.5 * p.mass * v[i] * v[i];
    expected[n + i] = p.mass * v[i];
  }
  for (int b = 0; b + 1 < p.particles; ++b) {
    varia::Jet2 bond_value;
    std::vector<varia::Jet2> bond_gradient(8);
    REQUIRE(bond.gradient_jet(q.data() + 2 * b, v.data() + 2 * b, &bond_value, bond_gradient.data()) == nullptr);
    expected_value += bond_value;
    for (int i = 0; i < 4; ++i) expected[2 * b + i] += bond_gradient[i];
  }
  double worst = jet_distance(value, expected_value, N);
  for (int i = 0; i < 2 * n; ++i) worst = std::max(worst, jet_distance(gradient[i], expected[i], N));
  CHECK(worst < 1e-13);
  // A wrong derivative is seen: the chain of another range differs by far more.
  MorseChainParameters other = p;
  other.range = 1.01;
  DenseMorseChain wrong(other);
  REQUIRE(wrong.gradient_jet(q.data(), v.data(), &value, gradient.data()) == nullptr);
  double far = 0.0;
  for (int i = 0; i < n; ++i) far = std::max(far, jet_distance(gradient[i], expected[i], N));
  CHECK(far > 1e-4);
}
