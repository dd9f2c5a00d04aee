// Gauss-Legendre quadrature on [0, 1] with n = `points` nodes: c_i = (1 + x_i)/2 for the zeros x_i
// of P_n, b_i = 1 / ((1 - x_i^2) P_n'(x_i)^2) (A&S 25.4.29, halved for [0, 1]). It integrates
// polynomials of degree 2n - 1 exactly and is symmetric, so as the quadrature of a Galerkin or
// shooting-based discrete Lagrangian (paper, secs. 2 and 3) it contributes order 2n and
// self-adjointness. Computed at construction to full double precision (legendre.hpp).
#include "legendre.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

namespace legendre = varia::plugins::legendre;

legendre::Rule gauss_legendre_rule(int n) {
  const std::vector<long double> x = legendre::nonnegative_zeros(n, 0);
  std::vector<long double> w;
  for (const long double xi : x) {
    const long double dp = legendre::evaluate(n, xi)[1];
    w.push_back(2 / ((1 - xi * xi) * dp * dp));
  }
  return legendre::mirrored_to_unit_interval(n, x, w);
}

class GaussLegendre final : public legendre::SymmetricRule {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "points": {"type": "integer", "minimum": 1, "maximum": 64, "default": 2,
                 "description": "n, the number of nodes: the zeros of the Legendre polynomial P_n"}
    },
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "degree": "2*points-1",
    "order": "2*points",
    "symmetric": true,
    "nodes_include_endpoints": false
  })";

  GaussLegendre(const nlohmann::json& parameters, const varia::sdk::Context&)
      : SymmetricRule(
            gauss_legendre_rule(legendre::points_parameter(parameters, "gauss-legendre", 1, 2))) {}

  int degree() const noexcept override { return 2 * size() - 1; }
};

}  // namespace

VARIA_PLUGIN(GaussLegendre, quadrature, gauss_legendre)
