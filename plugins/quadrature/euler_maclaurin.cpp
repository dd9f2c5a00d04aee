// The Euler-Maclaurin formula on [0, h] (paper, sec. 3 "More general quadrature formulas" and
// "Examples": sviRK4EM), truncated after `terms` terms:
//   terms = 1: h/2 (f(0) + f(h)), the trapezoidal rule, degree 1;
//   terms = 2: + h^2/12 (f'(0) - f'(h)), degree 3 (order 4).
// The shooting construction supplies f' = dL/dt from the prolongation of the Euler-Lagrange
// vector field. The next term, h^4/720 (f'''(h) - f'''(0)), would need third derivatives of L
// along the flow at jets, which the construction does not compute: terms <= 2.
#include <array>
#include <cmath>
#include <stdexcept>

#include "varia/abi/quadrature.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

int terms_parameter(const nlohmann::json& parameters) {
  for (const auto& item : parameters.items())
    if (item.key() != "terms")
      throw std::invalid_argument("euler-maclaurin: unknown parameter '" + item.key() +
                                  "' (the only parameter is 'terms')");
  const auto value = parameters.value("terms", nlohmann::json(2));
  if (!value.is_number_integer() || value.get<int>() < 1 || value.get<int>() > 2)
    throw std::invalid_argument("euler-maclaurin: 'terms' must be 1 or 2, got " + value.dump());
  return value.get<int>();
}

class EulerMaclaurin final : public varia::Quadrature {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "terms": {"type": "integer", "minimum": 1, "maximum": 2, "default": 2,
                "description": "1: the trapezoidal rule; 2: adds h^2/12 (f'(0) - f'(h))"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"({
    "degree": "2*terms-1",
    "order": "2*terms",
    "symmetric": true,
    "nodes_include_endpoints": true,
    "derivative_terms": "terms-1"
  })";

  EulerMaclaurin(const nlohmann::json& parameters, const varia::sdk::Context&)
      : terms_(terms_parameter(parameters)) {}

  int size() const noexcept override { return 2; }
  const double* nodes() const noexcept override { return kNodes.data(); }
  const double* weights() const noexcept override { return kWeights.data(); }
  int degree() const noexcept override { return 2 * terms_ - 1; }
  // Symmetric also with the end correction: t -> h - t maps f'(0) - f'(h) to itself.
  bool symmetric() const noexcept override { return true; }
  int derivative_terms() const noexcept override { return terms_ - 1; }
  const double* derivative_weights(int k) const noexcept override {
    return k == 1 && terms_ == 2 ? kFirstDerivative.data() : nullptr;
  }

 private:
  static constexpr std::array<double, 2> kNodes{0.0, 1.0}, kWeights{0.5, 0.5};
  static constexpr std::array<double, 2> kFirstDerivative{1.0 / 12, -1.0 / 12};
  int terms_;
};

}  // namespace

VARIA_PLUGIN(EulerMaclaurin, quadrature, euler_maclaurin)
