// Gauss-Lobatto quadrature on [0, 1] with n = `points` >= 2 nodes: the endpoints and the zeros of
// P'_{n-1}, mapped by c_i = (1 + x_i)/2, with b_i = 1 / (n (n - 1) P_{n-1}(x_i)^2) (A&S 25.4.32,
// halved for [0, 1]; at the endpoints P_{n-1}(+-1)^2 = 1). It integrates polynomials of degree
// 2n - 3 exactly and is symmetric; its nodes include 0 and 1, as the shooting-based discrete
// Lagrangian's quadrature does (paper, sec. 3). Points 2 and 3 are the trapezoid and Simpson rules.
// Computed at construction to full double precision (legendre.hpp).
#include "legendre.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

namespace legendre = varia::plugins::legendre;

legendre::Rule gauss_lobatto_rule(int n) {
  std::vector<long double> x = legendre::nonnegative_zeros(n - 1, 1);
  x.push_back(1.0L);
  std::vector<long double> w;
  for (const long double xi : x) {
    const long double p = legendre::evaluate(n - 1, xi)[0];
    w.push_back(2 / (static_cast<long double>(n) * (n - 1) * p * p));
  }
  return legendre::mirrored_to_unit_interval(n, x, w);
}

class GaussLobatto final : public legendre::SymmetricRule {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "points": {"type": "integer", "minimum": 2, "maximum": 64, "default": 3,
                 "description": "n, the number of nodes: 0, 1 and the zeros of P'_{n-1}"}
    },
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "degree": "2*points-3",
    "order": "2*points-2",
    "symmetric": true,
    "nodes_include_endpoints": true
  })";

  GaussLobatto(const nlohmann::json& parameters, const varia::sdk::Context&)
      : SymmetricRule(
            gauss_lobatto_rule(legendre::points_parameter(parameters, "gauss-lobatto", 2, 3))) {}

  int degree() const noexcept override { return 2 * size() - 3; }
};

}  // namespace

VARIA_PLUGIN(GaussLobatto, quadrature, gauss_lobatto)
