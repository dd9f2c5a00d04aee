// The product manifold (plugins/manifold/product.cpp): the Lie group conformance suite on products
// of the bundled groups and of R^n with a group, the factors' own operations on their blocks, the
// structure it declares (a vector space, a Lie group, or `product` where a factor is neither), and
// a factor's failure named by its index.
#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

#include "load_plugin.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/sdk/conformance/manifold.hpp"

namespace {

using nlohmann::json;
using varia::Manifold;
using varia::ManifoldStructure;
using varia::test::load_plugin;

// Factors made from the bundled plugins, kept alive with their libraries, and products of them.
struct Factors {
  std::vector<varia::test::LoadedPlugin> files;
  std::vector<std::shared_ptr<Manifold>> made;

  Manifold& add(const std::string& type, const json& parameters = json::object()) {
    files.push_back(load_plugin("manifold", type));
    made.push_back(files.back().create<Manifold>(parameters, json::object()));
    return *made.back();
  }
  std::shared_ptr<Manifold> product() {
    std::vector<varia::Part> parts;
    for (const auto& factor : made) parts.push_back(varia::Part{"factors", factor.get()});
    files.push_back(load_plugin("manifold", "product"));
    return files.back().create<Manifold>(json{{"factors", json(made.size(), json{{"type", "factor"}})}},
                                         json::object(), parts);
  }
};

// A point of the product: the factors' points g_f exp(xi_f), xi random.
Eigen::VectorXd product_point(Manifold& product, const Eigen::VectorXd& start, std::mt19937& engine) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd xi(product.dim()), g(product.point_size());
  for (auto& x : xi) x = normal(engine);
  REQUIRE(product.retract(start.data(), xi.data(), g.data()) == nullptr);
  return g;
}

const Eigen::VectorXd kRotationIdentity = (Eigen::VectorXd(9) << 1, 0, 0, 0, 1, 0, 0, 0, 1).finished();

// A manifold that is neither a vector space nor a Lie group (it only declares so).
class Homogeneous final : public Manifold {
 public:
  int point_size() const noexcept override { return 3; }
  int dim() const noexcept override { return 2; }
  ManifoldStructure structure() const noexcept override { return ManifoldStructure::homogeneous_space; }
  varia::Status retract(const double*, const double*, double*) noexcept override { return "not here"; }
  varia::Status local(const double*, const double*, double*) noexcept override { return "not here"; }
  bool contains(const double*, char*, int) noexcept override { return true; }
};

}  // namespace

TEST_CASE("the product of SO3, SE3 and R^2 passes the Lie group conformance suite at random points") {
  Factors factors;
  factors.add("SO3");
  factors.add("SE3");
  factors.add("Rn", {{"dim", 2}});
  const auto product = factors.product();
  CHECK(product->point_size() == 9 + 12 + 2);
  CHECK(product->dim() == 3 + 6 + 2);
  CHECK(product->structure() == ManifoldStructure::lie_group);
  CHECK(product->has_constraint());
  Eigen::VectorXd start(23);
  start << kRotationIdentity, kRotationIdentity, 0.3, -2, 5, 1.5, -0.5;
  std::mt19937 engine(20261129);
  for (int trial = 0; trial < 4; ++trial) {
    const auto failures = varia::sdk::conformance::check_lie_group(*product, product_point(*product, start, engine), engine);
    for (const auto& failure : failures.list()) FAIL_CHECK(failure);
    CHECK(failures.empty());
  }
}

TEST_CASE("the product's operations are its factors' on their blocks") {
  Factors factors;
  Manifold& so3 = factors.add("SO3");
  Manifold& rn = factors.add("Rn", {{"dim", 2}});
  const auto product = factors.product();
  std::mt19937 engine(3);
  Eigen::VectorXd start(11);
  start << kRotationIdentity, 0.25, 4.0;
  const Eigen::VectorXd q0 = product_point(*product, start, engine);
  const Eigen::VectorXd xi = (Eigen::VectorXd(5) << 0.3, -0.2, 0.9, 1.5, -2.0).finished();
  Eigen::VectorXd q(11), q_so3(9), q_rn(2), back(5), back_so3(3);
  REQUIRE(product->retract(q0.data(), xi.data(), q.data()) == nullptr);
  REQUIRE(so3.retract(q0.data(), xi.data(), q_so3.data()) == nullptr);
  REQUIRE(rn.retract(q0.data() + 9, xi.data() + 3, q_rn.data()) == nullptr);
  CHECK((q.head(9) - q_so3).norm() == 0.0);
  CHECK((q.tail(2) - q_rn).norm() == 0.0);
  REQUIRE(product->local(q0.data(), q.data(), back.data()) == nullptr);
  REQUIRE(so3.local(q0.data(), q.data(), back_so3.data()) == nullptr);
  CHECK((back.head(3) - back_so3).norm() == 0.0);
  CHECK((back - xi).norm() < 1e-14);
  // The generators: SO3's in its block, the identity on R^2, zeros elsewhere.
  std::vector<varia::Jet2> at(11), D(11 * 5), D_so3(9 * 3);
  for (int k = 0; k < 11; ++k) at[k] = varia::Jet2(q0[k]);
  REQUIRE(product->generators(at.data(), D.data()) == nullptr);
  REQUIRE(so3.generators(at.data(), D_so3.data()) == nullptr);
  for (int k = 0; k < 11; ++k)
    for (int a = 0; a < 5; ++a) {
      CAPTURE(k);
      CAPTURE(a);
      const double expected = k < 9 && a < 3 ? D_so3[k * 3 + a].value : k >= 9 && a >= 3 && k - 9 == a - 3 ? 1.0 : 0.0;
      CHECK(D[k * 5 + a].value == expected);
    }
}

TEST_CASE("a product declares a vector space of vector spaces, and refuses to be a Lie group with a factor of another "
          "structure") {
  Factors spaces;
  spaces.add("Rn", {{"dim", 2}});
  spaces.add("Rn", {{"dim", 3}});
  CHECK(spaces.product()->structure() == ManifoldStructure::vector_space);
  CHECK_FALSE(spaces.product()->has_constraint());

  Factors mixed;
  mixed.add("SO3");
  mixed.made.push_back(std::make_shared<Homogeneous>());
  CHECK(mixed.product()->structure() == ManifoldStructure::product);
}

TEST_CASE("a product names the factor that failed and what it said") {
  Factors factors;
  factors.add("Rn", {{"dim", 1}});
  factors.add("SO3");
  const auto product = factors.product();
  Eigen::VectorXd q(10);
  q << 0.5, 1, 0, 0, 0, 1, 0, 0, 0, -1;  // a reflection, not a rotation
  char why[256] = {};
  CHECK_FALSE(product->contains(q.data(), why, sizeof why));
  CHECK(std::string(why).rfind("factor 1: ", 0) == 0);
  q(9) = 1;
  CHECK(product->contains(q.data(), why, sizeof why));
  CHECK(product->constraint_error(q.data()) < 1e-15);
}

TEST_CASE("a product made without the parts its factors name is refused") {
  auto file = load_plugin("manifold", "product");
  CHECK_THROWS_WITH_AS(file.create<Manifold>(json{{"factors", json::array({json{{"type", "SO3"}}})}}, json::object()),
                       doctest::Contains("manifold objects that the host makes"), std::runtime_error);
}
