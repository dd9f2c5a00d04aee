// The s-stage Gauss collocation method (Hairer, Lubich & Wanner, sec. II.1.3): collocation at the
// zeros of the shifted Legendre polynomial P_s(2t - 1), order 2s, self-adjoint and symplectic.
// s = 2 is the paper's SRK4 (sec. 3 "Examples"); s = 1 the implicit midpoint rule.
#include "../quadrature/legendre.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

namespace legendre = varia::plugins::legendre;

// The Gauss-Legendre nodes on [0, 1]: the collocation points.
std::vector<double> gauss_nodes(int stages) {
  const std::vector<long double> x = legendre::nonnegative_zeros(stages, 0);
  return legendre::mirrored_to_unit_interval(stages, x, std::vector<long double>(x.size())).nodes;
}

int stages_parameter(const nlohmann::json& parameters) {
  for (const auto& item : parameters.items())
    if (item.key() != "stages")
      throw std::invalid_argument("gauss-collocation: unknown parameter '" + item.key() +
                                  "' (the only parameter is 'stages')");
  const auto value = parameters.value("stages", nlohmann::json(2));
  const double stages = value.is_number() ? value.get<double>() : std::nan("");
  if (!(stages >= 1 && stages <= 8 && stages == std::floor(stages)))
    throw std::invalid_argument("gauss-collocation: 'stages' must be an integer from 1 to 8, got " +
                                value.dump());
  return static_cast<int>(stages);
}

class GaussCollocation final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "stages": {"type": "integer", "minimum": 1, "maximum": 8, "default": 2,
                 "description": "s, the number of Gauss-Legendre collocation points"}
    },
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "order": "2*stages",
    "self_adjoint": true,
    "symplectic": true,
    "equivariance": "affine",
    "implicit": true
  })";

  GaussCollocation(const nlohmann::json& parameters, const varia::sdk::Context&)
      : GaussCollocation(stages_parameter(parameters)) {}

 private:
  explicit GaussCollocation(int stages)
      : RungeKutta(varia::sdk::collocation_tableau(gauss_nodes(stages)), 2 * stages, true) {}
};

}  // namespace

VARIA_PLUGIN(GaussCollocation, one_step, gauss_collocation)
