// The trapezoidal rule on [0, 1]: int_0^1 f ~= (f(0) + f(1))/2. Nodes 0 and 1, weights 1/2 each;
// exact for degree 1 and symmetric. With the midpoint one-step method it gives the paper's
// shooting-based example of sec. 3 ("Examples"), whose nodes include the endpoints.
#include <array>
#include <stdexcept>

#include "varia/core/quadrature.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

class Trapezoid final : public varia::Quadrature {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {},
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "degree": 1,
    "order": 2,
    "symmetric": true,
    "nodes_include_endpoints": true
  })";

  Trapezoid(const nlohmann::json& parameters, const varia::sdk::Context&) {
    if (!parameters.empty())
      throw std::invalid_argument("trapezoid takes no parameters, got " + parameters.dump());
  }

  int size() const noexcept override { return 2; }
  const double* nodes() const noexcept override { return kNodes.data(); }
  const double* weights() const noexcept override { return kWeights.data(); }
  int degree() const noexcept override { return 1; }
  bool symmetric() const noexcept override { return true; }

 private:
  static constexpr std::array<double, 2> kNodes{0.0, 1.0}, kWeights{0.5, 0.5};
};

}  // namespace

VARIA_PLUGIN(Trapezoid, quadrature, trapezoid)
