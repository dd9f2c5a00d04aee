// The Lie group manifold conformance suite (varia/sdk/conformance/manifold.hpp) on the bundled
// groups, at random points, on a group that breaks the SDK adapter's hypothesis (a composition
// that is not affine in its second factor), and on a chart whose first derivatives asked alone
// are wrong: the suite must refuse both.
#include <doctest/doctest.h>

#include <random>
#include <utility>
#include <vector>

#include "load_plugin.hpp"
#include "varia/sdk/conformance/manifold.hpp"
#include "varia/sdk/lie_group.hpp"

namespace {

using nlohmann::json;
using varia::test::load_plugin;

// Random points g = g0 exp(xi) of the manifold, from a point g0 on it.
Eigen::VectorXd random_point(varia::Manifold& manifold, const Eigen::VectorXd& g0, std::mt19937& engine) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd xi(manifold.dim()), g(manifold.point_size());
  for (auto& x : xi) x = normal(engine);
  REQUIRE(manifold.retract(g0.data(), xi.data(), g.data()) == nullptr);
  return g;
}

// R under addition, a group the suite passes, whose chart then lies about its gradient away from
// 0 when asked without the Hessian (a hand-written first-order path that went wrong).
struct Line {
  static constexpr int point_size = 1, dim = 1;
  template <class T>
  static void compose(const T* a, const T* b, T* ab) {
    ab[0] = a[0] + b[0];
  }
  static void inverse(const double* a, double* a_inverse) { a_inverse[0] = -a[0]; }
  template <class T>
  static void exp(const T* xi, T* g) {
    g[0] = xi[0];
  }
  template <class T>
  static void log(const T* g, T* xi) {
    xi[0] = g[0];
  }
  template <class T>
  static void bracket(const T*, const T*, T* ab) {
    ab[0] = T(0.0);
  }
};

// The same group embedded as (x, x^3): its composition (a, b) -> (a0 + b0, (a0 + b0)^3) is not
// affine in b, so compose(q, e + E) - q is not the tangent vector. log and the bracket are Line's.
struct Cubic : Line {
  static constexpr int point_size = 2;
  template <class T>
  static void compose(const T* a, const T* b, T* ab) {
    ab[0] = a[0] + b[0];
    ab[1] = ab[0] * ab[0] * ab[0];
  }
  static void inverse(const double* a, double* a_inverse) {
    a_inverse[0] = -a[0];
    a_inverse[1] = -a[1];
  }
  template <class T>
  static void exp(const T* xi, T* g) {
    g[0] = xi[0];
    g[1] = xi[0] * xi[0] * xi[0];
  }
};

class CubicLine final : public varia::sdk::LieGroupManifold<Cubic> {
 public:
  bool contains(const double* q, char*, int) noexcept override { return std::abs(q[1] - q[0] * q[0] * q[0]) < 1e-12; }
};

class LyingLine final : public varia::sdk::LieGroupManifold<Line> {
 public:
  bool contains(const double*, char*, int) noexcept override { return true; }
  varia::Status chart(const double* q0, const double* xi, const double* xi_dot, varia::Derivatives point,
                      varia::Derivatives velocity) noexcept override {
    varia::Status status = LieGroupManifold::chart(q0, xi, xi_dot, point, velocity);
    if (xi[0] != 0.0 && point.hessian == nullptr && point.gradient != nullptr) point.gradient[1] *= 1.5;
    return status;
  }
};

// The bundled Lie groups, each with a point of it to start random points from (SE3's translated).
std::vector<std::pair<const char*, Eigen::VectorXd>> bundled_groups() {
  return {{"SO3", (Eigen::VectorXd(9) << 1, 0, 0, 0, 1, 0, 0, 0, 1).finished()},
          {"SE3", (Eigen::VectorXd(12) << 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.3, -2, 5).finished()}};
}

}  // namespace

TEST_CASE("the Lie group conformance suite passes SO3 and SE3 at random points, with the generators' Taylor test") {
  std::mt19937 engine(20261124);
  for (const auto& [type, identity] : bundled_groups()) {
    CAPTURE(type);
    auto file = load_plugin("manifold", type);
    auto manifold = file.create<varia::Manifold>(json::object(), json::object());
    for (int trial = 0; trial < 5; ++trial) {
      const auto failures = varia::sdk::conformance::check_lie_group(*manifold, random_point(*manifold, identity, engine), engine);
      for (const auto& failure : failures.list()) FAIL_CHECK(failure);
      CHECK(failures.empty());
    }
  }
}

TEST_CASE("the Lie group conformance suite refuses a group whose composition is not affine in its second factor") {
  std::mt19937 engine(7);
  CubicLine line;
  const Eigen::Vector2d q(0.7, 0.343);
  const auto failures = varia::sdk::conformance::check_lie_group(line, q, engine);
  REQUIRE_FALSE(failures.empty());
  bool names_generators = false;
  for (const auto& failure : failures.list()) names_generators |= failure.find("generators") != std::string::npos;
  CHECK(names_generators);
}

TEST_CASE("the Lie group conformance suite refuses a chart whose gradient without the Hessian is not the one with it") {
  std::mt19937 engine(11);
  LyingLine line;
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.4);
  const auto failures = varia::sdk::conformance::check_lie_group(line, q, engine);
  REQUIRE_FALSE(failures.empty());
  bool names_chart = false;
  for (const auto& failure : failures.list()) names_chart |= failure.find("without the Hessian") != std::string::npos;
  CHECK(names_chart);
  // The same group without the lie passes.
  class HonestLine final : public varia::sdk::LieGroupManifold<Line> {
   public:
    bool contains(const double*, char*, int) noexcept override { return true; }
  } honest;
  CHECK(varia::sdk::conformance::check_lie_group(honest, q, engine).empty());
}

TEST_CASE("SO3 and SE3 give their generators at a point (constant jets, composed in doubles) equal to the bit to the "
          "values of the generators at jets of the point's numbers") {
  std::mt19937 engine(20261128);
  for (const auto& [type, identity] : bundled_groups()) {
    CAPTURE(type);
    auto file = load_plugin("manifold", type);
    auto manifold = file.create<varia::Manifold>(json::object(), json::object());
    const int m = manifold->point_size(), n = manifold->dim();
    const Eigen::VectorXd g = random_point(*manifold, identity, engine);
    std::vector<varia::Jet2> at_point(m), at_jets(m), D_point(m * n), D_jets(m * n);
    for (int k = 0; k < m; ++k) at_point[k] = varia::Jet2(g[k]), at_jets[k] = varia::Jet2::variable(g[k], m, k);
    REQUIRE(manifold->generators(at_point.data(), D_point.data()) == nullptr);
    REQUIRE(manifold->generators(at_jets.data(), D_jets.data()) == nullptr);
    int differing = 0, constant = 0;
    for (int i = 0; i < m * n; ++i) {
      differing += D_point[i].value != D_jets[i].value;
      constant += D_point[i].constant();
    }
    CHECK(differing == 0);
    CHECK(constant == m * n);
  }
}
