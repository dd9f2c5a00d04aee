// Simpson's rule on [0, 1]: int_0^1 f ~= (f(0) + 4 f(1/2) + f(1))/6. Exact for degree 3 (one more
// than its three nodes suggest, by symmetry) and symmetric; the quadrature of the paper's
// sviRK4Sim method (sec. 3, "Examples": RK4 shooting with Simpson's rule).
#include <array>
#include <stdexcept>

#include "varia/core/quadrature.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

class Simpson final : public varia::Quadrature {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {},
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "degree": 3,
    "order": 4,
    "symmetric": true,
    "nodes_include_endpoints": true
  })";

  Simpson(const nlohmann::json& parameters, const varia::sdk::Context&) {
    if (!parameters.empty())
      throw std::invalid_argument("simpson takes no parameters, got " + parameters.dump());
  }

  int size() const noexcept override { return 3; }
  const double* nodes() const noexcept override { return kNodes.data(); }
  const double* weights() const noexcept override { return kWeights.data(); }
  int degree() const noexcept override { return 3; }
  bool symmetric() const noexcept override { return true; }

 private:
  static constexpr std::array<double, 3> kNodes{0.0, 0.5, 1.0}, kWeights{1.0 / 6, 2.0 / 3, 1.0 / 6};
};

}  // namespace

VARIA_PLUGIN(Simpson, quadrature, simpson)
